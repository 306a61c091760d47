//! The second way onto a quantum grid: resampling the planned motion in time.
//!
//! Owns the uniform time scaling of a settled, un-gridded plan to whole quanta, the grid
//! knots (planned knot times rounded to the grid, split where the tolerance needs it and,
//! under a jerk limit, beside a knot whose acceleration steps too far), the cubic Hermite
//! pieces through the planned motion at the grid knots, their exact deviation from the
//! planned motion, the shares of the limits the plan is made with ([`Shares`]), and the
//! rounds that slow the plan where a resampled piece or knot is over a limit, and the
//! storage a resampling fills ([`Scratch`]), which its caller keeps so that every round
//! and window reuses it. It must not compute the planned pieces or choose between this
//! grid and the stretched one: that is [`super::pieces`] and [`super`].

use super::curve::Curve;
use super::knots::{KnotStorage, Knots};
use super::piece::{Piece, Pieces};
use super::{settle_into, AxisBounds, Vector, MAX_ROUNDS};
use crate::hermite::{HermiteSegment, State};
use crate::plan::quantize::{quanta_time, Quantum};
use crate::program::SegmentRef;

/// Share of the path (and corner) tolerance the plan that is resampled is planned to: the
/// rest is for the resampled pieces' deviation from it. On 1 ms grids that deviation is
/// of the order of `q²·Δa/8` where the planned acceleration steps by `Δa` (a few µm at
/// 1000 mm/s²), so a fifth of a tolerance of 0.01 mm or more rarely needs a split, while
/// the plan loses little: arcs get about 6 % more pieces (the bound goes with `T⁴`) and
/// corner blends are 0.8 as long.
pub(super) const RESAMPLE_SHARE: f64 = 0.8;

/// The planned motion scaled uniformly in time by `scale`: the same path, velocities
/// divided by `scale`, accelerations by `scale²`.
struct Motion<'a> {
    pieces: &'a Pieces,
    /// Planned (unscaled) start time of every piece, and the total at the end.
    starts: &'a [f64],
    scale: f64,
    /// The piece the last [`Motion::locate`] found: the grid is walked forward, so the
    /// next time is mostly in it or the one after.
    hint: std::cell::Cell<usize>,
}

impl<'a> Motion<'a> {
    /// The motion of `pieces` scaled by `scale`, its start times kept in `starts`.
    fn new(pieces: &'a Pieces, scale: f64, starts: &'a mut Vec<f64>) -> Motion<'a> {
        starts.clear();
        let mut t = 0.0;
        starts.push(t);
        for duration in pieces.durations() {
            t += duration;
            starts.push(t);
        }
        Motion {
            pieces,
            starts,
            scale,
            hint: std::cell::Cell::new(0),
        }
    }

    /// The piece that holds scaled time `t` (the later one at a knot) and the planned
    /// time into it.
    fn locate(&self, t: f64) -> (usize, f64) {
        let u = t / self.scale;
        let n = self.pieces.len();
        // The last piece `i` with `starts[i] ≤ u` (the first where none is): the starts
        // do not fall, so it is the hinted piece or the next where `u` lies between
        // their starts, else the search finds it.
        let holds =
            |i: usize| (i == 0 || self.starts[i] <= u) && (i + 1 >= n || self.starts[i + 1] > u);
        let hint = self.hint.get();
        let i = if hint < n && holds(hint) {
            hint
        } else if hint + 1 < n && holds(hint + 1) {
            hint + 1
        } else {
            self.starts[1..n].partition_point(|&s| s <= u)
        };
        self.hint.set(i);
        (i, (u - self.starts[i]).clamp(0.0, self.pieces.duration(i)))
    }

    /// Axis `axis` of piece `i` at planned time `u` into it, in scaled time.
    fn axis_state(&self, i: usize, axis: usize, u: f64) -> State {
        let s = self.pieces.cubic(i, axis).at(u);
        let k = self.scale;
        State {
            position: s.position,
            velocity: s.velocity / k,
            acceleration: s.acceleration / (k * k),
            jerk: s.jerk / (k * k * k),
        }
    }

    /// Position and (scaled) velocity at grid time `t`; the contour's ends exactly.
    fn at(&self, t: f64, last: bool) -> (Vector, Vector) {
        let dim = self.pieces.dim();
        if t <= 0.0 {
            let p = self.pieces.at(0);
            return (
                Vector::from_slice(p.start),
                Vector::from_fn(dim, |a| p.start_velocity[a] / self.scale),
            );
        }
        if last {
            let p = self.pieces.at(self.pieces.len() - 1);
            return (
                Vector::from_slice(p.end),
                Vector::from_fn(dim, |a| p.end_velocity[a] / self.scale),
            );
        }
        let (i, u) = self.locate(t);
        let (mut position, mut velocity) = (Vector::zeros(dim), Vector::zeros(dim));
        for a in 0..dim {
            let s = self.axis_state(i, a, u);
            (position[a], velocity[a]) = (s.position, s.velocity);
        }
        (position, velocity)
    }

    /// Scaled time at which piece `i` starts.
    fn start(&self, i: usize) -> f64 {
        self.starts[i] * self.scale
    }
}

/// Largest `|c₀ + c₁u + c₂u² + c₃u³|` on `[0, h]`: at an end or where the derivative
/// vanishes inside.
fn cubic_peak(c: [f64; 4], h: f64) -> f64 {
    let f = |u: f64| c[0] + u * (c[1] + u * (c[2] + u * c[3]));
    let mut peak = f(0.0).abs().max(f(h).abs());
    // c₁ + 2c₂u + 3c₃u² = 0.
    let (a, b, cc) = (3.0 * c[3], 2.0 * c[2], c[1]);
    let mut roots = [f64::NAN; 2];
    if a != 0.0 {
        let disc = b * b - 4.0 * a * cc;
        if disc >= 0.0 {
            let r = disc.sqrt();
            roots = [(-b - r) / (2.0 * a), (-b + r) / (2.0 * a)];
        }
    } else if b != 0.0 {
        roots[0] = -cc / b;
    }
    for u in roots {
        if u > 0.0 && u < h {
            peak = peak.max(f(u).abs());
        }
    }
    peak
}

/// The vectors a resampling fills, kept by its caller and reused by every round, try and
/// window (cleared, not reallocated), so that a streamed contour's resident memory stays
/// flat: the knots' and the plan's storage of a window on the grid, and the resampling's
/// own. The resampled pieces go out in [`Resampled`] and come back with
/// [`Scratch::give_back`].
#[derive(Debug, Default)]
pub(super) struct Scratch {
    /// The knots' vectors of the plan that is resampled.
    pub knots: KnotStorage,
    /// The pieces of the plan that is resampled.
    pub planned: Pieces,
    /// Planned start time of every piece (see [`Motion`]).
    starts: Vec<f64>,
    /// The grid knots, in quanta.
    grid: Vec<u64>,
    /// The resampled pieces' storage: under a jerk limit each round writes its pieces
    /// over the last round's, taking the last's on the same intervals (see [`Rewrite`]).
    done: GridPieces,
    /// The last round's pieces that a round's own have overtaken before it passed them.
    displaced: std::collections::VecDeque<Displaced>,
    /// Parts of a grid interval still to resample, latest first.
    todo: Vec<(u64, u64)>,
    /// The plan's speed at each resampled piece's mid-time.
    speeds: Vec<f64>,
}

impl Scratch {
    /// Takes back the storage of a window's knots and resampled pieces once they are out.
    pub fn give_back(&mut self, knots: Knots, pieces: GridPieces) {
        self.knots = knots.into_storage();
        self.done = pieces;
    }
}

/// Resampled pieces as the grid keeps them, in a third of the room of [`Piece`]s: each
/// piece's end position and velocity (its axes only, in one flat vector) and its grid
/// interval `[a, b]` in quanta, time, error bound and knot. Each piece starts where the
/// one before ends: both are the planned motion at the same grid time, the same state
/// (the first at the window's start, kept once).
#[derive(Debug, Default)]
pub(super) struct GridPieces {
    /// Axes of every state.
    dim: usize,
    /// The first piece's start position and velocity, then every piece's end position
    /// and velocity: `2·dim` values each.
    states: Vec<f64>,
    ends: Vec<GridEnd>,
}

/// What a resampled piece keeps besides its end state.
#[derive(Debug, Clone, Copy)]
struct GridEnd {
    interval: (u64, u64),
    duration: f64,
    error: f64,
    knot: usize,
}

/// A piece of the last round that a round's own overtook (see [`Rewrite`]): its end
/// position and velocity.
#[derive(Debug)]
struct Displaced {
    end: GridEnd,
    position: Vector,
    velocity: Vector,
}

/// A round's pieces written over the last round's in one vector, front to back, each of
/// the last round's taken over where a piece is on the same interval: the last round's
/// pieces are passed in order, and one that the round's own reach before it is passed
/// moves aside (`displaced`, in order), so that two rounds take the room of one and the
/// few pieces a round adds.
struct Rewrite<'a> {
    pieces: &'a mut GridPieces,
    displaced: &'a mut std::collections::VecDeque<Displaced>,
    /// The last round's pieces, how many of them are passed, and the round's own written.
    old: usize,
    read: usize,
    write: usize,
}

impl<'a> Rewrite<'a> {
    fn new(
        pieces: &'a mut GridPieces,
        displaced: &'a mut std::collections::VecDeque<Displaced>,
    ) -> Rewrite<'a> {
        displaced.clear();
        let old = pieces.len();
        Rewrite {
            pieces,
            displaced,
            old,
            read: 0,
            write: 0,
        }
    }

    /// The interval of the last round's first piece not passed yet.
    fn next_old(&self) -> Option<(u64, u64)> {
        if self.read >= self.old {
            None
        } else if self.read < self.write {
            self.displaced.front().map(|p| p.end.interval)
        } else {
            Some(self.pieces.ends[self.read].interval)
        }
    }

    /// Passes the last round's pieces that start before `a`; where the next is on
    /// `[a, b]`, takes it over and returns true.
    fn take_over(&mut self, (a, b): (u64, u64)) -> bool {
        while self.next_old().is_some_and(|i| i.0 < a) {
            if self.read < self.write {
                self.displaced.pop_front();
            }
            self.read += 1;
        }
        if self.next_old() != Some((a, b)) {
            return false;
        }
        if self.read == self.write {
            // Already where it is written.
            self.read += 1;
            self.write += 1;
            return true;
        }
        let p = if self.read < self.write {
            self.displaced.pop_front().expect("displaced in order")
        } else {
            self.old_piece(self.read)
        };
        self.read += 1;
        self.write(p.end, [&p.position, &p.velocity], None);
        true
    }

    /// The last round's piece `i`, still in place.
    fn old_piece(&self, i: usize) -> Displaced {
        let (position, velocity) = self.pieces.end_state(i);
        let dim = position.len();
        Displaced {
            end: self.pieces.ends[i],
            position: Vector::from_fn(dim, |a| position[a]),
            velocity: Vector::from_fn(dim, |a| velocity[a]),
        }
    }

    /// Writes the round's next piece (moving the last round's piece there aside when it
    /// is not passed yet).
    fn write(&mut self, end: GridEnd, state: [&[f64]; 2], start: Option<[&[f64]; 2]>) {
        let w = self.write;
        if w < self.old && w >= self.read {
            let p = self.old_piece(w);
            self.displaced.push_back(p);
        }
        self.pieces.write_at(w, end, state, start);
        self.write += 1;
    }

    /// Writes `piece` on grid interval `interval` as the round's next.
    fn push(&mut self, interval: (u64, u64), piece: &Piece) {
        // A piece that follows the last one on the grid starts in its end state (a
        // round with a piece left out fails as a whole: its pieces are not used).
        debug_assert!(
            self.write == 0 || self.pieces.ends[self.write - 1].interval.1 != interval.0 || {
                let (end, velocity) = self.pieces.end_state(self.write - 1);
                (end, velocity) == (&piece.start[..], &piece.start_velocity[..])
            }
        );
        let end = GridEnd {
            interval,
            duration: piece.duration,
            error: piece.error,
            knot: piece.knot,
        };
        let start = (self.write == 0).then_some([&piece.start[..], &piece.start_velocity[..]]);
        self.write(end, [&piece.end, &piece.end_velocity], start);
    }

    /// Drops what is left of the last round's pieces.
    fn finish(self) {
        self.pieces.truncate(self.write);
    }
}

impl GridPieces {
    fn clear(&mut self) {
        self.states.clear();
        self.ends.clear();
    }

    /// Makes piece `i` (at most one past the last) `end` with end position `position` and
    /// velocity `velocity`, and the first piece's start `start` where given.
    fn write_at(&mut self, i: usize, end: GridEnd, state: [&[f64]; 2], start: Option<[&[f64]; 2]>) {
        if self.states.is_empty() {
            self.dim = state[0].len();
            self.states.resize(2 * self.dim, 0.0);
        }
        let d = self.dim;
        if let Some([position, velocity]) = start {
            self.states[..d].copy_from_slice(position);
            self.states[d..2 * d].copy_from_slice(velocity);
        }
        if i == self.ends.len() {
            self.states.extend_from_slice(state[0]);
            self.states.extend_from_slice(state[1]);
            self.ends.push(end);
        } else {
            let at = 2 * d * (i + 1);
            self.states[at..at + d].copy_from_slice(state[0]);
            self.states[at + d..at + 2 * d].copy_from_slice(state[1]);
            self.ends[i] = end;
        }
    }

    /// Keeps the first `len` pieces.
    fn truncate(&mut self, len: usize) {
        self.ends.truncate(len);
        self.states.truncate(2 * self.dim * (len + 1));
    }

    /// Whether the pieces run over every interval of `grid` in turn (each starting where
    /// the one before ends).
    fn is_whole(&self, grid: &[u64]) -> bool {
        let mut at = grid.first().copied();
        for e in &self.ends {
            if at != Some(e.interval.0) {
                return false;
            }
            at = Some(e.interval.1);
        }
        at == grid.last().copied()
    }

    /// How many pieces there are.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// Every piece's time, in order.
    pub fn durations(&self) -> impl Iterator<Item = f64> + '_ {
        self.ends.iter().map(|e| e.duration)
    }

    /// Every piece's error bound, in order.
    pub fn errors(&self) -> impl Iterator<Item = f64> + '_ {
        self.ends.iter().map(|e| e.error)
    }

    /// The largest error bound of the pieces before the first from knot `count` on.
    pub fn worst_before(&self, count: usize) -> f64 {
        super::worst_before(self.ends.iter().map(|e| (e.knot, e.error)), count)
    }

    /// Piece `i`'s end position and velocity.
    fn end_state(&self, i: usize) -> (&[f64], &[f64]) {
        self.state(i + 1)
    }

    /// Piece `i`'s start position and velocity: the end of the one before.
    fn start_state(&self, i: usize) -> (&[f64], &[f64]) {
        self.state(i)
    }

    /// State `s` of `states` (0 the first piece's start, `i + 1` piece `i`'s end).
    fn state(&self, s: usize) -> (&[f64], &[f64]) {
        let (d, at) = (self.dim, 2 * self.dim * s);
        (&self.states[at..at + d], &self.states[at + d..at + 2 * d])
    }

    /// Piece `i` whole.
    pub fn piece(&self, i: usize) -> Piece {
        let dim = self.dim;
        let (start, start_velocity) = self.start_state(i);
        let (end, end_velocity) = self.end_state(i);
        let e = &self.ends[i];
        Piece {
            start: Vector::from_fn(dim, |a| start[a]),
            end: Vector::from_fn(dim, |a| end[a]),
            start_velocity: Vector::from_fn(dim, |a| start_velocity[a]),
            end_velocity: Vector::from_fn(dim, |a| end_velocity[a]),
            duration: e.duration,
            error: e.error,
            knot: e.knot,
            part: None,
        }
    }

    /// Emits the pieces of `knots`' knots before knot `count`, in order (as
    /// [`Knots::emit`] does for pieces).
    pub fn emit(
        &self,
        knots: &Knots,
        curves: &[Curve],
        count: usize,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) {
        for (i, e) in self
            .ends
            .iter()
            .enumerate()
            .take_while(|(_, e)| e.knot < count)
        {
            let (end, velocity) = self.end_state(i);
            emit(&SegmentRef {
                end,
                velocity,
                duration: e.duration,
                line: curves[knots.knots[e.knot].after.element].line,
            });
        }
    }
}

/// The resampled contour.
pub(super) struct Resampled {
    /// The pieces, in the storage of [`Scratch`] (give it back when done with them).
    pub pieces: GridPieces,
    /// Largest relative change of the speed at a resampled piece's mid-time against the
    /// plan at the same point of the path, where the plan moves at 1 % of the contour's
    /// fastest or more (near a stop a relative change says little: the grid times there
    /// move by at most half a quantum).
    pub speed_change: f64,
}

/// Why a grid interval's piece cannot be used.
enum Over {
    /// Over the tolerance, or over more than three elements: split it (when it spans
    /// two quanta or more) or slow it.
    Tolerance,
    /// Over a limit by this factor of its speeds.
    Limit(f64),
}

/// Tolerances the resampled pieces keep: the path tolerance, and a corner blend's.
#[derive(Clone, Copy)]
pub(super) struct Tolerances {
    pub path: f64,
    pub corner: f64,
}

/// How the plan that is resampled is made: its share of the path and corner tolerance,
/// and, in turn, its shares of the acceleration limits and of the acceleration step
/// bound (under a jerk limit), each with the most rounds of slowing it may take.
pub(super) struct Shares {
    pub tolerance: f64,
    pub tries: Vec<Try>,
}

/// One plan to resample: shares of the limits and the most rounds of slowing.
#[derive(Clone, Copy)]
pub(super) struct Try {
    pub acceleration: f64,
    pub step: f64,
    pub jerk: f64,
    pub rounds: usize,
}

impl Try {
    /// The bounds this plan is made to on a grid of `q` seconds: its shares of the
    /// acceleration, step ([`planned_step`]) and jerk limits, with no position rounding.
    pub fn planning(&self, bounds: &AxisBounds, q: f64) -> AxisBounds {
        AxisBounds {
            acceleration: bounds
                .acceleration
                .iter()
                .map(|a| a * self.acceleration)
                .collect(),
            step: bounds
                .step
                .iter()
                .map(|&s| planned_step(s, self.step, bounds.resolution, q))
                .collect(),
            jerk: bounds.jerk.iter().map(|j| j * self.jerk).collect(),
            resolution: 0.0,
            ..bounds.clone()
        }
    }
}

/// Shares of the acceleration limits the plan that is resampled is planned to without a
/// jerk limit, each tried in turn, with the most rounds of slowing it may take. Hermite
/// resampling of a motion whose acceleration is a short pulse (a corner blend under a
/// millisecond) can ask up to 4/3 of the pulse's acceleration at an interval's end,
/// depending on where the grid cuts it; with thousands of blends some always fall badly,
/// and slowing those moves the others on the grid. Planned at 0.75 (≤ 3/4 · 4/3 = 1)
/// nearly all fit at once; at 1.0 a plan with few such pulses keeps its full
/// acceleration, in a few rounds or not at all (its rounds are few: on a long contour
/// each settles the whole plan again); 0.6 is for splines, whose interpolation adds
/// more. All the rounds together stay within a fifth of [`MAX_ROUNDS`].
pub(super) const ACCELERATION_SHARES: [(f64, usize); 3] = [(0.75, 32), (1.0, 8), (0.6, 32)];

/// Under a jerk limit: shares of the acceleration step bound (left after the room for
/// rounding, see [`planned_step`]) tried in turn (the fastest wins), all but the last
/// at the acceleration share of [`Shares::new`], the first at the whole jerk, the second
/// at [`FIRST_JERK_SHARE`] of it and the later ones at a jerk low enough for the grid
/// (see there), the last at 0.75 of the acceleration limits. A
/// planned knot at full step whose acceleration pulse the grid cuts badly comes out up
/// to 4/3 of it on the grid: most fit at once, and where slowing does not converge the
/// lower shares do.
const JERK_TRIES: [(f64, usize); 4] = [(1.0, 8), (1.0, 24), (0.7, 16), (0.5, 32)];

const _: () = {
    let (mut rounds, mut i) = (0, 0);
    while i < ACCELERATION_SHARES.len() {
        rounds += ACCELERATION_SHARES[i].1;
        i += 1;
    }
    assert!(rounds <= MAX_ROUNDS / 5);
    let (mut rounds, mut i) = (0, 0);
    while i < JERK_TRIES.len() {
        rounds += JERK_TRIES[i].1;
        i += 1;
    }
    assert!(rounds <= MAX_ROUNDS / 5);
};

/// Under a jerk limit, the share of the jerk limits the second plan takes (the first
/// takes the whole limits, which suits a few long pieces): a line's S-curves then use
/// 0.9 of the limit (see `knots::path_jerk`), whose jerk changes the grid resamples
/// within the step bound at most knots on 1 ms grids with a 0.5 ms servo period; at the
/// whole limit dense chords do not converge.
const FIRST_JERK_SHARE: f64 = 0.91;

/// Under a jerk limit, the share of the path tolerance the plan keeps: the motion the
/// grid resamples is acceleration-continuous along each S-curve, so the resampled
/// pieces deviate from it by far less than without.
const JERK_TOLERANCE_SHARE: f64 = 0.95;

impl Shares {
    /// The shares for `bounds` on a grid of `q` seconds. Under a jerk limit the plan's
    /// jerk is within `Jᵢ` on each axis, changing by at most `2·Jᵢ`; a Hermite piece
    /// through it misses its acceleration at an end by at most `4/27·|Δj|·T` for a jerk
    /// change inside, so on a quantum the resampled acceleration is within `8/27·Jᵢ·q`
    /// of the plan's: the first plans take that share of the acceleration limits off
    /// (keeping at least 0.75).
    pub fn new(bounds: &AxisBounds, q: f64) -> Shares {
        if !bounds.jerk_mode() {
            let tries = ACCELERATION_SHARES
                .iter()
                .map(|&(acceleration, rounds)| Try {
                    acceleration,
                    step: 1.0,
                    jerk: 1.0,
                    rounds,
                });
            return Shares {
                tolerance: RESAMPLE_SHARE,
                tries: tries.collect(),
            };
        }
        let margin = (0..bounds.jerk.len())
            .map(|i| 8.0 / 27.0 * bounds.jerk[i] * q / bounds.acceleration[i])
            .filter(|m| m.is_finite())
            .fold(0.0, f64::max);
        let acceleration = (1.0 - margin).max(0.75);
        // The later plans' jerk: `16/27·j·q` (a jerk change of `2·j` within a quantum
        // on both sides of a grid knot) within the step bound, and for the last within
        // the half of it that its plan leaves. A planned step `Δa` inside a quantum adds
        // up to `1.5·Δa/q` to the resampled piece's jerk (the Hermite kernel
        // `6t(T − t)/T³`): the later plans' steps take at most half the jerk limit, the
        // S-curves' path jerk (0.9 of it) the other half.
        let fitting = (0..bounds.jerk.len())
            .map(|i| {
                let left = planned_step(bounds.step[i], 1.0, bounds.resolution, q);
                left / (16.0 / 27.0 * bounds.jerk[i] * q)
            })
            .filter(|s| s.is_finite())
            .fold(1.0, f64::min)
            .min(0.5 / 0.9);
        let last = JERK_TRIES.len() - 1;
        let tries = JERK_TRIES
            .iter()
            .enumerate()
            .map(|(i, &(step, rounds))| Try {
                acceleration: if i < last { acceleration } else { 0.75 },
                step,
                jerk: match i {
                    0 => 1.0,
                    1 => FIRST_JERK_SHARE,
                    _ if i < last => fitting,
                    _ => (1.0 - step) * fitting,
                },
                rounds,
            });
        Shares {
            tolerance: JERK_TOLERANCE_SHARE,
            tries: tries.collect(),
        }
    }
}

/// An axis' acceleration step bound `step` for the plan that is resampled onto a grid of
/// `q` seconds, at `share` of it: less the room the rounding of written positions
/// (resolution `r`) takes beside a knot between two pieces of one quantum, `12·r/q²`,
/// and at least a quarter of the share (a knot still over on the grid is slowed there).
pub(super) fn planned_step(step: f64, share: f64, resolution: f64, q: f64) -> f64 {
    (share * step - 12.0 * resolution / (q * q)).max(0.25 * share * step)
}

/// What the resampled pieces keep and how the plan is made.
pub(super) struct Limits<'a> {
    /// The bounds the plan is settled with.
    pub planning: &'a AxisBounds,
    /// The bounds every resampled piece keeps.
    pub bounds: &'a AxisBounds,
    /// The tolerance the plan is settled with.
    pub tolerance: f64,
    /// The tolerances the resampled pieces keep.
    pub tolerances: Tolerances,
    /// Most rounds of slowing.
    pub rounds: usize,
}

/// Resamples the settled `planned` pieces of `knots` onto the grid of `quantum` (see
/// "Quantization" in [`super`]); where a resampled piece is over a limit, or a piece of
/// one quantum over the tolerance, the planned knots its interval covers are slowed, the
/// plan is settled again and resampled again. `None` when that does not converge within
/// `limits.rounds`, the plan cannot be settled, or its total on the grid is not under `bar`
/// by half a quantum (slowing only lengthens it: it cannot win any more).
pub(super) fn resample(
    knots: &mut Knots,
    curves: &[Curve],
    limits: &Limits<'_>,
    quantum: Quantum,
    bar: f64,
    planned: &mut Pieces,
    scratch: &mut Scratch,
) -> Option<Resampled> {
    let q = quantum.seconds;
    for _ in 0..limits.rounds {
        if quanta_time(grid_count(planned, q), q) >= bar - 0.5 * q {
            return None;
        }
        let bounds = limits.bounds;
        match resample_once(knots, bounds, limits.tolerances, q, planned, true, scratch) {
            Ok(resampled) => return Some(resampled),
            Err(slow) => {
                for (knot_range, factor) in slow {
                    knots.slow_knots(knot_range, factor);
                }
                if !settle_into(knots, curves, limits.planning, limits.tolerance, planned) {
                    return None;
                }
            }
        }
    }
    None
}

/// Whole quanta of the planned total time, rounded up (at least one).
fn grid_count(planned: &Pieces, q: f64) -> f64 {
    let total: f64 = planned.durations().sum();
    (total / q - 1e-9).ceil().max(1.0)
}

/// One resampling of `planned`: the pieces, or the planned knot ranges to slow and by
/// what factor of their speeds. With `scaled` the plan is scaled in time to whole quanta
/// (a whole contour); without, it keeps its times from a start on the grid (a window of
/// a streamed contour, see "Streaming on a grid" in [`super`]): it ends on the grid
/// already (a window's prefix up to a knot placed at a grid time), or at rest, where
/// the last grid interval holds the end until the next whole quantum. Every vector it
/// fills is `scratch`'s.
pub(super) fn resample_once(
    knots: &Knots,
    bounds: &AxisBounds,
    tolerances: Tolerances,
    q: f64,
    planned: &Pieces,
    scaled: bool,
    scratch: &mut Scratch,
) -> Result<Resampled, Vec<(std::ops::Range<usize>, f64)>> {
    let Scratch {
        starts,
        grid,
        done,
        displaced,
        todo,
        speeds,
        ..
    } = scratch;
    let total: f64 = planned.durations().sum();
    let count = grid_count(planned, q);
    let scale = if scaled {
        quanta_time(count, q) / total
    } else {
        1.0
    };
    let motion = Motion::new(planned, scale, starts);
    let last = count as u64;
    // Grid knots: every planned knot's scaled time rounded to the grid, duplicates
    // dropped; the contour's ends at 0 and `count`.
    grid.clear();
    grid.push(0);
    for i in 1..planned.len() {
        let g = ((motion.start(i) / q).round() as u64).min(last);
        if g > *grid.last().unwrap_or(&0) && g < last {
            grid.push(g);
        }
    }
    grid.push(last);
    // Under a jerk limit, rounds of placing grid knots next to a knot whose acceleration
    // steps too far (each round at least one more; see [`steps_over`]). The first round
    // fills `done`, a later one writes over it, taking over its pieces on the same
    // intervals: without a jerk limit there is one round.
    done.clear();
    for _ in 0..=MAX_ROUNDS {
        let rewrite = Rewrite::new(done, displaced);
        let slow = resample_grid(knots, bounds, tolerances, q, &motion, grid, rewrite, todo);
        if !slow.is_empty() {
            return Err(slow);
        }
        if !bounds.jerk_mode() {
            break;
        }
        match steps_over(done, bounds) {
            Steps::Within => break,
            Steps::Split(knots_to_add) => {
                // Both runs are sorted: the stable sort merges them in one pass.
                grid.extend(knots_to_add);
                grid.sort();
                grid.dedup();
            }
            Steps::Slow(over) => {
                let slow = over.into_iter().map(|(at, factor)| {
                    let (a, b) = (
                        done.ends[at.start].interval.0,
                        done.ends[at.end - 1].interval.1,
                    );
                    (covered(&motion, a, b, q), factor)
                });
                return Err(slow.collect());
            }
        }
    }
    debug_assert!(done.is_whole(grid), "the pieces cover the grid");
    let speed_change = speed_change(&motion, done, speeds);
    Ok(Resampled {
        pieces: std::mem::take(done),
        speed_change,
    })
}

/// Into `pieces`, the pieces of every interval of `grid` (taking over the last round's on
/// the same interval), each over the tolerance split at its middle, with their intervals; the
/// planned knot ranges to slow and by what factor (none when every piece is in).
/// `todo` is storage for the parts of one grid interval still to resample.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn resample_grid(
    knots: &Knots,
    bounds: &AxisBounds,
    tolerances: Tolerances,
    q: f64,
    motion: &Motion<'_>,
    grid: &[u64],
    mut pieces: Rewrite<'_>,
    todo: &mut Vec<(u64, u64)>,
) -> Vec<(std::ops::Range<usize>, f64)> {
    let last = *grid.last().unwrap_or(&0);
    let mut slow = Vec::new();
    for w in grid.windows(2) {
        // The parts of this interval still to resample, latest first: a part over the
        // tolerance is split in two, each resampled before the next interval.
        todo.clear();
        todo.push((w[0], w[1]));
        while let Some((a, b)) = todo.pop() {
            if pieces.take_over((a, b)) {
                continue;
            }
            match interval(knots, bounds, tolerances, q, motion, (a, b), last) {
                Ok(piece) => pieces.push((a, b), &piece),
                Err(Over::Tolerance) if b - a >= 2 => {
                    let mid = a + (b - a) / 2;
                    todo.push((mid, b));
                    todo.push((a, mid));
                }
                Err(Over::Tolerance) => slow.push((covered(motion, a, b, q), 0.9)),
                Err(Over::Limit(factor)) => slow.push((covered(motion, a, b, q), factor)),
            }
        }
    }
    pieces.finish();
    slow
}

/// Each piece's speed at mid-time against the plan's at the same point of the path: the
/// largest relative change where the plan moves at 1 % of its fastest or more. `plan` is
/// storage for the plan's speed at every piece (a piece's own speed is made where it
/// counts, once the fastest is known).
fn speed_change(motion: &Motion<'_>, pieces: &GridPieces, plan: &mut Vec<f64>) -> f64 {
    let mut start = 0.0;
    plan.clear();
    plan.extend(pieces.durations().map(|duration| {
        let mid = start + 0.5 * duration;
        start += duration;
        let (k, u) = motion.locate(mid);
        let velocity = Vector::from_fn(pieces.dim, |a| {
            motion.axis_state(k, a, u).velocity * motion.scale
        });
        crate::vector::norm(&velocity)
    }));
    let fastest = plan.iter().fold(0.0_f64, |m, &s| m.max(s));
    plan.iter()
        .enumerate()
        .filter(|&(_, &before)| before > 0.01 * fastest)
        .map(|(i, &before)| {
            let p = pieces.piece(i);
            let now = Vector::from_fn(p.start.len(), |a| p.cubic(a).at(0.5 * p.duration).velocity);
            (crate::vector::norm(&now) - before).abs() / before
        })
        .fold(0.0, f64::max)
}

/// What the acceleration steps at the grid knots ask.
enum Steps {
    /// Every step within its bound.
    Within,
    /// Grid knots to add: one quantum inside each interval of two quanta or more beside
    /// a knot that steps too far.
    Split(Vec<u64>),
    /// Knots that step too far between intervals of one quantum: slow the plan over
    /// each range of pieces by its factor (steps grow with the square of the speeds).
    Slow(Vec<(std::ops::Range<usize>, f64)>),
}

/// Under a jerk limit, the acceleration step at every grid knot of `pieces` (with their
/// intervals, in quanta) against `bounds.step`, less the room for written positions'
/// rounding beside the knot, and at the contour's ends against rest by half of it (see
/// "Jerk" in [`super`]). A Hermite piece through a motion whose jerk changes inside it
/// misses the motion's acceleration at its ends by up to `4/27·|Δj|·T` (on one quantum:
/// `T = q`), so where a step is over, the intervals beside the knot get a grid knot one
/// quantum from it; where both are one quantum already, the plan is slowed.
fn steps_over(pieces: &GridPieces, bounds: &AxisBounds) -> Steps {
    let n = pieces.len();
    let dim = pieces.dim;
    let mut split = Vec::new();
    let mut slow = Vec::new();
    // The acceleration at the end of the piece before the knot (rest before the first).
    let mut end_before = Vector::zeros(dim);
    for i in 0..=n {
        let accelerations = (i < n).then(|| pieces.piece(i).end_accelerations());
        let after = accelerations.map_or(Vector::zeros(dim), |e| e[0]);
        let end = accelerations.map_or(Vector::zeros(dim), |e| e[1]);
        let before = std::mem::replace(&mut end_before, end);
        let share = if i == 0 || i == n { 0.5 } else { 1.0 };
        let beside = i.saturating_sub(1)..(i + 1).min(n);
        let around = i.saturating_sub(2)..(i + 2).min(n);
        let rounding: f64 = pieces.ends[beside.clone()]
            .iter()
            .map(|p| 6.0 * bounds.resolution / (p.duration * p.duration))
            .sum();
        let mut factor: f64 = 1.0;
        for a in 0..dim {
            let step = (after[a] - before[a]).abs();
            let bound = share * bounds.step[a] - rounding;
            if step > bound.max(0.0) * (1.0 + 1e-9) {
                factor = factor.min(if bound > 0.0 {
                    (bound / step).sqrt()
                } else {
                    0.5
                });
            }
        }
        if factor >= 1.0 {
            continue;
        }
        let mut wide = false;
        let interval = |i: usize| pieces.ends[i].interval;
        if i > 0 && interval(i - 1).1 - interval(i - 1).0 >= 2 {
            split.push(interval(i - 1).1 - 1);
            wide = true;
        }
        if i < n && interval(i).1 - interval(i).0 >= 2 {
            split.push(interval(i).0 + 1);
            wide = true;
        }
        if !wide {
            slow.push((around, factor));
        }
    }
    if !split.is_empty() {
        Steps::Split(split)
    } else if !slow.is_empty() {
        Steps::Slow(slow)
    } else {
        Steps::Within
    }
}

/// The planned knots whose pieces grid interval `[a, b]` covers.
fn covered(motion: &Motion<'_>, a: u64, b: u64, q: f64) -> std::ops::Range<usize> {
    let first = motion.locate(quanta_time(a as f64, q)).0;
    let mut end = motion.locate(quanta_time(b as f64, q)).0;
    if end > first && motion.start(end) >= quanta_time(b as f64, q) {
        end -= 1;
    }
    motion.pieces.knot(first)..motion.pieces.knot(end) + 2
}

/// The resampled piece on grid interval `[a, b]` (quanta), and whether it keeps the
/// tolerance and the limits.
fn interval(
    knots: &Knots,
    bounds: &AxisBounds,
    tolerances: Tolerances,
    q: f64,
    motion: &Motion<'_>,
    (a, b): (u64, u64),
    last: u64,
) -> Result<Piece, Over> {
    let (ta, tb) = (quanta_time(a as f64, q), quanta_time(b as f64, q));
    let (start, start_velocity) = motion.at(ta, false);
    let (end, end_velocity) = motion.at(tb, b == last);
    let duration = quanta_time((b - a) as f64, q);
    let (first, _) = motion.locate(ta);
    let dim = start.len();
    let mut piece = Piece {
        start,
        end,
        start_velocity,
        end_velocity,
        duration,
        error: 0.0,
        knot: motion.pieces.knot(first),
        part: None,
    };
    let factor = piece.limit_factor(bounds);
    if factor < 1.0 {
        return Err(Over::Limit(factor));
    }
    // The deviation from the plan on each sub-interval between planned knots: both are
    // cubics there, so their difference is one (per axis, its largest magnitude);
    // the axes combine by the norm of their maxima, an upper bound.
    let mut h = [HermiteSegment::new(0.0, 0.0, 0.0, 0.0, 1.0); crate::axis::AXIS_COUNT];
    for (ax, hx) in h.iter_mut().enumerate().take(dim) {
        *hx = piece.cubic(ax);
    }
    let h = &h[..dim];
    let mut error: f64 = 0.0;
    // The elements the interval's planned pieces run on (a corner blend: two), each
    // with the first planned knot on it: at most three (see below).
    let mut elements = Elements::default();
    let mut i = first;
    loop {
        let from = ta.max(motion.start(i));
        let to = tb.min(motion.start(i + 1));
        if to > from || i == first {
            let u0 = (from / motion.scale - motion.starts[i]).max(0.0);
            let mut squares = 0.0;
            for (ax, hx) in h.iter().enumerate() {
                let p = motion.axis_state(i, ax, u0);
                let r = hx.at(from - ta);
                let c = [
                    p.position - r.position,
                    p.velocity - r.velocity,
                    0.5 * (p.acceleration - r.acceleration),
                    (p.jerk - r.jerk) / 6.0,
                ];
                let peak = cubic_peak(c, (to - from).max(0.0));
                squares += peak * peak;
            }
            let planned_knot = motion.pieces.knot(i);
            let knot = &knots.knots[planned_knot];
            let mut over = elements.add(knot.after.element, planned_knot);
            if knot.blend.is_some() {
                over |= elements.add(knot.after.element + 1, planned_knot + 1);
            }
            if over {
                return Err(Over::Tolerance);
            }
            let limit = match knot.blend_index() {
                Some(j) if knots.junctions[j].transition.is_none() => tolerances.corner,
                _ => tolerances.path,
            };
            let sum = motion.pieces.error(i) + squares.sqrt();
            if sum > limit {
                return Err(Over::Tolerance);
            }
            error = error.max(sum);
        }
        if i + 1 >= motion.pieces.len() || motion.start(i + 1) >= tb {
            break;
        }
        i += 1;
    }
    // Past the plan's end (an unscaled plan that ends at rest off the grid): the motion
    // holds the end point, at rest.
    let end = motion.start(motion.pieces.len());
    if tb > end && i + 1 == motion.pieces.len() {
        let last = motion.pieces.at(i);
        let from = ta.max(end);
        let mut squares = 0.0;
        for (ax, hx) in h.iter().enumerate() {
            let r = hx.at(from - ta);
            let c = [
                last.end[ax] - r.position,
                last.end_velocity[ax] - r.velocity,
                -0.5 * r.acceleration,
                -r.jerk / 6.0,
            ];
            let peak = cubic_peak(c, tb - from);
            squares += peak * peak;
        }
        if squares.sqrt() > tolerances.path {
            return Err(Over::Tolerance);
        }
        error = error.max(squares.sqrt());
    }
    // A piece names one source line; a check looks for the motion near that line's
    // elements and their neighbours. A piece over more than three elements is split
    // (or its plan slowed) as one over the tolerance (found as they are added, above);
    // otherwise it names the middle one.
    if let Some(knot) = elements.middle_knot() {
        piece.knot = knot;
    }
    piece.error = error;
    Ok(piece)
}

/// The distinct elements a resampled piece's planned pieces run on, each with the first
/// planned knot on it, in the order met, while they span at most three elements.
#[derive(Default)]
struct Elements {
    seen: [(usize, usize); 3],
    count: usize,
    lo: usize,
    hi: usize,
}

impl Elements {
    /// Adds `element` with planned knot `knot` (kept only where the element is new).
    /// True when the elements met span more than three: the piece is over the
    /// tolerance, whatever else it runs on.
    fn add(&mut self, element: usize, knot: usize) -> bool {
        if self.seen[..self.count].iter().any(|e| e.0 == element) {
            return false;
        }
        if self.count == 0 {
            (self.lo, self.hi) = (element, element);
        }
        (self.lo, self.hi) = (self.lo.min(element), self.hi.max(element));
        if self.hi > self.lo + 2 {
            return true;
        }
        // Within three elements: at most three distinct ones.
        self.seen[self.count] = (element, knot);
        self.count += 1;
        false
    }

    /// The first planned knot on the middle element of those met.
    fn middle_knot(&self) -> Option<usize> {
        let middle = self.lo + (self.hi - self.lo) / 2;
        self.seen[..self.count]
            .iter()
            .find(|e| e.0 == middle)
            .map(|e| e.1)
    }
}

#[cfg(test)]
mod tests {
    use super::cubic_peak;

    /// The peak of a cubic's magnitude against dense sampling.
    #[test]
    fn cubic_peak_is_the_largest_magnitude() {
        let cases = [
            [0.1, -2.0, 0.5, 3.0],
            [0.0, 1.0, -3.0, 1.5],
            [-1.0, 0.0, 0.0, 0.0],
            [0.2, 1.0, -1.0, 0.0],
        ];
        for c in cases {
            let h = 2.0;
            let f = |u: f64| c[0] + c[1] * u + c[2] * u * u + c[3] * u * u * u;
            let sampled = (0..=100_000)
                .map(|k| f(h * k as f64 / 100_000.0).abs())
                .fold(0.0, f64::max);
            let peak = cubic_peak(c, h);
            assert!(peak >= sampled * (1.0 - 1e-12), "{c:?}: {peak} < {sampled}");
            assert!(peak <= sampled * (1.0 + 1e-6), "{c:?}: {peak} > {sampled}");
        }
    }
}
