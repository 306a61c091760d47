//! One piece of a planned contour: its end states, time, error bound and cubics.
//!
//! Owns the [`Piece`] value (start and end points and velocities, time, error bound, the
//! knot it starts from, its S-curve part), the [`Pieces`] that hold a plan's pieces flat
//! at the plan's own number of axes (read back as [`PieceRef`]s, bit for bit the
//! pieces pushed), and what follows from a piece alone: each axis' cubic, its end
//! accelerations and the closed-form per-axis peaks that limits are checked against. It
//! must not build pieces from knots or move knots: that is [`super::pieces`] and
//! [`super::knots`], which both read this one.

use super::{AxisBounds, Vector};
use crate::hermite::HermiteSegment;

/// One piece, ready to emit.
#[derive(Debug, Clone)]
pub(super) struct Piece {
    pub start: Vector,
    pub end: Vector,
    pub start_velocity: Vector,
    pub end_velocity: Vector,
    /// Seconds.
    pub duration: f64,
    /// Bound on the distance between the cubic and the programmed point, program units.
    pub error: f64,
    /// The knot the piece starts from (the piece of an S-curve's part).
    pub knot: usize,
    /// Where on its knot's piece an S-curve part runs (jerk mode); `None` for a whole piece.
    pub part: Option<Part>,
}

/// One part of a piece's S-curve (jerk mode): its parameters and parameter rates at both
/// ends, and which end is a knot (the other is inside the S-curve).
#[derive(Debug, Clone, Copy)]
pub(super) struct Part {
    pub params: [f64; 2],
    pub rates: [f64; 2],
    pub at_knot: [bool; 2],
}

impl Piece {
    /// The piece after knot `k` in `dim` axes with every state, time and error zero: the
    /// start its builders fill in.
    pub fn zeroed(dim: usize, knot: usize) -> Piece {
        Piece {
            start: Vector::zeros(dim),
            end: Vector::zeros(dim),
            start_velocity: Vector::zeros(dim),
            end_velocity: Vector::zeros(dim),
            duration: 0.0,
            error: 0.0,
            knot,
            part: None,
        }
    }

    /// The piece as its storage reads it back.
    #[inline]
    pub fn as_ref(&self) -> PieceRef<'_> {
        PieceRef {
            start: &self.start,
            end: &self.end,
            start_velocity: &self.start_velocity,
            end_velocity: &self.end_velocity,
            duration: self.duration,
            error: self.error,
            knot: self.knot,
            part: self.part,
        }
    }

    /// Each axis' acceleration at the start and at the end of the cubic.
    pub fn end_accelerations(&self) -> [Vector; 2] {
        self.as_ref().end_accelerations()
    }

    /// The cubic of axis `i`: from its start to its end state over the piece's time.
    #[inline]
    pub fn cubic(&self, i: usize) -> HermiteSegment {
        self.as_ref().cubic(i)
    }

    /// True when the piece starts and ends at rest.
    pub fn at_rest(&self) -> bool {
        self.as_ref().at_rest()
    }

    /// [`PieceRef::limit_factor`].
    pub fn limit_factor(&self, bounds: &AxisBounds) -> f64 {
        self.as_ref().limit_factor(bounds)
    }
}

/// A piece as [`Pieces`] holds it: its end states as slices of the plan's axes, the rest
/// as [`Piece`] has it.
#[derive(Debug, Clone, Copy)]
pub(super) struct PieceRef<'a> {
    pub start: &'a [f64],
    pub end: &'a [f64],
    pub start_velocity: &'a [f64],
    pub end_velocity: &'a [f64],
    /// Seconds.
    pub duration: f64,
    /// Bound on the distance between the cubic and the programmed point, program units.
    pub error: f64,
    /// The knot the piece starts from.
    pub knot: usize,
    /// Its S-curve part (jerk mode), `None` for a whole piece.
    pub part: Option<Part>,
}

impl PieceRef<'_> {
    /// The piece as a value.
    pub fn to_piece(self) -> Piece {
        Piece {
            start: Vector::from_slice(self.start),
            end: Vector::from_slice(self.end),
            start_velocity: Vector::from_slice(self.start_velocity),
            end_velocity: Vector::from_slice(self.end_velocity),
            duration: self.duration,
            error: self.error,
            knot: self.knot,
            part: self.part,
        }
    }

    /// Each axis' acceleration at the start and at the end of the cubic.
    pub fn end_accelerations(&self) -> [Vector; 2] {
        let n = self.start.len();
        let (mut start, mut end) = (Vector::zeros(n), Vector::zeros(n));
        for (i, (a0, a1)) in start.iter_mut().zip(end.iter_mut()).enumerate() {
            let h = self.cubic(i);
            (*a0, *a1) = (h.a0, h.end().acceleration);
        }
        [start, end]
    }

    /// The cubic of axis `i`: from its start to its end state over the piece's time.
    #[inline]
    pub fn cubic(&self, i: usize) -> HermiteSegment {
        HermiteSegment::new(
            self.start[i],
            self.start_velocity[i],
            self.end[i],
            self.end_velocity[i],
            self.duration,
        )
    }

    /// True when the piece starts and ends at rest.
    pub fn at_rest(&self) -> bool {
        self.start_velocity
            .iter()
            .chain(self.end_velocity)
            .all(|v| *v == 0.0)
    }

    /// 1 when every axis' closed-form velocity and acceleration peaks and its jerk are
    /// within its limits; otherwise the factor by which the piece's speeds should shrink.
    pub fn limit_factor(&self, bounds: &AxisBounds) -> f64 {
        let mut factor: f64 = 1.0;
        for i in 0..self.start.len() {
            let (vmax, amax, jmax) = (bounds.velocity[i], bounds.acceleration[i], bounds.jerk[i]);
            if vmax == f64::INFINITY && amax == f64::INFINITY && jmax == f64::INFINITY {
                // No limit on the axis: no peak of its cubic can be over one.
                continue;
            }
            let h = self.cubic(i);
            let (velocity, acceleration) = peaks(&h);
            if velocity > vmax * (1.0 + 1e-9) {
                factor = factor.min(vmax / velocity);
            }
            if acceleration > amax * (1.0 + 1e-9) {
                factor = factor.min((amax / acceleration).sqrt());
            }
            let jerk = h.jerk.abs();
            if jerk > jmax * (1.0 + 1e-9) {
                factor = factor.min(libm::cbrt(jmax / jerk));
            }
        }
        factor
    }
}

/// A plan's pieces, flat: the end states of every piece in one vector at the plan's own
/// number of axes (a piece of `d` axes takes `4·d` values, not the `4·6` of a
/// [`Piece`]), its time, error bound and knot in another, and the S-curve parts (jerk
/// mode) in a third that stays empty where no piece has one. Read back, a piece is bit
/// for bit the one pushed ([`Pieces::get`]).
#[derive(Clone, Default)]
pub(super) struct Pieces {
    /// Axes of every piece: set by the first piece pushed into an empty store.
    dim: usize,
    /// Per piece: start, end, start velocity and end velocity, `dim` values each.
    states: Vec<f64>,
    /// Per piece: time, error bound and knot.
    scalars: Vec<Scalars>,
    /// Per piece up to the last that has one: its part. Empty where none has.
    parts: Vec<Option<Part>>,
}

/// A stored piece's values but its states and part.
#[derive(Debug, Clone, Copy)]
struct Scalars {
    duration: f64,
    error: f64,
    knot: usize,
}

impl Pieces {
    /// No pieces, with room for `n` of `dim` axes.
    pub fn with_capacity(dim: usize, n: usize) -> Pieces {
        Pieces {
            dim,
            states: Vec::with_capacity(4 * dim * n),
            scalars: Vec::with_capacity(n),
            parts: Vec::new(),
        }
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.scalars.len()
    }

    /// The pieces' axes (those of the first pushed since the store was empty).
    #[inline]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.scalars.is_empty()
    }

    /// Drops every piece; the storage is kept.
    pub fn clear(&mut self) {
        self.truncate(0);
    }

    /// Keeps the first `n` pieces.
    pub fn truncate(&mut self, n: usize) {
        self.scalars.truncate(n);
        self.states.truncate(4 * self.dim * n);
        self.parts.truncate(n);
    }

    /// Adds `piece` after the last.
    #[inline]
    pub fn push(&mut self, piece: &Piece) {
        if self.scalars.is_empty() {
            self.dim = piece.start.len();
        }
        debug_assert_eq!(piece.start.len(), self.dim);
        // One copy of a size known where it is compiled, for each number of axes.
        match self.dim {
            1 => extend_states::<1>(&mut self.states, piece),
            2 => extend_states::<2>(&mut self.states, piece),
            3 => extend_states::<3>(&mut self.states, piece),
            4 => extend_states::<4>(&mut self.states, piece),
            5 => extend_states::<5>(&mut self.states, piece),
            _ => extend_states::<{ crate::axis::AXIS_COUNT }>(&mut self.states, piece),
        }
        self.scalars.push(Scalars {
            duration: piece.duration,
            error: piece.error,
            knot: piece.knot,
        });
        if piece.part.is_some() {
            self.parts.resize(self.scalars.len() - 1, None);
            self.parts.push(piece.part);
        }
    }

    /// Piece `i` written over with `piece`.
    pub fn set(&mut self, i: usize, piece: &Piece) {
        debug_assert_eq!(piece.start.len(), self.dim);
        let d = self.dim;
        let at = &mut self.states[4 * d * i..4 * d * (i + 1)];
        at[..d].copy_from_slice(&piece.start);
        at[d..2 * d].copy_from_slice(&piece.end);
        at[2 * d..3 * d].copy_from_slice(&piece.start_velocity);
        at[3 * d..].copy_from_slice(&piece.end_velocity);
        self.scalars[i] = Scalars {
            duration: piece.duration,
            error: piece.error,
            knot: piece.knot,
        };
        self.set_part(i, piece.part);
    }

    fn set_part(&mut self, i: usize, part: Option<Part>) {
        if i < self.parts.len() {
            self.parts[i] = part;
        } else if part.is_some() {
            self.parts.resize(i, None);
            self.parts.push(part);
        }
    }

    /// Piece `from` copied onto piece `to` as the piece after knot `knot`.
    pub fn copy_to(&mut self, from: usize, to: usize, knot: usize) {
        let n = 4 * self.dim;
        self.states.copy_within(n * from..n * (from + 1), n * to);
        self.scalars[to] = Scalars {
            knot,
            ..self.scalars[from]
        };
        let part = self.parts.get(from).copied().flatten();
        self.set_part(to, part);
    }

    /// Makes the store `n` pieces long: the pieces after the first `n` dropped, zero
    /// pieces after knot 0 of `dim` axes added up to `n`.
    pub fn resize(&mut self, n: usize, dim: usize) {
        if self.is_empty() {
            self.dim = dim;
        }
        self.truncate(n);
        self.states.resize(4 * self.dim * n, 0.0);
        self.scalars.resize(
            n,
            Scalars {
                duration: 0.0,
                error: 0.0,
                knot: 0,
            },
        );
    }

    /// Piece `i`.
    #[inline(always)]
    pub fn at(&self, i: usize) -> PieceRef<'_> {
        let d = self.dim;
        let states = &self.states[4 * d * i..4 * d * (i + 1)];
        let (start, rest) = states.split_at(d);
        let (end, rest) = rest.split_at(d);
        let (start_velocity, end_velocity) = rest.split_at(d);
        let s = self.scalars[i];
        PieceRef {
            start,
            end,
            start_velocity,
            end_velocity,
            duration: s.duration,
            error: s.error,
            knot: s.knot,
            part: self.parts.get(i).copied().flatten(),
        }
    }

    /// Piece `i`, `None` past the last.
    #[inline]
    pub fn get(&self, i: usize) -> Option<PieceRef<'_>> {
        (i < self.len()).then(|| self.at(i))
    }

    /// The last piece.
    #[inline]
    pub fn last(&self) -> Option<PieceRef<'_>> {
        self.len().checked_sub(1).map(|i| self.at(i))
    }

    /// The knot piece `i` starts from.
    #[inline]
    pub fn knot(&self, i: usize) -> usize {
        self.scalars[i].knot
    }

    /// Piece `i`'s time.
    #[inline]
    pub fn duration(&self, i: usize) -> f64 {
        self.scalars[i].duration
    }

    /// Piece `i`'s error bound.
    #[inline]
    pub fn error(&self, i: usize) -> f64 {
        self.scalars[i].error
    }

    /// Piece `i`'s end position and velocity.
    #[inline]
    pub fn end_state(&self, i: usize) -> (&[f64], &[f64]) {
        let d = self.dim;
        let at = 4 * d * i;
        (
            &self.states[at + d..at + 2 * d],
            &self.states[at + 3 * d..at + 4 * d],
        )
    }

    /// Every piece's time, in order.
    pub fn durations(&self) -> impl Iterator<Item = f64> + '_ {
        self.scalars.iter().map(|s| s.duration)
    }

    /// Every piece's knot and error bound, in order.
    pub fn knots_and_errors(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.scalars.iter().map(|s| (s.knot, s.error))
    }

    /// The number of pieces after knots before `knot` (the pieces are in knot order).
    pub fn before_knot(&self, knot: usize) -> usize {
        self.scalars.partition_point(|s| s.knot < knot)
    }

    /// The cubic of axis `axis` of piece `i` ([`PieceRef::cubic`], without the slices).
    #[inline]
    pub fn cubic(&self, i: usize, axis: usize) -> HermiteSegment {
        let d = self.dim;
        let at = 4 * d * i + axis;
        HermiteSegment::new(
            self.states[at],
            self.states[at + 2 * d],
            self.states[at + d],
            self.states[at + 3 * d],
            self.scalars[i].duration,
        )
    }

    /// The pieces in order.
    #[inline]
    pub fn iter(&self) -> Iter<'_> {
        Iter {
            pieces: self,
            range: 0..self.len(),
        }
    }
}

/// Appends the four states of `piece`, of `D` axes, to `states`.
#[inline(always)]
fn extend_states<const D: usize>(states: &mut Vec<f64>, piece: &Piece) {
    let row = |v: &Vector| -> [f64; D] { std::array::from_fn(|i| v.values[i]) };
    let rows = [
        row(&piece.start),
        row(&piece.end),
        row(&piece.start_velocity),
        row(&piece.end_velocity),
    ];
    states.extend_from_slice(rows.as_flattened());
}

/// The pieces of a [`Pieces`] in order.
#[derive(Debug, Clone)]
pub(super) struct Iter<'a> {
    pieces: &'a Pieces,
    range: std::ops::Range<usize>,
}

impl<'a> Iterator for Iter<'a> {
    type Item = PieceRef<'a>;
    #[inline]
    fn next(&mut self) -> Option<PieceRef<'a>> {
        self.range.next().map(|i| self.pieces.at(i))
    }
    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.range.size_hint()
    }
}

impl DoubleEndedIterator for Iter<'_> {
    #[inline]
    fn next_back(&mut self) -> Option<Self::Item> {
        self.range.next_back().map(|i| self.pieces.at(i))
    }
}

impl ExactSizeIterator for Iter<'_> {}

/// As the list of the pieces read back, whatever the storage holds besides.
impl std::fmt::Debug for Pieces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.iter().map(|p| p.to_piece()))
            .finish()
    }
}

impl<'a> IntoIterator for &'a Pieces {
    type Item = PieceRef<'a>;
    type IntoIter = Iter<'a>;
    #[inline]
    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

/// Largest |velocity| and |acceleration| of a cubic: the velocity at an end or where the
/// acceleration vanishes inside, the acceleration at an end.
fn peaks(h: &HermiteSegment) -> (f64, f64) {
    let end = h.end();
    let mut velocity = h.v0.abs().max(end.velocity.abs());
    if h.jerk != 0.0 {
        let t = -h.a0 / h.jerk;
        if t > 0.0 && t < h.duration {
            velocity = velocity.max(h.at(t).velocity.abs());
        }
    }
    (velocity, h.a0.abs().max(end.acceleration.abs()))
}

#[cfg(test)]
mod tests {
    use super::{Part, Piece, Pieces, Vector};

    /// Every value of a piece as bits, in a fixed order: two pieces read back alike
    /// exactly when these are equal (a −0 is not a +0, every NaN its own payload).
    fn bits(p: &Piece) -> Vec<u64> {
        let mut out: Vec<u64> = [&p.start, &p.end, &p.start_velocity, &p.end_velocity]
            .iter()
            .flat_map(|v| v.iter().map(|x| x.to_bits()))
            .collect();
        out.extend([p.duration.to_bits(), p.error.to_bits(), p.knot as u64]);
        if let Some(part) = p.part {
            out.extend(part.params.iter().chain(&part.rates).map(|x| x.to_bits()));
            out.extend(part.at_knot.map(u64::from));
        } else {
            out.push(u64::MAX);
        }
        out.push(p.start.len() as u64);
        out
    }

    /// A piece of `dim` axes whose every value follows from `seed` (a 64-bit LCG): odd
    /// values, −0, infinities and a NaN among them, and a part on some.
    fn piece(dim: usize, seed: &mut u64) -> Piece {
        let mut next = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let r = *seed >> 11;
            match r % 11 {
                0 => -0.0,
                1 => f64::INFINITY,
                2 => f64::from_bits(0x7ff8_0000_0000_1234),
                _ => (r as f64 / (1u64 << 53) as f64 - 0.5) * 1e3,
            }
        };
        let mut vector = || Vector::from_fn(dim, |_| next());
        let (start, end, start_velocity, end_velocity) = (vector(), vector(), vector(), vector());
        let (duration, error) = (next(), next());
        let knot = (next().abs() as usize) % 1000;
        let with_part = next() > 0.0;
        let part = with_part.then(|| Part {
            params: [next(), next()],
            rates: [next(), next()],
            at_knot: [next() > 0.0, next() > 0.0],
        });
        Piece {
            start,
            end,
            start_velocity,
            end_velocity,
            duration,
            error,
            knot,
            part,
        }
    }

    /// Pieces stored flat read back bit for bit as the pieces held one by one in a
    /// `Vec<Piece>` given the same pushes, writes, copies, truncations and resizes, on 1
    /// to 6 axes, with and without parts; each axis' cubic is the piece's own.
    #[test]
    fn pieces_stored_flat_read_back_bit_for_bit() {
        let mut seed = 7;
        for dim in 1..=crate::axis::AXIS_COUNT {
            let mut flat = Pieces::default();
            let mut model: Vec<Piece> = Vec::new();
            for round in 0..40 {
                let n = 1 + (seed >> 40) as usize % 30;
                for _ in 0..n {
                    let p = piece(dim, &mut seed);
                    flat.push(&p);
                    model.push(p);
                }
                let len = model.len();
                let (i, j) = ((seed >> 20) as usize % len, (seed >> 30) as usize % len);
                let p = piece(dim, &mut seed);
                flat.set(i, &p);
                model[i] = p;
                let knot = (seed >> 10) as usize % 500;
                flat.copy_to(i, j, knot);
                model[j] = Piece {
                    knot,
                    ..model[i].clone()
                };
                match round % 4 {
                    0 => {
                        let keep = len / 2;
                        flat.truncate(keep);
                        model.truncate(keep);
                    }
                    1 => {
                        let to = len + 3;
                        flat.resize(to, dim);
                        model.resize(to, Piece::zeroed(dim, 0));
                    }
                    2 if round % 8 == 2 => {
                        flat.clear();
                        model.clear();
                    }
                    _ => {}
                }
                assert_eq!(flat.len(), model.len());
                for (k, (a, b)) in flat.iter().zip(&model).enumerate() {
                    assert_eq!(bits(&a.to_piece()), bits(b), "{dim} axes, piece {k}");
                    assert_eq!(flat.knot(k), b.knot);
                    assert_eq!(flat.duration(k).to_bits(), b.duration.to_bits());
                    for axis in 0..dim {
                        let (x, y) = (flat.cubic(k, axis), b.cubic(axis));
                        assert_eq!(format!("{x:?}"), format!("{y:?}"));
                    }
                }
                assert_eq!(format!("{flat:?}"), format!("{model:?}"));
            }
        }
    }

    /// The flat store takes a plan's own axes: `4·d` values a piece, not the six a
    /// [`Vector`] holds.
    #[test]
    fn pieces_take_room_for_their_own_axes() {
        let mut seed = 3;
        for dim in 1..=crate::axis::AXIS_COUNT {
            let mut flat = Pieces::with_capacity(dim, 100);
            for _ in 0..100 {
                let mut p = piece(dim, &mut seed);
                p.part = None;
                flat.push(&p);
            }
            assert_eq!(flat.states.len(), 4 * dim * 100);
            assert!(flat.parts.is_empty(), "no piece has a part");
        }
    }
}
