//! Point-time CSV reader and every planner on what it reads: no input may panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pvt_core::{plan_timed, PlanOptions, Planner, Units};
use pvt_emit::{emit_to_vec, EmitOptions, Format};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(series) = pvt_csv::read_points(&text, Units::Millimetre) else {
        return;
    };
    for planner in Planner::ALL {
        let options = PlanOptions {
            planner,
            accel: Some(1000.0),
            ..PlanOptions::default()
        };
        let Ok(planned) = plan_timed(&series.points, series.axes.clone(), series.units, &options)
        else {
            continue;
        };
        emit_to_vec(&planned.program, Format::Json, &EmitOptions::default())
            .expect("planned programs are valid");
    }
});
