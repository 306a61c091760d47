//! Helpers shared by the integration tests: compact renderings of results and errors.
#![allow(dead_code)]

use std::fmt::Write;

use pvt_core::{ArcDirection, Axis, ElementKind, Plane, Position};
use pvt_gcode::{compile, line_col, Compiled, GcodeDiagnostic, GcodeOptions};

/// A number with up to six decimals, trailing zeros trimmed, `-0` shown as `0`.
pub fn num(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_owned()
    } else {
        s.to_owned()
    }
}

fn position(p: &Position, axes: &[Axis]) -> String {
    axes.iter()
        .map(|a| format!("{a}{}", num(p[a.index()])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `line:col code message` for one diagnostic (code without the `pvtc::gcode::` prefix).
pub fn diagnostic_line(source: &str, d: &GcodeDiagnostic) -> String {
    // Every diagnostic's own code must agree with miette's.
    let miette_code = miette::Diagnostic::code(d).map(|c| c.to_string());
    assert_eq!(miette_code.as_deref(), Some(d.code()));
    let (line, col) = line_col(source, d.span().start);
    let code = d.code().trim_start_matches("pvtc::gcode::");
    format!("{line}:{col} {code}: {d}")
}

/// A summary of a compiled program: units, contours, elements, end points, feeds, warnings.
pub fn render_compiled(source: &str, compiled: &Compiled) -> String {
    let toolpath = &compiled.toolpath;
    let axes = toolpath.moved_axes();
    let mut out = String::new();
    let names: Vec<_> = axes.iter().map(ToString::to_string).collect();
    writeln!(
        out,
        "units {}; axes {}",
        toolpath.units.name(),
        names.join(" ")
    )
    .unwrap();
    for (index, contour) in toolpath.contours.iter().enumerate() {
        render_events(&mut out, compiled, index);
        let start = &contour.elements[0].start;
        writeln!(
            out,
            "{} contour from {}",
            contour.motion.name(),
            position(start, &axes)
        )
        .unwrap();
        for e in &contour.elements {
            let what = match e.kind {
                ElementKind::Line => "line".to_owned(),
                ElementKind::Arc(arc) => {
                    let dir = match arc.direction {
                        ArcDirection::Clockwise => "cw",
                        ArcDirection::CounterClockwise => "ccw",
                    };
                    let plane = match arc.plane {
                        Plane::XY => "XY",
                        Plane::ZX => "ZX",
                        Plane::YZ => "YZ",
                    };
                    let sweep = arc.sweep(&e.start, &e.end).sweep.to_degrees();
                    format!(
                        "arc {dir} {plane} centre {} {} sweep {}°",
                        num(arc.center[0]),
                        num(arc.center[1]),
                        num(sweep)
                    )
                }
                ElementKind::Bezier(b) => format!(
                    "bezier controls {} {}, {} {}",
                    num(b.controls[0][0]),
                    num(b.controls[0][1]),
                    num(b.controls[1][0]),
                    num(b.controls[1][1])
                ),
            };
            writeln!(
                out,
                "  {}: {what} to {} at {}/s",
                e.span.line,
                position(&e.end, &axes),
                num(e.feed)
            )
            .unwrap();
        }
    }
    render_events(&mut out, compiled, toolpath.contours.len());
    if let Some(p) = compiled.path_tolerance {
        writeln!(out, "G64 P tolerance {}", num(p)).unwrap();
    }
    for w in &compiled.warnings {
        let kind = match miette::Diagnostic::severity(w) {
            Some(miette::Severity::Advice) => "note",
            _ => "warning",
        };
        writeln!(out, "{kind} {}", diagnostic_line(source, w)).unwrap();
    }
    out
}

/// The events before contour `index`, one line each.
fn render_events(out: &mut String, compiled: &Compiled, index: usize) {
    use pvt_core::EventKind;
    for event in compiled
        .toolpath
        .events
        .iter()
        .filter(|e| e.before_contour == index)
    {
        let detail = match &event.kind {
            EventKind::Dwell { seconds } => format!(" {}s", num(*seconds)),
            EventKind::SpindleSpeed { rpm } => format!(" {}", num(*rpm)),
            EventKind::ToolSelect { tool } => format!(" {tool}"),
            EventKind::Message { text } => format!(" {text:?}"),
            _ => String::new(),
        };
        writeln!(out, "  {}: event {}{detail}", event.line, event.kind.name()).unwrap();
    }
}

/// Every diagnostic of a failed compile, one per line; or the summary when it compiled.
pub fn render(source: &str, options: &GcodeOptions) -> String {
    match compile(source, options) {
        Ok(compiled) => render_compiled(source, &compiled),
        Err(errors) => {
            let mut out = format!("{errors}\n");
            for d in &errors.diagnostics {
                writeln!(out, "{}", diagnostic_line(source, d)).unwrap();
            }
            out
        }
    }
}

/// Compiles with default options and a feed, panicking with the diagnostics on failure.
pub fn ok(source: &str) -> Compiled {
    compile(source, &GcodeOptions::default())
        .unwrap_or_else(|_| panic!("{}", render(source, &GcodeOptions::default())))
}

/// The (code, line, column) of every error of a program that must fail.
pub fn errors(source: &str) -> Vec<(&'static str, usize, usize)> {
    let errors = compile(source, &GcodeOptions::default()).expect_err("the program must fail");
    errors
        .diagnostics
        .iter()
        .map(|d| {
            let (line, col) = line_col(source, d.span().start);
            (d.code().trim_start_matches("pvtc::gcode::"), line, col)
        })
        .collect()
}

/// rs274's reading of `source`: the point counts of its NURBS_FEED calls in order, or
/// its error line; `None` when rs274 is not installed.
pub fn rs274_nurbs_counts(source: &str, name: &str) -> Option<Result<Vec<usize>, String>> {
    if std::process::Command::new("rs274")
        .arg("-h")
        .output()
        .is_err()
    {
        assert!(
            std::env::var_os("PVTC_REQUIRE_RS274").is_none(),
            "rs274 is not installed, and PVTC_REQUIRE_RS274 is set"
        );
        return None;
    }
    let dir = std::env::temp_dir().join(format!("pvtc-rs274-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (ngc, out) = (dir.join("p.ngc"), dir.join("out.txt"));
    std::fs::write(&ngc, source).unwrap();
    // Two rs274 runs at once can kill each other (shared memory): try again.
    for _ in 0..20 {
        let run = std::process::Command::new("rs274")
            .arg("-g")
            .arg(&ngc)
            .arg(&out)
            .stdin(std::process::Stdio::null())
            .output()
            .expect("rs274 runs");
        if run.status.code().is_none() {
            std::thread::sleep(std::time::Duration::from_millis(200));
            continue;
        }
        let text = std::fs::read_to_string(&out).unwrap_or_default();
        let counts = text
            .lines()
            .filter_map(|l| l.split("NURBS_FEED(").nth(1))
            .map(|rest| rest.split(',').next().unwrap().trim().parse().unwrap())
            .collect();
        let said = String::from_utf8_lossy(&run.stdout).to_string()
            + &String::from_utf8_lossy(&run.stderr);
        std::fs::remove_dir_all(&dir).ok();
        return Some(match run.status.success() {
            true => Ok(counts),
            false => Err(said),
        });
    }
    panic!("rs274 was killed 20 times");
}
