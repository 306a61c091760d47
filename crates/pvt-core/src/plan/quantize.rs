//! Time quantization for controllers that take whole multiples of a time unit.
//!
//! Seed 003: PMAC takes PVT piece times in whole milliseconds and silently rounds any other
//! value (to the nearest). Owns the rounding of piece times to a multiple of a quantum `q`
//! and the velocities that go with the new times, and measures what that did to the
//! speed. It must not move a point: positions stay exact.
//!
//! Method:
//! - every piece time `T` becomes `k` quanta, `k = ⌈T/q⌉` ([`Rounding::Up`], the default:
//!   speeds stay at or below plan; a time on the grid within 1e-9 of a quantum stays) or
//!   `k` the nearest whole number ([`Rounding::Nearest`], as PMAC rounds: speeds may rise
//!   by up to `q/2` over the piece time); never less than one quantum. The time is stored
//!   as the f64 nearest to `k/n` when `q = 1/n` s for a whole `n` (1 ms: `k/1000`, so
//!   820 quanta are 0.82, not 0.8200000000000001), else as `k·q`;
//! - PT and the velocity methods (chord, const-accel, spline) are planned again from the
//!   new times with the same method, so the result is what that method gives for them;
//! - LSPB quantizes its own blend and cruise times (see its module): stretching its
//!   constant-acceleration pieces one by one would take them above the limit;
//! - contour, path and given velocities are re-timed with [`retime`]: each piece is
//!   stretched by `k = T'/T ≥ 1` and the velocity at each point is divided by the larger
//!   stretch of the two pieces meeting there. A run of equal stretches is an exact time
//!   scaling (the same path, speed divided by `k`); velocities stay continuous because each
//!   point keeps one velocity, and lowering end velocities never makes a piece back up.
//!
//! The report is the largest relative change of the vector speed at any piece's mid-time.

use std::fmt;
use std::str::FromStr;

use crate::program::{Interpolation, PvtContour};
use crate::vector::norm;

/// Which way a piece time goes onto the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Rounding {
    /// Up to the next whole quantum: never faster than planned.
    #[default]
    Up,
    /// To the nearest whole quantum (at least one), as PMAC rounds a `TA` time.
    Nearest,
}

impl Rounding {
    /// The name on the command line: `up` or `nearest`.
    pub fn name(self) -> &'static str {
        match self {
            Rounding::Up => "up",
            Rounding::Nearest => "nearest",
        }
    }
}

impl fmt::Display for Rounding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Rounding {
    type Err = String;

    fn from_str(s: &str) -> Result<Rounding, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "up" => Ok(Rounding::Up),
            "nearest" => Ok(Rounding::Nearest),
            _ => Err(format!("unknown rounding `{s}`; expected up or nearest")),
        }
    }
}

/// `k` whole quanta of `quantum` seconds: the f64 nearest to `k/n` when `quantum` is `1/n`
/// for a whole `n` (so 820 ms is 0.82 exactly as parsed), else `k·quantum`.
pub fn quanta_time(k: f64, quantum: f64) -> f64 {
    let per_second = 1.0 / quantum;
    let whole = per_second.round();
    if whole >= 1.0 && (per_second - whole).abs() <= 1e-9 * whole {
        k / whole
    } else {
        k * quantum
    }
}

/// A time grid: the quantum and which way times go onto it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantum {
    /// Seconds per quantum.
    pub seconds: f64,
    /// Which way a time goes onto the grid.
    pub rounding: Rounding,
}

impl Quantum {
    /// `t` on the grid, rounded as asked (at least one quantum).
    pub fn time(self, t: f64) -> f64 {
        quantize_time(t, self.seconds, self.rounding)
    }

    /// Whole quanta nearest to `t` as the grid rounds (up or nearest), possibly none.
    pub fn count(self, t: f64) -> f64 {
        match self.rounding {
            Rounding::Up => (t / self.seconds - 1e-9).ceil().max(0.0),
            Rounding::Nearest => (t / self.seconds).round().max(0.0),
        }
    }
}

/// The piece time `t` as a whole, positive multiple of `quantum`, rounded as asked.
pub fn quantize_time(t: f64, quantum: f64, rounding: Rounding) -> f64 {
    let k = match rounding {
        Rounding::Up => (t / quantum - 1e-9).ceil(),
        Rounding::Nearest => (t / quantum).round(),
    };
    quanta_time(k.max(1.0), quantum)
}

/// Re-times a PVT contour onto the quantum grid as the module documentation describes.
pub fn retime(contour: &PvtContour, quantum: f64, rounding: Rounding) -> PvtContour {
    let n = contour.len();
    let dim = contour.dim;
    let stretch: Vec<f64> = contour
        .durations
        .iter()
        .map(|&t| quantize_time(t, quantum, rounding) / t)
        .collect();
    let mut out = PvtContour::new(contour.motion, contour.start.clone());
    let mut v = vec![0.0; dim];
    for i in 0..n {
        let seg = contour.segment(i);
        let k = if i + 1 < n {
            stretch[i].max(stretch[i + 1])
        } else {
            stretch[i]
        };
        for (o, x) in v.iter_mut().zip(seg.velocity) {
            *o = x / k;
        }
        out.push(
            seg.end,
            &v,
            quantize_time(seg.duration, quantum, rounding),
            seg.line,
        );
    }
    out
}

/// Vector speed at the middle of piece `i`, under the given interpolation.
pub fn mid_speed(contour: &PvtContour, i: usize, interpolation: Interpolation) -> f64 {
    match interpolation {
        Interpolation::Pt => norm(contour.segment(i).velocity),
        Interpolation::Pvt => {
            let t = contour.durations[i] / 2.0;
            let v: Vec<f64> = (0..contour.dim)
                .map(|k| contour.hermite(i, k).at(t).velocity)
                .collect();
            norm(&v)
        }
    }
}

/// Largest relative change in mid-piece speed from `before` to `after` (same pieces).
///
/// Pieces that stand still before (mid speed below 1e-12 of the contour's fastest) are left
/// out: a relative change of nothing is not defined.
pub fn mid_speed_change(
    before: &PvtContour,
    after: &PvtContour,
    interpolation: Interpolation,
) -> f64 {
    let speeds: Vec<f64> = (0..before.len())
        .map(|i| mid_speed(before, i, interpolation))
        .collect();
    let fastest = speeds.iter().fold(0.0_f64, |m, &s| m.max(s));
    let mut worst = 0.0_f64;
    for (i, &s) in speeds.iter().enumerate() {
        if s > 1e-12 * fastest && i < after.len() {
            worst = worst.max((mid_speed(after, i, interpolation) - s).abs() / s);
        }
    }
    worst
}

/// The shortest piece the LSPB planner writes, seconds: 0.1 µs, the finest time an output
/// prints (PMAC: 4 decimals of milliseconds). Shorter pieces print as `TA0.0000`, and the
/// rounding of their end positions swamps their acceleration.
pub const MIN_PIECE_SECONDS: f64 = 1e-7;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::Motion;

    #[test]
    fn times_round_up_to_the_grid() {
        let up = |t| quantize_time(t, 0.001, Rounding::Up);
        assert_eq!(up(0.0101), 0.011);
        assert_eq!(up(0.003), 0.003);
        assert_eq!(up(1e-6), 0.001);
        // 820 quanta of 1 ms are 0.82, the f64 the decimal parses to.
        assert_eq!(up(0.8193295), 0.82);
        assert_eq!(up(0.8200000000000001), 0.82);
        assert_eq!(quantize_time(0.07, 0.03, Rounding::Up), 3.0 * 0.03);
    }

    #[test]
    fn times_round_to_the_nearest_quantum_but_never_to_none() {
        let nearest = |t| quantize_time(t, 0.001, Rounding::Nearest);
        assert_eq!(nearest(0.8193295), 0.819);
        assert_eq!(nearest(0.8196), 0.82);
        assert_eq!(nearest(1e-6), 0.001);
        assert_eq!("nearest".parse::<Rounding>(), Ok(Rounding::Nearest));
        assert!("down".parse::<Rounding>().is_err());
    }

    #[test]
    fn equal_stretch_is_a_time_scaling() {
        let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
        c.push(&[1.0], &[2.0], 0.75, 1);
        c.push(&[2.0], &[0.0], 0.75, 2);
        let r = retime(&c, 1.0, Rounding::Up);
        assert_eq!(r.durations, vec![1.0, 1.0]);
        assert_eq!(r.velocities, vec![1.5, 0.0]);
        let change = mid_speed_change(&c, &r, Interpolation::Pvt);
        assert!((change - 0.25).abs() < 1e-12, "{change}");
    }
}
