//! The LSPB planner of seed 004: linear segments with parabolic blends.
//!
//! Owns the trapezoidal-velocity plan through timed waypoints under an acceleration limit
//! `a` (units/s², per axis), emitted exactly as PVT pieces: a blend is a constant
//! acceleration piece (a cubic with zero jerk), a cruise a constant velocity piece.
//!
//! - Segment `i` from `X(i)` to `X(i+1)` takes its given time `T(i)`; its line velocity is
//!   `d(i)/T(i)`, so the line passes through both waypoints at their times.
//! - Coordination: seed 004 works per axis; pvtc gives every axis the same blend interval,
//!   `t_b = max over axes |ΔV| / a`, so all axes accelerate together, the axis with the
//!   largest velocity change at exactly `a`, the others less. The path stays coordinated:
//!   straight on the cruises and a parabola in space across each blend.
//! - Rest at both ends (seed 004's "calculated slightly differently"): the first blend
//!   starts at `X(0)` at rest and lies wholly inside the first segment, whose line is made
//!   steeper to still pass through `X(1)` at `T(0)`: `t_b = T − √(T² − 2D/a)`, `V = d/(T − t_b/2)`
//!   with `D` the largest axis distance; the last segment mirrors it. A single segment is a
//!   trapezoid: `t_b = (T − √(T² − 4D/a))/2`, `V = d/(T − t_b)`.
//! - Interior blends are centred on the waypoint times and do not pass through the
//!   waypoints: they cut the corner. The blend's midpoint lies `|ΔV|·t_b/8` from the
//!   waypoint (see [`blend_corner_deviation`]); that is the closest approach when the
//!   speeds on both sides are equal.
//! - Too short segments (blends that would overlap, or an end segment too short to reach
//!   its line): the segment's time is raised to the smallest value at which its cruise
//!   stays non-negative whatever its neighbours do later (each blend bounded by the sum of
//!   the two line speeds over `a`). Raising a time only lowers speeds, so a raised segment
//!   never needs raising again and the repair ends after at most one raise per segment.
//!   The raised count is reported; total time grows by the added time.
//!
//! - Piece times (the finishing step): the plan is a sequence of blends and cruises, and
//!   given their times the line velocities follow (`V = d/L`, `L` the segment's cruise plus
//!   half of each blend at its ends; for an end segment half of the end blend too, as
//!   above). No piece is shorter than [`MIN_PIECE_SECONDS`]: a cruise shorter than that is
//!   left out (the blends touch) or, between two empty blends, made that long; a blend is
//!   at least that long (a velocity change of 0 needs no blend). With `--quantize q` every
//!   piece time is a whole multiple of `q` instead: blends and cruises go onto the grid as
//!   the quantum rounds (up, or to the nearest; a blend at least one quantum, a cruise that
//!   rounds to none left out when blends border it). The velocities of the segments whose pieces
//!   changed are then taken again, and every blend that no longer covers its velocity
//!   change at `a` is lengthened (to the grid) until all do; should that not settle, all
//!   piece times are scaled by one factor (a whole number on a grid), which divides every
//!   acceleration by its square. Speeds only go down; positions stay exact; a blend is
//!   always a constant-acceleration piece at or below `a` (measured from the written
//!   numbers, within what the f64 rounding of its end positions adds: for a piece of
//!   0.1 µs 1000 units from the origin, about 140 units/s²). The quantum's largest change
//!   of a segment's line speed is reported.
//!
//! Given velocities are not used. It must not move the end points or exceed `a` on any axis.

use super::quantize::{quanta_time, Quantum};
use super::timed::TimedPoints;
use super::MIN_PIECE_SECONDS;
use crate::program::PvtContour;
use crate::toolpath::Motion;
use crate::vector::{max_abs, norm};

/// Sweeps of blend lengthening before the piece times are scaled as a whole.
const MAX_SWEEPS: usize = 64;

/// Distance from a waypoint to the midpoint of its blend, for line velocities `v_in` and
/// `v_out` and acceleration limit `accel`: `|ΔV|·t_b/8` with `t_b = max|ΔV_axis|/accel`.
pub fn blend_corner_deviation(v_in: &[f64], v_out: &[f64], accel: f64) -> f64 {
    let dv: Vec<f64> = v_out.iter().zip(v_in).map(|(o, i)| o - i).collect();
    norm(&dv) * (max_abs(&dv) / accel) / 8.0
}

/// Blend and cruise times and line velocities of one run for given segment times.
struct Layout {
    /// Line velocity of each segment, flat.
    velocity: Vec<f64>,
    /// Blend time at each waypoint (the first and last wholly inside their segment).
    blend: Vec<f64>,
    /// Cruise time of each segment (negative when blends overlap).
    cruise: Vec<f64>,
    /// False where an end segment is too short to reach its line at all.
    reachable: Vec<bool>,
}

/// The end blend `T − √(T² − k·D/a)` in cancellation-free form, `None` when unreachable
/// (a discriminant below 0 by more than its rounding).
fn end_blend(t: f64, big: f64, accel: f64, k: f64) -> Option<f64> {
    let disc = t * t - k * big / accel;
    (disc >= -1e-12 * t * t).then(|| (2.0 * big / accel) / (t + disc.max(0.0).sqrt()))
}

fn layout(run: &TimedPoints, times: &[f64], accel: f64) -> Layout {
    let (dim, segs) = (run.dim, times.len());
    let mut l = Layout {
        velocity: vec![0.0; segs * dim],
        blend: vec![0.0; segs + 1],
        cruise: vec![0.0; segs],
        reachable: vec![true; segs],
    };
    for (i, &t) in times.iter().enumerate() {
        let d: Vec<f64> = run
            .point(i + 1)
            .iter()
            .zip(run.point(i))
            .map(|(b, a)| b - a)
            .collect();
        let span = line_span(&mut l, i, t, max_abs(&d), accel);
        for (v, x) in l.velocity[i * dim..(i + 1) * dim].iter_mut().zip(&d) {
            *v = x / span;
        }
    }
    for w in 1..segs {
        let (a, b) = (
            &l.velocity[(w - 1) * dim..w * dim],
            &l.velocity[w * dim..(w + 1) * dim],
        );
        l.blend[w] = a
            .iter()
            .zip(b)
            .fold(0.0_f64, |m, (x, y)| m.max((y - x).abs()))
            / accel;
    }
    for (i, &t) in times.iter().enumerate() {
        let left = if i == 0 { l.blend[0] } else { l.blend[i] / 2.0 };
        let right = if i + 1 == segs {
            l.blend[segs]
        } else {
            l.blend[i + 1] / 2.0
        };
        l.cruise[i] = t - left - right;
    }
    l
}

/// Sets the end blends of segment `i` (if it is an end) and returns the time its line
/// needs to cover its chord `d`: `T` inside, `T − t_b/2` at an end, `T − t_b` alone.
fn line_span(l: &mut Layout, i: usize, t: f64, big: f64, accel: f64) -> f64 {
    let segs = l.cruise.len();
    if segs == 1 {
        let tb = end_blend(t, big, accel, 4.0);
        l.reachable[i] = tb.is_some();
        let tb = tb.unwrap_or(t / 2.0);
        l.blend[0] = tb;
        l.blend[1] = tb;
        t - tb
    } else if i == 0 || i + 1 == segs {
        let tb = end_blend(t, big, accel, 2.0);
        l.reachable[i] = tb.is_some();
        let tb = tb.unwrap_or(t);
        l.blend[if i == 0 { 0 } else { segs }] = tb;
        t - tb / 2.0
    } else {
        t
    }
}

/// Largest axis line speed of segment `i` in a layout.
fn line_speed(l: &Layout, dim: usize, i: usize) -> f64 {
    max_abs(&l.velocity[i * dim..(i + 1) * dim])
}

/// Smallest time for segment `i` that leaves room for its blends whatever its neighbours do.
fn safe_time(run: &TimedPoints, l: &Layout, times: &[f64], i: usize, accel: f64) -> f64 {
    let (dim, segs) = (run.dim, times.len());
    let d: Vec<f64> = run
        .point(i + 1)
        .iter()
        .zip(run.point(i))
        .map(|(b, a)| b - a)
        .collect();
    let big = max_abs(&d);
    if segs == 1 {
        // The triangle: blends that touch, no cruise.
        return 2.0 * (big / accel).sqrt();
    }
    let neighbour = |j: usize| line_speed(l, dim, j) / (2.0 * accel);
    let room = |t: f64| -> f64 {
        if i == 0 || i + 1 == segs {
            let other = if i == 0 {
                neighbour(1)
            } else {
                neighbour(segs - 2)
            };
            end_blend(t, big, accel, 2.0).map_or(f64::NEG_INFINITY, |tb| t - 1.5 * tb - other)
        } else {
            t - big / (accel * t) - neighbour(i - 1) - neighbour(i + 1)
        }
    };
    let mut hi = times[i];
    let mut lo = times[i];
    for _ in 0..2000 {
        if room(hi) >= 0.0 {
            break;
        }
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if room(mid) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// A planned run: its pieces, how many segments were lengthened to fit their blends, and
/// the largest relative change of a segment's line speed that the quantum caused.
#[derive(Debug, Clone, PartialEq)]
pub struct LspbPlan {
    /// The blend and cruise pieces.
    pub contour: PvtContour,
    /// Segments whose given time was raised so that their blends fit.
    pub raised: usize,
    /// Largest relative change of a segment's line speed from quantization (0 without).
    pub speed_change: f64,
}

/// Plans one run with parabolic blends (every piece time a whole multiple of `quantum` if
/// given). `accel` must be finite and positive, `quantum` positive.
pub fn plan_lspb(
    run: &TimedPoints,
    accel: f64,
    quantum: Option<Quantum>,
    motion: Motion,
) -> LspbPlan {
    let segs = run.durations.len();
    let mut times = run.durations.clone();
    let mut raised = vec![false; segs];
    let mut l = layout(run, &times, accel);
    for _ in 0..=segs {
        let short: Vec<usize> = (0..segs)
            .filter(|&i| !l.reachable[i] || l.cruise[i] < -1e-9 * times[i])
            .collect();
        if short.is_empty() {
            break;
        }
        for i in short {
            times[i] = times[i].max(safe_time(run, &l, &times, i, accel));
            raised[i] = true;
        }
        l = layout(run, &times, accel);
    }
    let exact = Pieces {
        blend: l.blend,
        cruise: l.cruise,
        velocity: l.velocity,
    };
    let pieces = finish(run, &exact, accel, quantum);
    let speed_change = if quantum.is_some() {
        speed_change(run.dim, &exact.velocity, &pieces.velocity)
    } else {
        0.0
    };
    LspbPlan {
        contour: emit(run, &pieces, motion),
        raised: raised.iter().filter(|&&r| r).count(),
        speed_change,
    }
}

/// Blend times (one per waypoint, the first and last from and to rest), cruise times (one
/// per segment) and the line velocity of each segment (flat).
#[derive(Debug, Clone)]
struct Pieces {
    blend: Vec<f64>,
    cruise: Vec<f64>,
    velocity: Vec<f64>,
}

/// The time grid of the piece times: the quantum, or none above [`MIN_PIECE_SECONDS`].
#[derive(Debug, Clone, Copy)]
struct Grid(Option<Quantum>);

impl Grid {
    /// The shortest piece.
    fn least(self) -> f64 {
        self.0.map_or(MIN_PIECE_SECONDS, |q| q.seconds)
    }

    /// A planned piece time `t > 0` on the grid as the quantum rounds (at least the
    /// shortest piece); `None` when it rounds to no time at all (only a cruise may).
    fn snap(self, t: f64) -> Option<f64> {
        match self.0 {
            Some(q) => {
                let k = q.count(t);
                (k >= 1.0).then(|| quanta_time(k, q.seconds))
            }
            None => (t >= MIN_PIECE_SECONDS).then_some(t),
        }
    }

    /// `t > 0` as a piece time: at least the shortest, up to the grid, never below `t` by
    /// more than a relative 1e-12 (the tolerance of the blend check).
    fn up(self, t: f64) -> f64 {
        match self.0 {
            Some(q) => {
                let mut k = (t / q.seconds - 1e-9).ceil().max(1.0);
                while quanta_time(k, q.seconds) * (1.0 + 1e-12) < t {
                    k += 1.0;
                }
                quanta_time(k, q.seconds)
            }
            None => t.max(MIN_PIECE_SECONDS),
        }
    }
}

/// The piece times of `exact` made valid (see the module documentation), with the line
/// velocities that go with them.
fn finish(run: &TimedPoints, exact: &Pieces, accel: f64, quantum: Option<Quantum>) -> Pieces {
    let (dim, segs) = (run.dim, exact.cruise.len());
    let grid = Grid(quantum);
    let mut p = exact.clone();
    let mut stale = vec![false; segs];
    for (w, tb) in p.blend.iter_mut().enumerate() {
        // A blend rounded below its velocity change is lengthened again below.
        let snapped = if *tb > 0.0 {
            grid.snap(*tb).unwrap_or(grid.least())
        } else {
            0.0
        };
        if snapped != *tb {
            *tb = snapped;
            stale[w.saturating_sub(1)] = true;
            if w < segs {
                stale[w] = true;
            }
        }
    }
    for (i, changed) in stale.iter_mut().enumerate() {
        let c = p.cruise[i];
        let snapped = if let Some(c) = grid.snap(c) {
            c
        } else if p.blend[i] + p.blend[i + 1] > 0.0 {
            0.0 // the blends touch
        } else {
            grid.least()
        };
        if snapped != c {
            p.cruise[i] = snapped;
            *changed = true;
        }
    }
    let chord = |i: usize| -> Vec<f64> {
        run.point(i + 1)
            .iter()
            .zip(run.point(i))
            .map(|(b, a)| b - a)
            .collect()
    };
    let retake = |p: &mut Pieces, i: usize| {
        let span = p.blend[i] / 2.0 + p.cruise[i] + p.blend[i + 1] / 2.0;
        for (v, d) in p.velocity[i * dim..(i + 1) * dim].iter_mut().zip(chord(i)) {
            *v = d / span;
        }
    };
    for i in (0..segs).filter(|&i| stale[i]) {
        retake(&mut p, i);
    }
    // Velocity change at waypoint `w` (from rest at the first, to rest at the last).
    let change = |p: &Pieces, w: usize| -> f64 {
        let before = |k: usize| {
            if w == 0 {
                0.0
            } else {
                p.velocity[(w - 1) * dim + k]
            }
        };
        let after = |k: usize| {
            if w == segs {
                0.0
            } else {
                p.velocity[w * dim + k]
            }
        };
        (0..dim).fold(0.0_f64, |m, k| m.max((after(k) - before(k)).abs()))
    };
    for _ in 0..MAX_SWEEPS {
        let mut lengthened = false;
        for w in 0..=segs {
            let need = change(&p, w) / accel;
            if need > p.blend[w] * (1.0 + 1e-12) {
                p.blend[w] = grid.up(need);
                for i in [w.wrapping_sub(1), w] {
                    if i < segs {
                        retake(&mut p, i);
                    }
                }
                lengthened = true;
            }
        }
        if !lengthened {
            return p;
        }
    }
    // Still short somewhere: scale every piece time by one factor s (whole on a grid);
    // accelerations fall by s².
    let worst = (0..=segs).fold(1.0_f64, |m, w| {
        m.max(change(&p, w) / accel / p.blend[w].max(f64::MIN_POSITIVE))
    });
    let s = match quantum {
        Some(_) => worst.sqrt().ceil(),
        None => worst.sqrt() * (1.0 + 1e-12),
    };
    p.blend.iter_mut().chain(p.cruise.iter_mut()).for_each(|t| {
        *t = match quantum {
            Some(q) => quanta_time((*t / q.seconds).round() * s, q.seconds),
            None => *t * s,
        }
    });
    p.velocity.iter_mut().for_each(|v| *v /= s);
    p
}

/// Largest relative change of a segment's line speed from `before` to `after`.
fn speed_change(dim: usize, before: &[f64], after: &[f64]) -> f64 {
    before
        .chunks(dim)
        .zip(after.chunks(dim))
        .filter(|(b, _)| norm(b) > 0.0)
        .map(|(b, a)| (norm(a) - norm(b)).abs() / norm(b))
        .fold(0.0, f64::max)
}

/// Writes the blend and cruise pieces; pieces of time 0 are left out.
fn emit(run: &TimedPoints, p: &Pieces, motion: Motion) -> PvtContour {
    let (dim, segs) = (run.dim, p.cruise.len());
    let mut out = PvtContour::new(motion, run.point(0).to_vec());
    if segs == 0 {
        return out;
    }
    let v = |i: usize| &p.velocity[i * dim..(i + 1) * dim];
    let along = |x: &[f64], vel: &[f64], t: f64| -> Vec<f64> {
        x.iter().zip(vel).map(|(x, w)| x + w * t).collect()
    };
    let mut push = |end: &[f64], vel: &[f64], t: f64, i: usize| {
        if t > 0.0 {
            out.push(end, vel, t, run.lines[i]);
        }
    };
    push(
        &along(run.point(0), v(0), p.blend[0] / 2.0),
        v(0),
        p.blend[0],
        0,
    );
    for i in 0..segs {
        let to = run.point(i + 1);
        push(
            &along(to, v(i), -p.blend[i + 1] / 2.0),
            v(i),
            p.cruise[i],
            i,
        );
        if i + 1 < segs {
            push(
                &along(to, v(i + 1), p.blend[i + 1] / 2.0),
                v(i + 1),
                p.blend[i + 1],
                i,
            );
        } else {
            push(to, &vec![0.0; dim], p.blend[segs], i);
        }
    }
    out
}

#[cfg(test)]
#[path = "lspb_tests.rs"]
mod tests;
