//! The check: what a planned program will do on the machine, in numbers.
//!
//! Owns the pure computation behind `pvtc check`: total time; per axis the peak |v|, |a|,
//! |j| of the pieces and the largest acceleration step at a knot over one servo period
//! (`|Δa|/P`, checked against the jerk limit) in closed form (`peaks`) and the velocity and acceleration a servo
//! loop sees from positions sampled at its period (`servo`); the vector speed against the
//! programmed feed; the largest distance from the motion to the true source geometry
//! (`geometry`); and every axis limit exceeded. PT programs are evaluated as PT
//! (straight pieces, velocity steps at the points). It must not render: the CLI prints
//! the [`CheckReport`] as text or JSON.
//!
//! Path error: every piece is sampled at 17 evenly spaced instants (ends included); the
//! distance from each sample to the nearest source element on the piece's line (or its
//! neighbours, found through a tree of their boxes) is measured exactly (lines) or by refined search (arcs), and the worst
//! sample is refined by golden-section search over the two sample intervals around it.

mod boxes;
mod geometry;
mod peaks;
mod servo;
mod timeline;

use std::collections::BTreeMap;

use crate::axis::Axis;
pub use crate::limits::AxisLimits;
use crate::program::PvtProgram;
use crate::toolpath::Toolpath;
use geometry::{golden, Source};
use timeline::Timeline;

/// Samples per piece for the path error search (plus one: both ends).
const PATH_SAMPLES: usize = 16;

/// What to check and how the servo loop samples.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckOptions {
    /// Servo period, seconds (seed 001's XMP: 500 µs).
    pub servo_period: f64,
    /// Limits per axis; axes not listed are not limited.
    pub limits: BTreeMap<Axis, AxisLimits>,
}

impl Default for CheckOptions {
    fn default() -> CheckOptions {
        CheckOptions {
            servo_period: crate::defaults::SERVO_PERIOD_S,
            limits: BTreeMap::new(),
        }
    }
}

/// A peak value with where it happens.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Peak {
    /// The value (an absolute value for axis quantities).
    pub value: f64,
    /// Time from the program start, seconds.
    pub time: f64,
    /// Source line of the piece running then.
    pub line: u32,
}

/// The quantity a peak or a limit is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Quantity {
    /// Velocity, units/s.
    Velocity,
    /// Acceleration, units/s².
    Acceleration,
    /// Jerk, units/s³.
    Jerk,
    /// The acceleration step at a knot spread over one servo period, `|Δa|/P`, units/s³
    /// (checked against the jerk limit).
    AccelerationStep,
}

impl Quantity {
    /// The word used in every output: `velocity`, `acceleration`, `jerk` or
    /// `acceleration_step`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
            Quantity::AccelerationStep => "acceleration_step",
        }
    }
}

/// The peaks of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisReport {
    /// The axis.
    pub axis: Axis,
    /// Closed-form peak |velocity| of the pieces.
    pub velocity: Peak,
    /// Closed-form peak |acceleration| (PT: velocity step over one servo period).
    pub acceleration: Peak,
    /// Closed-form peak |jerk| (PT: velocity step over one servo period squared).
    pub jerk: Peak,
    /// Closed-form largest acceleration step at a knot (a contour's ends against rest)
    /// over one servo period, `|Δa|/P` (PT: `|ΔV|/P²`, as `jerk`).
    pub acceleration_step: Peak,
    /// Peak |first difference| of positions sampled at the servo period.
    pub sampled_velocity: Peak,
    /// Peak |second difference| of positions sampled at the servo period.
    pub sampled_acceleration: Peak,
}

/// Vector speed against the programmed feed over the servo samples of feed motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedReport {
    /// Lowest vector speed, units/s (0 at every start and stop).
    pub min: Peak,
    /// Highest vector speed, units/s.
    pub max: Peak,
    /// Root mean square of (speed − feed), units/s.
    pub rms_error: f64,
    /// Number of samples compared.
    pub samples: usize,
}

/// One limit exceeded: the worst value of one quantity on one axis from one source line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// The axis.
    pub axis: Axis,
    /// What was exceeded.
    pub quantity: Quantity,
    /// The worst value from that line.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// When the worst value happens, seconds.
    pub time: f64,
    /// Source line.
    pub line: u32,
}

/// Everything the check found.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReport {
    /// Total motion time, seconds.
    pub total_time: f64,
    /// The servo period used, seconds.
    pub servo_period: f64,
    /// Per program axis, in program order.
    pub axes: Vec<AxisReport>,
    /// Vector speed against the feed; `None` without a source or without feed motion.
    pub speed: Option<SpeedReport>,
    /// Largest distance from the motion to the source geometry; `None` without a source.
    pub path_error: Option<Peak>,
    /// Limits exceeded, one per axis, quantity and source line, in time order.
    pub violations: Vec<Violation>,
}

impl CheckReport {
    /// The largest path error in units, if a source was given.
    pub fn max_path_error(&self) -> Option<f64> {
        self.path_error.map(|p| p.value)
    }

    /// The peaks of one axis, if the program moves it.
    pub fn axis(&self, axis: Axis) -> Option<&AxisReport> {
        self.axes.iter().find(|a| a.axis == axis)
    }

    /// True when any given limit is exceeded.
    pub fn exceeded(&self) -> bool {
        !self.violations.is_empty()
    }
}

/// Checks a program, against its source geometry and feeds when `source` is given.
pub fn check_program(
    program: &PvtProgram,
    source: Option<&Toolpath>,
    options: &CheckOptions,
) -> CheckReport {
    let period = if options.servo_period.is_finite() && options.servo_period > 0.0 {
        options.servo_period
    } else {
        crate::defaults::SERVO_PERIOD_S
    };
    let tl = Timeline::new(program);
    let (closed, violations) = closed_form(&tl, period, options);
    let (sampled_v, sampled_a) = servo::sampled_peaks(&tl, period);
    let axes = program
        .axes
        .iter()
        .enumerate()
        .map(|(k, &axis)| AxisReport {
            axis,
            velocity: closed[k][0],
            acceleration: closed[k][1],
            jerk: closed[k][2],
            acceleration_step: closed[k][3],
            sampled_velocity: sampled_v[k],
            sampled_acceleration: sampled_a[k],
        })
        .collect();
    let source = source.map(|s| Source::new(s, &program.axes));
    CheckReport {
        total_time: tl.total,
        servo_period: period,
        axes,
        speed: source
            .as_ref()
            .and_then(|s| servo::speed_against_feed(&tl, s, period)),
        path_error: source.as_ref().map(|s| path_error(&tl, s)),
        violations,
    }
}

/// The closed-form peaks of every axis of `program`, in program order: velocity,
/// acceleration, jerk and the acceleration step over `servo_period`, as
/// [`check_program`] finds them (without servo sampling or limits): what `pvtc diff`
/// compares.
pub fn closed_form_peaks(program: &PvtProgram, servo_period: f64) -> Vec<[Peak; 4]> {
    let options = CheckOptions {
        servo_period,
        limits: BTreeMap::new(),
    };
    closed_form(&Timeline::new(program), servo_period, &options).0
}

/// Relative amount by which a peak may exceed its limit and still pass: the rounding
/// of the arithmetic that computes it, nothing more.
pub const LIMIT_ROUNDING: f64 = 1e-9;

/// Closed-form peaks per axis ([velocity, acceleration, jerk, acceleration step]) and the
/// limits exceeded.
fn closed_form(
    tl: &Timeline<'_>,
    period: f64,
    options: &CheckOptions,
) -> (Vec<[Peak; 4]>, Vec<Violation>) {
    let axes = &tl.program.axes;
    let mut peaks = vec![[Peak::default(); 4]; axes.len()];
    let mut worst: BTreeMap<(usize, Quantity, u32), usize> = BTreeMap::new();
    let mut violations: Vec<Violation> = Vec::new();
    for i in 0..tl.pieces.len() {
        for (k, &axis) in axes.iter().enumerate() {
            let limits = options.limits.get(&axis).copied().unwrap_or_default();
            let mut found: Vec<(Quantity, Peak)> = peaks::piece_peaks(tl, i, k, period).to_vec();
            found.extend(peaks::stop(tl, &tl.pieces[i], k, period));
            for (q, peak) in found {
                let slot = &mut peaks[k][q as usize];
                if peak.value > slot.value {
                    *slot = peak;
                }
                let limit = match q {
                    Quantity::Velocity => limits.velocity,
                    Quantity::Acceleration => limits.acceleration,
                    Quantity::Jerk | Quantity::AccelerationStep => limits.jerk,
                };
                let Some(limit) = limit.filter(|&l| peak.value > l * (1.0 + LIMIT_ROUNDING)) else {
                    continue;
                };
                let v = Violation {
                    axis,
                    quantity: q,
                    value: peak.value,
                    limit,
                    time: peak.time,
                    line: peak.line,
                };
                match worst.get(&(k, q, peak.line)) {
                    Some(&at) if violations[at].value >= v.value => {}
                    Some(&at) => violations[at] = v,
                    None => {
                        worst.insert((k, q, peak.line), violations.len());
                        violations.push(v);
                    }
                }
            }
        }
    }
    violations.sort_by(|a, b| a.time.total_cmp(&b.time));
    (peaks, violations)
}

/// The largest distance from the motion to the source geometry, with where it happens.
/// The box of a piece's cubic on every axis: its Bézier control points' (PT: its ends').
fn piece_box(tl: &Timeline<'_>, p: &timeline::Piece) -> (Vec<f64>, Vec<f64>) {
    let dim = tl.program.axes.len();
    let (mut lo, mut hi) = (vec![0.0; dim], vec![0.0; dim]);
    for k in 0..dim {
        let h = tl.cubic(p, k);
        let end = h.end();
        let t3 = p.duration / 3.0;
        let points = [
            h.p0,
            h.p0 + h.v0 * t3,
            end.position - end.velocity * t3,
            end.position,
        ];
        lo[k] = points.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        hi[k] = points.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    }
    (lo, hi)
}

fn path_error(tl: &Timeline<'_>, source: &Source<'_>) -> Peak {
    let dim = tl.program.axes.len();
    let mut worst = Peak::default();
    let mut point = vec![0.0; dim];
    for p in &tl.pieces {
        let (lo, hi) = piece_box(tl, p);
        for (k, x) in point.iter_mut().enumerate() {
            *x = tl.position(p, k, 0.0);
        }
        let candidates = source.near(p.line, &point, &lo, &hi);
        let mut gap = |t: f64| {
            for (k, x) in point.iter_mut().enumerate() {
                *x = tl.position(p, k, t);
            }
            source.distance(&candidates, &point)
        };
        let step = p.duration / PATH_SAMPLES as f64;
        let (mut best_i, mut best) = (0, f64::NEG_INFINITY);
        for i in 0..=PATH_SAMPLES {
            let d = gap(i as f64 * step);
            if d > best {
                (best_i, best) = (i, d);
            }
        }
        let lo = best_i.saturating_sub(1) as f64 * step;
        let hi = ((best_i + 1).min(PATH_SAMPLES)) as f64 * step;
        let t = golden(lo, hi, &mut gap);
        let (t, d) = match gap(t) {
            refined if refined > best => (t, refined),
            _ => (best_i as f64 * step, best),
        };
        if d > worst.value {
            worst = Peak {
                value: d,
                time: p.start + t,
                line: p.line,
            };
        }
    }
    worst
}

#[cfg(test)]
mod tests;
