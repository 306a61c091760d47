//! Settle rounds that make again only what the last round changed, where every knot's
//! speed is local.
//!
//! Owns [`Knots::settle_locally`]. Where no piece's way bounds a change of speed
//! ([`PieceWay::is_free`]: no finite acceleration, path jerk or ratio, as without
//! limits), the passes of [`Knots::plan_speeds`] set each knot's speed from its own cap
//! and its two pieces' caps alone: `limit(speed, v)` is `speed` whatever `v` (∞ for a
//! NaN). A round that splits piece `k` or caps a corner blend's knots then changes the
//! ways of the two pieces beside each new knot, the speeds of the new knots, of the
//! knots beside them and of the capped knots, and the error bounds of the pieces beside
//! those knots; nothing else. A local round makes those again and moves every other
//! way, time and bound up in place with the knots, and checks for a split only the
//! pieces whose bound it made: a piece it did not make was checked last round with the
//! same bound and speeds, so it is within the tolerance, or a blend whose caps are
//! already at its slower end speed.
//!
//! It must not decide anything the whole rounds (`settle_by_errors` in [`super::super`])
//! would decide otherwise: its knots, caps, speeds, times and error bounds are theirs,
//! bit for bit, round by round (tested), and where a way that is not free appears it
//! stops and leaves the rest of the rounds to them.

use super::{insert_after, Knots, PieceWay};
use crate::plan::path::curve::Curve;
use crate::plan::path::AxisBounds;

impl Knots {
    /// True when every piece's way ([`Knots::plan_speeds`] made them last) is free
    /// ([`PieceWay::is_free`]): each knot's speed is then local.
    pub fn speeds_are_local(&self) -> bool {
        self.scratch.ways.iter().all(PieceWay::is_free)
    }

    /// The rounds of `settle_by_errors`, at most `rounds` of them, each making again
    /// only what the last changed (see the module documentation), on knots whose
    /// speeds [`Knots::plan_speeds`] has just planned and are local
    /// ([`Knots::speeds_are_local`]). `None` when a round splits and caps nothing: the
    /// knots are settled, and every piece's time and error bound is in the scratch,
    /// where [`Knots::pieces_from_bounds`] takes them. Otherwise `Some(round)`, the first
    /// round not made (a new piece's way is not free, or `rounds` were made): the whole
    /// rounds go on from there, the knots split and capped as that round finds them.
    pub fn settle_locally(
        &mut self,
        curves: &[Curve],
        bounds: &AxisBounds,
        tolerance: f64,
        rounds: usize,
    ) -> Option<usize> {
        debug_assert!(!self.jerk_mode && self.speeds_are_local());
        let n = self.knots.len();
        self.scratch.errors.resize(n - 1, 0.0);
        self.scratch.durations.resize(n - 1, 0.0);
        self.bounds_of(curves, bounds, 0..n - 1);
        let mut changed = std::mem::take(&mut self.scratch.changed);
        changed.clear();
        changed.extend(0..n - 1);
        for round in 0..rounds {
            if round > 0 {
                if !self.ways_beside_inserted(curves, bounds) {
                    self.scratch.changed = changed;
                    return Some(round);
                }
                self.touched_speeds();
                self.pieces_beside_touched(&mut changed);
                self.bounds_of(curves, bounds, changed.iter().copied());
            }
            if !self.split_changed(&changed, tolerance) {
                self.scratch.changed = changed;
                return None;
            }
        }
        self.scratch.changed = changed;
        Some(rounds)
    }

    /// The time and error bound of each piece of `pieces`, into the scratch.
    fn bounds_of(
        &mut self,
        curves: &[Curve],
        bounds: &AxisBounds,
        pieces: impl Iterator<Item = usize>,
    ) {
        for k in pieces {
            let (duration, error) = self.piece_time_and_error(curves, bounds, k);
            self.scratch.durations[k] = duration;
            self.scratch.errors[k] = error;
        }
    }

    /// The ways of the two pieces beside each knot the last round inserted; false,
    /// with the ways made so far, where one is not free.
    fn ways_beside_inserted(&mut self, curves: &[Curve], bounds: &AxisBounds) -> bool {
        for i in 0..self.scratch.inserted.len() {
            let m = self.scratch.inserted[i];
            for k in [m - 1, m] {
                let way = self.piece_way(curves, bounds, k);
                if !way.is_free() {
                    return false;
                }
                self.scratch.ways[k] = way;
            }
        }
        true
    }

    /// The speed of every knot the last round touched, as [`Knots::plan_speeds`] sets
    /// it: the backward pass's, then the forward pass's limit from the knot before,
    /// each of which, on free ways, reads no other knot's speed. Keeps, of the touched
    /// knots, those the last round inserted and those whose speed changed (bit for
    /// bit): the pieces beside the others are as they were.
    fn touched_speeds(&mut self) {
        let mut touched = std::mem::take(&mut self.scratch.touched);
        let mut next = 0;
        touched.retain(|&j| {
            let ways = &self.scratch.ways;
            let mut speed = self.backward_speed(j, ways);
            if j > 0 {
                speed = ways[j - 1].limit(speed, self.knots[j - 1].speed);
            }
            let was = std::mem::replace(&mut self.knots[j].speed, speed);
            let inserted = &self.scratch.inserted;
            while inserted.get(next).is_some_and(|&m| m < j) {
                next += 1;
            }
            inserted.get(next) == Some(&j) || was.to_bits() != speed.to_bits()
        });
        self.scratch.touched = touched;
    }

    /// The pieces beside the knots [`Knots::touched_speeds`] kept, in order, into
    /// `pieces`.
    fn pieces_beside_touched(&self, pieces: &mut Vec<usize>) {
        let last = self.knots.len() - 1;
        pieces.clear();
        for &j in &self.scratch.touched {
            for k in [j.wrapping_sub(1), j] {
                if k < last && pieces.last().is_none_or(|&p| p < k) {
                    pieces.push(k);
                }
            }
        }
    }

    /// `split_errors` on the pieces `pieces` (in order) alone: caps a corner blend
    /// over its tolerance and splits a piece over the tolerance, as the whole round
    /// does; the ways, times and error bounds move up with the knots (a split piece's
    /// two halves hold its old ones until the next round makes theirs). Notes the
    /// knots inserted and the knots whose speed may change next. Returns whether any
    /// knot was inserted or capped.
    fn split_changed(&mut self, pieces: &[usize], tolerance: f64) -> bool {
        let mut touched = std::mem::take(&mut self.scratch.touched);
        let mut splits = std::mem::take(&mut self.scratch.inserted);
        touched.clear();
        splits.clear();
        for &k in pieces {
            let error = self.scratch.errors[k];
            let lowered = self.cap_blend_over(k, error);
            touched.extend((0..2).filter(|&i| lowered[i]).map(|i| k + i));
            if self.splits_at(k, error, tolerance) {
                splits.push(k);
            }
        }
        // The capped knots move up by the splits before them.
        for j in &mut touched {
            *j += splits.partition_point(|&k| k < *j);
        }
        let count = splits.len();
        let down = || splits.iter().rev().copied();
        self.insert_splits(&splits);
        let scratch = &mut *self.scratch;
        insert_after(&mut scratch.ways, count, down(), |ways, k| (k, ways[k]));
        insert_after(&mut scratch.errors, count, down(), |errors, k| {
            (k, errors[k])
        });
        insert_after(&mut scratch.durations, count, down(), |d, k| (k, d[k]));
        // The split of piece `k`, the `i`-th, is knot `k + i + 1` now.
        for (i, k) in splits.iter_mut().enumerate() {
            *k += i + 1;
            touched.extend([*k - 1, *k, *k + 1]);
        }
        touched.sort_unstable();
        touched.dedup();
        let any = !touched.is_empty();
        self.scratch.touched = touched;
        self.scratch.inserted = splits;
        any
    }
}

#[cfg(test)]
mod tests {
    use super::super::shortcut_tests::{program, xyz_without_limits};
    use super::super::{KnotStorage, Knots, Start};
    use crate::plan::path::{curve::Curve, piece::Pieces, AxisBounds, MAX_ROUNDS};

    /// The knots, caps, speeds, times and error bounds, bit for bit.
    fn state(knots: &Knots) -> String {
        let (d, e) = (&knots.scratch.durations, &knots.scratch.errors);
        format!("{} {d:?} {e:?}", knots.settled_state())
    }

    /// What the settled `knots` emit: from `pieces` ([`Knots::emit`]), or from the knots
    /// and their bounds alone ([`Knots::emit_ends`]), every piece.
    fn written(knots: &Knots, curves: &[Curve], pieces: Option<&Pieces>) -> String {
        let mut text = String::new();
        let mut emit = |s: &crate::program::SegmentRef<'_>| {
            text += &format!("{:?} {:?} {:?} {}\n", s.end, s.velocity, s.duration, s.line);
        };
        let count = knots.knots.len() - 1;
        match pieces {
            Some(pieces) => knots.emit(curves, pieces, count, &mut emit),
            None => knots.emit_ends(curves, count, &mut emit),
        }
        text
    }

    /// Local rounds, all of them or the first `local` and the whole rounds after, settle
    /// to the whole rounds' knots and pieces bit for bit, and the pieces written from
    /// the knots and bounds alone are those made, on random programs of lines
    /// and arcs with sharp corners (stops, whose slowing pieces split round after
    /// round), with and without corner blends.
    #[test]
    fn local_rounds_are_the_whole_rounds() {
        let (axes, options) = xyz_without_limits();
        let bounds = AxisBounds::new(&axes, &options);
        let (mut rounds_seen, mut inserted, mut capped) = (0, 0, 0);
        for seed in 1..30 {
            let mut curves = Vec::new();
            for e in &program(seed, 80) {
                Curve::push_new(e, &axes, &mut curves);
            }
            let slowed_blends = [(None, false), (Some(0.01), false), (Some(1e-4), true)];
            for (corner, slowed) in slowed_blends {
                let start = Start {
                    param: 0.0,
                    speed: 0.0,
                    junction: None,
                };
                let storage = KnotStorage::default();
                let tolerance = 1e-4;
                let mut fresh =
                    Knots::new(&curves, &bounds, tolerance, corner, &start, false, storage);
                if slowed {
                    // A corner blend ending at a tenth of its speed is over its
                    // tolerance: the rounds cap its knots.
                    for k in 1..fresh.knots.len() {
                        if fresh.knots[k - 1].blend.is_some() {
                            fresh.knots[k].cap = fresh.knots[k - 1].cap / 10.0;
                        }
                    }
                }
                let mut whole = fresh.clone();
                let mut whole_pieces = Pieces::default();
                whole.plan_speeds(&curves, &bounds);
                let settled = crate::plan::path::settle_from_round(
                    &mut whole, &curves, &bounds, tolerance, 0,
                );
                assert!(settled);
                whole.pieces_from_bounds(&curves, &bounds, &mut whole_pieces);
                for local in [1, 2, 3, MAX_ROUNDS] {
                    let mut knots = fresh.clone();
                    knots.plan_speeds(&curves, &bounds);
                    assert!(knots.speeds_are_local());
                    let mut pieces = Pieces::default();
                    let left = knots.settle_locally(&curves, &bounds, tolerance, local);
                    if let Some(round) = left {
                        assert_eq!(round, local, "every way is free without limits");
                        knots.forget_pieces();
                        knots.plan_speeds(&curves, &bounds);
                        assert!(crate::plan::path::settle_from_round(
                            &mut knots, &curves, &bounds, tolerance, round,
                        ));
                        rounds_seen += 1;
                    }
                    knots.pieces_from_bounds(&curves, &bounds, &mut pieces);
                    assert_eq!(
                        state(&knots),
                        state(&whole),
                        "seed {seed} {corner:?} {local}"
                    );
                    assert_eq!(format!("{pieces:?}"), format!("{whole_pieces:?}"));
                    assert_eq!(
                        written(&knots, &curves, None),
                        written(&knots, &curves, Some(&pieces))
                    );
                }
                inserted += whole.knots.len() - fresh.knots.len();
                let junctions = &whole.junctions;
                capped += (whole.knots.iter())
                    .filter(|k| k.blend_index().is_some_and(|j| k.cap < junctions[j].cap))
                    .count();
            }
        }
        assert!(
            rounds_seen > 50,
            "{rounds_seen} settlings left to whole rounds"
        );
        assert!(inserted > 1000, "{inserted} knots inserted");
        assert!(capped > 100, "{capped} corner blends capped");
    }
}
