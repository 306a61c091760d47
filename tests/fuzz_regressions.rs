//! Inputs that once broke an invariant under fuzzing (fuzz/), kept as regressions: each
//! is run the way its fuzz target runs it, and whatever plans must pass the back ends'
//! validation (no NaN, infinity or non-positive time) in every format, its pieces cut
//! for the format as the pipeline cuts them; only a piece too long to cut, or one that
//! breaks a controller rule (refused with that rule's code), may be refused.

use pvt_core::{
    plan_timed, plan_toolpath, split_long_pieces, PlanOptions, Planner, PvtProgram, Units,
};
use pvt_emit::{emit_to_vec, AxisSetup, EmitOptions, Format, InvalidProgram, StreamError};
use pvtc_tests::root;

fn assert_valid(name: &str, program: &PvtProgram) {
    for format in Format::ALL {
        let mut program = program.clone();
        let max = format.max_piece_seconds();
        if let Some(max) = max {
            for c in &mut program.contours {
                *c = split_long_pieces(c, max, format.piece_time_quantum());
            }
        }
        // Formats written in counts get 1000 per unit on every axis.
        let options = EmitOptions {
            axes: pvt_core::Axis::ALL
                .iter()
                .map(|a| {
                    let setup = AxisSetup {
                        counts_per_unit: Some(1000.0),
                        ..AxisSetup::default()
                    };
                    (*a, setup)
                })
                .collect(),
            ..EmitOptions::default()
        };
        match emit_to_vec(&program, format, &options) {
            Ok(_) | Err(StreamError::Unsupported(_)) => {}
            // A controller rule (a piece under the shortest, off the grid), refused with
            // its own code: the fuzz target plans without the format's grid.
            Err(StreamError::Invalid(e)) if e.code != InvalidProgram::CODE => {}
            Err(StreamError::Invalid(e)) if !e.internal => {
                let uncut = pvt_core::split::MAX_SUB_PIECES as f64 * max.unwrap_or(f64::INFINITY);
                let too_long = program.contours.iter().flat_map(|c| &c.durations);
                assert!(too_long.into_iter().any(|&t| t > uncut), "{name}: {e}");
            }
            Err(e) => panic!("{name} as {}: {e}", format.name()),
        }
    }
}

#[test]
fn fuzz_findings_stay_fixed() {
    let dir = root().join("tests/fuzz-regressions");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(!names.is_empty());
    for name in names {
        let name = name.to_string_lossy().into_owned();
        let bytes = std::fs::read(dir.join(&name)).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        if name.ends_with(".ngc") {
            let toolpath = pvt_gcode::compile(&text, &Default::default())
                .expect("valid G-code")
                .toolpath;
            if let Ok(program) = plan_toolpath(&toolpath, &PlanOptions::default()) {
                assert_valid(&name, &program);
            }
        } else if name.ends_with(".csv") {
            let series = pvt_csv::read_points(&text, Units::Millimetre).expect("valid CSV");
            for planner in Planner::ALL {
                let options = PlanOptions {
                    planner,
                    accel: Some(1000.0),
                    ..PlanOptions::default()
                };
                if let Ok(planned) =
                    plan_timed(&series.points, series.axes.clone(), series.units, &options)
                {
                    assert_valid(&format!("{name} ({})", planner.name()), &planned.program);
                }
            }
        } else {
            // The dxf crate panics on this file; pvt-dxf must turn that into a read error.
            let result = pvt_dxf::read_drawing(&bytes, &pvt_dxf::DxfOptions::with_feed(1200.0));
            if let Ok(drawing) = result {
                if let Ok(program) = plan_toolpath(&drawing.toolpath, &PlanOptions::default()) {
                    assert_valid(&name, &program);
                }
            }
        }
    }
}
