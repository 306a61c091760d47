//! Contour collecting: the [`ToolpathSink`] behind [`crate::compile`], stream to
//! [`pvt_core::Toolpath`] parts.
//!
//! Owns grouping streamed elements into contours and placing events between them; it must
//! not know G-code nor decide where contours end (the interpreter does).

use pvt_core::{Contour, Element, EventKind, Motion, ProgramEvent};

use crate::ToolpathSink;

/// Collects a streamed toolpath into contours and events.
#[derive(Debug, Default)]
pub(crate) struct CollectingSink {
    /// Finished contours.
    pub contours: Vec<Contour>,
    /// Events, each before the contour of its index.
    pub events: Vec<ProgramEvent>,
    /// G64 P tolerances with the first contour each applies to.
    pub path_tolerances: Vec<(usize, f64)>,
    run: Vec<Element>,
    motion: Option<Motion>,
}

impl CollectingSink {
    /// Ends the open contour, if any, and returns everything collected.
    pub fn finish(mut self) -> (Vec<Contour>, Vec<ProgramEvent>, Vec<(usize, f64)>) {
        self.end_contour();
        (self.contours, self.events, self.path_tolerances)
    }
}

impl ToolpathSink for CollectingSink {
    fn element(&mut self, motion: Motion, element: &Element) {
        if self.motion.is_some_and(|m| m != motion) {
            self.end_contour();
        }
        self.motion = Some(motion);
        self.run.push(*element);
    }

    fn end_contour(&mut self) {
        if let Some(motion) = self.motion.take() {
            let elements = std::mem::take(&mut self.run);
            self.contours.push(Contour { motion, elements });
        }
    }

    fn path_tolerance(&mut self, tolerance: f64) {
        // It applies from the next contour to begin.
        let next = self.contours.len() + usize::from(self.motion.is_some());
        self.path_tolerances.push((next, tolerance));
    }

    fn event(&mut self, event: &EventKind, line: u32) {
        self.end_contour();
        self.events.push(ProgramEvent {
            before_contour: self.contours.len(),
            kind: event.clone(),
            line,
        });
    }
}
