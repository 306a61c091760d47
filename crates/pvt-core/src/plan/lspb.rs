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
//! Given velocities are not used. It must not move the end points or exceed `a` on any axis.

use super::timed::TimedPoints;
use crate::program::PvtContour;
use crate::toolpath::Motion;
use crate::vector::{max_abs, norm};

/// Piece times at most this fraction of the segment time are dropped as empty.
const EMPTY_PIECE: f64 = 1e-12;

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

/// The end blend `T − √(T² − k·D/a)` in cancellation-free form, `None` when unreachable.
fn end_blend(t: f64, big: f64, accel: f64, k: f64) -> Option<f64> {
    let disc = t * t - k * big / accel;
    (disc >= 0.0).then(|| (2.0 * big / accel) / (t + disc.sqrt()))
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
        return 2.0 * (big / accel).sqrt() * (1.0 + 1e-12);
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

/// Plans one run with parabolic blends; returns the contour and how many segments were
/// lengthened to fit their blends. `accel` must be finite and positive.
pub fn plan_lspb(run: &TimedPoints, accel: f64, motion: Motion) -> (PvtContour, usize) {
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
    (
        emit(run, &l, &times, motion),
        raised.iter().filter(|&&r| r).count(),
    )
}

/// Writes the blend and cruise pieces of a layout.
fn emit(run: &TimedPoints, l: &Layout, times: &[f64], motion: Motion) -> PvtContour {
    let (dim, segs) = (run.dim, times.len());
    let mut out = PvtContour::new(motion, run.point(0).to_vec());
    if segs == 0 {
        return out;
    }
    let v = |i: usize| &l.velocity[i * dim..(i + 1) * dim];
    let along = |p: &[f64], vel: &[f64], t: f64| -> Vec<f64> {
        p.iter().zip(vel).map(|(x, w)| x + w * t).collect()
    };
    let mut push = |end: &[f64], vel: &[f64], t: f64, i: usize| {
        if t > EMPTY_PIECE * times[i] {
            out.push(end, vel, t, run.lines[i]);
        }
    };
    push(
        &along(run.point(0), v(0), l.blend[0] / 2.0),
        v(0),
        l.blend[0],
        0,
    );
    for i in 0..segs {
        let to = run.point(i + 1);
        push(
            &along(to, v(i), -l.blend[i + 1] / 2.0),
            v(i),
            l.cruise[i],
            i,
        );
        if i + 1 < segs {
            push(
                &along(to, v(i + 1), l.blend[i + 1] / 2.0),
                v(i + 1),
                l.blend[i + 1],
                i,
            );
        } else {
            push(to, &vec![0.0; dim], l.blend[segs], i);
        }
    }
    out
}

#[cfg(test)]
#[path = "lspb_tests.rs"]
mod tests;
