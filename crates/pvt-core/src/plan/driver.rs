//! Planning whole toolpaths and point-time series with the chosen planner.
//!
//! Owns the dispatch from [`PlanOptions`] to a planner for every contour or run, the
//! option checks, quantization of the result and the [`PlanReport`] of what the planning
//! changed. It must not implement a planner itself, and it sits below the planning stage
//! ([`crate::stream`]), which calls it: nothing here names the stage.

use super::chord::{chord_back_velocities, chord_velocities};
use super::const_accel::const_accel_velocities;
use super::lspb::plan_lspb;
use super::plan_path;
use super::pt::plan_pt;
use super::quantize::{mid_speed_change, quantize_time, retime, Quantum};
use super::spline::spline_velocities;
use super::timed::{contour_from_velocities, runs_from_polyline, TimedPoints};
use super::{plan_contour, PlanError, PlanOptions, Planner, Timing};
use crate::axis::Axis;
use crate::discretize::flatten_contour;
use crate::polyline::Polyline;
use crate::program::{Interpolation, PvtContour};
use crate::toolpath::{Contour, Element, ElementKind, Motion, Span};
use crate::vector::{distance, max_abs};

/// What planning changed that the user should hear about.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanReport {
    /// Largest relative change of mid-piece vector speed caused by quantization (0 without).
    pub quantize_speed_change: f64,
    /// Segments whose time the LSPB planner raised so that their blends fit.
    pub lengthened_segments: usize,
    /// True when the input gave velocities that the chosen planner does not use.
    pub velocities_ignored: bool,
    /// The path planner's largest per-piece error bound, program units (`None` for the
    /// other planners, which promise no distance to the geometry between points).
    pub path_error: Option<f64>,
    /// Time the planned path takes at its feeds with no acceleration at all (the sum
    /// of every element's length over its feed), seconds.
    pub feed_time: f64,
}

/// Plans one whole contour with the chosen planner, then quantizes it: the planning of a
/// contour [`crate::stream::PlanStage`] holds until it ends.
pub(crate) fn plan_buffered(
    contour: &Contour,
    axes: &[Axis],
    options: &PlanOptions,
    report: &mut PlanReport,
) -> Result<PvtContour, PlanError> {
    if contour.elements.is_empty() {
        return Ok(PvtContour::new(contour.motion, vec![0.0; axes.len()]));
    }
    Ok(match options.planner {
        Planner::Path => follow_path(contour, axes, options, report)?,
        Planner::Contour => {
            let polyline = flatten_contour(contour, axes, options.tolerance);
            let planned = plan_contour(&polyline, contour.motion)?;
            quantize_whole(planned, options, report)
        }
        _ => {
            let polyline = flatten_contour(contour, axes, options.tolerance);
            let mut whole = PvtContour::new(contour.motion, polyline.point(0).to_vec());
            for run in runs_from_polyline(&polyline, options.timing)? {
                append(
                    &mut whole,
                    &plan_run(&run, options, contour.motion, report)?,
                );
            }
            whole
        }
    })
}

/// Rejects options that are out of range or that the chosen planner cannot honour.
pub fn check_options(options: &PlanOptions) -> Result<(), PlanError> {
    // The path tolerance is the caller's share of these (a drawing's curves take the
    // rest), so only the two given tolerances are held to the smallest.
    let tolerances = [Some(options.tolerance.get()), options.corner_tolerance];
    for tolerance in tolerances.into_iter().flatten() {
        if !(tolerance.is_finite() && tolerance >= crate::discretize::ChordTolerance::SMALLEST) {
            return Err(PlanError::BadTolerance { tolerance });
        }
    }
    if let Some(q) = options.quantize {
        if !(q.is_finite() && q > 0.0) {
            return Err(PlanError::BadQuantum { seconds: q });
        }
    }
    match options.accel {
        None if options.planner == Planner::Lspb => return Err(PlanError::MissingAccel),
        Some(a) if !(a.is_finite() && a > 0.0) => return Err(PlanError::BadAccel { accel: a }),
        _ => {}
    }
    if let Timing::TimeSlice(s) = options.timing {
        if !(s.is_finite() && s > 0.0) {
            return Err(PlanError::BadTimeSlice { seconds: s });
        }
        if matches!(options.planner, Planner::Contour | Planner::Path) {
            return Err(PlanError::UnsupportedOption {
                planner: options.planner.name(),
                option: "a time slice",
            });
        }
    }
    Ok(())
}

/// Plans one run (rest to rest) with the chosen planner and quantizes it.
pub(crate) fn plan_run(
    run: &TimedPoints,
    options: &PlanOptions,
    motion: Motion,
    report: &mut PlanReport,
) -> Result<PvtContour, PlanError> {
    let planner = options.planner;
    report.velocities_ignored |= run.velocities.is_some() && !planner.is_velocity_method();
    match planner {
        Planner::Path => follow_path(&lines_of(run), &axes_of(run.dim), options, report),
        Planner::Contour => {
            let planned = plan_contour(&polyline_of(run), motion)?;
            Ok(quantize_whole(planned, options, report))
        }
        Planner::Lspb => {
            // LSPB quantizes its own piece times: stretching pieces one by one (retime)
            // would break the constant-acceleration blends.
            let accel = options.accel.ok_or(PlanError::MissingAccel)?;
            let quantum = options.quantize.map(|seconds| Quantum {
                seconds,
                rounding: options.quantize_rounding,
            });
            let plan = plan_lspb(run, accel, quantum, motion);
            report.lengthened_segments += plan.raised;
            report.quantize_speed_change = report.quantize_speed_change.max(plan.speed_change);
            Ok(plan.contour)
        }
        Planner::Chord | Planner::ChordBack | Planner::ConstAccel | Planner::Spline
            if run.velocities.is_some() =>
        {
            let given = run.velocities.as_deref().unwrap_or_default();
            Ok(quantize_whole(
                contour_from_velocities(run, given, motion),
                options,
                report,
            ))
        }
        Planner::Pt
        | Planner::Chord
        | Planner::ChordBack
        | Planner::ConstAccel
        | Planner::Spline => {
            let planned = plan_with_times(run, planner, motion);
            let Some(q) = options.quantize else {
                return Ok(planned);
            };
            let mut regridded = run.clone();
            regridded
                .durations
                .iter_mut()
                .for_each(|t| *t = quantize_time(*t, q, options.quantize_rounding));
            let quantized = plan_with_times(&regridded, planner, motion);
            note_change(report, &planned, &quantized, options.interpolation());
            Ok(quantized)
        }
    }
}

/// Plans one contour with the path planner at the options' path tolerance and limits,
/// on the quantum grid if asked (the path planner quantizes its own pieces).
fn follow_path(
    contour: &Contour,
    axes: &[Axis],
    options: &PlanOptions,
    report: &mut PlanReport,
) -> Result<PvtContour, PlanError> {
    let path = options.path_options();
    let (planned, achieved) = plan_path(contour, axes, &path)?;
    let worst = report.path_error.unwrap_or(0.0).max(achieved.error_bound);
    report.path_error = Some(worst);
    report.quantize_speed_change = report.quantize_speed_change.max(achieved.speed_change);
    Ok(planned)
}

/// The first `dim` axes, X Y Z A B C order: a series' columns as the path planner sees them.
fn axes_of(dim: usize) -> Vec<Axis> {
    Axis::ALL.into_iter().take(dim).collect()
}

/// A run as a contour of lines, each at its mean speed (chord / time); dwells dropped.
fn lines_of(run: &TimedPoints) -> Contour {
    let poly = polyline_of(run);
    let axes = axes_of(run.dim);
    let position = |i: usize| {
        let mut p = [0.0; crate::axis::AXIS_COUNT];
        for (k, a) in axes.iter().enumerate() {
            p[a.index()] = poly.point(i)[k];
        }
        p
    };
    let elements = (0..poly.feeds.len())
        .map(|i| Element {
            kind: ElementKind::Line,
            start: position(i),
            end: position(i + 1),
            feed: poly.feeds[i],
            span: Span {
                line: poly.lines[i],
                ..Span::default()
            },
        })
        .collect();
    Contour {
        motion: Motion::Feed,
        elements,
    }
}

/// The planners that keep the given times: PT and the three velocity methods.
fn plan_with_times(run: &TimedPoints, planner: Planner, motion: Motion) -> PvtContour {
    let velocities = match planner {
        Planner::Pt => return plan_pt(run, motion),
        Planner::ConstAccel => const_accel_velocities(run),
        Planner::Spline => spline_velocities(run),
        Planner::ChordBack => chord_back_velocities(run),
        _ => chord_velocities(run),
    };
    contour_from_velocities(run, &velocities, motion)
}

/// Re-times a finished PVT contour onto the quantum grid, if asked.
fn quantize_whole(
    planned: PvtContour,
    options: &PlanOptions,
    report: &mut PlanReport,
) -> PvtContour {
    let Some(q) = options.quantize else {
        return planned;
    };
    let quantized = retime(&planned, q, options.quantize_rounding);
    note_change(report, &planned, &quantized, Interpolation::Pvt);
    quantized
}

fn note_change(
    report: &mut PlanReport,
    before: &PvtContour,
    after: &PvtContour,
    interpolation: Interpolation,
) {
    let change = mid_speed_change(before, after, interpolation);
    report.quantize_speed_change = report.quantize_speed_change.max(change);
}

/// A run as a polyline for the contour planner: feed = chord / time, dwells dropped.
fn polyline_of(run: &TimedPoints) -> Polyline {
    let mut poly = Polyline::start_at(run.point(0));
    for i in 1..run.len() {
        let (a, b) = (poly.last_point(), run.point(i));
        let chord = distance(a, b);
        if chord > 1e-12 * max_abs(a).max(max_abs(b)) {
            poly.push(b, chord / run.durations[i - 1], run.lines[i - 1]);
        }
    }
    poly
}

/// Appends the segments of `from` (which starts where `into` ends) to `into`.
fn append(into: &mut PvtContour, from: &PvtContour) {
    for seg in from.segments() {
        into.push(seg.end, seg.velocity, seg.duration, seg.line);
    }
}

#[cfg(test)]
#[path = "planner_tests.rs"]
mod planner_tests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tolerance_finer_than_the_smallest_is_refused() {
        let smallest = crate::discretize::ChordTolerance::SMALLEST;
        let with = |tolerance: f64, corner: Option<f64>| PlanOptions {
            tolerance: crate::discretize::ChordTolerance::new(tolerance).unwrap(),
            corner_tolerance: corner,
            ..PlanOptions::default()
        };
        assert_eq!(check_options(&with(smallest, Some(smallest))), Ok(()));
        let fine = smallest * 0.999;
        for options in [
            with(fine, None),
            with(0.001, Some(fine)),
            with(1e-200, None),
        ] {
            assert!(matches!(
                check_options(&options),
                Err(PlanError::BadTolerance { .. })
            ));
        }
    }
}
