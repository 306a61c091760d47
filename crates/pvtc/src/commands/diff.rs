//! `pvtc diff`: two programs compared as motion.
//!
//! Owns loading each side (an emitted program read back by pvt-emit's readers, a pvtc
//! JSON program, a CSV table, or a source compiled to the other side's format and read
//! back, each piece with the line of the file named: a source's line, the emitted text's
//! line), the tolerances, and rendering pvt-core's [`Comparison`] as a summary or as JSON
//! on standard output, as diagnostics (`pvtc::diff::…`) on standard error and, with
//! `-o`, as the interactive HTML view. It must not compare: pvt-core's `compare` does.

use crate::args::DiffArgs;
use crate::options::{CompileOptions, Failure, Source};
use crate::report::{Reporter, EXIT_INPUT_ERROR};
use crate::settings::DiffTolerances;
use pvt_core::compare::{compare, CompareOptions, Comparison, Difference};
use pvt_core::{PvtProgram, Quantity};
use pvt_emit::readback::ReadProgram;
use pvt_emit::Format;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

/// Bins of the difference's profile the HTML view draws.
const PROFILE_BINS: usize = 4096;

/// One program to compare, as read.
pub struct Loaded {
    /// The name given.
    pub name: String,
    /// The format it was read in, and whether it was compiled from a source first.
    pub format: Format,
    /// Whether it is a source compiled for the comparison.
    pub compiled: bool,
    /// The program, its events and triggers; each piece's line is a line of `text`.
    pub read: ReadProgram,
    /// The text of the file named, whose lines the pieces name.
    pub text: String,
    /// The options it was read (or compiled) with.
    pub options: CompileOptions,
}

/// How a file is read: as a format pvtc writes, or as a source to compile.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Emitted(Format),
    Source,
}

/// Runs `pvtc diff`.
pub fn run(args: &DiffArgs) -> ExitCode {
    let reporter = Reporter::new(&args.pipeline);
    if let Some(path) = args
        .output
        .as_deref()
        .filter(|p| !crate::commands::view::is_html(p))
    {
        return reporter.fail(&Failure::Usage(format!(
            "diff writes an HTML page: name the output FILE.html, not {}",
            path.display()
        )));
    }
    let sides = match load_both(args, &reporter) {
        Ok(sides) => sides,
        Err(code) => return code,
    };
    let [a, b] = &sides;
    let tolerances = crate::settings::diff_tolerances(
        (
            args.position_tolerance,
            args.time_tolerance,
            args.peak_tolerance,
        ),
        a.read.program.units,
    );
    let options = match compare_options(&tolerances, a, args.output.is_some()) {
        Ok(options) => options,
        Err(failure) => return reporter.fail(&failure),
    };
    let comparison = compare(a.read.side(), b.read.side(), &options);
    if let Some(path) = &args.output {
        if let Err(failure) = page(path, [a, b], &comparison, tolerances.position) {
            return reporter.fail(&failure);
        }
    }
    let text = if args.json {
        serde_json::to_string_pretty(&to_json(&comparison, [a, b], &tolerances)).expect("JSON")
            + "\n"
    } else {
        summary(&comparison, [a, b], &tolerances)
    };
    let written = crate::output::write_stdout_status(text.as_bytes(), &reporter);
    if written != ExitCode::SUCCESS {
        return written;
    }
    for d in &comparison.differences {
        reporter.error(&diagnostic(d, &comparison, [a, b], &tolerances));
    }
    if comparison.equal() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_INPUT_ERROR)
    }
}

/// Writes the HTML page of the comparison, with the first side's machine limits.
fn page(path: &Path, sides: [&Loaded; 2], c: &Comparison, tolerance: f64) -> Result<(), Failure> {
    let first = &sides[0].read.program;
    let limits = crate::settings::machine_limits(
        sides[0].options.machine.as_ref(),
        first.units,
        &first.axes,
    )?;
    let motions = sides.map(|s| pvt_emit::view::Motion {
        name: &s.name,
        program: &s.read.program,
        text: &s.text,
    });
    crate::commands::view::write_diff(path, motions, limits, c, tolerance)
}

/// Reads both sides: emitted ones as they are, then each source compiled to the other
/// side's format (`--format`, else JSON when both are sources).
fn load_both(args: &DiffArgs, reporter: &Reporter) -> Result<[Loaded; 2], ExitCode> {
    let fail = |f: Failure| reporter.fail(&f);
    let sources = [
        Source::read(&args.first).map_err(fail)?,
        Source::read(&args.second).map_err(fail)?,
    ];
    let kinds = sources.each_ref().map(|s| kind_of(s, args));
    let chosen = |other: Kind| match (args.format, other) {
        (Some(f), _) => Format::from(f),
        (None, Kind::Emitted(f)) => f,
        (None, Kind::Source) => Format::Json,
    };
    let [first, second] = sources;
    let a = load(first, kinds[0], chosen(kinds[1]), args, reporter)?;
    let b = load(second, kinds[1], chosen(kinds[0]), args, reporter)?;
    Ok([a, b])
}

/// How `source` is read: `--input-format` makes it a source; else the extension (the
/// formats `check` reads back, `.json`, and a `.csv` holding a `--format csv` table).
fn kind_of(source: &Source, args: &DiffArgs) -> Kind {
    if args.pipeline.input_format.is_some() {
        return Kind::Source;
    }
    let name = source.name.to_ascii_lowercase();
    if let Some(format) = pvt_emit::readback::format_of(&name) {
        return Kind::Emitted(format);
    }
    if name.ends_with(".json") {
        return Kind::Emitted(Format::Json);
    }
    let table = name.ends_with(".csv")
        && pvt_emit::readback::is_table(&String::from_utf8_lossy(&source.bytes));
    if table {
        Kind::Emitted(Format::Csv)
    } else {
        Kind::Source
    }
}

/// Loads one side: read back, or compiled to `format` and read back.
fn load(
    source: Source,
    kind: Kind,
    format: Format,
    args: &DiffArgs,
    reporter: &Reporter,
) -> Result<Loaded, ExitCode> {
    let fail = |f: Failure| reporter.fail(&f);
    let (format, compiled) = match kind {
        Kind::Emitted(f) => (f, false),
        Kind::Source => (format, true),
    };
    let options = if compiled {
        args.pipeline.compile_options(&source.name, format)
    } else {
        args.pipeline
            .asked()
            .map(|asked| crate::settings::compile_options(&asked, &source.name, format))
    }
    .map_err(fail)?;
    let text = String::from_utf8_lossy(&source.bytes).into_owned();
    let read = if compiled {
        let built = crate::route::compile(&source, &options).map_err(fail)?;
        reporter.warnings(&built.warnings)?;
        let emitted = String::from_utf8_lossy(&built.bytes).into_owned();
        let mut read = read_emitted(format, &emitted, &options, &source.name).map_err(fail)?;
        source_lines(&mut read.program, &built.program);
        read
    } else {
        read_emitted(format, &text, &options, &source.name).map_err(fail)?
    };
    Ok(Loaded {
        name: source.name,
        format,
        compiled,
        read,
        text,
        options,
    })
}

/// Reads a text of `format`: each piece with its line in the text (a JSON program's
/// segment lines, one segment a line as pvtc writes them).
fn read_emitted(
    format: Format,
    text: &str,
    options: &CompileOptions,
    name: &str,
) -> Result<ReadProgram, Failure> {
    if format == Format::Json {
        let (mut program, triggers) = pvt_emit::json::read_with_triggers(text).map_err(|e| {
            Failure::Input(vec![miette::miette!(
                code = "pvtc::json::read",
                "{name}: {e}"
            )])
        })?;
        json_lines(&mut program, text);
        return Ok(ReadProgram {
            program,
            carries_events: true,
            triggers: Some(triggers),
        });
    }
    let hint = crate::commands::verify::read_hint(options);
    pvt_emit::readback::read_program(format, text, &hint).map_err(|e| {
        Failure::Input(vec![miette::miette!(
            code = pvt_emit::readback::ReadBackError::CODE,
            "{name}: {e} (read as {} output)",
            format.name()
        )])
    })
}

/// Gives each segment of a JSON program the line of the text it is written on, where
/// the text has one segment a line (as pvtc writes it); else keeps the source lines.
pub fn json_lines(program: &mut PvtProgram, text: &str) {
    let lines: Vec<u32> = pvt_core::text::numbered_lines(text)
        .filter(|(_, l)| l.trim_start().starts_with("{\"p\": "))
        .map(|(n, _)| n as u32)
        .collect();
    if lines.len() != program.segment_count() {
        return;
    }
    let mut each = lines.into_iter();
    for c in &mut program.contours {
        for line in &mut c.lines {
            *line = each.next().unwrap_or(*line);
        }
    }
}

/// Each span of a program in time (pieces, and dwells as spans of their own): its end
/// and its line.
fn spans(program: &PvtProgram) -> Vec<(f64, u32)> {
    let mut out = Vec::with_capacity(program.segment_count());
    let mut clock = 0.0;
    let mut events = program.events.iter().peekable();
    for c in 0..=program.contours.len() {
        while let Some(e) = events.next_if(|e| e.before_contour <= c) {
            if let pvt_core::EventKind::Dwell { seconds } = e.kind {
                clock += seconds;
                out.push((clock, e.line));
            }
        }
        for (t, line) in program
            .contours
            .get(c)
            .into_iter()
            .flat_map(|k| k.durations.iter().zip(&k.lines))
        {
            clock += t;
            out.push((clock, *line));
        }
    }
    out
}

/// Gives the pieces read back from a compiled source the lines of the source: piece
/// by piece where the counts agree, else the line of the compiled piece running at
/// each read piece's middle (a dwell written as a piece at rest takes its G4's line).
fn source_lines(read: &mut PvtProgram, compiled: &PvtProgram) {
    if read.segment_count() == compiled.segment_count() {
        let mut each = compiled.contours.iter().flat_map(|c| c.lines.iter());
        for c in &mut read.contours {
            for line in &mut c.lines {
                *line = each.next().copied().unwrap_or(*line);
            }
        }
        return;
    }
    let target = spans(compiled);
    let line_at = |t: f64| {
        let i = target.partition_point(|(end, _)| *end <= t);
        target.get(i).or(target.last()).map_or(0, |s| s.1)
    };
    let mut clock = 0.0;
    for c in &mut read.contours {
        for (t, line) in c.durations.iter().zip(c.lines.iter_mut()) {
            *line = line_at(clock + t / 2.0);
            clock += t;
        }
    }
}

/// The comparison's options: the tolerances, in counts at `--counts-per-unit` when the
/// position tolerance is, and the profile when the HTML view is asked for.
fn compare_options(
    tolerances: &DiffTolerances,
    first: &Loaded,
    profile: bool,
) -> Result<CompareOptions, Failure> {
    let mut counts_per_unit = std::collections::BTreeMap::new();
    if tolerances.in_counts {
        let hint = crate::commands::verify::read_hint(&first.options);
        for axis in &first.read.program.axes {
            let Some(n) = hint.counts_per_unit.get(axis) else {
                return Err(Failure::Usage(format!(
                    "--tolerance in counts needs the counts per unit of axis {axis}: give \
                     --counts-per-unit {axis}=N (or counts_per_unit in the machine file)"
                )));
            };
            counts_per_unit.insert(*axis, *n);
        }
    }
    Ok(CompareOptions {
        tolerance: tolerances.position,
        time_tolerance: tolerances.time,
        peak_tolerance: tolerances.peak,
        servo_period: crate::settings::servo_period(first.options.machine.as_ref()),
        counts_per_unit,
        profile_bins: if profile { PROFILE_BINS } else { 0 },
    })
}

/// Seconds as milliseconds with at most six decimals, no trailing zeros.
fn millis(seconds: f64) -> String {
    let text = format!("{:.6}", seconds * 1000.0);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0" } else { text }.to_string()
}

/// A tolerance for people: six significant digits, no trailing zeros.
fn decimal(x: f64) -> String {
    let mut decimals = 5usize;
    let mut scaled = x.abs();
    while scaled > 0.0 && scaled < 1.0 && decimals < 15 {
        scaled *= 10.0;
        decimals += 1;
    }
    let text = format!("{x:.decimals$}");
    match text.contains('.') {
        true => text.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => text,
    }
}

/// What a side is, for people: `a.pmac (pmac)`, `a.ngc (compiled to pmac)`.
fn label(side: &Loaded) -> String {
    let how = if side.compiled { "compiled to " } else { "" };
    format!("{} ({how}{})", side.name, side.format.name())
}

/// The unit of compared positions.
fn unit(c: &Comparison) -> &'static str {
    if c.in_counts {
        "counts"
    } else {
        c.units.name()
    }
}

/// Where a spot is: `t=1.2345 s (A line 3, B line 7)`.
fn place(time: f64, lines: [u32; 2], sides: [&Loaded; 2]) -> String {
    format!(
        "t={time:.4} s ({} line {}, {} line {})",
        sides[0].name, lines[0], sides[1].name, lines[1]
    )
}

/// The summary for people.
fn summary(c: &Comparison, sides: [&Loaded; 2], tol: &DiffTolerances) -> String {
    let mut t = String::new();
    let u = unit(c);
    for (k, (side, letter)) in sides.iter().zip(["A", "B"]).enumerate() {
        let _ = writeln!(
            t,
            "{letter}: {}: {} pieces, {:.6} s",
            label(side),
            c.pieces[k],
            c.total_time[k]
        );
    }
    let _ = writeln!(
        t,
        "at the same instant: largest difference {:.9} {u} at {}",
        c.aligned.value,
        place(c.aligned.time, c.aligned.lines, sides)
    );
    match &c.first_divergence {
        Some(f) => {
            let _ = writeln!(
                t,
                "first beyond {} {u} at {}",
                decimal(tol.position),
                place(f.time, f.lines, sides)
            );
        }
        None => {
            let _ = writeln!(t, "never beyond {} {u}", decimal(tol.position));
        }
    }
    let _ = writeln!(
        t,
        "along the path: largest distance {:.9} {u}, largest time shift {} ms",
        c.path.value,
        millis(c.time_shift.value)
    );
    let _ = writeln!(
        t,
        "total time: B - A = {} ms",
        millis(c.total_time[1] - c.total_time[0])
    );
    peak_table(&mut t, c);
    let listed = |what: &str, l: &Option<pvt_core::compare::Listed>| match l {
        Some(l) => format!("{what}: {} and {}", l.counts[0], l.counts[1]),
        None => format!("{what}: not compared (a format without them)"),
    };
    let _ = writeln!(t, "{}", listed("events", &c.events));
    let _ = writeln!(t, "{}", listed("triggers", &c.triggers));
    let tolerances = format!(
        "{} {u}, {} ms and {} %",
        decimal(tol.position),
        millis(tol.time),
        decimal(tol.peak * 100.0)
    );
    if c.equal() {
        let _ = writeln!(t, "equal within {tolerances}");
    } else {
        let names: Vec<&str> = c.differences.iter().map(Difference::code_name).collect();
        let _ = writeln!(t, "DIFFERENT beyond {tolerances}: {}", names.join(", "));
    }
    t
}

fn quantity_symbol(q: Quantity) -> &'static str {
    match q {
        Quantity::Velocity => "|v|",
        Quantity::Acceleration => "|a|",
        _ => "|j|",
    }
}

/// Each axis' peaks in A and B.
fn peak_table(t: &mut String, c: &Comparison) {
    let _ = write!(t, "{:<4}", "axis");
    for (q, _) in c.peaks.first().map_or(&[][..], |p| &p.peaks[..]) {
        let s = quantity_symbol(*q);
        let _ = write!(t, " {:>16} {:>16}", format!("{s} A"), format!("{s} B"));
    }
    let _ = writeln!(t);
    for a in &c.peaks {
        let _ = write!(t, "{:<4}", a.axis.to_string());
        for (_, [x, y]) in &a.peaks {
            let _ = write!(t, " {:>16.6} {:>16.6}", x.value, y.value);
        }
        let _ = writeln!(t);
    }
}

/// The diagnostic of one difference.
fn diagnostic(
    d: &Difference,
    c: &Comparison,
    sides: [&Loaded; 2],
    tol: &DiffTolerances,
) -> miette::Report {
    let code = format!("pvtc::diff::{}", d.code_name());
    let u = unit(c);
    let first = c.first_divergence.map_or(String::new(), |f| {
        format!("; they first diverge at {}", place(f.time, f.lines, sides))
    });
    let [a, b] = sides.map(|s| s.name.as_str());
    let text = match d {
        Difference::Position(s) => format!(
            "the motions are {:.9} {u} apart at {}, more than --tolerance {} {u}{first}",
            s.value,
            place(s.time, s.lines, sides),
            decimal(tol.position)
        ),
        Difference::TimeShift(s) => format!(
            "{b} passes {a}'s place at {} {} ms {}, more than --time-tolerance {} ms{first}",
            place(s.time, s.lines, sides),
            millis(s.value.abs()),
            if s.value > 0.0 { "later" } else { "earlier" },
            millis(tol.time)
        ),
        Difference::TotalTime(dt) => format!(
            "the total times differ by {} ms ({:.6} s and {:.6} s), more than --time-tolerance {} ms",
            millis(*dt),
            c.total_time[0],
            c.total_time[1],
            millis(tol.time)
        ),
        Difference::Peak {
            axis,
            quantity,
            peaks,
        } => format!(
            "axis {axis} {} peak {:.6} ({a} line {} at t={:.4} s) and {:.6} ({b} line {} at t={:.4} s) differ by more than --peak-tolerance {} %",
            quantity.name(),
            peaks[0].value,
            peaks[0].line,
            peaks[0].time,
            peaks[1].value,
            peaks[1].line,
            peaks[1].time,
            decimal(tol.peak * 100.0)
        ),
        Difference::Events(m) | Difference::Triggers(m) => {
            let what = |k: usize| m.names[k].clone().unwrap_or_else(|| "nothing".into());
            format!(
                "{} {}: {a} has {} at line {} (t={:.4} s), {b} has {} at line {} (t={:.4} s)",
                if matches!(d, Difference::Events(_)) { "event" } else { "trigger" },
                m.index + 1,
                what(0),
                m.lines[0],
                m.times[0],
                what(1),
                m.lines[1],
                m.times[1]
            )
        }
    };
    miette::miette!(code = code, "{text}")
}

fn spot_json(s: &pvt_core::compare::Spot) -> serde_json::Value {
    serde_json::json!({"value": s.value, "time": s.time, "lines": s.lines})
}

/// The comparison as one JSON object (see the README for the fields).
fn to_json(c: &Comparison, sides: [&Loaded; 2], tol: &DiffTolerances) -> serde_json::Value {
    let side = |k: usize| {
        let s = sides[k];
        serde_json::json!({
            "name": s.name, "format": s.format.name(), "compiled": s.compiled,
            "pieces": c.pieces[k], "total_time": c.total_time[k],
        })
    };
    let peaks: serde_json::Map<String, serde_json::Value> = c
        .peaks
        .iter()
        .map(|a| {
            let each: serde_json::Map<String, serde_json::Value> = a
                .peaks
                .iter()
                .map(|(q, [x, y])| (q.name().to_string(), serde_json::json!([x.value, y.value])))
                .collect();
            (a.axis.to_string(), serde_json::Value::Object(each))
        })
        .collect();
    let listed = |l: &Option<pvt_core::compare::Listed>| {
        l.as_ref()
            .map(|l| serde_json::json!({"counts": l.counts, "equal": l.mismatch.is_none()}))
    };
    let differences: Vec<serde_json::Value> = c
        .differences
        .iter()
        .map(|d| {
            serde_json::json!({
                "code": format!("pvtc::diff::{}", d.code_name()),
                "message": diagnostic(d, c, sides, tol).to_string(),
            })
        })
        .collect();
    serde_json::json!({
        "a": side(0),
        "b": side(1),
        "units": unit(c),
        "tolerance": tol.position,
        "time_tolerance": tol.time,
        "peak_tolerance": tol.peak,
        "aligned": spot_json(&c.aligned),
        "first_divergence": c.first_divergence.as_ref().map(spot_json),
        "path": spot_json(&c.path),
        "time_shift": spot_json(&c.time_shift),
        "peaks": peaks,
        "events": listed(&c.events),
        "triggers": listed(&c.triggers),
        "equal": c.equal(),
        "differences": differences,
    })
}
