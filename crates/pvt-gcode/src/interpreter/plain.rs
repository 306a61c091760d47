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

impl Interpreter<'_> {
    /// Runs the plain line `plain` (its text at `span`) without an I or J word as
    /// [`Interpreter::execute`] runs its block and returns true; or returns false,
    /// having changed nothing, when the general path must run it.
    pub fn run_plain(&mut self, plain: &PlainLine, span: Span) -> bool {
        let mode = plain.motion.or(self.modal.motion);
        let plain_mode = (self.plain_idle(), mode, plain.has_center_words());
        let (true, Some(mode @ (MotionMode::Rapid | MotionMode::Linear)), false) = plain_mode
        else {
            return false;
        };
        let feed = plain
            .feed()
            .map(|written| self.feed_word(written))
            .or(self.modal.feed);
        let step = match plain.has_axis_words() {
            true => match self.plain_move(plain, mode, feed) {
                Some(step) => Some(step),
                None => return false,
            },
            false => None,
        };
        self.plain_modes(plain);
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

    /// [`Interpreter::run_plain`] for a plain line with an I or J word: a G2/G3 arc.
    /// Apart from it (the reader chooses): the plain lines of a program are mostly
    /// straight, and that function stays as small as they need.
    #[inline(never)]
    pub fn run_plain_arc(&mut self, plain: &PlainLine, span: Span) -> bool {
        let mode = plain.motion.or(self.modal.motion);
        let (true, Some(MotionMode::Arc(direction))) = (self.plain_idle(), mode) else {
            return false;
        };
        let feed = plain
            .feed()
            .map(|written| self.feed_word(written))
            .or(self.modal.feed);
        let Some(element) = self.plain_arc(plain, direction, feed, span) else {
            return false;
        };
        self.plain_modes(plain);
        self.output_units.get_or_insert(Units::Millimetre);
        self.position = element.end;
        self.route(Motion::Feed, element);
        true
    }

    /// True when the state lets a plain line run here: no NURBS block, cutter
    /// compensation, G93 or rotated system.
    #[inline(always)]
    fn plain_idle(&self) -> bool {
        self.nurbs.is_none()
            && self.cutter_idle()
            && self.modal.feed_mode == FeedMode::PerMinute
            && self.rotation() == 0.0
    }

    /// The modes a plain line sets: its motion mode (which ends a canned cycle) and its
    /// feed.
    #[inline(always)]
    fn plain_modes(&mut self, plain: &PlainLine) {
        if let Some(motion) = plain.motion {
            self.modal.motion = Some(motion);
            self.cycle.code = None;
            self.cycle.initial_level = None;
        }
        if let Some(written) = plain.feed() {
            self.modal.feed = Some(self.feed_word(written));
            self.feed_reported = false;
        }
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
        let end = self.plain_end(plain)?;
        let start = self.tool_start();
        let (motion, rate) = match mode {
            MotionMode::Rapid => (Motion::Rapid, self.rapid_rate()),
            _ => {
                let rate = super::motion::feed_per_second(self.feed_per_minute(feed)?)?;
                (Motion::Feed, self.rotary_rate(rate, feed, &start, &end))
            }
        };
        (!super::motion::no_move(&start, &end)).then_some((motion, start, end, rate))
    }

    /// The element of a plain G2/G3 line (`direction`) with an I or J word at `feed`, its
    /// text at `span`, as `arc_move` makes it in the XY plane (the centre by
    /// `center_offsets` and `arcs::center_from_offsets`, one turn); `None` when the
    /// general path would report something or the plane is another.
    fn plain_arc(
        &self,
        plain: &PlainLine,
        direction: ArcDirection,
        feed: Option<Feed>,
        span: Span,
    ) -> Option<Element> {
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
        let element = Element {
            kind: ElementKind::Arc(arc),
            start: self.position,
            end,
            feed: rate,
            span,
        };
        Some(element)
    }

    /// The end of a plain line's move, as `target` makes it without a rotation or G53;
    /// `None` where it is not finite.
    #[inline(always)]
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
