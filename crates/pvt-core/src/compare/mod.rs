//! Two programs compared as motion, for `pvtc diff` and golden-file tests.
//!
//! Owns the pure computation: both programs on one time line (pieces, and dwells as time
//! at rest) on the union of their axes, the second in the first's units (or both in
//! counts); the difference in position at every instant, bounded exactly between knots
//! (`aligned`); where that exceeds the tolerance, the distance along the path and the
//! time shift, matching each program's knots to the other's path (`along`), so a motion
//! that is the same but later is a time shift, not a position error; the total times;
//! each axis' closed-form peaks (`check`'s); the events and triggers in order
//! (`events`); and the differences beyond the tolerances. It must not read or render:
//! the CLI reads both programs and prints the [`Comparison`].

mod aligned;
mod along;
mod cubic;
mod events;
mod track;

use crate::axis::{Axis, Units};
use crate::check::{closed_form_peaks, Peak, Quantity};
use crate::program::PvtProgram;
use std::collections::BTreeMap;
use track::Track;

pub use events::{Listed, Mismatch};

/// One program to compare, with what its format carries.
#[derive(Debug, Clone, Copy)]
pub struct Side<'a> {
    /// The motion and events.
    pub program: &'a PvtProgram,
    /// Whether the format carries events other than dwells (XPS, Zaber and the CSV
    /// table carry none): events are compared only when both carry them.
    pub carries_events: bool,
    /// The triggers, each as the number of pieces before it, where the format carries
    /// triggers; compared only when both do.
    pub triggers: Option<&'a [usize]>,
}

/// The tolerances and what else the comparison takes.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// Farthest apart the positions may be: in the first program's units, or in counts
    /// with [`CompareOptions::counts_per_unit`].
    pub tolerance: f64,
    /// Largest time shift and difference of total times, seconds.
    pub time_tolerance: f64,
    /// Largest relative difference of a peak (0.01: 1 %).
    pub peak_tolerance: f64,
    /// Servo period for the peaks of PT motion (`check`'s), seconds.
    pub servo_period: f64,
    /// Counts per unit (of the first program) of each compared axis: when given, every
    /// position is compared in counts. Empty: in units.
    pub counts_per_unit: BTreeMap<Axis, f64>,
    /// Bins of the profile of the difference against time (0: none).
    pub profile_bins: usize,
}

/// A largest value and where it is.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Spot {
    /// The value.
    pub value: f64,
    /// When, seconds on the first program's time line.
    pub time: f64,
    /// The line of each program there.
    pub lines: [u32; 2],
}

/// The peaks of one axis in both programs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisPeaks {
    /// The axis.
    pub axis: Axis,
    /// Velocity, acceleration and jerk, each in both programs (0 where one does not
    /// move the axis).
    pub peaks: [(Quantity, [Peak; 2]); 3],
}

/// What is beyond a tolerance.
#[derive(Debug, Clone, PartialEq)]
pub enum Difference {
    /// The paths are farther apart than the tolerance.
    Position(Spot),
    /// The same place is passed at times farther apart than the time tolerance.
    TimeShift(Spot),
    /// The total times differ by more than the time tolerance (seconds, second less first).
    TotalTime(f64),
    /// A peak differs by more than the peak tolerance.
    Peak {
        /// The axis.
        axis: Axis,
        /// The quantity.
        quantity: Quantity,
        /// Both peaks.
        peaks: [Peak; 2],
    },
    /// The events differ.
    Events(Mismatch),
    /// The triggers differ.
    Triggers(Mismatch),
}

impl Difference {
    /// The last part of the diagnostic code (`pvtc::diff::NAME`).
    pub fn code_name(&self) -> &'static str {
        match self {
            Difference::Position(_) => "position",
            Difference::TimeShift(_) => "time_shift",
            Difference::TotalTime(_) => "total_time",
            Difference::Peak { .. } => "peak",
            Difference::Events(_) => "events",
            Difference::Triggers(_) => "triggers",
        }
    }
}

/// Everything the comparison found.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The compared axes (both programs' together), in X Y Z A B C order.
    pub axes: Vec<Axis>,
    /// The units positions are compared in (the first program's), unless in counts.
    pub units: Units,
    /// Whether positions are compared in counts.
    pub in_counts: bool,
    /// Pieces of each program.
    pub pieces: [usize; 2],
    /// Total time of each (motion and dwells), seconds.
    pub total_time: [f64; 2],
    /// The largest difference of positions at the same instant.
    pub aligned: Spot,
    /// The first instant the difference at the same instant exceeds the tolerance.
    pub first_divergence: Option<Spot>,
    /// The largest distance from either motion to the other's path (the difference at
    /// the same instant where that is within the tolerance).
    pub path: Spot,
    /// The largest time shift (seconds, the second program later when positive).
    pub time_shift: Spot,
    /// Peaks per axis.
    pub peaks: Vec<AxisPeaks>,
    /// The events (but dwells), when both programs carry them.
    pub events: Option<Listed>,
    /// The triggers, when both programs carry them.
    pub triggers: Option<Listed>,
    /// The largest difference at the same instant in each bin of equal time, over the
    /// longer program's time ([`CompareOptions::profile_bins`] of them).
    pub profile: Vec<f64>,
    /// What is beyond the tolerances, in the order above.
    pub differences: Vec<Difference>,
}

impl Comparison {
    /// True when the programs are the same within the tolerances.
    pub fn equal(&self) -> bool {
        self.differences.is_empty()
    }
}

/// The factors from each program's units to the compared scale, per compared axis.
fn factors(axes: &[Axis], units: [Units; 2], options: &CompareOptions) -> [Vec<f64>; 2] {
    let to_first = units[1].mm_per_unit() / units[0].mm_per_unit();
    let counts = |a: &Axis| options.counts_per_unit.get(a).copied().unwrap_or(1.0);
    let first = axes.iter().map(counts).collect();
    let second = axes
        .iter()
        .map(|a| counts(a) * if a.is_rotary() { 1.0 } else { to_first })
        .collect();
    [first, second]
}

/// Compares two programs as motion.
pub fn compare(a: Side<'_>, b: Side<'_>, options: &CompareOptions) -> Comparison {
    let axes: Vec<Axis> = Axis::ALL
        .into_iter()
        .filter(|x| a.program.axes.contains(x) || b.program.axes.contains(x))
        .collect();
    let units = [a.program.units, b.program.units];
    let [fa, fb] = factors(&axes, units, options);
    let tracks = [
        Track::new(a.program, &axes, &fa),
        Track::new(b.program, &axes, &fb),
    ];
    let tolerance = options.tolerance;
    let sweep = aligned::sweep(&tracks[0], &tracks[1], tolerance, options.profile_bins);
    let forth = along::along(&tracks[0], &tracks[1], &sweep.failing, tolerance);
    let back = along::along(&tracks[1], &tracks[0], &sweep.failing, tolerance);
    let path = path_spot(&sweep, &forth, &back);
    let within = tolerance + path.value.max(0.0);
    let time_shift = shift_spot(
        &along::shift(&tracks[0], &tracks[1], &forth.matches, within),
        &along::shift(&tracks[1], &tracks[0], &back.matches, within),
    );
    let mut comparison = Comparison {
        in_counts: !options.counts_per_unit.is_empty(),
        pieces: [a.program.segment_count(), b.program.segment_count()],
        total_time: [tracks[0].total, tracks[1].total],
        aligned: sweep.largest,
        first_divergence: sweep.first,
        path,
        time_shift,
        peaks: peaks(&axes, [a.program, b.program], units, options.servo_period),
        events: (a.carries_events && b.carries_events).then(|| {
            events::events(
                [&tracks[0], &tracks[1]],
                [&a.program.events, &b.program.events],
                tolerance,
            )
        }),
        triggers: a.triggers.zip(b.triggers).map(|(x, y)| {
            events::triggers(
                [&tracks[0], &tracks[1]],
                [x, y],
                [tolerance, options.time_tolerance],
            )
        }),
        profile: sweep.profile,
        differences: Vec::new(),
        axes,
        units: units[0],
    };
    comparison.differences = differences(&comparison, forth.unmatched + back.unmatched, options);
    comparison
}

/// A finding of the matching from the first program to the second, as a spot.
fn forth(m: &along::Meet, value: f64) -> Spot {
    Spot {
        value,
        time: m.at[0],
        lines: m.lines,
    }
}

/// A finding of the matching from the second program to the first, as a spot on the
/// first's time line, the first's line first.
fn back(m: &along::Meet, value: f64) -> Spot {
    Spot {
        value,
        time: m.at[1],
        lines: [m.lines[1], m.lines[0]],
    }
}

/// The largest distance along the path: from the matching where the instants differ,
/// else the largest difference at the same instant.
fn path_spot(sweep: &aligned::Aligned, there: &along::Along, home: &along::Along) -> Spot {
    let (f, b) = (&there.distance, &home.distance);
    match (sweep.failing.is_empty(), f.value >= b.value) {
        (true, _) => sweep.largest,
        (false, true) => forth(f, f.value),
        (false, false) => back(b, b.value),
    }
}

/// The larger time shift of both matchings, as the second program's time less the
/// first's.
fn shift_spot(f: &along::Meet, b: &along::Meet) -> Spot {
    if f.value.abs() >= b.value.abs() {
        forth(f, f.value)
    } else {
        back(b, -b.value)
    }
}

/// Each axis' velocity, acceleration and jerk peaks in both programs, the second's in
/// the first's units.
fn peaks(
    axes: &[Axis],
    programs: [&PvtProgram; 2],
    units: [Units; 2],
    period: f64,
) -> Vec<AxisPeaks> {
    let found = programs.map(|p| closed_form_peaks(p, period));
    let to_first = units[1].mm_per_unit() / units[0].mm_per_unit();
    let of = |side: usize, axis: Axis, q: usize| -> Peak {
        let program = programs[side];
        let Some(k) = program.axes.iter().position(|a| *a == axis) else {
            return Peak::default();
        };
        let mut peak = found[side][k][q];
        if side == 1 && !axis.is_rotary() {
            peak.value *= to_first;
        }
        peak
    };
    axes.iter()
        .map(|&axis| AxisPeaks {
            axis,
            peaks: [
                (Quantity::Velocity, [of(0, axis, 0), of(1, axis, 0)]),
                (Quantity::Acceleration, [of(0, axis, 1), of(1, axis, 1)]),
                (Quantity::Jerk, [of(0, axis, 2), of(1, axis, 2)]),
            ],
        })
        .collect()
}

/// Whether two peaks differ by more than `share` of the larger, where the larger is
/// more than the rounding of the largest such peak of any axis.
fn peaks_differ(pair: &[Peak; 2], share: f64, largest: f64) -> bool {
    let (x, y) = (pair[0].value, pair[1].value);
    let scale = x.max(y);
    scale > 1e-9 * largest && (x - y).abs() > share * scale
}

/// What is beyond the tolerances; `unmatched`: the samples of either program with no
/// point of the other's path within the tolerance.
fn differences(c: &Comparison, unmatched: usize, options: &CompareOptions) -> Vec<Difference> {
    let mut out = Vec::new();
    if unmatched > 0 && c.path.value > options.tolerance {
        out.push(Difference::Position(c.path));
    }
    if c.time_shift.value.abs() > options.time_tolerance {
        out.push(Difference::TimeShift(c.time_shift));
    }
    let total = c.total_time[1] - c.total_time[0];
    if total.abs() > options.time_tolerance {
        out.push(Difference::TotalTime(total));
    }
    for q in 0..3 {
        let largest = c
            .peaks
            .iter()
            .flat_map(|a| a.peaks[q].1)
            .fold(0.0f64, |m, p| m.max(p.value));
        for a in &c.peaks {
            let (quantity, pair) = a.peaks[q];
            if peaks_differ(&pair, options.peak_tolerance, largest) {
                out.push(Difference::Peak {
                    axis: a.axis,
                    quantity,
                    peaks: pair,
                });
            }
        }
    }
    if let Some(m) = c.events.as_ref().and_then(|e| e.mismatch.clone()) {
        out.push(Difference::Events(m));
    }
    if let Some(m) = c.triggers.as_ref().and_then(|e| e.mismatch.clone()) {
        out.push(Difference::Triggers(m));
    }
    out
}

#[cfg(test)]
mod tests;
