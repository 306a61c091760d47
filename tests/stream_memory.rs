//! The path planner streams a long contour on a time grid in memory that does not grow
//! with the contour: 40,000 lines on PMAC's 1 ms grid (its default route: no machine
//! file) take no more than 4,000, and the pieces come out while the lines go in. Its own
//! test binary, because the counting allocator counts every thread of it.

use peak_alloc::PeakAlloc;
use pvt_core::{
    Axis, Element, ElementKind, PathOptions, PathStream, Position, Quantum, Rounding, SegmentRef,
    Span,
};
use std::collections::BTreeMap;

/// Counts the bytes allocated (every thread of this test binary).
#[global_allocator]
static ALLOCATOR: PeakAlloc = PeakAlloc;

const AXES: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

/// Line `i` of a surfacing zigzag: 0.5 mm steps along X with a small Z wave, one feed.
fn element(i: usize) -> Element {
    let at = |i: usize| -> Position {
        let mut p = [0.0; pvt_core::AXIS_COUNT];
        p[0] = 0.5 * i as f64;
        p[1] = 0.01 * (i % 7) as f64;
        p[2] = 0.02 * ((i % 13) as f64 - 6.0).abs();
        p
    };
    Element {
        kind: ElementKind::Line,
        start: at(i),
        end: at(i + 1),
        feed: 50.0,
        span: Span {
            line: i as u32 + 1,
            ..Span::default()
        },
    }
}

/// The most memory planning `n` lines on the 1 ms grid holds at once, in bytes, and the
/// pieces that came out before the contour ended, of all.
fn peak(n: usize) -> (usize, usize, usize) {
    let options = PathOptions {
        tolerance: 0.01,
        corner_tolerance: None,
        limits: BTreeMap::new(),
        quantum: Some(Quantum {
            seconds: 0.001,
            rounding: Rounding::Up,
        }),
        servo_period: 0.0005,
        position_resolution: 0.0,
    };
    let (pieces, mut time) = (std::cell::Cell::new(0), 0.0);
    let before = ALLOCATOR.current_usage();
    ALLOCATOR.reset_peak_usage();
    let mut stream = PathStream::new(&AXES, &options);
    let mut emit = |s: &SegmentRef<'_>| {
        pieces.set(pieces.get() + 1);
        time += s.duration;
        // Independently: every piece is whole milliseconds.
        let ms = s.duration * 1e3;
        assert!(
            ms >= 1.0 - 1e-9 && (ms - ms.round()).abs() < 1e-9,
            "{ms} ms"
        );
    };
    for i in 0..n {
        stream.push(&element(i), &mut emit).expect("plans");
    }
    let early = pieces.get();
    stream.finish(&mut emit).expect("plans");
    let peak = ALLOCATOR.peak_usage() - before;
    // At 50 mm/s at most: 0.5 mm a line takes at least 10 ms.
    assert!(time >= n as f64 * 0.01, "{time} s for {n} lines");
    (peak, early, pieces.get())
}

#[test]
fn a_long_contour_on_a_grid_streams_in_the_memory_of_a_short_one() {
    let (short, _, _) = peak(4_000);
    let (long, early, all) = peak(40_000);
    assert!(
        early * 10 >= all * 9,
        "{early} of {all} pieces before the end"
    );
    assert!(
        long <= short + 64 * 1024,
        "{long} bytes for 40,000 lines, {short} for 4,000"
    );
    assert!(long < 8 << 20, "{long} bytes");
}
