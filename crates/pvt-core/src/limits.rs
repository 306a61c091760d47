//! The machine model: what each axis may do (velocity, acceleration and jerk limits).
//!
//! Owns [`AxisLimits`], which the path planner plans within (`plan`) and the check
//! verifies (`check`), so that neither imports the other for it. It must not compute
//! with the limits: planning and checking do.

use crate::axis::Axis;
use std::collections::BTreeMap;

/// Limits of one axis; `None` means unchecked.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisLimits {
    /// Largest |velocity|, units/s.
    pub velocity: Option<f64>,
    /// Largest |acceleration|, units/s².
    pub acceleration: Option<f64>,
    /// Largest |jerk|, units/s³.
    pub jerk: Option<f64>,
}

/// Limits per axis; an axis not listed is not limited.
pub type MachineLimits = BTreeMap<Axis, AxisLimits>;
