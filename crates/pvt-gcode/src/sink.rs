//! The streaming interface: where the interpreter hands elements, contour ends and events.
//!
//! Owns the [`ToolpathSink`] contract and the [`StreamSummary`]; it must not build
//! contours (that is [`crate::contours`], one sink) nor interpret G-code.

use pvt_core::{Element, EventKind, Motion, Units};

use crate::GcodeDiagnostic;

/// Receives a program's toolpath as it is compiled, one element at a time.
///
/// The calls come in program order. Elements between two [`ToolpathSink::end_contour`]
/// calls form one rest-to-rest contour and share one [`Motion`]; a rapid move is always
/// followed by `end_contour`. An event comes only with no contour open (the machine at
/// rest). When [`crate::compile_into`] returns an error, what the sink received is
/// incomplete and must be discarded.
pub trait ToolpathSink {
    /// The next move of the open contour (or the first of a new one).
    fn element(&mut self, motion: Motion, element: &Element);
    /// The open contour ends: the machine comes to rest.
    fn end_contour(&mut self);
    /// Something happens at rest, from source line `line`.
    fn event(&mut self, event: &EventKind, line: u32);
}

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
}
