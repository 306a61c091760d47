//! A whole toolpath planned into a program, the report left out.
//!
//! Owns [`plan_toolpath`], the plain entry of planning. It must not plan by itself: the
//! dispatch (`driver`) does.

use super::{plan_toolpath_report, PlanError, PlanOptions};
use crate::program::PvtProgram;
use crate::toolpath::Toolpath;

/// Plans every contour of a toolpath on the axes it moves with the chosen planner.
/// Contours that do not move (every point the same) are left out.
pub fn plan_toolpath(toolpath: &Toolpath, options: &PlanOptions) -> Result<PvtProgram, PlanError> {
    plan_toolpath_report(toolpath, options).map(|planned| planned.program)
}
