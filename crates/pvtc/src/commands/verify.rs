//! `pvtc check`: compiles (or reads) a program and prints what its motion will do.
//!
//! Owns loading the program to check (a source through the pipeline, a pvtc JSON
//! program, or an emitted controller program read back by `pvt_emit::readback`, chosen
//! by extension: `.pmac`, `.pmc`, `.c`, `.trj`, `.dmc`, `.zaber`) and rendering pvt-core's [`CheckReport`] as a table or as JSON. It must not
//! compute any of the numbers.

use crate::args::CheckArgs;
use crate::options::{CompileOptions, Failure, Source};
use crate::report::Reporter;
use crate::report::EXIT_INPUT_ERROR;
use crate::route::plan;
use pvt_core::{check_program, CheckReport, Peak, PvtProgram, Toolpath};
use pvt_emit::Format;
use std::fmt::Write as _;
use std::process::ExitCode;

/// Runs `pvtc check`.
pub fn run(args: &CheckArgs) -> ExitCode {
    let reporter = Reporter::new(&args.pipeline);
    let Loaded {
        program,
        toolpath,
        options,
    } = match load(&args.input, &args.pipeline, &reporter) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let given = Given {
        limits: args.limits(),
        servo_period: args.servo_period,
        max_samples: args.max_samples,
    };
    let report = match checked(&program, toolpath.as_ref(), &options, &given) {
        Ok(report) => report,
        Err(failure) => return reporter.fail(&failure),
    };
    let units = program.units.name();
    let too_far = args
        .max_path_error
        .zip(report.max_path_error())
        .filter(|(allowed, error)| error > allowed);
    let text = if args.json {
        serde_json::to_string_pretty(&to_json(&report)).expect("JSON") + "\n"
    } else {
        table(&report, units, too_far)
    };
    // A reader that closed the pipe (`| head`) is not a failure of the check.
    let written = crate::output::write_stdout_status(text.as_bytes(), &reporter);
    if written != ExitCode::SUCCESS {
        return written;
    }
    if let Some((allowed, error)) = too_far {
        reporter.error(&miette::miette!(
            code = "pvtc::check::path_error",
            "the motion is {error:.6} {units} from the programmed geometry, more than \
             --max-path-error {allowed}"
        ));
    }
    if report.exceeded() || too_far.is_some() {
        ExitCode::from(EXIT_INPUT_ERROR)
    } else {
        ExitCode::SUCCESS
    }
}

/// What `check` is given besides the program: limits, servo period and sample guard.
#[derive(Debug, Clone, Default)]
pub struct Given {
    /// Limits per axis over the machine file's (`--max-vel`, `--max-accel`, `--max-jerk`).
    pub limits: std::collections::BTreeMap<pvt_core::Axis, pvt_core::AxisLimits>,
    /// `--servo-period`.
    pub servo_period: Option<f64>,
    /// `--max-samples`.
    pub max_samples: u64,
}

/// The check of `program` against the limits and servo period `given` over the machine
/// file of `options` (resolved by [`crate::settings`]), its path error measured from
/// `toolpath` where there is one: what `pvtc check` prints, as data.
pub fn checked(
    program: &PvtProgram,
    toolpath: Option<&Toolpath>,
    options: &CompileOptions,
    given: &Given,
) -> Result<CheckReport, Failure> {
    let check = crate::settings::check_options(
        options.machine.as_ref(),
        program,
        given.limits.clone(),
        given.servo_period,
    )?;
    within_samples(program, check.servo_period, given.max_samples)?;
    Ok(check_program(program, toolpath, &check))
}

/// Refuses a program whose motion lasts more than `--max-samples` servo periods: a guard on
/// time, not memory (sampling streams over the pieces in constant memory, but a JSON
/// program may carry any time, and sampling 10^300 s would never end).
fn within_samples(program: &PvtProgram, period: f64, max_samples: u64) -> Result<(), Failure> {
    let total: f64 = program
        .contours
        .iter()
        .flat_map(|c| c.durations.iter())
        .sum();
    let samples = total / period;
    if samples <= max_samples as f64 {
        return Ok(());
    }
    Err(Failure::Input(vec![miette::miette!(
        code = "pvtc::check::too_many_samples",
        help = "pass a longer --servo-period, or raise --max-samples",
        "the motion lasts {total:.4e} s: {samples:.4e} servo samples at {period} s, over the limit of {max_samples}",
    )]))
}

/// A program to check or plot, with what it was planned from.
pub struct Loaded {
    /// The program.
    pub program: PvtProgram,
    /// The geometry it was planned from (none for a JSON program).
    pub toolpath: Option<Toolpath>,
    /// The resolved options (planner, machine).
    pub options: CompileOptions,
}

/// Loads the program named by `input`: a pvtc JSON program, or a source compiled with
/// the pipeline arguments (whose toolpath then serves as the true geometry).
pub fn load(
    input: &std::path::Path,
    pipeline: &crate::args::PipelineArgs,
    reporter: &Reporter,
) -> Result<Loaded, ExitCode> {
    let (loaded, warnings) = load_quietly(input, pipeline).map_err(|f| reporter.fail(&f))?;
    reporter.warnings(&warnings)?;
    Ok(loaded)
}

/// [`load`] without printing: the program, and the warnings and notes met planning it.
pub fn load_quietly(
    input: &std::path::Path,
    pipeline: &crate::args::PipelineArgs,
) -> Result<(Loaded, Vec<miette::Report>), Failure> {
    load_source(&Source::read(input)?, pipeline)
}

/// [`load_quietly`] of a source already read (a program that embeds pvtc holds its
/// text): a program file by its name's extension, else a source planned.
pub fn load_source(
    source: &Source,
    pipeline: &crate::args::PipelineArgs,
) -> Result<(Loaded, Vec<miette::Report>), Failure> {
    let options = pipeline.compile_options(&source.name, Format::Json)?;
    let emitted = pvt_emit::readback::format_of(&source.name);
    if let (None, Some(format)) = (pipeline.input_format, emitted) {
        let text = String::from_utf8_lossy(&source.bytes);
        return match pvt_emit::readback::read_back(format, &text, &read_hint(&options)) {
            Ok(program) => Ok(without_geometry(program, options)),
            Err(e) => Err(Failure::Input(vec![miette::miette!(
                code = pvt_emit::readback::ReadBackError::CODE,
                "{}: {e} (read as {} output)",
                source.name,
                format.name()
            )])),
        };
    }
    if pipeline.input_format.is_none() && source.name.to_ascii_lowercase().ends_with(".json") {
        let text = String::from_utf8_lossy(&source.bytes);
        return match pvt_emit::json::read(&text) {
            Ok(program) => Ok(without_geometry(program, options)),
            Err(e) => Err(Failure::Input(vec![miette::miette!(
                code = "pvtc::json::read",
                "{}: {e}",
                source.name
            )])),
        };
    }
    let (planned, toolpath, warnings) = plan(source, &options)?;
    let loaded = Loaded {
        program: planned.program,
        toolpath: Some(toolpath),
        options,
    };
    Ok((loaded, warnings))
}

/// A program read from a file, with no geometry and no warnings.
fn without_geometry(program: PvtProgram, options: CompileOptions) -> (Loaded, Vec<miette::Report>) {
    let loaded = Loaded {
        program,
        toolpath: None,
        options,
    };
    (loaded, Vec::new())
}

/// What an emitted text does not say: `--units` (default mm) and counts per unit, from
/// `--counts-per-unit` over the machine file's.
pub fn read_hint(options: &CompileOptions) -> pvt_emit::readback::ReadHint {
    let units = crate::settings::readback_units(options);
    let mut counts: std::collections::BTreeMap<_, _> = options
        .machine
        .as_ref()
        .map(|m| m.setup_in(units))
        .unwrap_or_default()
        .into_iter()
        .filter_map(|(a, s)| s.counts_per_unit.map(|c| (a, c)))
        .collect();
    counts.extend(options.counts_per_unit.iter().copied());
    pvt_emit::readback::ReadHint {
        units,
        counts_per_unit: counts,
    }
}

fn peak_json(p: &Peak) -> serde_json::Value {
    serde_json::json!({"value": p.value, "time": p.time, "line": p.line})
}

/// The report as one JSON object (see the README for the fields).
pub fn to_json(report: &CheckReport) -> serde_json::Value {
    let mut peaks = serde_json::Map::new();
    for a in &report.axes {
        peaks.insert(
            a.axis.to_string(),
            serde_json::json!({
                "velocity": a.velocity.value,
                "acceleration": a.acceleration.value,
                "jerk": a.jerk.value,
                "acceleration_step": a.acceleration_step.value,
                "sampled_velocity": a.sampled_velocity.value,
                "sampled_acceleration": a.sampled_acceleration.value,
                "at": {
                    "velocity": peak_json(&a.velocity),
                    "acceleration": peak_json(&a.acceleration),
                    "jerk": peak_json(&a.jerk),
                    "acceleration_step": peak_json(&a.acceleration_step),
                    "sampled_velocity": peak_json(&a.sampled_velocity),
                    "sampled_acceleration": peak_json(&a.sampled_acceleration),
                },
            }),
        );
    }
    let speed = report.speed.map(|s| {
        serde_json::json!({"min": peak_json(&s.min), "max": peak_json(&s.max), "rms_error": s.rms_error, "samples": s.samples})
    });
    let violations: Vec<serde_json::Value> = report
        .violations
        .iter()
        .map(|v| {
            serde_json::json!({
                "axis": v.axis.to_string(), "quantity": v.quantity.name(), "value": v.value,
                "limit": v.limit, "time": v.time, "line": v.line,
            })
        })
        .collect();
    serde_json::json!({
        "total_time": report.total_time,
        "servo_period": report.servo_period,
        "max_path_error": report.max_path_error(),
        "path_error": report.path_error.as_ref().map(peak_json),
        "peaks": peaks,
        "speed": speed,
        "violations": violations,
        "exceeded": report.exceeded(),
    })
}

/// A source line as the table prints it: `line N`, or `unknown line` for 0 (a binary DXF
/// file, a JSON program without lines).
struct Line(u32);

impl std::fmt::Display for Line {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            0 => f.write_str("unknown line"),
            n => write!(f, "line {n}"),
        }
    }
}

/// Seconds as milliseconds with at most six decimals and no trailing zeros: 50 µs is
/// `0.05`, not `0.049999999999999996`.
fn millis(seconds: f64) -> String {
    let text = format!("{:.6}", seconds * 1000.0);
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The report as a table for people.
/// `too_far`: the `--max-path-error` allowed and the larger distance found, when the
/// motion is farther than allowed.
pub fn table(report: &CheckReport, units: &str, too_far: Option<(f64, f64)>) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "total time: {:.6} s (servo period {} ms)",
        report.total_time,
        millis(report.servo_period)
    );
    let _ = writeln!(
        t,
        "\n{:<4} {:>14} {:>14} {:>16} {:>16} {:>14} {:>16}",
        "axis", "|v| peak", "|a| peak", "|j| peak", "|Δa|/P step", "sampled |v|", "sampled |a|"
    );
    let _ = writeln!(
        t,
        "{:<4} {:>14} {:>14} {:>16} {:>16} {:>14} {:>16}",
        "",
        format!("{units}/s"),
        format!("{units}/s²"),
        format!("{units}/s³"),
        format!("{units}/s³"),
        format!("{units}/s"),
        format!("{units}/s²")
    );
    for a in &report.axes {
        let _ = writeln!(
            t,
            "{:<4} {:>14.6} {:>14.6} {:>16.6} {:>16.6} {:>14.6} {:>16.6}",
            a.axis.to_string(),
            a.velocity.value,
            a.acceleration.value,
            a.jerk.value,
            a.acceleration_step.value,
            a.sampled_velocity.value,
            a.sampled_acceleration.value
        );
        let at = |p: &Peak| format!("t={:.4} s {}", p.time, Line(p.line));
        let _ = writeln!(
            t,
            "     at: |v| {}, |a| {}, |j| {}, |Δa|/P {}",
            at(&a.velocity),
            at(&a.acceleration),
            at(&a.jerk),
            at(&a.acceleration_step)
        );
    }
    if let Some(s) = &report.speed {
        let _ = writeln!(
            t,
            "\nvector speed: min {:.6} {units}/s ({}), max {:.6} {units}/s ({}), RMS error against feed {:.6} {units}/s over {} samples",
            s.min.value, Line(s.min.line), s.max.value, Line(s.max.line), s.rms_error, s.samples
        );
    }
    match &report.path_error {
        Some(p) => {
            let _ = writeln!(
                t,
                "largest distance from the source geometry: {:.9} {units} at t={:.4} s ({})",
                p.value,
                p.time,
                Line(p.line)
            );
        }
        None => {
            let _ = writeln!(
                t,
                "largest distance from the source geometry: not known (no source geometry)"
            );
        }
    }
    if let Some((allowed, error)) = too_far {
        let _ = writeln!(
            t,
            "PATH ERROR EXCEEDED: {error:.6} {units} > --max-path-error {allowed}"
        );
    }
    if report.violations.is_empty() {
        let _ = writeln!(t, "limits: none exceeded");
    }
    for v in &report.violations {
        let _ = writeln!(
            t,
            "LIMIT EXCEEDED: {} {} {:.6} > {:.6} at t={:.4} s ({})",
            v.axis,
            v.quantity.name(),
            v.value,
            v.limit,
            v.time,
            Line(v.line)
        );
    }
    t
}
