//! Plain lines ([`crate::plain`]) run straight from their words: what [`Interpreter::execute`]
//! does with such a line's block, without building its request.
//!
//! Owns the conditions under which a plain line runs here: no cutter compensation, no
//! NURBS block, G94, no rotated coordinate system, a G0/G1 motion mode, and a move that
//! raises no diagnostic (a feed in force, a finite end, an end away from the start).
//! Otherwise it changes nothing and the general path runs the line. It must compute
//! every value with the same operations, in the same order, as the general path
//! (`target`, `feed_rate`, `line_move`), so that the elements are the same bit for bit.

use pvt_core::{Axis, Element, ElementKind, Motion, Position, Span, Units};

use super::{Feed, Interpreter};
use crate::codes::{Distance, FeedMode, MotionMode};
use crate::plain::PlainLine;

impl Interpreter<'_> {
    /// Runs the plain line `plain` (its text at `span`) as [`Interpreter::execute`] runs
    /// its block and returns true; or returns false, having changed nothing, when the
    /// general path must run it.
    pub fn run_plain(&mut self, plain: &PlainLine, span: Span) -> bool {
        let idle = self.nurbs.is_none()
            && self.cutter_idle()
            && self.modal.feed_mode == FeedMode::PerMinute
            && self.rotation() == 0.0;
        let mode = plain.motion.or(self.modal.motion);
        let (true, Some(mode @ (MotionMode::Rapid | MotionMode::Linear))) = (idle, mode) else {
            return false;
        };
        let feed = plain.feed().map(|written| Feed { written }).or(self.feed);
        let step = match plain.has_axis_words() {
            true => match self.plain_move(plain, mode, feed) {
                Some(step) => Some(step),
                None => return false,
            },
            false => None,
        };
        if let Some(motion) = plain.motion {
            self.modal.motion = Some(motion);
            self.cycle.code = None;
            self.cycle.initial_level = None;
        }
        if let Some(written) = plain.feed() {
            self.feed = Some(Feed { written });
            self.feed_reported = false;
        }
        if let Some((motion, start, end, rate)) = step {
            self.output_units.get_or_insert(Units::Millimetre);
            self.position = end;
            let element = Element {
                kind: ElementKind::Line,
                start,
                end,
                feed: rate,
                span,
            };
            self.route(motion, element);
        }
        true
    }

    /// The move of a plain line with axis words in `mode` at `feed` (the line's or the one
    /// in force): motion, start, end and rate as `line_move` makes them; `None` when the
    /// general path would report something.
    fn plain_move(
        &self,
        plain: &PlainLine,
        mode: MotionMode,
        feed: Option<Feed>,
    ) -> Option<(Motion, Position, Position, f64)> {
        // The output units are those in force, or millimetres as `line_move` fixes them:
        // `output()` reads the same either way.
        let mut end = self.position;
        for axis in Axis::ALL {
            let i = axis.index();
            let Some(written) = plain.axis(i) else {
                continue;
            };
            let value = self.program_value(axis, written);
            end[i] = match self.modal.distance {
                Distance::Absolute => value + self.offset(i),
                Distance::Incremental => end[i] + value,
            };
        }
        if !end.iter().all(|v| v.is_finite()) {
            return None;
        }
        let (motion, rate) = match mode {
            MotionMode::Rapid => (Motion::Rapid, self.rapid_rate()),
            _ => (
                Motion::Feed,
                super::motion::feed_per_second(self.feed_per_minute(feed)?)?,
            ),
        };
        let start = self.tool_start();
        (!super::motion::no_move(&start, &end)).then_some((motion, start, end, rate))
    }
}
