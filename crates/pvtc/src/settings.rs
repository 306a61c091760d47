//! The pipeline: source → front end → toolpath or point series → planner → back end → bytes.
//!
//! Owns the order of the phases and the settings each gets. It must not parse, plan or
//! format by itself, and it does no output I/O (see [`crate::output`]).

use crate::front::{self, Input};
pub(crate) use crate::options::at_line;
pub use crate::options::{
    CompileOptions, DrawingOptions, Failure, InputKind, Source, VelocitySource,
    DEFAULT_RAPID_MM_PER_MIN,
};
use miette::{Report, Severity};
use pvt_core::{
    plan_timed, plan_toolpath_report, split_long_pieces, ChordTolerance, Interpolation,
    PlanOptions, PlanReport, Planned, Planner, PvtProgram, Rounding, Timing, Toolpath, Units,
};
use pvt_emit::stream::Totals;
use pvt_emit::{emit_to_vec, EmitOptions, Format, StreamError};
use std::path::PathBuf;

/// Refuses PMAC axis definitions that leave a moved axis undefined
/// (`pvtc::pmac::undefined_axis`): the controller would not move it.
pub(crate) fn check_pmac_axes(
    options: &CompileOptions,
    moved: &[pvt_core::Axis],
) -> Result<(), Failure> {
    if options.format != Format::Pmac {
        return Ok(());
    }
    let missing = options.pmac.undefined_axes(moved);
    if missing.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = missing.iter().map(|a| a.to_string()).collect();
    Err(Failure::Input(vec![miette::miette!(
        code = "pvtc::pmac::undefined_axis",
        help = "add a definition like --pmac-axis '#3->1000Z' for each, or leave out --pmac-axis",
        "the program moves {} but no --pmac-axis defines {}",
        names.join(" "),
        if names.len() == 1 { "it" } else { "them" },
    )]))
}

/// A successful compilation.
#[derive(Debug)]
pub struct Compiled {
    /// The output, exactly as it is to be written.
    pub bytes: Vec<u8>,
    /// The planned program.
    pub program: PvtProgram,
    /// The geometry the program was planned from (for checking and plotting).
    pub toolpath: Toolpath,
    /// What planning changed.
    pub report: PlanReport,
    /// Warnings, ready to print.
    pub warnings: Vec<Report>,
}

/// Reads and plans `source` into a program, without writing any format.
pub fn plan(
    source: &Source,
    options: &CompileOptions,
) -> Result<(Planned, Toolpath, Vec<Report>), Failure> {
    let (mut input, mut warnings) = front::read(source, options)?;
    if let Input::Series(series) = &mut input {
        warnings.extend(choose_velocities(&mut series.points, options)?);
    }
    let moved = match &input {
        Input::Toolpath(t) => t.moved_axes(),
        Input::Series(s) => s.axes.clone(),
    };
    let plan_options = plan_options(options, input.units(), &moved)?;
    let (planned, toolpath) = match input {
        Input::Toolpath(toolpath) => (plan_toolpath_report(&toolpath, &plan_options), toolpath),
        Input::Series(series) => (
            plan_timed(
                &series.points,
                series.axes.clone(),
                series.units,
                &plan_options,
            ),
            series.toolpath(),
        ),
    };
    let planned = planned.map_err(|e| {
        let report = if e.line() == 0 {
            miette::miette!(code = e.code().to_string(), "{e}")
        } else {
            at_line(e.code(), &e.to_string(), e.line(), source)
                .with_source_code(source.named_text())
        };
        Failure::Input(vec![report])
    })?;
    warnings.extend(plan_notes(&planned.report, options));
    Ok((planned, toolpath, warnings))
}

/// Applies `--velocities` to a series: drops its velocity columns for `plan` (with a
/// note), refuses `file` when it has none or the planner takes no velocities, and says
/// which velocities a velocity method uses, and when a planner replaces the series' times.
fn choose_velocities(
    points: &mut pvt_core::TimedPoints,
    options: &CompileOptions,
) -> Result<Vec<Report>, Failure> {
    let planner = options.planner;
    let name = planner.name();
    let given = points.velocities.is_some();
    let mut notes = Vec::new();
    match options.velocities {
        Some(VelocitySource::Plan) if given => {
            points.velocities = None;
            notes.push(miette::miette!(
                severity = Severity::Advice,
                code = "pvtc::plan::velocity_columns_ignored",
                "the series' velocity columns are ignored (--velocities plan): the {name} planner chooses the velocities"
            ));
        }
        Some(VelocitySource::File) if !given => {
            return Err(Failure::Usage(
                "--velocities file: the series has no velocity columns (v<axis>, e.g. vx)".into(),
            ));
        }
        Some(VelocitySource::File) if !planner.is_velocity_method() => {
            return Err(Failure::Usage(format!(
                "--velocities file does nothing with the {name} planner, which chooses its own \
                 velocities: use chord-forward, chord-back, const-accel or spline"
            )));
        }
        None if given && planner.is_velocity_method() => notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::file_velocities",
            help = format!("pass --velocities plan to use the {name} method's velocities instead"),
            "the velocities are the series' velocity columns, as given, not the {name} method's"
        )),
        _ => {}
    }
    if matches!(planner, Planner::Contour | Planner::Path) {
        notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::times_replaced",
            help = "pt, chord-forward, chord-back, const-accel and spline keep the series' times",
            "the {name} planner chooses its own piece times: the series' times only set each segment's speed (chord / time)"
        ));
    }
    Ok(notes)
}

/// What the path planner achieved, for standard error: pieces, the path error bound and
/// the total time against the time at the feeds; `None` for the other planners.
pub(crate) fn summary_note(report: &PlanReport, totals: &Totals, units: Units) -> Option<Report> {
    let error = report.path_error?;
    // A point series has no feed to compare with: its pieces come from the points.
    let ratio = match report.feed_time > 0.0 {
        true => format!(" ({:.3} x length / feed)", totals.time / report.feed_time),
        false => String::new(),
    };
    Some(miette::miette!(
        severity = Severity::Advice,
        code = "pvtc::plan::summary",
        "{} pieces; path error at most {error:.6} {}; total time {:.4} s{ratio}",
        totals.segments,
        units.name(),
        totals.time
    ))
}

/// The totals a back end would count over `program`.
fn totals_of(program: &PvtProgram) -> Totals {
    let mut totals = Totals::default();
    program
        .contours
        .iter()
        .flat_map(|c| &c.durations)
        .for_each(|t| totals.add_segment(*t));
    totals
}

/// The planner's options for a program in `units` moving `moved`: every default of the
/// planning resolved here, once, for every route.
pub fn plan_options(
    options: &CompileOptions,
    units: Units,
    moved: &[pvt_core::Axis],
) -> Result<PlanOptions, Failure> {
    let tolerance = ChordTolerance::new(resolved_tolerance(options, units))
        .expect("the CLI accepts only positive tolerances");
    let limits = match &options.machine {
        Some(m) => m
            .limits_in(units, moved)
            .map_err(|e| Failure::Input(vec![Report::new(e)]))?,
        None => Default::default(),
    };
    let path_tolerance =
        (options.curve_share() < 1.0).then(|| tolerance.get() * (1.0 - options.curve_share()));
    Ok(PlanOptions {
        tolerance,
        path_tolerance,
        corner_tolerance: options.corner_tolerance,
        limits,
        planner: options.planner,
        timing: options.timing,
        accel: options.accel,
        quantize: options.quantize,
        quantize_rounding: options.quantize_rounding,
        servo_period: options.machine.as_ref().and_then(|m| m.servo_period),
        position_resolution: options.format.position_resolution(),
    })
}

/// Compiles `source` into the bytes of `options.format`.
pub fn compile(source: &Source, options: &CompileOptions) -> Result<Compiled, Failure> {
    let (planned, toolpath, mut warnings) = plan(source, options)?;
    let header = settings(options, planned.program.units);
    check_pmac_axes(options, &planned.program.axes)?;
    let program = fit_pieces(planned.program, options);
    let totals = totals_of(&program);
    warnings.extend(summary_note(&planned.report, &totals, program.units));
    let emit_options = emit_options(options, &source.name, header, program.units);
    let bytes = emit_to_vec(&program, options.format, &emit_options)
        .map_err(|e| emit_failure(e, options, Some(source)))?;
    if options.format == Format::Pmac && options.quantize.is_none() {
        warnings.extend(fractional_ms_warning(&program));
    }
    Ok(Compiled {
        bytes,
        program,
        toolpath,
        report: planned.report,
        warnings,
    })
}

/// What the back end is told besides the motion: the source, the header's settings, the
/// PMAC settings and, per axis in `units`, the machine file's travel, limits and counts
/// per unit with `--counts-per-unit` over them.
pub(crate) fn emit_options(
    options: &CompileOptions,
    name: &str,
    settings: Vec<(String, String)>,
    units: Units,
) -> EmitOptions {
    let mut axes = options
        .machine
        .as_ref()
        .map(|m| m.setup_in(units))
        .unwrap_or_default();
    for (axis, counts) in &options.counts_per_unit {
        axes.entry(*axis).or_default().counts_per_unit = Some(*counts);
    }
    EmitOptions {
        source: name.to_owned(),
        settings,
        pmac: options.pmac.clone(),
        axes,
    }
}

/// `program` with every piece longer than the format takes cut along its own cubic (the
/// same motion; see [`split_grid`] for the times).
pub fn fit_pieces(mut program: PvtProgram, options: &CompileOptions) -> PvtProgram {
    if let (Some(max), Interpolation::Pvt) =
        (options.format.max_piece_seconds(), program.interpolation)
    {
        for contour in &mut program.contours {
            *contour = split_long_pieces(contour, max, split_grid(options));
        }
    }
    program
}

/// The grid a long piece's time is cut on when the time is on it: `--quantize`, else the
/// time the format's controller rounds to (PMAC: whole ms), so whole times stay whole.
pub fn split_grid(options: &CompileOptions) -> Option<f64> {
    options
        .quantize
        .or_else(|| options.format.piece_time_quantum())
}

/// A back end's refusal as a failure; `source` (when known) labels the line at fault.
pub(crate) fn emit_failure(
    e: StreamError,
    options: &CompileOptions,
    source: Option<&Source>,
) -> Failure {
    match e {
        StreamError::Invalid(invalid) => {
            let report = match source {
                Some(source) => at_line(
                    invalid.code,
                    &invalid.to_string(),
                    invalid.line,
                    source,
                )
                .with_source_code(source.named_text()),
                None => miette::miette!(code = invalid.code, "{invalid}"),
            };
            Failure::Input(vec![report])
        }
        StreamError::Io(error) => Failure::Io {
            path: PathBuf::from("<output>"),
            action: "write",
            error,
        },
        StreamError::MissingScale(..) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::no_scale",
            help = "give --counts-per-unit AXIS=N for each moved axis, or counts_per_unit in the machine file's [axes.AXIS]",
            "{e}"
        )]),
        StreamError::Unsupported(interpolation) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::unsupported_interpolation",
            help =
                "PMAC PVT mode needs velocities: choose a PVT planner, or --format movepvt (MovePT arrays) or json",
            "the {} format cannot express {interpolation:?} motion",
            options.format.name()
        )]),
    }
}

/// Seed 003: PMAC rounds piece times to whole milliseconds without telling anyone.
fn fractional_ms_warning(program: &PvtProgram) -> Option<Report> {
    let totals = totals_of(program);
    fractional_ms_report(totals.fractional_ms, totals.segments)
}

/// The warning for `fractional` of `segments` piece times that are not whole ms.
pub(crate) fn fractional_ms_report(fractional: usize, segments: usize) -> Option<Report> {
    (fractional > 0).then(|| {
        miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::emit::fractional_ms",
            help = "pass --quantize 1ms to make every piece time whole while keeping the path",
            "{fractional} of {segments} piece times are not whole milliseconds; PMAC rounds TA to whole ms, which changes speeds and times"
        )
    })
}

/// Notes on what planning changed (quantization, lengthened blends, ignored velocities).
pub(crate) fn plan_notes(report: &PlanReport, options: &CompileOptions) -> Vec<Report> {
    let mut notes = Vec::new();
    if let Some(q) = options.quantize {
        notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::quantized",
            "piece times made whole multiples of {} ms (rounded {}); largest change of mid-segment speed: {:.4} %",
            q * 1000.0,
            rounding_words(options.quantize_rounding),
            report.quantize_speed_change * 100.0
        ));
    }
    if report.lengthened_segments > 0 {
        notes.push(miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::plan::lengthened",
            "{} segments were too short for their blends at --accel; their times were raised",
            report.lengthened_segments
        ));
    }
    if report.velocities_ignored {
        notes.push(miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::plan::velocities_ignored",
            help = "--velocities plan ignores the velocity columns without a warning",
            "the input gives velocities, which the {} planner does not use",
            options.planner.name()
        ));
    }
    notes
}

/// The tolerance of a program in `units`: `--tolerance`, or pvt-core's default converted.
/// The one place it is resolved: planning and the header both read it.
pub(crate) fn resolved_tolerance(options: &CompileOptions, units: Units) -> f64 {
    options
        .tolerance
        .unwrap_or_else(|| units.from_mm(pvt_core::defaults::TOLERANCE_MM))
}

/// The rapid rate of a program in `units`, per minute: `--rapid`, or pvt-core's default
/// converted (as the G-code and DXF front ends resolve a rapid they are not given).
pub(crate) fn resolved_rapid(options: &CompileOptions, units: Units) -> f64 {
    options
        .rapid
        .unwrap_or_else(|| units.from_mm(DEFAULT_RAPID_MM_PER_MIN))
}

/// The settings every output header names, in a fixed order (a CSV series' header leaves
/// out what it does not use: rapid, default feed and, but for `path`, the tolerance).
pub(crate) fn settings(options: &CompileOptions, units: Units) -> Vec<(String, String)> {
    let u = units.name();
    let tolerance = match options.tolerance {
        Some(t) => t,
        None => significant(resolved_tolerance(options, units)),
    };
    let rapid = match options.rapid {
        Some(r) => format!("{r} {u}/min"),
        None if units == Units::Millimetre => {
            format!("{} {u}/min (default)", resolved_rapid(options, units))
        }
        None => format!(
            "{} {u}/min (default {DEFAULT_RAPID_MM_PER_MIN} mm/min)",
            significant(resolved_rapid(options, units))
        ),
    };
    let feed = match options.feed {
        Some(f) => format!("{f} {u}/min"),
        None => "none (every feed move needs an F word)".into(),
    };
    let tolerance_name = match options.planner {
        Planner::Path => "path tolerance",
        _ => "chord tolerance",
    };
    let mut out = vec![(
        "planner".into(),
        planner_description(options.planner).into(),
    )];
    // A series has no rapid moves, no feed and no arcs: only `path` reads a tolerance.
    let series = options.input == InputKind::Csv;
    if !series || options.planner == Planner::Path {
        out.push((tolerance_name.into(), format!("{tolerance} {u}")));
    }
    if !series {
        out.push(("rapid".into(), rapid));
        out.push(("default feed".into(), feed));
    }
    if let Timing::TimeSlice(t) = options.timing {
        out.push(("time slice".into(), format!("{t} s")));
    }
    if let Some(a) = options.accel {
        out.push(("acceleration".into(), format!("{a} {u}/s^2")));
    }
    if let Some(q) = options.quantize {
        out.push((
            "piece times quantized to".into(),
            format!(
                "{q} s, rounded {}",
                rounding_words(options.quantize_rounding)
            ),
        ));
    }
    if let Some(m) = &options.machine {
        out.push(("machine".into(), m.name.clone()));
    }
    out
}

/// Significant digits of a default converted into other units, as a header prints it.
const HEADER_DIGITS: usize = 6;

/// `x` rounded to [`HEADER_DIGITS`] significant digits, for the header text only (a
/// converted default such as 5000 mm/min reads `196.85 in/min`, not
/// `196.8503937007874`); planning uses the unrounded value.
fn significant(x: f64) -> f64 {
    format!("{x:.*e}", HEADER_DIGITS - 1).parse().unwrap_or(x)
}

/// How a rounding reads after "rounded": `up`, `to nearest`.
fn rounding_words(rounding: Rounding) -> &'static str {
    match rounding {
        Rounding::Up => "up",
        Rounding::Nearest => "to nearest",
    }
}

fn planner_description(planner: Planner) -> &'static str {
    match planner {
        Planner::Contour => {
            "contour (bisector velocities at the feed, mid-segment speed = mean of end speeds)"
        }
        Planner::Path => {
            "path (within the path tolerance of the true elements and the axis limits)"
        }
        Planner::Pt => "pt (position-time: constant velocity between points, AN208's PT)",
        Planner::Chord => {
            "chord-forward (velocity at a point = outgoing chord / its time, rest at both ends)"
        }
        Planner::ChordBack => {
            "chord-back (velocity at a point = incoming chord / its time, AN208; rest at both ends)"
        }
        Planner::ConstAccel => {
            "const-accel (each piece at constant acceleration from the previous velocity, AN208)"
        }
        Planner::Spline => "spline (C2 cubic spline through the points, rest at both ends)",
        Planner::Lspb => "lspb (linear segments with parabolic blends at --accel)",
    }
}
