//! The real programs of `../shared/corpus/linuxcnc` (see its README): each compiles, or
//! fails only with the diagnostics its README allows (`unsupported` features and
//! probing moves without a result). Skipped, saying so,
//! when the folder is absent.

mod common;

use std::path::PathBuf;

use pvt_core::ElementKind;
use pvt_gcode::{compile, GcodeOptions};

fn corpus() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus/linuxcnc");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("SKIPPED: corpus folder {} is absent", dir.display());
        None
    }
}

/// What each file must do: compile, or fail with exactly these unsupported features
/// (or codes, for other refusals).
const EXPECTED: &[(&str, &[&str])] = &[
    ("3D_Chips.ngc", &[]),
    ("3dtest.ngc", &[]),
    ("arcspiral.ngc", &[]),
    ("lathe_pawn.ngc", &[]),
    ("tort.ngc", &[]),
    (
        "plasmac_metric_pipe.ngc",
        &[
            "pvtc::gcode::probe",
            "HAL pins (#<_hal[…]>) without --hal NAME=VALUE",
            "pvtc::gcode::probe",
        ],
    ),
];

#[test]
fn corpus_programs_compile_or_are_refused_precisely() {
    let Some(dir) = corpus() else { return };
    for (name, features) in EXPECTED {
        let path = dir.join(name);
        let source = std::fs::read_to_string(&path).expect("a readable UTF-8 program");
        let options = GcodeOptions::default();
        let result = compile(&source, &options);
        println!("{name}:\n{}", summary(&source, &result));
        match result {
            Ok(compiled) => {
                assert!(features.is_empty(), "{name} compiled but must fail");
                assert!(
                    !compiled.toolpath.contours.is_empty(),
                    "{name}: no contours"
                );
            }
            Err(errors) => {
                let got: Vec<_> = errors
                    .diagnostics
                    .iter()
                    .map(|d| match d {
                        pvt_gcode::GcodeDiagnostic::Unsupported { feature, .. } => *feature,
                        pvt_gcode::GcodeDiagnostic::Probe { .. } => d.code(),
                        _ => panic!("{name}: {}", common::diagnostic_line(&source, d)),
                    })
                    .collect();
                assert_eq!(&got, features, "{name}");
            }
        }
    }
}

fn summary(source: &str, result: &Result<pvt_gcode::Compiled, pvt_gcode::GcodeErrors>) -> String {
    match result {
        Ok(c) => {
            let elements: usize = c.toolpath.contours.iter().map(|c| c.elements.len()).sum();
            format!(
                "  {} contours, {elements} elements, {} events, {} warnings",
                c.toolpath.contours.len(),
                c.toolpath.events.len(),
                c.warnings.len()
            )
        }
        Err(e) => e
            .diagnostics
            .iter()
            .map(|d| format!("  {}\n", common::diagnostic_line(source, d)))
            .collect(),
    }
}

#[test]
fn tort_points_lie_on_their_arcs_and_helices() {
    let Some(dir) = corpus() else { return };
    let source = std::fs::read_to_string(dir.join("tort.ngc")).expect("tort.ngc");
    let compiled = compile(&source, &GcodeOptions::default()).expect("tort.ngc compiles");
    let mut arcs = 0;
    for e in compiled.toolpath.contours.iter().flat_map(|c| &c.elements) {
        let ElementKind::Arc(arc) = e.kind else {
            continue;
        };
        arcs += 1;
        let sweep = arc.sweep(&e.start, &e.end);
        // tort.ngc's end points are on the circle to its six decimals.
        assert!(
            (sweep.start_radius - sweep.end_radius).abs() < 1e-5,
            "line {}: radii {} and {}",
            e.span.line,
            sweep.start_radius,
            sweep.end_radius
        );
    }
    assert!(arcs > 50, "tort.ngc has {arcs} arcs");
}

#[test]
fn chips_reads_its_parameters() {
    let Some(dir) = corpus() else { return };
    let source = std::fs::read_to_string(dir.join("3D_Chips.ngc")).expect("3D_Chips.ngc");
    let compiled = compile(&source, &GcodeOptions::default()).expect("3D_Chips.ngc compiles");
    let first = &compiled.toolpath.contours[0].elements[0];
    // N90G0Z[#<zscale>*10.] with #<zscale> = 1.0
    assert_eq!(first.end[2], 10.0);
    let names: Vec<_> = compiled
        .toolpath
        .events
        .iter()
        .map(|e| e.kind.name())
        .collect();
    assert_eq!(
        names,
        [
            "tool_select",
            "spindle_off",
            "tool_change",
            "coolant_flood",
            "spindle_speed",
            "spindle_cw",
            "coolant_off"
        ]
    );
}
