//! `check` samples the servo loop in memory that does not grow with the samples: one
//! piece checked over 2·10^7 servo periods takes no more than over 2·10^3. Its own test
//! binary, because the counting allocator counts every thread of it.

use peak_alloc::PeakAlloc;
use pvt_core::{
    check_program, Axis, CheckOptions, Interpolation, Motion, PvtContour, PvtProgram, Units,
};

/// Counts the bytes allocated (every thread of this test binary).
#[global_allocator]
static ALLOCATOR: PeakAlloc = PeakAlloc;

/// One rest-to-rest piece of `seconds` on X, Y and Z.
fn program(seconds: f64) -> PvtProgram {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0; 3]);
    c.push(&[10.0, -5.0, 1.0], &[0.0; 3], seconds, 1);
    PvtProgram {
        axes: vec![Axis::X, Axis::Y, Axis::Z],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

/// The most memory checking the piece of `seconds` holds at once, in bytes.
fn peak(seconds: f64) -> usize {
    let p = program(seconds);
    let before = ALLOCATOR.current_usage();
    ALLOCATOR.reset_peak_usage();
    let report = check_program(&p, None, &CheckOptions::default());
    let peak = ALLOCATOR.peak_usage() - before;
    // Independently: rest to rest over 10 in T peaks at 1.5·10/T mid-way.
    let v = report.axis(Axis::X).unwrap().sampled_velocity.value;
    assert!((v - 15.0 / seconds).abs() < 1e-6 * v, "{v}");
    peak
}

#[test]
fn check_samples_twenty_million_servo_periods_in_the_memory_of_two_thousand() {
    // At the default 0.5 ms: 2·10^3 and 2·10^7 samples.
    // The test harness's own thread allocates a little meanwhile (a few hundred bytes, now
    // and then); a Vec of the samples alone would take 160 MB.
    let (short, long) = (peak(1.0), peak(10_000.0));
    assert!(
        long <= short + 16 * 1024,
        "{long} bytes for 2e7 samples, {short} for 2e3"
    );
    assert!(long < 64 * 1024, "{long} bytes");
}
