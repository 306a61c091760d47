//! Plain lines ([`crate::plain`]) run straight from their words: what [`Interpreter::execute`]
//! does with such a line's block, without building its request.
//!
//! Owns the conditions under which a plain line runs here: no cutter compensation, no
//! NURBS block, G94, no rotated coordinate system, a G0/G1 motion mode without I or J
//! words, or a G2/G3 one in the XY plane with an I or J word, and a move that raises no
//! diagnostic (a feed in force, a finite end, a line's end away from its start, an
//! arc's centre found within the radius tolerance). Otherwise it changes nothing and
//! the general path runs the line. It must compute every value with the same
//! operations, in the same order, as the general path (`target`, `feed_rate`,
//! `line_move`, `arc_move`), so that the elements are the same bit for bit.

use pvt_core::{
    Arc, ArcDirection, Axis, Element, ElementKind, Motion, Plane, Position, Span, Units,
};

use super::{Feed, Interpreter};
use crate::arcs;
use crate::codes::{Distance, FeedMode, MotionMode};
use crate::plain::PlainLine;

/// A plain line's move: its motion, start, end, shape and rate.
type PlainMove = (Motion, Position, Position, ElementKind, f64);

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
        let feed = plain.feed().map(|written| Feed { written }).or(self.feed);
        let step = match (idle, mode, plain.has_center_words()) {
            (true, Some(mode @ (MotionMode::Rapid | MotionMode::Linear)), false) => {
                match plain.has_axis_words() {
                    true => match self.plain_move(plain, mode, feed) {
                        Some(step) => Some(step),
                        None => return false,
                    },
                    false => None,
                }
            }
            (true, Some(MotionMode::Arc(direction)), true) => {
                match self.plain_arc(plain, direction, feed) {
                    Some(step) => Some(step),
                    None => return false,
                }
            }
            _ => return false,
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
        if let Some((motion, start, end, kind, rate)) = step {
            self.output_units.get_or_insert(Units::Millimetre);
            self.position = end;
            let element = Element {
                kind,
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
    ) -> Option<PlainMove> {
        let end = self.plain_end(plain)?;
        let (motion, rate) = match mode {
            MotionMode::Rapid => (Motion::Rapid, self.rapid_rate()),
            _ => (
                Motion::Feed,
                super::motion::feed_per_second(self.feed_per_minute(feed)?)?,
            ),
        };
        let start = self.tool_start();
        let moves = !super::motion::no_move(&start, &end);
        moves.then_some((motion, start, end, ElementKind::Line, rate))
    }

    /// The arc of a plain G2/G3 line (`direction`) with an I or J word at `feed`: start,
    /// end, arc and rate as `arc_move` makes them in the XY plane (the centre by
    /// `center_offsets` and `arcs::center_from_offsets`, one turn); `None` when the
    /// general path would report something or the plane is another.
    fn plain_arc(
        &self,
        plain: &PlainLine,
        direction: ArcDirection,
        feed: Option<Feed>,
    ) -> Option<PlainMove> {
        let plane = self.modal.plane;
        if plane != Plane::XY {
            return None;
        }
        let end = self.plain_end(plain)?;
        let (from, to) = (plane.project(&self.position), plane.project(&end));
        let offsets = self.center_offsets(plane, plain.center_words(), from);
        let center = arcs::center_from_offsets(from, to, offsets, self.arc_tolerance()).ok()?;
        if !center.iter().all(|c| c.is_finite()) {
            return None;
        }
        let rate = super::motion::feed_per_second(self.feed_per_minute(feed)?)?;
        let arc = Arc {
            plane,
            center,
            direction,
            extra_turns: 0,
        };
        Some((
            Motion::Feed,
            self.position,
            end,
            ElementKind::Arc(arc),
            rate,
        ))
    }

    /// The end of a plain line's move, as `target` makes it without a rotation or G53;
    /// `None` where it is not finite.
    fn plain_end(&self, plain: &PlainLine) -> Option<Position> {
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
        end.iter().all(|v| v.is_finite()).then_some(end)
    }
}
