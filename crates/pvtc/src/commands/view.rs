//! The interactive HTML view of `pvtc plot -o FILE.html` and `pvtc diff -o FILE.html`.
//!
//! Owns gathering what the page lists and draws beside the motions (the machine limits,
//! every violation, peak and slowest spot `check` finds, a comparison's differences and
//! its difference against time, the text of each file's lines) and writing the file; the
//! page itself is pvt-emit's `view` back end. It must not draw or compute the findings.

use crate::commands::verify::Loaded as Planned;
use crate::options::Failure;
use pvt_core::compare::{Comparison, Difference};
use pvt_core::{CheckReport, Peak, PvtProgram};
use pvt_emit::view::{with_dwells, DifferenceProfile, Finding, Motion, ViewOptions};
use std::path::Path;

/// Whether a path names an HTML page (`.html`, `.htm`).
pub fn is_html(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"))
}

/// What `check` finds, as findings of motion `motion`: each violation, the peaks of
/// every axis, the slowest and fastest feed and the largest path error.
fn check_findings(report: &CheckReport, program: &PvtProgram, motion: usize) -> Vec<Finding> {
    let units = program.units.name();
    let finding = |label: String, p: &Peak, violation: bool| Finding {
        label,
        time: with_dwells(program, p.time),
        line: p.line,
        motion,
        violation,
    };
    let mut out: Vec<Finding> = report
        .violations
        .iter()
        .map(|v| Finding {
            label: format!(
                "{} {} {:.6} over the limit {:.6}",
                v.axis,
                v.quantity.name(),
                v.value,
                v.limit
            ),
            time: with_dwells(program, v.time),
            line: v.line,
            motion,
            violation: true,
        })
        .collect();
    if let Some(s) = &report.speed {
        out.push(finding(
            format!("slowest feed {:.6} {units}/s", s.min.value),
            &s.min,
            false,
        ));
        out.push(finding(
            format!("fastest feed {:.6} {units}/s", s.max.value),
            &s.max,
            false,
        ));
    }
    if let Some(p) = &report.path_error {
        out.push(finding(
            format!("largest path error {:.9} {units}", p.value),
            p,
            false,
        ));
    }
    for a in &report.axes {
        for (name, p) in [
            ("velocity", &a.velocity),
            ("acceleration", &a.acceleration),
            ("jerk", &a.jerk),
            ("acceleration step", &a.acceleration_step),
        ] {
            out.push(finding(
                format!("{} peak {name} {:.6}", a.axis, p.value),
                p,
                false,
            ));
        }
    }
    out
}

/// Writes the page of one program (`pvtc plot -o FILE.html`), with what `report` found.
pub fn write_plot(
    path: &Path,
    planned: &Planned,
    text: &str,
    name: &str,
    report: &CheckReport,
) -> Result<(), Failure> {
    let program = &planned.program;
    let limits = crate::settings::machine_limits(
        planned.options.machine.as_ref(),
        program.units,
        &program.axes,
    )?;
    let options = ViewOptions {
        title: format!("{name} ({})", planned.options.planner.name()),
        limits,
        programmed: planned.toolpath.as_ref(),
        findings: check_findings(report, program, 0),
        difference: None,
    };
    let motion = Motion {
        name,
        program,
        text,
    };
    crate::output::write_file(path, &pvt_emit::view::page(&[motion], &options))
}

/// The differences of a comparison as findings: where each is, on the first
/// program's time line.
fn difference_findings(c: &Comparison) -> Vec<Finding> {
    let mut out = Vec::new();
    if let Some(f) = &c.first_divergence {
        out.push(Finding {
            label: format!("first beyond the tolerance: {:.9}", f.value),
            time: f.time,
            line: f.lines[0],
            motion: 0,
            violation: true,
        });
    }
    for d in &c.differences {
        let (label, time, line) = match d {
            Difference::Position(s) => (
                format!("position: {:.9} apart", s.value),
                s.time,
                s.lines[0],
            ),
            Difference::TimeShift(s) => {
                (format!("time shift {:.6} s", s.value), s.time, s.lines[0])
            }
            Difference::TotalTime(dt) => (
                format!("total time differs by {dt:.6} s"),
                c.total_time[0],
                0,
            ),
            Difference::Peak {
                axis,
                quantity,
                peaks,
            } => (
                format!(
                    "{axis} {} peak {:.6} and {:.6}",
                    quantity.name(),
                    peaks[0].value,
                    peaks[1].value
                ),
                peaks[0].time,
                peaks[0].line,
            ),
            Difference::Events(m) | Difference::Triggers(m) => (
                format!(
                    "{} {}: {:?} and {:?}",
                    d.code_name(),
                    m.index + 1,
                    m.names[0],
                    m.names[1]
                ),
                m.times[0],
                m.lines[0],
            ),
        };
        out.push(Finding {
            label,
            time,
            line,
            motion: 0,
            violation: true,
        });
    }
    out.push(Finding {
        label: format!(
            "largest difference at the same instant {:.9}",
            c.aligned.value
        ),
        time: c.aligned.time,
        line: c.aligned.lines[0],
        motion: 0,
        violation: false,
    });
    out
}

/// Writes the page of a comparison (`pvtc diff -o FILE.html`): both motions (the second
/// drawn in the first's units), the machine's `limits`, and their difference against time
/// with the position `tolerance`.
pub fn write_diff(
    path: &Path,
    motions: [Motion<'_>; 2],
    limits: std::collections::BTreeMap<pvt_core::Axis, pvt_core::AxisLimits>,
    c: &Comparison,
    tolerance: f64,
) -> Result<(), Failure> {
    let options = ViewOptions {
        title: format!("{} and {}", motions[0].name, motions[1].name),
        limits,
        programmed: None,
        findings: difference_findings(c),
        difference: Some(DifferenceProfile {
            bins: c.profile.clone(),
            end: c.total_time[0].max(c.total_time[1]),
            tolerance,
            unit: if c.in_counts {
                "counts"
            } else {
                c.units.name()
            }
            .to_string(),
        }),
    };
    crate::output::write_file(path, &pvt_emit::view::page(&motions, &options))
}
