//! DXF reader: no input bytes may panic; whatever reads must plan into valid pieces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pvt_core::{plan_toolpath, PlanOptions};
use pvt_emit::{emit_to_vec, EmitOptions, Format};

fuzz_target!(|data: &[u8]| {
    let options = pvt_dxf::DxfOptions::with_feed(1200.0);
    let Ok(drawing) = pvt_dxf::read_drawing(data, &options) else {
        return;
    };
    let Ok(program) = plan_toolpath(&drawing.toolpath, &PlanOptions::default()) else {
        return;
    };
    emit_to_vec(&program, Format::Json, &EmitOptions::default())
        .expect("planned programs are valid");
});
