//! Contour building: rapid moves each on their own, runs of feed moves together.
//!
//! Owns where one contour ends and the next begins; it must not know G-code.

use pvt_core::{Contour, Element, Motion};

/// Collects elements into rest-to-rest contours.
#[derive(Debug, Default)]
pub(crate) struct Contours {
    done: Vec<Contour>,
    run: Vec<Element>,
}

impl Contours {
    /// Adds a move: a rapid is a contour of its own, a feed move joins the current run.
    pub fn push(&mut self, motion: Motion, element: Element) {
        match motion {
            Motion::Rapid => {
                self.end_run();
                self.done.push(Contour {
                    motion,
                    elements: vec![element],
                });
            }
            Motion::Feed => self.run.push(element),
        }
    }

    /// Ends the current run of feed moves (the machine comes to rest).
    pub fn end_run(&mut self) {
        if !self.run.is_empty() {
            let elements = std::mem::take(&mut self.run);
            self.done.push(Contour {
                motion: Motion::Feed,
                elements,
            });
        }
    }

    /// All contours, the last run ended.
    pub fn finish(mut self) -> Vec<Contour> {
        self.end_run();
        self.done
    }

    /// True while no move has been added.
    pub fn is_empty(&self) -> bool {
        self.done.is_empty() && self.run.is_empty()
    }
}
