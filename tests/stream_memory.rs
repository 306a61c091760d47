//! The path planner streams a long contour on a time grid in memory that does not grow
//! with the contour: 40,000 lines on PMAC's 1 ms grid (its default route: no machine
//! file) take no more than 4,000, and the pieces come out while the lines go in; so does
//! a pocket of arcs with exact stops, on the grid and without one (where the window is
//! bounded by its pieces). Its own test binary, and one test at a time,
//! because the counting allocator counts every thread of it.

use peak_alloc::PeakAlloc;
use pvt_core::{
    Arc, ArcDirection, Axis, Element, ElementKind, PathOptions, PathStream, Plane, Position,
    Quantum, Rounding, SegmentRef, Span,
};
use std::collections::BTreeMap;

/// Counts the bytes allocated (every thread of this test binary).
#[global_allocator]
static ALLOCATOR: PeakAlloc = PeakAlloc;

/// Held by each test while it measures: the allocator counts every thread.
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

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

/// Element `i` of a pocket, as `generate pocket` writes it: circles of radius 1 to 20 mm
/// about the origin in 0.5 mm steps, each two half arcs and a 0.5 mm step-over line out
/// to the next (exact stops at its corners), one feed.
fn pocket_element(i: usize) -> Element {
    let r = 1.0 + 0.5 * ((i / 3) % 39) as f64;
    let at = |x: f64| -> Position {
        let mut p = [0.0; pvt_core::AXIS_COUNT];
        p[0] = x;
        p
    };
    let arc = ElementKind::Arc(Arc {
        plane: Plane::XY,
        center: [0.0, 0.0],
        direction: ArcDirection::CounterClockwise,
        extra_turns: 0,
    });
    let (kind, start, end) = match i % 3 {
        0 => (arc, at(r), at(-r)),
        1 => (arc, at(-r), at(r)),
        _ if r < 20.0 => (ElementKind::Line, at(r), at(r + 0.5)),
        _ => (ElementKind::Line, at(r), at(1.0)),
    };
    Element {
        kind,
        start,
        end,
        feed: 800.0 / 60.0,
        span: Span {
            line: i as u32 + 1,
            ..Span::default()
        },
    }
}

/// The most memory planning `n` lines on the 1 ms grid holds at once, in bytes, and the
/// pieces that came out before the contour ended, of all.
fn peak(n: usize) -> (usize, usize, usize) {
    let (peak, early, all, time) = peak_of(n, element, 0.01, Some(MS));
    // At 50 mm/s at most: 0.5 mm a line takes at least 10 ms.
    assert!(time >= n as f64 * 0.01, "{time} s for {n} lines");
    (peak, early, all)
}

/// PMAC's default grid: 1 ms, piece times rounded up.
const MS: Quantum = Quantum {
    seconds: 0.001,
    rounding: Rounding::Up,
};

/// As [`peak`], for `n` elements of `elements` at `tolerance` on the grid of `quantum`
/// (none: piece times as planned), with the motion's time.
fn peak_of(
    n: usize,
    elements: fn(usize) -> Element,
    tolerance: f64,
    quantum: Option<Quantum>,
) -> (usize, usize, usize, f64) {
    let options = PathOptions {
        tolerance,
        corner_tolerance: None,
        limits: BTreeMap::new(),
        quantum,
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
        // Independently: on the grid every piece is whole quanta.
        if let Some(q) = quantum {
            let quanta = s.duration / q.seconds;
            assert!(
                quanta >= 1.0 - 1e-9 && (quanta - quanta.round()).abs() < 1e-9,
                "{quanta} quanta"
            );
        }
    };
    for i in 0..n {
        stream.push(&elements(i), &mut emit).expect("plans");
    }
    let early = pieces.get();
    stream.finish(&mut emit).expect("plans");
    let peak = ALLOCATOR.peak_usage() - before;
    (peak, early, pieces.get(), time)
}

#[test]
fn a_long_contour_on_a_grid_streams_in_the_memory_of_a_short_one() {
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
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
    // A window's plan and its resampled pieces (kept compact: each piece's end state on
    // its axes, with its time, error bound and knot): 1,256,875 bytes before the knots
    // took 72 bytes and the speed change kept 8 bytes a piece, 1,237,819 after, 1,065,859
    // with the plan's pieces stored flat at its axes and the knots inserted in place.
    assert!(long < 9 << 17, "{long} bytes");
}

#[test]
fn a_pocket_of_arcs_and_exact_stops_streams_on_a_grid() {
    // Its step-over lines are single pieces from rest to rest and its arcs have no
    // room to stop on a line: its windows end at the stops.
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let (short, _, _, _) = peak_of(3_000, pocket_element, 0.001, Some(MS));
    let (long, early, all, time) = peak_of(12_000, pocket_element, 0.001, Some(MS));
    assert!(
        early * 10 >= all * 9,
        "{early} of {all} pieces before the end"
    );
    assert!(
        long <= short + 256 * 1024,
        "{long} bytes for 12,000 elements, {short} for 3,000"
    );
    // About 7,500 planned pieces a window of 1024 elements and as many resampled ones
    // (kept compact) with the knots (13 MB with the resampled pieces whole): 7,077,283
    // bytes before the knots took 72 bytes and the speed change kept 8 bytes a piece,
    // 6,851,803 after, 4,663,027 with the plan's pieces stored flat at its axes and a
    // split's knots inserted in place.
    assert!(long < 19 << 18, "{long} bytes");
    // Independently: at the feed, the 4,000 circles of radius 1 mm or more take at
    // least 4,000 · 2π mm / (40/3 mm/s).
    assert!(time >= 4_000.0 * std::f64::consts::TAU * 0.075, "{time} s");
}

#[test]
fn a_pocket_of_arcs_without_a_grid_holds_a_window_of_pieces_not_of_elements() {
    // Each arc becomes several pieces at 0.001 mm (about 7 an element on this pocket):
    // a window of 1024 elements held about 7,500 pieces, some 5 MB of plan (as six-axis
    // pieces).
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let (short, _, _, _) = peak_of(3_000, pocket_element, 0.001, None);
    let (long, early, all, time) = peak_of(12_000, pocket_element, 0.001, None);
    assert!(
        early * 10 >= all * 9,
        "{early} of {all} pieces before the end"
    );
    assert!(
        long <= short + 64 * 1024,
        "{long} bytes for 12,000 elements, {short} for 3,000"
    );
    // 1,395,155 bytes before the knots took 72 bytes, 1,341,043 after, 680,395 with the
    // pieces stored flat at the plan's axes and a split's knots inserted in place.
    assert!(long < 3 << 18, "{long} bytes");
    assert!(time >= 4_000.0 * std::f64::consts::TAU * 0.075, "{time} s");
}
