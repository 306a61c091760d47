//! DXF reader: no input bytes may panic; whatever reads must plan into valid pieces.
//!
//! The `dxf` crate panics on some malformed files (chrono date ranges, indexing).
//! `pvt_dxf::read_drawing` catches those with `catch_unwind` and returns `pvtc::dxf::read`,
//! exactly as the CLI does; libFuzzer's panic hook would abort before that catch runs, so
//! this target lets a panic raised inside that one call (`pvt_dxf::panic_is_contained`)
//! unwind to it and keeps the abort for every other panic (ours, or an allocation failure
//! in std), which stays a crash.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pvt_core::{plan_toolpath, PlanOptions};
use pvt_emit::{emit_to_vec, EmitOptions, Format};
use std::sync::Once;

static CONTAIN: Once = Once::new();

fn contain_third_party_panics() {
    CONTAIN.call_once(|| {
        let abort = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !pvt_dxf::panic_is_contained() {
                abort(info);
            }
        }));
    });
}

fuzz_target!(|data: &[u8]| {
    contain_third_party_panics();
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
