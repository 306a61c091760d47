//! G-code parser + interpreter + planner + every back end: no input may panic, and
//! whatever compiles must plan into finite, positive-time pieces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pvt_core::{plan_toolpath, PlanOptions};
use pvt_emit::{emit_to_vec, EmitOptions, Format};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(compiled) = pvt_gcode::compile(&text, &Default::default()) else {
        return;
    };
    let Ok(program) = plan_toolpath(&compiled.toolpath, &PlanOptions::default()) else {
        return;
    };
    for format in Format::ALL {
        // A program the planner produced must always pass the back ends' validation.
        emit_to_vec(&program, format, &EmitOptions::default()).expect("planned programs are valid");
    }
});
