//! The streaming interface: where the interpreter hands elements, contour ends and events.
//!
//! Owns the [`StreamSummary`] and re-exports pvt-core's [`ToolpathSink`], the contract
//! the interpreter feeds; it must not build contours (that is [`crate::contours`], one
//! sink) nor interpret G-code.

use pvt_core::Units;

use crate::GcodeDiagnostic;

pub use pvt_core::ToolpathSink;

/// What a streamed compile reports besides the toolpath.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamSummary {
    /// Units of every coordinate and feed that was streamed.
    pub units: Units,
    /// Warnings, in source order.
    pub warnings: Vec<GcodeDiagnostic>,
    /// The last G64 P tolerance, output units: recorded only, since the contour planner
    /// passes exactly through every programmed point, which meets any tolerance.
    pub path_tolerance: Option<f64>,
    /// The last G64 Q (LinuxCNC's naive-CAM tolerance, which merges nearly collinear
    /// moves), output units: recorded only, every programmed point is kept.
    pub naive_cam_tolerance: Option<f64>,
}
