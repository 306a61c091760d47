//! The pieces between knots: their cubic's end conditions, time and error bound.
//!
//! Owns the piece time from the reference motion (constant parameter acceleration), the
//! per-piece error bound of the module documentation, and the same pieces on a quantum
//! grid; under a jerk limit, each piece's S-curve parts (three parts that carry the
//! parameter acceleration of a junction between two parts of a Bézier, and C² parts on
//! the grid) and each corner blend's two parts (a pulse of acceleration at rest at both
//! ends) with their error bound. It must not move knots or change speeds, nor define what a piece
//! is: that is [`super::knots`] and [`super::piece`].

use super::curve::Curve;
use super::knots::{path_jerk, speed_cap, Knot, Knots};
use super::piece::{Part, Piece, PieceRef, Pieces};
use super::{AxisBounds, Vector};
use crate::hermite::HermiteSegment;
use crate::plan::quantize::{quanta_time, Quantum};

impl Knots {
    /// The piece between every two consecutive knots, in order, into `out` (emptied
    /// first: its storage is reused); in jerk mode a piece that changes speed is its
    /// S-curve's two or three parts.
    pub fn pieces_into(&self, curves: &[Curve], bounds: &AxisBounds, out: &mut Pieces) {
        out.clear();
        self.pieces_up_to(curves, bounds, 0..self.knots.len() - 1, out);
    }

    /// As [`Knots::pieces_into`] where `out` holds the last round's pieces of one
    /// settling: a piece between two knots that were consecutive last round
    /// ([`Knot::last_round`]) at the same speeds (bit for bit) is the same piece, since a
    /// piece follows from its two knots alone (and the window's curves, junctions and
    /// bounds, which a settling does not change) and a round moves no knot (it inserts
    /// knots and sets speeds and caps), so only the pieces a round changed are made
    /// again. Each piece kept moves back in `out` (or stays), and `out` is rewritten
    /// from its end. Under a jerk limit, where a piece may be several parts, every piece
    /// is made again.
    pub fn pieces_again(&mut self, curves: &[Curve], bounds: &AxisBounds, out: &mut Pieces) {
        let made_at = std::mem::take(&mut self.scratch.made_at);
        let n = self.knots.len();
        if self.jerk_mode || made_at.is_empty() || out.len() + 1 != made_at.len() {
            self.pieces_into(curves, bounds, out);
        } else {
            let dim = curves[0].start.len();
            out.resize(n - 1, dim);
            for k in (0..n - 1).rev() {
                // `out[..=k]` still holds the last round's pieces: those after it are
                // this round's.
                match self.made_last_round(k, &made_at) {
                    Some(i) => out.copy_to(i, k, k),
                    None => out.set(k, &self.piece(curves, bounds, k)),
                }
            }
        }
        self.round_made(made_at);
    }

    /// Where the piece after knot `k` is one the last round made, with `made_at` the
    /// speeds of that round's knots: its index then, when knots `k` and `k + 1` were
    /// consecutive then ([`Knot::last_round`]) and have the same speeds, bit for bit.
    fn made_last_round(&self, k: usize, made_at: &[f64]) -> Option<usize> {
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let i = a.last_round as usize;
        let same = |knot: &Knot, i: usize| made_at[i].to_bits() == knot.speed.to_bits();
        let kept = i <= k
            && i + 1 < made_at.len()
            && b.last_round as usize == i + 1
            && same(a, i)
            && same(b, i + 1);
        kept.then_some(i)
    }

    /// Notes this round's knots as the ones its pieces (or error bounds) were made from:
    /// their speeds into `made_at` (its storage reused) and each one's index.
    fn round_made(&mut self, mut made_at: Vec<f64>) {
        made_at.clear();
        made_at.extend(self.knots.iter().map(|k| k.speed));
        for (k, knot) in self.knots.iter_mut().enumerate() {
            knot.last_round = k as u32;
        }
        self.scratch.made_at = made_at;
    }

    /// As [`Knots::pieces_again`] for the pieces' error bounds alone, one for the piece
    /// after every knot but the last, into the knots' scratch (where
    /// [`Knots::split_over_errors`] reads them): what a round needs where the tolerance
    /// is the only repair ([`Knots::tolerance_alone_repairs`]). A bound is made again
    /// only where the piece would be: the rest are the last round's, moved back.
    /// Without a jerk limit only (a piece is one cubic).
    pub fn errors_again(&mut self, curves: &[Curve], bounds: &AxisBounds) {
        debug_assert!(!self.jerk_mode, "a piece under a jerk limit has parts");
        let made_at = std::mem::take(&mut self.scratch.made_at);
        let mut errors = std::mem::take(&mut self.scratch.errors);
        let mut durations = std::mem::take(&mut self.scratch.durations);
        let n = self.knots.len();
        if made_at.is_empty()
            || errors.len() + 1 != made_at.len()
            || durations.len() != errors.len()
        {
            errors.clear();
            durations.clear();
            for k in 0..n - 1 {
                let (duration, error) = self.piece_time_and_error(curves, bounds, k);
                durations.push(duration);
                errors.push(error);
            }
        } else {
            errors.resize(n - 1, 0.0);
            durations.resize(n - 1, 0.0);
            for k in (0..n - 1).rev() {
                (durations[k], errors[k]) = match self.made_last_round(k, &made_at) {
                    Some(i) => (durations[i], errors[i]),
                    None => self.piece_time_and_error(curves, bounds, k),
                };
            }
        }
        self.scratch.errors = errors;
        self.scratch.durations = durations;
        self.round_made(made_at);
    }

    /// The time and error bound of the piece after knot `k` (without a jerk limit): those
    /// of [`Knots::piece`], without its end states where it is no corner blend.
    pub(super) fn piece_time_and_error(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
    ) -> (f64, f64) {
        match self.knots[k].blend_index() {
            Some(j) => {
                let blend = self.blend_piece(curves, k, j);
                (blend.duration, blend.error)
            }
            None => {
                let (duration, error, _) = self.time_and_error(curves, bounds, k);
                (duration, error)
            }
        }
    }

    /// [`Knots::pieces_into`] on the knots of the last [`Knots::errors_again`], which no
    /// repair has changed since: each piece that is no corner blend takes the time and
    /// error bound that round made ([`Scratch::durations`] and
    /// [`Scratch::errors`](super::knots::Scratch)), the same numbers
    /// [`Knots::time_and_error`] would make again, and only its end states are made.
    pub fn pieces_from_bounds(&self, curves: &[Curve], bounds: &AxisBounds, out: &mut Pieces) {
        let (durations, errors) = (&self.scratch.durations, &self.scratch.errors);
        debug_assert!(!self.jerk_mode && durations.len() + 1 == self.knots.len());
        out.clear();
        for k in 0..self.knots.len() - 1 {
            let timed = Some((durations[k], errors[k]));
            self.push_piece(curves, bounds, k, true, timed, out);
        }
    }

    /// Emits the pieces of the knots before knot `count` as [`Knots::emit`] emits those
    /// [`Knots::pieces_from_bounds`] makes, without making them: each piece's end state
    /// ([`Knots::fill_piece`]'s end, a corner blend's [`Knots::blend_piece`]), its
    /// time from the last [`Knots::errors_again`] (the settled knots'), and its line;
    /// the same values, bit for bit. Without a jerk limit (a piece is one cubic).
    pub fn emit_ends(
        &self,
        curves: &[Curve],
        count: usize,
        emit: &mut dyn FnMut(&crate::program::SegmentRef<'_>),
    ) {
        debug_assert!(!self.jerk_mode && self.scratch.durations.len() + 1 == self.knots.len());
        for k in 0..count {
            let line = curves[self.knots[k].after.element].line;
            if let Some(j) = self.knots[k].blend_index() {
                let blend = self.blend_piece(curves, k, j);
                emit(&crate::program::SegmentRef {
                    end: &blend.end,
                    velocity: &blend.end_velocity,
                    duration: blend.duration,
                    line,
                });
                continue;
            }
            let (curve, _, to) = self.piece_span(curves, k);
            emit(&crate::program::SegmentRef {
                end: &curve.point(to),
                velocity: &self.velocity_at(k + 1, curve, to),
                duration: self.scratch.durations[k],
                line,
            });
        }
    }

    /// Forgets the last round's pieces: the next [`Knots::pieces_again`] makes all.
    pub fn forget_pieces(&mut self) {
        self.scratch.made_at.clear();
    }

    /// The pieces of knots `knots` (a range that starts at or before the first knot of
    /// no piece in `out`) in place of `out`'s from that knot on, and none after: each
    /// piece follows from its two knots alone, so where the knots before `knots.start`
    /// are those `out` was made from, `out` is what [`Knots::pieces_into`] makes, up to
    /// `knots.end`.
    pub fn pieces_up_to(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        knots: std::ops::Range<usize>,
        out: &mut Pieces,
    ) {
        out.truncate(out.before_knot(knots.start));
        let first = knots.start;
        for k in knots {
            if let Some(j) = self.knots[k].blend_index() {
                if self.junctions[j].transition.is_some() {
                    self.transition_parts(curves, k, j, out);
                    continue;
                }
            }
            if self.jerk_mode {
                let piece = self.piece(curves, bounds, k);
                self.scurve(curves, bounds, k, piece, out);
            } else {
                // Without a jerk limit this loop pushed the piece of knot `k − 1` last.
                self.push_piece(curves, bounds, k, k > first, None, out);
            }
        }
    }

    /// True when the piece after knot `k` (not a corner blend) starts in the state the
    /// piece before it ends in: both are made by [`Knots::fill_piece`] (neither is a
    /// corner blend) and knot `k` lies inside one element, where both ask the position
    /// and the velocity of knot `k` at the same place on the same curve (the same
    /// parameter bit for bit: −0 and +0 are equal, not the same).
    fn shares_its_start(&self, k: usize) -> bool {
        let (before, after) = (self.knots[k].before, self.knots[k].after);
        k > 0
            && self.knots[k - 1].blend.is_none()
            && before.element == after.element
            && before.param.to_bits() == after.param.to_bits()
    }

    fn piece(&self, curves: &[Curve], bounds: &AxisBounds, k: usize) -> Piece {
        if let Some(j) = self.knots[k].blend_index() {
            return self.blend_piece(curves, k, j);
        }
        let mut piece = Piece::zeroed(curves[0].start.len(), k);
        self.fill_piece(curves, bounds, k, None, None, &mut piece);
        piece
    }

    /// [`Knots::piece`] pushed onto `out`. Where `after_last` (the last piece in `out` is
    /// that of knot `k − 1`) and the piece shares its start ([`Knots::shares_its_start`]),
    /// it starts in that piece's end state; `timed` as [`Knots::fill_piece`] takes it.
    fn push_piece(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
        after_last: bool,
        timed: Option<(f64, f64)>,
        out: &mut Pieces,
    ) {
        if let Some(j) = self.knots[k].blend_index() {
            out.push(&self.blend_piece(curves, k, j));
            return;
        }
        let before = out
            .last()
            .filter(|_| after_last && self.shares_its_start(k));
        let start = before.map(|p| {
            (
                Vector::from_slice(p.end),
                Vector::from_slice(p.end_velocity),
            )
        });
        let mut piece = Piece::zeroed(curves[0].start.len(), k);
        self.fill_piece(curves, bounds, k, start, timed, &mut piece);
        out.push(&piece);
    }

    /// The piece after knot `k`, not a corner blend, written into `piece` (zeroed, of
    /// the curves' axes, after knot `k`). `start` is its start position and velocity
    /// where the piece before ends in them ([`Knots::shares_its_start`]): the values it
    /// would compute, taken over; `timed` its time and error bound where
    /// [`Knots::errors_again`] made them on these knots (without a jerk limit).
    fn fill_piece(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
        start: Option<(Vector, Vector)>,
        timed: Option<(f64, f64)>,
        piece: &mut Piece,
    ) {
        let (curve, from, to) = self.piece_span(curves, k);
        (piece.start, piece.start_velocity) = match start {
            Some(state) => state,
            None => (curve.point(from), self.velocity_at(k, curve, from)),
        };
        piece.end = curve.point(to);
        piece.end_velocity = self.velocity_at(k + 1, curve, to);
        if let Some((duration, error)) = timed {
            (piece.duration, piece.error) = (duration, error);
            return;
        }
        let at_rest;
        (piece.duration, piece.error, at_rest) = self.time_and_error(curves, bounds, k);
        if at_rest && self.jerk_mode {
            piece.duration = piece.duration.max(rest_time(piece, bounds));
        }
    }

    /// The time and error bound of the piece after knot `k`, not a corner blend, from
    /// its knots' speeds alone, and whether it is at rest at both ends (then under a jerk
    /// limit its time may be longer: [`Knots::fill_piece`]).
    fn time_and_error(&self, curves: &[Curve], bounds: &AxisBounds, k: usize) -> (f64, f64, bool) {
        let (curve, from, to) = self.piece_span(curves, k);
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let (wa, wb) = (a.speed / curve.rate(from), b.speed / curve.rate(to));
        let span = to - from;
        if wa + wb > 0.0 {
            let duration = 2.0 * span / (wa + wb);
            let [d2, d3, d4] = curve.derivative_bounds();
            let (t, w) = (duration, wa.max(wb));
            let dw = (wb - wa).abs() / t;
            let bend =
                t.powi(4) / 384.0 * (d4 * w.powi(4) + 6.0 * d3 * w * w * dw + 3.0 * d2 * dw * dw);
            let mismatch = |speed: f64, junction: Option<usize>| {
                junction.map_or(0.0, |j| speed * self.junctions[j].deviation)
            };
            let turn = 4.0 / 27.0
                * t
                * (mismatch(a.speed, a.junction_index()) + mismatch(b.speed, b.junction_index()));
            (duration, bend + turn + curve.fit, false)
        } else {
            // At rest at both ends: the smoothstep along the chord, peaking at the cap.
            let cap = speed_cap(curve, from, to, bounds);
            let error = if curve.is_line() {
                curve.fit
            } else {
                f64::INFINITY
            };
            (1.5 * curve.length(from, to) / cap, error, true)
        }
    }
}

impl Knots {
    /// Piece `k` in jerk mode: a piece that changes speed from `va` to `vb` in its time
    /// `T` becomes the S-curve in the parameter that fills `T` (see "Jerk" in
    /// [`super`]): jerk `+j`, constant parameter acceleration `A`, jerk `−j`, with `A` the
    /// smaller root of `T = Δw/A + A/j`, or two parts of jerk `4·Δw/T²` when the middle
    /// would be under 1 % of `T`. Each part's reference motion `φ(t)` is a cubic, and
    /// its cubic runs from the exact position and velocity of `c(φ)` at its ends, with
    /// the "Quantization" error bound. A blend, a piece at rest and a piece whose whole
    /// speed change at constant acceleration steps the acceleration by at most a quarter
    /// of what one servo period allows stay whole.
    fn scurve(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
        whole: Piece,
        out: &mut Pieces,
    ) {
        if let Some(j) = self.knots[k].blend_index() {
            self.smooth_blend(curves, k, j, whole, out);
            return;
        }
        if whole.at_rest() {
            out.push(&whole);
            return;
        }
        let (curve, from, to) = self.piece_span(curves, k);
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let (wa, wb) = (a.speed / curve.rate(from), b.speed / curve.rate(to));
        let t = whole.duration;
        let dw = (wb - wa).abs();
        let rate = curve.rate(from).max(curve.rate(to));
        let jerk = path_jerk(curve, from, to, bounds);
        if !jerk.is_finite() {
            out.push(&whole);
            return;
        }
        // The parameter acceleration at each knot that keeps the tangential
        // acceleration from stepping at a junction of curves whose rates |dc/dφ|
        // change differently (two parts of a Bézier).
        let ends = [
            self.junction_accel(curves, k, true),
            self.junction_accel(curves, k + 1, false),
        ];
        let tangential = ends[0].abs() * curve.rate(from) + ends[1].abs() * curve.rate(to);
        let turned = tangential > RATE_ACCEL_SHARE * jerk * bounds.servo_period;
        if !turned && dw * rate / t <= 0.25 * jerk * bounds.servo_period {
            out.push(&whole);
            return;
        }
        let jp = jerk / rate;
        let middle = (t * t - 4.0 * dw / jp).max(0.0).sqrt();
        let (ramp, hold, accel) = if middle >= 0.01 * t {
            (0.5 * (t - middle), middle, 2.0 * dw / (t + middle))
        } else {
            (0.5 * t, 0.0, 2.0 * dw / t)
        };
        // Ramps of at least a third of the time, a middle of at least 1 %: the ramps
        // also carry the knots' accelerations (a ramp between the S-curve's and T/2
        // keeps the speed change's jerk within `j`).
        let turn = ramp.clamp(t / 3.0, 0.495 * t);
        let times = [turn, t - 2.0 * turn, turn];
        let turned_points = turned
            .then(|| rate_turn_points([from, to], [wa, wb], ends, times))
            .filter(|points| moves_forward(points));
        let points = if let Some(points) = turned_points {
            points
        } else {
            let sign = if wb > wa { 1.0 } else { -1.0 };
            let j = accel / ramp;
            let w1 = wa + sign * 0.5 * accel * ramp;
            let p1 = from + wa * ramp + sign * j * ramp.powi(3) / 6.0;
            let w2 = w1 + sign * accel * hold;
            let p2 = p1 + w1 * hold + sign * 0.5 * accel * hold * hold;
            let mut points = vec![(from, wa, ramp)];
            if hold == 0.0 {
                points.push((p1, w1, ramp));
            } else {
                points.extend([(p1, w1, hold), (p2, w2, ramp)]);
            }
            points.push((to, wb, 0.0));
            points
        };
        let last = points.len() - 2;
        for (i, w) in points.windows(2).enumerate() {
            let ((p0, r0, dt), (p1, r1, _)) = (w[0], w[1]);
            let mut part = Piece {
                start: whole.start,
                end: whole.end,
                start_velocity: whole.start_velocity,
                end_velocity: whole.end_velocity,
                duration: dt,
                error: 0.0,
                knot: k,
                part: Some(Part {
                    params: [p0, p1],
                    rates: [r0, r1],
                    at_knot: [i == 0, i == last],
                }),
            };
            let inner = |phi: f64, w: f64, position: &mut Vector, velocity: &mut Vector| {
                curve.position(phi, position);
                curve.derivative(phi, velocity);
                velocity.iter_mut().for_each(|v| *v *= w);
            };
            if i > 0 {
                inner(p0, r0, &mut part.start, &mut part.start_velocity);
            }
            if i < last {
                inner(p1, r1, &mut part.end, &mut part.end_velocity);
            }
            let phi = HermiteSegment::new(p0, r0, p1, r1, dt);
            let ends = [(a, i == 0, 1.0), (b, i == last, 1.0)];
            part.error = bend(curve, &phi) + self.turn(dt, ends);
            out.push(&part);
        }
    }

    /// Piece `k` in jerk mode when it is the corner blend of junction `j` (see "Jerk" in
    /// [`super`]): two cubics whose acceleration rises linearly from zero to `2·Δv/T` and
    /// falls back to zero, along `Δv = vb·t₂ − va·t₁`, so that neither knot steps. Its
    /// apex is at `θ·T`, `θ = (2vb − va)/(va + vb)`, and `T = L/va + L/vb`: the only
    /// pulse of that shape that leaves the first line at `L` before the corner and joins
    /// the second at `L` after it. Each cubic is the motion itself (its acceleration is
    /// linear), so it is exact; the error is [`smooth_blend_error`]. Speeds more than a
    /// factor of two apart (`θ` outside `(0, 1)`; the passes keep them within 1.5) keep
    /// the one-cubic blend `whole`.
    fn smooth_blend(&self, curves: &[Curve], k: usize, j: usize, whole: Piece, out: &mut Pieces) {
        let junction = &self.junctions[j];
        let l = junction.blend.unwrap_or(0.0);
        let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
        let theta = (2.0 * vb - va) / (va + vb);
        if !(va > 0.0 && vb > 0.0 && theta > 1e-3 && theta < 1.0 - 1e-3 && l > 0.0) {
            out.push(&whole);
            return;
        }
        let t = l / va + l / vb;
        let [t1, t2] = &self.blend_tangents(curves, k);
        let dim = whole.start.len();
        let dv = Vector::from_fn(dim, |i| vb * t2[i] - va * t1[i]);
        let mid = Vector::from_fn(dim, |i| {
            whole.start[i] + va * t1[i] * theta * t + theta * theta * t / 3.0 * dv[i]
        });
        let mid_velocity = Vector::from_fn(dim, |i| va * t1[i] + theta * dv[i]);
        let error = smooth_blend_error(l, va, vb, junction.half_turn_sin);
        out.push(&Piece {
            end: mid,
            end_velocity: mid_velocity,
            duration: theta * t,
            error,
            ..whole.clone()
        });
        out.push(&Piece {
            start: mid,
            start_velocity: mid_velocity,
            duration: (1.0 - theta) * t,
            error,
            ..whole
        });
    }

    /// The error term `4/27·t·(|Δv_a| + |Δv_b|)/K` of a piece's knot ends (`(knot, is
    /// a knot, K)`): a junction passed at speed, whose velocity is not the element's.
    fn turn(&self, t: f64, ends: [(&Knot, bool, f64); 2]) -> f64 {
        let mismatch =
            |(knot, at_knot, scale): (&Knot, bool, f64)| match (at_knot, knot.junction_index()) {
                (true, Some(j)) => knot.speed * self.junctions[j].deviation / scale,
                _ => 0.0,
            };
        4.0 / 27.0 * t * (mismatch(ends[0]) + mismatch(ends[1]))
    }
}

impl Knots {
    /// Piece `k` when it is the curvature transition of junction `j` (see
    /// [`super::transition`]): its two parts at the speed of its knots, the path of its
    /// shape, times divided by the speed, velocities multiplied by it. Both knots have
    /// the same speed (the passes keep it so); at rest it is one piece along its chord.
    fn transition_parts(&self, curves: &[Curve], k: usize, j: usize, out: &mut Pieces) {
        let Some(transition) = self.junctions[j].transition.as_deref().copied() else {
            return;
        };
        let (before, after) = (self.knots[k].after, self.knots[k + 1].before);
        let (a, b) = (&curves[before.element], &curves[after.element]);
        let dim = a.start.len();
        let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
        let mut piece = Piece {
            error: transition.error,
            ..Piece::zeroed(dim, k)
        };
        a.position(before.param, &mut piece.start);
        b.position(after.param, &mut piece.end);
        self.velocity(k, a, before.param, &mut piece.start_velocity);
        self.velocity(k + 1, b, after.param, &mut piece.end_velocity);
        let v = 0.5 * (va + vb);
        if !(va > 0.0 && vb > 0.0) {
            // At rest: the smoothstep along the chord, at the transition's own cap.
            piece.duration = 1.5 * transition.length / self.junctions[j].cap;
            piece.error = transition.chord_error;
            out.push(&piece);
            return;
        }
        if (va - vb).abs() > 1e-12 * v {
            // Not the transition's motion: over every tolerance, so that the speeds
            // are evened out (see `Knots::split_over`).
            piece.duration = transition.length / v;
            piece.error = f64::INFINITY;
            out.push(&piece);
            return;
        }
        let middle_velocity = Vector::from_fn(dim, |i| v * transition.middle_velocity[i]);
        out.push(&Piece {
            end: transition.middle,
            end_velocity: middle_velocity,
            duration: transition.times[0] / v,
            ..piece
        });
        out.push(&Piece {
            start: transition.middle,
            start_velocity: middle_velocity,
            duration: transition.times[1] / v,
            ..piece
        });
    }
}

/// Share of `j·Tₛ` (the piece's path jerk times the servo period) above which the
/// tangential acceleration its knots carry (see [`Knots::junction_accel`]) makes a
/// piece three parts that carry it, whatever its speed change; below it the piece may
/// stay one cubic.
const RATE_ACCEL_SHARE: f64 = 0.25;

impl Knots {
    /// The parameter acceleration at knot `k` of the piece after it (`after`) or before
    /// it: zero inside an element, where both pieces have the same rate `ρ`, and at a
    /// junction passed at speed `v` the one that gives the element the tangential
    /// acceleration halfway between the two elements' `g·v²` (`g = ρ'/ρ²`, what zero
    /// parameter acceleration leaves), so that the tangential acceleration does not
    /// step there.
    fn junction_accel(&self, curves: &[Curve], k: usize, after: bool) -> f64 {
        let knot = &self.knots[k];
        if knot.junction.is_none() || knot.speed <= 0.0 {
            return 0.0;
        }
        let (b, a) = (knot.before, knot.after);
        let g = |place: super::knots::Place| rate_growth(&curves[place.element], place.param);
        let (gb, ga) = (g(b), g(a));
        let v2 = knot.speed * knot.speed;
        let mean = 0.5 * (gb + ga) * v2;
        let (place, own) = if after { (a, ga) } else { (b, gb) };
        (mean - own * v2) / curves[place.element].rate(place.param)
    }
}

/// `g = ρ'/ρ²` at `phi` on `curve`, whose rate is `ρ(φ) = |dc/dφ|`: the tangential
/// acceleration `d(ρ·φ')/dt = ρ'·φ'² + ρ·φ''` is `g·v²` at speed `v` where the parameter
/// acceleration `φ''` is zero. Zero on a line and a circle (`ρ'` by a central difference
/// over 10⁻⁵ of the span).
fn rate_growth(curve: &Curve, phi: f64) -> f64 {
    if curve.is_line() {
        return 0.0;
    }
    let h = 1e-5 * curve.span;
    let (lo, hi) = ((phi - h).max(0.0), (phi + h).min(curve.span));
    if hi <= lo {
        return 0.0;
    }
    let slope = (curve.rate(hi) - curve.rate(lo)) / (hi - lo);
    slope / curve.rate(phi).powi(2)
}

/// The points `(φ, φ', time to the next)` of a parameter motion from `φ₀ = phis[0]` at
/// rate `rates[0]` to `phis[1]` at `rates[1]` in three parts of `times`, whose parameter
/// acceleration is linear on each part, `ends[0]` and `ends[1]` at the two knots, and
/// takes the two inner values that meet the end rate and the span (a 2×2 system: the
/// rate change is the acceleration's integral, the span its moment). The last point is
/// the end exactly.
fn rate_turn_points(
    phis: [f64; 2],
    rates: [f64; 2],
    ends: [f64; 2],
    times: [f64; 3],
) -> Vec<(f64, f64, f64)> {
    let total: f64 = times.iter().sum();
    let starts = [0.0, times[0], times[0] + times[1]];
    // ∫(T − t)·a(t) dt over a part from `start` of length `h` whose acceleration goes
    // linearly from α to β.
    let moment = |alpha: f64, beta: f64, start: f64, h: f64| {
        let c = total - start;
        alpha * h * (c - 0.5 * h) + (beta - alpha) * h * (0.5 * c - h / 3.0)
    };
    let (a11, a12) = (0.5 * (times[0] + times[1]), 0.5 * (times[1] + times[2]));
    let a21 = moment(0.0, 1.0, starts[0], times[0]) + moment(1.0, 0.0, starts[1], times[1]);
    let a22 = moment(0.0, 1.0, starts[1], times[1]) + moment(1.0, 0.0, starts[2], times[2]);
    let r1 = rates[1] - rates[0] - 0.5 * (ends[0] * times[0] + ends[1] * times[2]);
    let r2 = (phis[1] - phis[0])
        - rates[0] * total
        - moment(ends[0], 0.0, starts[0], times[0])
        - moment(0.0, ends[1], starts[2], times[2]);
    let det = a11 * a22 - a12 * a21;
    let accel = [
        ends[0],
        (r1 * a22 - a12 * r2) / det,
        (a11 * r2 - a21 * r1) / det,
        ends[1],
    ];
    let (mut phi, mut rate) = (phis[0], rates[0]);
    let mut points = Vec::with_capacity(4);
    for i in 0..3 {
        let (h, alpha, beta) = (times[i], accel[i], accel[i + 1]);
        points.push((phi, rate, h));
        phi += rate * h + 0.5 * alpha * h * h + (beta - alpha) * h * h / 6.0;
        rate += 0.5 * (alpha + beta) * h;
    }
    points.push((phis[1], rates[1], 0.0));
    points
}

/// True when every part of `points` (see [`rate_turn_points`]) moves forward in the
/// parameter: else the piece is the plain S-curve, at rest in parameter acceleration at
/// its knots.
fn moves_forward(points: &[(f64, f64, f64)]) -> bool {
    points.windows(2).all(|w| {
        let ((p0, r0, dt), (p1, r1, _)) = (w[0], w[1]);
        p1.is_finite() && parameter_peaks(&HermiteSegment::new(p0, r0, p1, r1, dt)).2 >= 0.0
    })
}

/// The error bound of a cubic reference motion `φ(t)` on `curve` (see "Quantization" in
/// [`super`]), without the junction term: against the programmed curve's true one, so
/// the curve's `fit` is added.
fn bend(curve: &Curve, phi: &HermiteSegment) -> f64 {
    let (rate, accel, _) = parameter_peaks(phi);
    let [d2, d3, d4] = curve.derivative_bounds();
    let (t, jerk) = (phi.duration, phi.jerk.abs());
    t.powi(4) / 384.0
        * (d4 * rate.powi(4)
            + 6.0 * d3 * rate * rate * accel
            + 3.0 * d2 * accel * accel
            + 4.0 * d2 * rate * jerk)
        + curve.fit
}

/// In jerk mode, the least time of a smoothstep at rest at both ends whose acceleration
/// at each end, `6·c/T²` on an axis moving `c`, is within half its step bound (with room
/// for `6·r/T²` of rounding of positions written to a resolution `r`) and its
/// acceleration limit, and whose jerk `12·c/T³` is within its limit.
fn rest_time(piece: &Piece, bounds: &AxisBounds) -> f64 {
    let mut t: f64 = 0.0;
    for i in 0..piece.start.len() {
        let c = (piece.end[i] - piece.start[i]).abs();
        t = t
            .max((12.0 * (c + bounds.resolution) / bounds.step[i]).sqrt())
            .max((6.0 * c / bounds.acceleration[i]).sqrt())
            .max(libm::cbrt(12.0 * c / bounds.jerk[i]));
    }
    t
}

impl Knots {
    /// The unit tangents of the two lines of the corner blend after knot `k`: those its
    /// junction was made with.
    fn blend_tangents(&self, curves: &[Curve], k: usize) -> [Vector; 2] {
        let e = self.knots[k].after.element;
        let (a, b) = (&curves[e], &curves[e + 1]);
        [a.unit_tangent(a.span), b.unit_tangent(0.0)]
    }

    /// The corner blend after knot `k`: from the first line at L before the corner to
    /// the second at L after it, velocities along each line, time from
    /// [`blend_time`], so both inner control points lie on the lines within L of the
    /// corner; its error is [`blend_error`].
    fn blend_piece(&self, curves: &[Curve], k: usize, j: usize) -> Piece {
        let junction = &self.junctions[j];
        let l = junction.blend.unwrap_or(0.0);
        let e = self.knots[k].after.element;
        let (a, b) = (&curves[e], &curves[e + 1]);
        let dim = a.start.len();
        let mut start = Vector::zeros(dim);
        let mut end = Vector::zeros(dim);
        a.position(a.span - l, &mut start);
        b.position(l, &mut end);
        let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
        let scaled = |t: &[f64], v: f64| Vector::from_fn(t.len(), |i| t[i] * v);
        let duration = blend_time(l, va, vb);
        let [t1, t2] = self.blend_tangents(curves, k);
        Piece {
            start,
            end,
            start_velocity: scaled(&t1, va),
            end_velocity: scaled(&t2, vb),
            duration,
            error: blend_error(
                l,
                va * duration / 3.0,
                vb * duration / 3.0,
                junction.half_turn_sin,
            ),
            knot: k,
            part: None,
        }
    }
}

/// How far a corner blend of half-length `l` whose inner control points lie `da` and
/// `db` from its ends (towards the corner C, both at most `l`) can be from the two lines
/// and how far C can be from it.
///
/// With unit tangents t₁, t₂ and turning angle α, the blend is
/// `B(u) − C = −A(u)·t₁ + E(u)·t₂`, `A(u) = (1−u)³l + 3u(1−u)²(l − da)` falling from l to
/// 0 and `E(u) = 3u²(1−u)(l − db) + u³l` rising from 0 to l. Its distance from the first
/// line is `E·sin α` and from the second `A·sin α` (whichever foot lies on its line; one
/// does), so at most `min(A, E)·sin α`; and C is at most `|B(u*) − C| = 2·A(u*)·sin(α/2)`
/// from it, where A and E cross at u*. Both are at most `2·A(u*)·sin(α/2)`; at equal end
/// speeds (da = db = 2l/3) `A(u*) = l/4`, so `l·sin(α/2)/2`. The crossing is the root of
/// the cubic `A − E`, found by a fixed number of Newton steps.
fn blend_error(l: f64, da: f64, db: f64, half_turn_sin: f64) -> f64 {
    let (a, e) = ((l - da).clamp(0.0, l), (l - db).clamp(0.0, l));
    let first = |u: f64| (1.0 - u).powi(3) * l + 3.0 * u * (1.0 - u).powi(2) * a;
    let second = |u: f64| 3.0 * u * u * (1.0 - u) * e + u.powi(3) * l;
    // A − E = l + 3(a − l)·u + 3(l − 2a − e)·u² + (3a + 3e − 2l)·u³ falls from l to −l
    // on [0, 1]: Newton's steps from the middle (exact at equal speeds, where it is
    // l − 2l·u), kept in [0, 1].
    let c = [
        l,
        3.0 * (a - l),
        3.0 * (l - 2.0 * a - e),
        3.0 * a + 3.0 * e - 2.0 * l,
    ];
    let mut u = 0.5_f64;
    for _ in 0..BLEND_NEWTON_STEPS {
        let f = c[0] + u * (c[1] + u * (c[2] + u * c[3]));
        let slope = c[1] + u * (2.0 * c[2] + u * 3.0 * c[3]);
        if f == 0.0 || slope >= 0.0 {
            break;
        }
        u = (u - f / slope).clamp(0.0, 1.0);
    }
    // At any u, min(A, E) ≤ max(A(u), E(u)) everywhere: left of u* (where A = E) E ≤
    // E(u*) = A(u*) and right of it A ≤ A(u*), and max(A(u), E(u)) ≥ A(u*) since A falls
    // and E rises; at u* it is A(u*). Whatever da and db, the blend stays in the
    // triangle of its ends and C, within l·sin(α/2) of both lines and of C.
    (2.0 * first(u).max(second(u))).min(l) * half_turn_sin
}

/// Newton steps of [`blend_error`]'s crossing: a fixed count, so the result is the same
/// on every run (the bound holds at any point; these make it tight to rounding).
const BLEND_NEWTON_STEPS: usize = 8;

/// How far the jerk-limited corner blend of half-length `l` from speed `va` to `vb` (see
/// `Knots::smooth_blend`) can be from the two lines and how far the corner C can be from
/// it. With `u = t/T` its position is `C − A(u)·t₁ + E(u)·t₂`, where `A = l − va·T·(u −
/// G(u))` falls from l to 0 and `E = vb·T·G(u)` rises from 0 to l, `G` the double
/// integral of the unit pulse: `u³/(3θ)` up to `θ`, then `u − (1 + θ)/3 + (1 −
/// u)³/(3(1 − θ))`. The argument of [`blend_error`] holds for any such A and E: the
/// bound is `2·max(A(u), E(u))·sin(α/2)` at any u, here at the crossing; at equal speeds
/// it is `l·sin(α/2)/3`.
///
/// The crossing is the root of `F = A − E = l − va·T·u − (vb − va)·T·G(u)`, found by
/// [`SMOOTH_BLEND_NEWTON_STEPS`] Newton steps from `u = 1/2` (the root at equal speeds).
/// `G` is C² (`G(θ) = θ²/3`, `G'(θ) = θ`, `G''(θ) = 2` from both sides) with `0 ≤ G' ≤
/// 1`, so `F' = −T·(va·(1 − G') + vb·G')` lies within `−T·[min(va, vb), max(va, vb)]`:
/// F falls strictly and has one root, which Newton's method reaches quadratically.
fn smooth_blend_error(l: f64, va: f64, vb: f64, half_turn_sin: f64) -> f64 {
    let theta = (2.0 * vb - va) / (va + vb);
    let t = l / va + l / vb;
    // G and G' together.
    let g = |u: f64| {
        if u <= theta {
            (u * u * u / (3.0 * theta), u * u / theta)
        } else {
            let w = 1.0 - u;
            (
                u - (1.0 + theta) / 3.0 + w * w * w / (3.0 * (1.0 - theta)),
                1.0 - w * w / (1.0 - theta),
            )
        }
    };
    let mut u = 0.5_f64;
    for _ in 0..SMOOTH_BLEND_NEWTON_STEPS {
        let (gu, slope) = g(u);
        let f = l - va * t * u - (vb - va) * t * gu;
        let df = -t * (va * (1.0 - slope) + vb * slope);
        if f == 0.0 || df >= 0.0 {
            break;
        }
        u = (u - f / df).clamp(0.0, 1.0);
    }
    let gu = g(u).0;
    let (first, second) = (l - va * t * (u - gu), vb * t * gu);
    (2.0 * first.max(second)).clamp(0.0, l) * half_turn_sin
}

/// Newton steps of [`smooth_blend_error`]'s crossing: a fixed count, so the result is the
/// same on every run (the bound holds at any point). Over the speed ratios a jerk-limited
/// blend takes (`θ` in `(0, 1)`: `vb/va` within `(1/2, 2)`), three steps leave the
/// crossing within 10⁻¹⁰ and four within rounding of it.
const SMOOTH_BLEND_NEWTON_STEPS: usize = 4;

/// Time of a blend of half-length `l` from speed `va` to `vb`: 4L/(va + vb), the
/// constant-acceleration time over its 2L, while that keeps each inner control point
/// within L of the corner (the faster end at most three times the slower); else 3L over
/// the faster speed, which puts that control point at the corner.
fn blend_time(l: f64, va: f64, vb: f64) -> f64 {
    let (slow, fast) = (va.min(vb), va.max(vb));
    if fast <= 3.0 * slow {
        4.0 * l / (va + vb)
    } else {
        3.0 * l / fast
    }
}

/// Most rounds of lengthening pieces on the grid before the planner lowers speeds instead.
const GRID_ROUNDS: usize = 64;

/// The grid times of `pieces` with `counts[i]` quanta of `q` each, and every knot's
/// divisor: the larger stretch `time/duration` of the pieces beside it (the first knot,
/// whose velocity is already written, 1; the last, its one piece's).
fn grid_scales(
    durations: impl Iterator<Item = f64>,
    counts: &[f64],
    q: f64,
) -> (Vec<f64>, Vec<f64>) {
    let n = counts.len();
    let times: Vec<f64> = counts.iter().map(|&k| quanta_time(k, q)).collect();
    let stretch: Vec<f64> = times.iter().zip(durations).map(|(t, d)| t / d).collect();
    let mut scale = vec![1.0; n + 1];
    for j in 1..=n {
        scale[j] = if j == n {
            stretch[n - 1]
        } else {
            stretch[j - 1].max(stretch[j])
        };
    }
    (times, scale)
}

/// Pieces on a time grid.
#[derive(Debug, Clone)]
pub(super) struct Grid {
    pub pieces: Pieces,
}

impl Knots {
    /// The pieces on the quantum grid (see the module documentation of [`super`],
    /// "Quantization"): each piece gets whole quanta, at first as the grid rounds its
    /// planned time, and each knot's velocity is divided by the larger stretch of its two
    /// pieces (the first knot, whose velocity is already written, by 1). A piece whose
    /// closed-form peaks then exceed a limit gets more quanta, up to [`GRID_ROUNDS`]
    /// rounds; each piece's error bound is recomputed for its new reference motion.
    pub fn on_grid(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        pieces: &Pieces,
        quantum: Quantum,
    ) -> Grid {
        if self.jerk_mode {
            return self.smooth_grid(curves, bounds, pieces, quantum);
        }
        let mut counts: Vec<f64> = pieces
            .iter()
            .map(|p| quantum.count(p.duration).max(1.0))
            .collect();
        let mut grid = self.grid_pieces(curves, pieces, &counts, quantum.seconds);
        for _ in 0..GRID_ROUNDS {
            let mut raised = false;
            for (count, piece) in counts.iter_mut().zip(&grid.pieces) {
                let factor = piece.limit_factor(bounds);
                if factor < 1.0 {
                    *count = (*count / factor).ceil().max(*count + 1.0);
                    raised = true;
                }
            }
            if !raised {
                break;
            }
            grid = self.grid_pieces(curves, pieces, &counts, quantum.seconds);
        }
        grid
    }

    /// The pieces with `counts[i]` quanta each and the knot velocities divided by the
    /// larger stretch beside them.
    fn grid_pieces(&self, curves: &[Curve], pieces: &Pieces, counts: &[f64], q: f64) -> Grid {
        let (times, scale) = grid_scales(pieces.durations(), counts, q);
        let mut grid = Pieces::with_capacity(curves[0].start.len(), pieces.len());
        for (i, p) in pieces.iter().enumerate() {
            grid.push(&self.grid_piece(curves, p, times[i], [scale[i], scale[i + 1]]));
        }
        Grid { pieces: grid }
    }

    /// Piece `p` in time `t` with its end velocities divided by `scale`, and its error
    /// bound for the reference motion φ(t) that is the cubic in the parameter from the
    /// knots' (or S-curve points') new parameter rates (see "Quantization" in [`super`]).
    fn grid_piece(&self, curves: &[Curve], p: PieceRef<'_>, t: f64, scale: [f64; 2]) -> Piece {
        let k = p.knot;
        let divide = |v: &[f64], s: f64| Vector::from_fn(v.len(), |i| v[i] / s);
        let mut piece = Piece {
            start: Vector::from_slice(p.start),
            end: Vector::from_slice(p.end),
            start_velocity: divide(p.start_velocity, scale[0]),
            end_velocity: divide(p.end_velocity, scale[1]),
            duration: t,
            error: p.error,
            knot: p.knot,
            part: p.part,
        };
        if let Some(j) = self.knots[k].blend_index() {
            // The inner control points move towards the ends (scale ≥ stretch): within
            // the triangle bound, which sizes blends on a grid.
            let l = self.junctions[j].blend.unwrap_or(0.0);
            let offset = |v: &[f64]| crate::vector::norm(v) * t / 3.0;
            let (da, db) = (offset(&piece.start_velocity), offset(&piece.end_velocity));
            piece.error = blend_error(l, da, db, self.junctions[j].half_turn_sin);
            return piece;
        }
        if p.at_rest() {
            // A slower smoothstep on the same chord.
            return piece;
        }
        let (curve, from, to) = self.piece_span(curves, k);
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        if let Some(part) = p.part {
            let phi = HermiteSegment::new(
                part.params[0],
                part.rates[0] / scale[0],
                part.params[1],
                part.rates[1] / scale[1],
                t,
            );
            piece.error = if parameter_peaks(&phi).2 < 0.0 {
                f64::INFINITY
            } else {
                let ends = [
                    (a, part.at_knot[0], scale[0]),
                    (b, part.at_knot[1], scale[1]),
                ];
                bend(curve, &phi) + self.turn(t, ends)
            };
            return piece;
        }
        let (wa, wb) = (
            a.speed / (scale[0] * curve.rate(from)),
            b.speed / (scale[1] * curve.rate(to)),
        );
        let phi = HermiteSegment::new(from, wa, to, wb, t);
        if parameter_peaks(&phi).2 < 0.0 {
            // φ would leave the piece's parameter range (not with K ≥ k).
            piece.error = f64::INFINITY;
            return piece;
        }
        piece.error = bend(curve, &phi) + self.turn(t, [(a, true, scale[0]), (b, true, scale[1])]);
        piece
    }
}

impl Knots {
    /// Jerk mode on the quantum grid (see "Jerk" in [`super`]): each knot's piece (its
    /// S-curve's parts joined again) gets whole quanta, at least three, and each knot's
    /// velocity is divided by the larger stretch beside it, as without a jerk limit. A
    /// piece that is not a blend and not at rest then becomes three parts of whole quanta
    /// (ramp, middle, ramp, the ramps as long as its S-curve's on the grid) whose
    /// parameter acceleration is linear on each part, zero at both knots, and takes the
    /// values at the two inner points that meet the new end rates and the piece's span
    /// in its new time. The motion stays C² in the parameter; each part's reference
    /// `φ(t)` is a cubic with the "Quantization" bound. A part over a limit gets its
    /// piece more quanta, up to [`GRID_ROUNDS`] rounds.
    fn smooth_grid(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        planned: &Pieces,
        quantum: Quantum,
    ) -> Grid {
        let mut whole: Vec<Piece> = Vec::with_capacity(self.knots.len());
        let mut ramps: Vec<f64> = Vec::with_capacity(self.knots.len());
        for p in planned {
            match whole.last_mut() {
                Some(last) if last.knot == p.knot => {
                    last.end = Vector::from_slice(p.end);
                    last.end_velocity = Vector::from_slice(p.end_velocity);
                    last.duration += p.duration;
                    last.error = last.error.max(p.error);
                }
                _ => {
                    let mut piece = p.to_piece();
                    piece.part = None;
                    whole.push(piece);
                    ramps.push(if p.part.is_some() { p.duration } else { 0.0 });
                }
            }
        }
        // A piece under 1.5 quanta stays one cubic: three quanta would stretch it, and
        // with it the velocities at its knots, too far.
        let smooth: Vec<bool> = whole
            .iter()
            .map(|p| {
                self.knots[p.knot].blend.is_none()
                    && !p.at_rest()
                    && p.duration >= 1.5 * quantum.seconds
            })
            .collect();
        let mut counts: Vec<f64> = whole
            .iter()
            .zip(&smooth)
            .map(|(p, &s)| {
                let n = quantum.count(p.duration).max(1.0);
                if s {
                    n.max(3.0)
                } else {
                    n
                }
            })
            .collect();
        let mut grid = self.smooth_grid_pieces(curves, &whole, &smooth, &ramps, &counts, quantum);
        for _ in 0..GRID_ROUNDS {
            let mut factors = vec![1.0_f64; whole.len()];
            for piece in &grid.pieces {
                let f = &mut factors[piece.knot];
                *f = f.min(piece.limit_factor(bounds));
            }
            let mut raised = false;
            for (count, factor) in counts.iter_mut().zip(factors) {
                if factor < 1.0 {
                    *count = (*count / factor).ceil().max(*count + 1.0);
                    raised = true;
                }
            }
            if !raised {
                break;
            }
            grid = self.smooth_grid_pieces(curves, &whole, &smooth, &ramps, &counts, quantum);
        }
        grid
    }

    /// The knots' pieces with `counts[k]` quanta each (see [`Knots::smooth_grid`]).
    fn smooth_grid_pieces(
        &self,
        curves: &[Curve],
        whole: &[Piece],
        smooth: &[bool],
        ramps: &[f64],
        counts: &[f64],
        quantum: Quantum,
    ) -> Grid {
        let q = quantum.seconds;
        let n = whole.len();
        let (times, scale) = grid_scales(whole.iter().map(|p| p.duration), counts, q);
        let mut pieces = Pieces::with_capacity(curves[0].start.len(), 3 * n);
        for (k, p) in whole.iter().enumerate() {
            let ends = [scale[k], scale[k + 1]];
            if smooth[k] {
                let ramp = if ramps[k] > 0.0 {
                    (ramps[k] * (times[k] / p.duration) / q).round()
                } else {
                    (counts[k] / 3.0).floor()
                };
                let ramp = ramp.min(((counts[k] - 1.0) / 2.0).floor()).max(1.0);
                let quanta = [ramp, counts[k] - 2.0 * ramp, ramp];
                self.smooth_parts(
                    curves,
                    p,
                    quanta.map(|c| quanta_time(c, q)),
                    ends,
                    &mut pieces,
                );
            } else {
                pieces.push(&self.grid_piece(curves, p.as_ref(), times[k], ends));
            }
        }
        Grid { pieces }
    }

    /// The three parts of durations `times` of knot piece `p` whose end velocities are
    /// divided by `scale` (see [`Knots::smooth_grid`]).
    fn smooth_parts(
        &self,
        curves: &[Curve],
        p: &Piece,
        times: [f64; 3],
        scale: [f64; 2],
        out: &mut Pieces,
    ) {
        let k = p.knot;
        let (curve, from, to) = self.piece_span(curves, k);
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let (wa, wb) = (
            a.speed / (scale[0] * curve.rate(from)),
            b.speed / (scale[1] * curve.rate(to)),
        );
        let total: f64 = times.iter().sum();
        // ∫(T − t)·a(t) dt over a part from `start` of length `h` whose acceleration
        // goes linearly from α to β: α·h·(c − h/2) + (β − α)·h·(c/2 − h/3), c = T − start.
        let moment = |alpha: f64, beta: f64, start: f64, h: f64| {
            let c = total - start;
            alpha * h * (c - 0.5 * h) + (beta - alpha) * h * (0.5 * c - h / 3.0)
        };
        let starts = [0.0, times[0], times[0] + times[1]];
        // The inner accelerations A₁, A₂: the rate change and the span.
        let (a11, a12) = (0.5 * (times[0] + times[1]), 0.5 * (times[1] + times[2]));
        let a21 = moment(0.0, 1.0, starts[0], times[0]) + moment(1.0, 0.0, starts[1], times[1]);
        let a22 = moment(0.0, 1.0, starts[1], times[1]) + moment(1.0, 0.0, starts[2], times[2]);
        let (r1, r2) = (wb - wa, (to - from) - wa * total);
        let det = a11 * a22 - a12 * a21;
        let accel = [
            0.0,
            (r1 * a22 - a12 * r2) / det,
            (a11 * r2 - a21 * r1) / det,
            0.0,
        ];
        let (mut phi, mut rate) = (from, wa);
        for i in 0..3 {
            let (h, alpha, beta) = (times[i], accel[i], accel[i + 1]);
            let (phi0, rate0) = (phi, rate);
            rate += 0.5 * (alpha + beta) * h;
            phi += rate0 * h + 0.5 * alpha * h * h + (beta - alpha) * h * h / 6.0;
            if i == 2 {
                (phi, rate) = (to, wb);
            }
            let mut part = Piece {
                start: p.start,
                end: p.end,
                start_velocity: Vector::from_fn(p.start.len(), |j| p.start_velocity[j] / scale[0]),
                end_velocity: Vector::from_fn(p.start.len(), |j| p.end_velocity[j] / scale[1]),
                duration: h,
                error: 0.0,
                knot: k,
                part: Some(Part {
                    params: [phi0, phi],
                    rates: [rate0, rate],
                    at_knot: [i == 0, i == 2],
                }),
            };
            let inner = |at: f64, w: f64, position: &mut Vector, velocity: &mut Vector| {
                curve.position(at, position);
                curve.derivative(at, velocity);
                velocity.iter_mut().for_each(|v| *v *= w);
            };
            if i > 0 {
                inner(phi0, rate0, &mut part.start, &mut part.start_velocity);
            }
            if i < 2 {
                inner(phi, rate, &mut part.end, &mut part.end_velocity);
            }
            let cubic = HermiteSegment::new(phi0, rate0, phi, rate, h);
            part.error = if !det.is_finite() || det == 0.0 || parameter_peaks(&cubic).2 < 0.0 {
                f64::INFINITY
            } else {
                let ends = [(a, i == 0, scale[0]), (b, i == 2, scale[1])];
                bend(curve, &cubic) + self.turn(h, ends)
            };
            out.push(&part);
        }
    }
}

/// Largest |φ'| and |φ''| of a cubic parameter motion, and its least φ'.
fn parameter_peaks(phi: &HermiteSegment) -> (f64, f64, f64) {
    let end = phi.end();
    let (mut fastest, mut slowest) = (phi.v0.max(end.velocity), phi.v0.min(end.velocity));
    if phi.jerk != 0.0 {
        let t = -phi.a0 / phi.jerk;
        if t > 0.0 && t < phi.duration {
            let v = phi.at(t).velocity;
            fastest = fastest.max(v);
            slowest = slowest.min(v);
        }
    }
    (
        fastest.max(-slowest),
        phi.a0.abs().max(end.acceleration.abs()),
        slowest,
    )
}

/// Largest relative change of the vector speed at mid-piece from `before` to `after`
/// (pieces that stand still at mid-piece left out).
pub(super) fn mid_speed_change(before: &Pieces, after: &Pieces) -> f64 {
    mid_speeds(before)
        .into_iter()
        .zip(mid_speeds(after))
        .filter(|(b, _)| *b > 1e-12)
        .map(|(b, a)| (a - b).abs() / b)
        .fold(0.0, f64::max)
}

/// The vector speed at the middle of each knot's piece (of the time of its parts).
fn mid_speeds(pieces: &Pieces) -> Vec<f64> {
    let speed = |p: PieceRef<'_>, t: f64| {
        let v = Vector::from_fn(p.start.len(), |i| p.cubic(i).at(t).velocity);
        crate::vector::norm(&v)
    };
    let mut out = Vec::new();
    let mut first = 0;
    while first < pieces.len() {
        let knot = pieces.knot(first);
        let count = (first..pieces.len())
            .take_while(|&i| pieces.knot(i) == knot)
            .count();
        let parts = || (first..first + count).map(|i| pieces.at(i));
        let half = parts().map(|p| p.duration).sum::<f64>() / 2.0;
        let mut start = 0.0;
        for (i, p) in parts().enumerate() {
            if half < start + p.duration || i + 1 == count {
                out.push(speed(p, half - start));
                break;
            }
            start += p.duration;
        }
        first += count;
    }
    out
}

#[cfg(test)]
// std's trigonometry on purpose: the check is independent of the planner's libm.
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::{blend_error, rate_turn_points, smooth_blend_error};
    use crate::hermite::HermiteSegment;

    /// A window's pieces made in one go (`Knots::pieces_into`, where a piece takes its
    /// start from the piece before it) are, bit for bit, those made one by one
    /// (`Knots::piece`): on settled pockets and corners, without and with limits.
    #[test]
    fn pieces_made_in_one_go_are_those_made_one_by_one() {
        use super::super::knots::{KnotStorage, Knots, Start};
        use super::super::tests::{rings_and_corners, test_options};
        use super::super::{settle_into, AxisBounds, Curve};
        use crate::axis::Axis;
        use crate::limits::AxisLimits;
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let limit = AxisLimits {
            velocity: Some(200.0),
            acceleration: Some(2000.0),
            jerk: None,
        };
        let start = Start {
            param: 0.0,
            speed: 0.0,
            junction: None,
        };
        for (elements, corner) in rings_and_corners() {
            for limit in [None, Some(limit)] {
                let options = test_options(corner, &axes, limit);
                let mut curves = Vec::new();
                for e in &elements {
                    Curve::push_new(e, &axes, &mut curves);
                }
                let bounds = AxisBounds::new(&axes, &options);
                let storage = KnotStorage::default();
                let mut knots = Knots::new(&curves, &bounds, 1e-4, corner, &start, false, storage);
                let mut pieces = crate::plan::path::piece::Pieces::default();
                assert!(settle_into(&mut knots, &curves, &bounds, 1e-4, &mut pieces));
                let n = knots.knots.len();
                assert!((1..n - 1).any(|k| knots.shares_its_start(k)));
                let mut all = crate::plan::path::piece::Pieces::default();
                knots.pieces_into(&curves, &bounds, &mut all);
                let one_by_one: Vec<_> = (0..n - 1)
                    .map(|k| knots.piece(&curves, &bounds, k))
                    .collect();
                assert_eq!(format!("{all:?}"), format!("{one_by_one:?}"));
            }
        }
    }

    /// The three parts of a piece whose knots carry parameter accelerations: the cubic
    /// through each part's end points and rates (the unique one) starts with the first
    /// knot's acceleration, ends with the second's, and joins the next part with the
    /// same acceleration, so the motion is C² in the parameter up to the span and rate
    /// asked. Speed rising, falling and level, accelerations of both signs.
    #[test]
    fn rate_turn_points_meet_their_end_accelerations_continuously() {
        for (rates, ends) in [
            ([10.0, 14.0], [3.0, -5.0]),
            ([14.0, 10.0], [-40.0, 25.0]),
            ([12.0, 12.0], [60.0, 60.0]),
            ([12.0, 12.0], [0.0, -80.0]),
        ] {
            let (t, span) = (0.03, 0.36);
            let times = [t / 3.0, t / 3.0, t / 3.0];
            let points = rate_turn_points([1.0, 1.0 + span], rates, ends, times);
            assert_eq!(points.len(), 4);
            let cubics: Vec<HermiteSegment> = points
                .windows(2)
                .map(|w| HermiteSegment::new(w[0].0, w[0].1, w[1].0, w[1].1, w[0].2))
                .collect();
            let scale = 1e-9 * (ends[0].abs() + ends[1].abs() + rates[0] / t);
            assert!(
                (cubics[0].a0 - ends[0]).abs() <= scale,
                "{rates:?} {ends:?}"
            );
            let last = cubics[2].end();
            assert!(
                (last.acceleration - ends[1]).abs() <= scale,
                "{rates:?} {ends:?}"
            );
            for w in cubics.windows(2) {
                let gap = (w[0].end().acceleration - w[1].a0).abs();
                assert!(gap <= scale, "{rates:?} {ends:?}: {gap}");
            }
        }
    }

    /// Pieces and curves own no heap memory (nothing to drop): the planner makes several
    /// pieces per element in every round of every window. A junction owns some only for
    /// a curvature transition (rare and large, boxed), so that every junction, with one
    /// or without, is a few vectors to build and move.
    #[test]
    fn planner_values_hold_no_heap_memory() {
        use super::super::knots::Junction;
        use super::super::transition::Transition;
        use std::mem::{needs_drop, size_of};
        assert!(!needs_drop::<super::Piece>());
        assert!(!needs_drop::<super::super::curve::Curve>());
        assert!(size_of::<Junction>() <= 256, "{}", size_of::<Junction>());
        assert!(size_of::<Junction>() < size_of::<Transition>() + 3 * size_of::<super::Vector>());
    }

    /// The Newton crossing against 200 bisection steps of `A − E`: the same bound to
    /// 10⁻¹², over inner control points anywhere within L of the ends.
    #[test]
    fn blend_error_is_the_bisected_crossing() {
        let l = 2.0;
        for i in 0..=20 {
            for j in 0..=20 {
                let (da, db) = (l * f64::from(i) / 20.0, l * f64::from(j) / 20.0);
                let (a, e) = (l - da, l - db);
                let first = |u: f64| (1.0 - u).powi(3) * l + 3.0 * u * (1.0 - u).powi(2) * a;
                let second = |u: f64| 3.0 * u * u * (1.0 - u) * e + u.powi(3) * l;
                let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if first(mid) >= second(mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let bisected = (2.0 * first(lo)).min(l);
                let bound = blend_error(l, da, db, 1.0);
                assert!(
                    (bound - bisected).abs() <= 1e-12 * l,
                    "{da} {db}: {bound} against {bisected}"
                );
            }
        }
    }

    /// The Newton crossing of the jerk-limited blend against 200 bisection steps of `A −
    /// E` (each written here from the pulse's double integral): the same bound to 10⁻¹³
    /// of L, and never above the bound at 32 bisections, over speed ratios across the
    /// whole range a blend takes (`θ` from 10⁻³ to 1 − 10⁻³).
    #[test]
    fn smooth_blend_error_is_the_bisected_crossing() {
        let l = 0.3;
        for i in 0..=400 {
            let (va, vb) = (1.0, 0.5 + 1.5 * f64::from(i) / 400.0);
            let theta = (2.0 * vb - va) / (va + vb);
            if !(theta > 1e-3 && theta < 1.0 - 1e-3) {
                continue;
            }
            let t = l / va + l / vb;
            // ∫₀ᵘ (u − s)·p(s) ds for the unit triangle p with its apex at θ.
            let double_integral = |u: f64| {
                let rise = u.min(theta);
                let mut g = 2.0 / theta * (u * rise * rise / 2.0 - rise.powi(3) / 3.0);
                if u > theta {
                    let c = 2.0 / (1.0 - theta);
                    // p(s) = c·(1 − s) on [θ, u]: ∫ (u − s)·(1 − s) ds.
                    let moment = |s: f64| u * s - (u + 1.0) * s * s / 2.0 + s.powi(3) / 3.0;
                    g += c * (moment(u) - moment(theta));
                }
                g
            };
            let first = |u: f64| l - va * t * (u - double_integral(u));
            let second = |u: f64| vb * t * double_integral(u);
            let crossing = |steps: usize| {
                let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
                for _ in 0..steps {
                    let mid = 0.5 * (lo + hi);
                    if first(mid) >= second(mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let u = 0.5 * (lo + hi);
                (2.0 * first(u).max(second(u))).clamp(0.0, l)
            };
            let bound = smooth_blend_error(l, va, vb, 1.0);
            let bisected = crossing(200);
            assert!(
                (bound - bisected).abs() <= 1e-13 * l,
                "{va} {vb}: {bound} against {bisected}"
            );
            assert!(bound <= crossing(32) + 1e-15 * l, "{va} {vb}: {bound}");
        }
    }

    /// Distance from `p` to the ray from the origin along `t` (unit).
    fn to_ray(p: [f64; 2], t: [f64; 2]) -> f64 {
        let along = (p[0] * t[0] + p[1] * t[1]).max(0.0);
        (p[0] - along * t[0]).hypot(p[1] - along * t[1])
    }

    /// The blend bound against the cubic sampled densely: its distance from the two
    /// lines and the corner's distance from it, for turns from 10° to 170° and inner
    /// control points anywhere within L of the ends.
    #[test]
    fn blend_bound_holds_and_is_tight_at_equal_speeds() {
        let l = 1.0;
        for degrees in [10.0f64, 45.0, 90.0, 135.0, 170.0] {
            let alpha = degrees.to_radians();
            // Corner at the origin; arrive along +x, leave turned by α.
            let t1 = [1.0, 0.0];
            let t2 = [alpha.cos(), alpha.sin()];
            let half = (alpha / 2.0).sin();
            for i in 0..=6 {
                for j in 0..=6 {
                    let (da, db) = (l * i as f64 / 6.0, l * j as f64 / 6.0);
                    let p = [
                        [-l * t1[0], -l * t1[1]],
                        [-(l - da) * t1[0], -(l - da) * t1[1]],
                        [(l - db) * t2[0], (l - db) * t2[1]],
                        [l * t2[0], l * t2[1]],
                    ];
                    let (mut far, mut near) = (0.0f64, f64::INFINITY);
                    for s in 0..=4000 {
                        let u = s as f64 / 4000.0;
                        let w = [
                            (1.0 - u).powi(3),
                            3.0 * u * (1.0 - u).powi(2),
                            3.0 * u * u * (1.0 - u),
                            u.powi(3),
                        ];
                        let b = [0, 1].map(|k| (0..4).map(|m| w[m] * p[m][k]).sum::<f64>());
                        // The incoming line is the ray from the corner along −t1.
                        let lines = to_ray(b, [-t1[0], -t1[1]]).min(to_ray(b, t2));
                        far = far.max(lines);
                        near = near.min(b[0].hypot(b[1]));
                    }
                    let bound = blend_error(l, da, db, half);
                    assert!(
                        far <= bound * (1.0 + 1e-9),
                        "lines: {degrees}° {da} {db}: {far} > {bound}"
                    );
                    // The corner's bound is its distance at one instant, which the
                    // samples straddle: 1e-4 covers their spacing.
                    assert!(
                        near <= bound * (1.0 + 1e-4),
                        "corner: {degrees}° {da} {db}: {near} > {bound}"
                    );
                }
            }
            let equal = blend_error(l, 2.0 * l / 3.0, 2.0 * l / 3.0, half);
            assert!((equal - l * half / 2.0).abs() < 1e-12, "{equal}");
        }
    }

    /// The jerk-limited blend against its motion integrated step by step from the pulse
    /// alone (acceleration `s(t)·(vb·t₂ − va·t₁)`, `s` the triangle of area 1 with its
    /// apex at `θ·T`): it ends at `L` along the second line with its end velocity, and
    /// its distance from the lines and the corner's distance from it are within
    /// [`smooth_blend_error`], for turns from 10° to 170° and speed ratios 0.52 to 1.95.
    #[test]
    fn smooth_blend_reaches_its_end_within_its_bound() {
        let l = 1.0;
        for degrees in [10.0f64, 45.0, 90.0, 135.0, 170.0] {
            let alpha = degrees.to_radians();
            let t1 = [1.0, 0.0];
            let t2 = [alpha.cos(), alpha.sin()];
            let half = (alpha / 2.0).sin();
            for (va, vb) in [
                (1.0, 1.0),
                (1.0, 1.5),
                (1.5, 1.0),
                (2.0, 1.7),
                (1.0, 0.7),
                (1.0, 0.52),
                (1.0, 1.95),
            ] {
                let theta: f64 = (2.0 * vb - va) / (va + vb);
                let t = l / va + l / vb;
                let dv = [vb * t2[0] - va * t1[0], vb * t2[1] - va * t1[1]];
                let pulse = |time: f64| {
                    let apex = theta * t;
                    if time <= apex {
                        2.0 / t * time / apex
                    } else {
                        2.0 / t * (t - time) / (t - apex)
                    }
                };
                let steps = 200_000;
                let h = t / steps as f64;
                let mut p = [-l * t1[0], -l * t1[1]];
                let mut v = [va * t1[0], va * t1[1]];
                let (mut far, mut near) = (0.0f64, f64::INFINITY);
                for s in 0..steps {
                    // Midpoint rule on the velocity, trapezoid on the position.
                    let a0 = pulse(s as f64 * h);
                    let a1 = pulse((s as f64 + 1.0) * h);
                    let am = pulse((s as f64 + 0.5) * h);
                    let v_next = [v[0] + am * h * dv[0], v[1] + am * h * dv[1]];
                    for i in 0..2 {
                        p[i] += h * v[i] + h * h * (2.0 * a0 + a1) / 6.0 * dv[i];
                    }
                    v = v_next;
                    let lines = to_ray(p, [-t1[0], -t1[1]]).min(to_ray(p, t2));
                    far = far.max(lines);
                    near = near.min(p[0].hypot(p[1]));
                }
                let end = [l * t2[0] - p[0], l * t2[1] - p[1]];
                assert!(end[0].hypot(end[1]) < 1e-9, "{degrees}° {va} {vb}: {end:?}");
                let vend = [vb * t2[0] - v[0], vb * t2[1] - v[1]];
                assert!(
                    vend[0].hypot(vend[1]) < 1e-9,
                    "{degrees}° {va} {vb}: {vend:?}"
                );
                let bound = smooth_blend_error(l, va, vb, half);
                assert!(
                    far <= bound * (1.0 + 1e-6),
                    "lines: {degrees}° {va} {vb}: {far} > {bound}"
                );
                assert!(
                    near <= bound * (1.0 + 1e-4),
                    "corner: {degrees}° {va} {vb}: {near} > {bound}"
                );
                if va == vb {
                    assert!((bound - l * half / 3.0).abs() < 1e-9, "{bound}");
                }
            }
        }
    }
}
