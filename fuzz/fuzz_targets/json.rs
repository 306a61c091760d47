//! The pvtc JSON program reader used by `pvtc check`, then the check itself.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(program) = pvt_emit::json::read(&text) else {
        return;
    };
    // Servo sampling costs time / period samples: bound it as `pvtc check` users would.
    if pvt_emit::validate(&program).is_ok()
        && program.total_time() < 100.0
        && program.segment_count() < 10_000
    {
        let _ = pvt_core::check_program(&program, None, &Default::default());
    }
});
