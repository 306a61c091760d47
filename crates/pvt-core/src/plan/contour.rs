//! The contour planner of seed 000, in any number of axes.
//!
//! At every interior point the velocity points along the unit bisector of the incoming and
//! outgoing chord directions (the normalized sum of the two unit vectors; never the mean of
//! two atan2 angles, which flips by 180° when they straddle ±180°) with the point's target
//! speed as its length. Each segment's time is the positive root of
//! `a·T² + b·T + c = 0` that makes the cubic's speed at mid-time equal `vmid`:
//!
//! ```text
//! s = v_start + v_end,  d = P(i+1) − P(i)
//! a = 1 − |s|²/(16·vmid²),  b = (3/4)(d·s)/vmid²,  c = −(9/4)|d|²/vmid²
//! ```
//!
//! `vmid` is the mean of the two end speeds (seed 000). Defined degenerate cases:
//! - repeated points (a chord no longer than 1e-12 of the coordinates' size) are dropped,
//!   keeping the lower target speed of the merged points;
//! - a full reversal (the two chord directions opposite within [`REVERSAL_TOLERANCE`])
//!   comes to rest at its point and the contour continues;
//! - a segment at rest at both ends (a two-point contour, or one next to a reversal) uses
//!   its programmed feed as `vmid`, so its peak speed, at mid-time, is the feed;
//! - a contour of a single point (after dropping repeats) has no segment.

use super::PlanError;
use crate::polyline::Polyline;
use crate::program::{PvtContour, SegmentRef};
use crate::toolpath::Motion;
use crate::vector::{max_abs, norm, sub_into};

/// Length of the sum of two unit chord directions below which a corner is a reversal.
///
/// It equals the angle, in radians, by which the corner falls short of a full 180° turn.
pub const REVERSAL_TOLERANCE: f64 = 1e-9;

/// Relative size below which a chord counts as a repeated point.
const REPEAT_TOLERANCE: f64 = 1e-12;

/// Time of one segment over chord `d` from velocity `v0` to `v1` with mid-time speed `vmid`.
///
/// Returns the positive root of seed 000's quadratic, computed in the cancellation-free form.
pub fn segment_time(d: &[f64], v0: &[f64], v1: &[f64], vmid: f64) -> f64 {
    let length = norm(d);
    segment_time_along(|k| d[k] / length, length, v0, v1, vmid)
}

/// [`segment_time`] for a chord of known `length` whose unit direction's component `k`
/// is `unit(k)` (`d[k] / length`, computed once by the caller).
fn segment_time_along(
    unit: impl Fn(usize) -> f64,
    length: f64,
    v0: &[f64],
    v1: &[f64],
    vmid: f64,
) -> f64 {
    // In units of the chord length L and vmid the quadratic is
    // (1 − |s|²/16vmid²)·τ² + (3/4)(u·s/vmid)·τ − 9/4 = 0 with T = τ·L/vmid, which neither
    // overflows nor underflows for any finite chord (seed 000's form squares |d|).
    let (mut ss, mut us) = (0.0, 0.0);
    for k in 0..v0.len() {
        let s = (v0[k] + v1[k]) / vmid;
        ss += s * s;
        us += unit(k) * s;
    }
    let a = 1.0 - ss / 16.0;
    let b = 0.75 * us;
    let c = -2.25;
    let root = (b * b - 4.0 * a * c).sqrt();
    let tau = if b >= 0.0 {
        // q < 0 and c < 0: c/q is the positive root without subtracting near-equal numbers.
        2.0 * c / (-b - root)
    } else {
        (root - b) / (2.0 * a)
    };
    tau * (length / vmid)
}

/// The segment whose end velocity waits for the next point's direction.
struct Pending {
    /// End point.
    end: Vec<f64>,
    /// Unit chord direction.
    unit: Vec<f64>,
    /// Chord vector.
    chord: Vec<f64>,
    /// Chord length.
    length: f64,
    /// Programmed feed of the segment, units/s.
    feed: f64,
    /// Upper bound on the target speed at `end` (the feeds met there so far).
    speed_cap: f64,
    /// The motion must stop at `end`.
    rest: bool,
    /// Source line.
    line: u32,
}

impl Pending {
    fn new(dim: usize) -> Pending {
        Pending {
            end: vec![0.0; dim],
            unit: vec![0.0; dim],
            chord: vec![0.0; dim],
            length: 0.0,
            feed: 0.0,
            speed_cap: 0.0,
            rest: false,
            line: 0,
        }
    }
}

/// Seed 000 as a stream: points go in one at a time, each segment comes out as soon as
/// the direction after its end point is known. Needs a three-point window, whatever the
/// length of the contour, and gives exactly what [`plan_contour`] gives.
pub struct ContourStream {
    dim: usize,
    start: Vec<f64>,
    v_start: Vec<f64>,
    speed_start: f64,
    pending: Option<Pending>,
    /// The buffers of the last emitted segment, reused for the next (no allocation per point).
    spare: Option<Pending>,
    v_end: Vec<f64>,
}

impl ContourStream {
    /// A contour starting at rest at `start`.
    pub fn new(start: &[f64]) -> ContourStream {
        let dim = start.len();
        ContourStream {
            dim,
            start: start.to_vec(),
            v_start: vec![0.0; dim],
            speed_start: 0.0,
            pending: None,
            spare: None,
            v_end: vec![0.0; dim],
        }
    }

    /// The last point accepted (where the contour is, once everything is emitted).
    pub fn last_point(&self) -> &[f64] {
        self.pending.as_ref().map_or(&self.start, |p| &p.end)
    }

    /// Adds a point reached at `feed` (units/s) from `line`; may emit the previous segment.
    pub fn push(
        &mut self,
        point: &[f64],
        feed: f64,
        line: u32,
        emit: &mut dyn FnMut(SegmentRef<'_>),
    ) -> Result<(), PlanError> {
        if point.iter().any(|x| !x.is_finite()) {
            return Err(PlanError::NonFinitePoint { line });
        }
        if !(feed.is_finite() && feed > 0.0) {
            return Err(PlanError::BadFeed { line, feed });
        }
        let mut next = self.spare.take().unwrap_or_else(|| Pending::new(self.dim));
        let from = self.last_point();
        sub_into(point, from, &mut next.chord);
        let len = norm(&next.chord);
        let scale = max_abs(from).max(max_abs(point));
        if self.dim == 0 || len <= REPEAT_TOLERANCE * scale {
            // A repeated point: the feeds it joins still bound the speed where it is.
            if let Some(p) = self.pending.as_mut() {
                p.speed_cap = p.speed_cap.min(feed);
            }
            self.spare = Some(next);
            return Ok(());
        }
        // A segment's time is at most about 3·len/feed; one that overflows is refused here
        // rather than written as NaN or infinity.
        if !(len.is_finite() && (4.0 * len / feed).is_finite()) {
            return Err(PlanError::BadDuration {
                line,
                duration: f64::INFINITY,
            });
        }
        for (u, c) in next.unit.iter_mut().zip(&next.chord) {
            *u = c / len;
        }
        next.end.copy_from_slice(point);
        (next.length, next.feed, next.speed_cap) = (len, feed, feed);
        (next.rest, next.line) = (false, line);
        if let Some(mut p) = self.pending.take() {
            p.speed_cap = p.speed_cap.min(feed);
            let speed = if p.rest { 0.0 } else { p.speed_cap };
            self.emit_pending(&p, Some(&next.unit), speed, emit);
            std::mem::swap(&mut self.start, &mut p.end);
            self.spare = Some(p);
        }
        self.pending = Some(next);
        Ok(())
    }

    /// Makes the motion come to rest at the last point pushed (exact stop).
    pub fn rest_here(&mut self) {
        if let Some(p) = self.pending.as_mut() {
            p.rest = true;
        }
    }

    /// Ends the contour at rest, emitting its last segment.
    pub fn finish(&mut self, emit: &mut dyn FnMut(SegmentRef<'_>)) {
        if let Some(mut p) = self.pending.take() {
            self.emit_pending(&p, None, 0.0, emit);
            std::mem::swap(&mut self.start, &mut p.end);
            self.spare = Some(p);
        }
        self.v_start.fill(0.0);
        self.speed_start = 0.0;
    }

    /// Emits the pending segment; `next` is the unit direction after its end, if any.
    fn emit_pending(
        &mut self,
        p: &Pending,
        next: Option<&[f64]>,
        speed: f64,
        emit: &mut dyn FnMut(SegmentRef<'_>),
    ) {
        let speed_end = match next {
            Some(u_out) if speed > 0.0 => bisector_velocity(&p.unit, u_out, speed, &mut self.v_end),
            _ => {
                self.v_end.fill(0.0);
                0.0
            }
        };
        let vmid = if self.speed_start == 0.0 && speed_end == 0.0 {
            p.feed
        } else {
            0.5 * (self.speed_start + speed_end)
        };
        let t = segment_time_along(|k| p.unit[k], p.length, &self.v_start, &self.v_end, vmid);
        emit(SegmentRef {
            end: &p.end,
            velocity: &self.v_end,
            duration: t,
            line: p.line,
        });
        self.v_start.copy_from_slice(&self.v_end);
        self.speed_start = speed_end;
    }
}

/// Writes `speed` along the bisector of `u_in` and `u_out` into `v`; 0 at a reversal.
fn bisector_velocity(u_in: &[f64], u_out: &[f64], speed: f64, v: &mut [f64]) -> f64 {
    for k in 0..v.len() {
        v[k] = u_in[k] + u_out[k];
    }
    let len = norm(v);
    if len < REVERSAL_TOLERANCE {
        v.fill(0.0);
        return 0.0;
    }
    v.iter_mut().for_each(|x| *x *= speed / len);
    speed
}

/// Plans one contour with seed 000's rule; see the module documentation.
pub fn plan_contour(poly: &Polyline, motion: Motion) -> Result<PvtContour, PlanError> {
    let first = poly.point(0);
    if first.iter().any(|x| !x.is_finite()) {
        return Err(PlanError::NonFinitePoint {
            line: poly.lines.first().copied().unwrap_or(0),
        });
    }
    let mut out = PvtContour::new(motion, first.to_vec());
    let mut stream = ContourStream::new(first);
    let mut emit = |s: SegmentRef<'_>| out.push(s.end, s.velocity, s.duration, s.line);
    for i in 1..poly.len() {
        stream.push(
            poly.point(i),
            poly.feeds[i - 1],
            poly.lines[i - 1],
            &mut emit,
        )?;
        if poly.is_rest(i) && i + 1 < poly.len() {
            stream.rest_here();
        }
    }
    stream.finish(&mut emit);
    Ok(out)
}

#[cfg(test)]
#[path = "contour_tests.rs"]
mod tests;
