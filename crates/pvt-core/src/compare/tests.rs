//! The comparison on programs whose differences are known by construction.

use super::*;
use crate::program::{Interpolation, PvtContour};
use crate::toolpath::{EventKind, Motion, ProgramEvent, SpindleState};

/// A 100 mm square from (0, 0), four rest-to-rest pieces of 1.5 s on lines 2–5; `skip`
/// leaves a corner out, `stretch` multiplies every time, `offset` moves every position.
fn square(skip: Option<usize>, stretch: f64, offset: [f64; 2]) -> PvtProgram {
    let corners = [[100.0, 0.0], [100.0, 100.0], [0.0, 100.0], [0.0, 0.0]];
    let at = |p: [f64; 2]| vec![p[0] + offset[0], p[1] + offset[1]];
    let mut c = PvtContour::new(Motion::Feed, at([0.0, 0.0]));
    for (i, p) in corners.iter().enumerate() {
        if Some(i) != skip {
            c.push(&at(*p), &[0.0, 0.0], 1.5 * stretch, i as u32 + 2);
        }
    }
    PvtProgram {
        axes: vec![Axis::X, Axis::Y],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

fn options(tolerance: f64) -> CompareOptions {
    CompareOptions {
        tolerance,
        time_tolerance: 0.001,
        peak_tolerance: 0.01,
        servo_period: 0.0005,
        counts_per_unit: BTreeMap::new(),
        profile_bins: 0,
    }
}

fn side(program: &PvtProgram) -> Side<'_> {
    Side {
        program,
        carries_events: true,
        triggers: None,
    }
}

fn codes(c: &Comparison) -> Vec<&'static str> {
    c.differences.iter().map(Difference::code_name).collect()
}

#[test]
fn the_same_motion_is_equal() {
    let a = square(None, 1.0, [0.0; 2]);
    let c = compare(side(&a), side(&a), &options(1e-6));
    assert!(c.equal(), "{:?}", c.differences);
    assert_eq!(c.aligned.value, 0.0);
    assert_eq!(c.total_time, [6.0, 6.0]);
    assert_eq!(c.pieces, [4, 4]);
}

#[test]
fn a_shift_of_a_micrometre_is_within_two_and_beyond_half() {
    let (a, b) = (square(None, 1.0, [0.0; 2]), square(None, 1.0, [0.001, 0.0]));
    let c = compare(side(&a), side(&b), &options(0.002));
    assert!(c.equal(), "{:?}", c.differences);
    assert!((c.aligned.value - 0.001).abs() < 1e-9, "{:?}", c.aligned);
    let c = compare(side(&a), side(&b), &options(0.0005));
    assert_eq!(codes(&c), ["position"]);
    let Difference::Position(spot) = c.differences[0] else {
        unreachable!()
    };
    assert!((spot.value - 0.001).abs() < 1e-6, "{spot:?}");
    let first = c.first_divergence.unwrap();
    assert_eq!((first.time, first.lines), (0.0, [2, 2]));
}

#[test]
fn a_time_stretch_is_a_time_shift_and_not_a_position_error() {
    let (a, b) = (square(None, 1.0, [0.0; 2]), square(None, 1.01, [0.0; 2]));
    let c = compare(side(&a), side(&b), &options(0.001));
    assert_eq!(
        codes(&c),
        ["time_shift", "total_time", "peak", "peak", "peak", "peak"]
    );
    assert!(c.path.value <= 0.001, "{:?}", c.path);
    // B reaches the last corner 60 ms late; within 1 µm of it about 7 ms earlier (the
    // smoothstep's 3·d·(τ/T)² of 100 mm is 1 µm at τ ≈ 4.7 ms of the 1.515 s piece).
    assert!(
        c.time_shift.value > 0.05 && c.time_shift.value < 0.06,
        "{:?}",
        c.time_shift
    );
    assert!((c.total_time[1] - c.total_time[0] - 0.06).abs() < 1e-12);
}

#[test]
fn a_dropped_piece_is_found_at_its_line() {
    let (a, b) = (square(None, 1.0, [0.0; 2]), square(Some(2), 1.0, [0.0; 2]));
    let c = compare(side(&a), side(&b), &options(0.001));
    assert_eq!(codes(&c)[0], "position");
    let first = c.first_divergence.unwrap();
    assert!((first.time - 3.0).abs() < 0.01, "{first:?}");
    assert_eq!(
        first.lines,
        [4, 5],
        "A's line 4 goes to (0, 100); B goes home"
    );
    let Difference::Position(spot) = c.differences[0] else {
        unreachable!()
    };
    assert!(
        spot.value > 70.0,
        "(0, 100) is 70.7 mm from B's diagonal: {spot:?}"
    );
}

#[test]
fn an_event_out_of_order_is_found() {
    let event = |state, before| ProgramEvent {
        before_contour: before,
        kind: EventKind::Spindle { state },
        line: 1,
    };
    let mut a = square(None, 1.0, [0.0; 2]);
    a.events = vec![
        event(SpindleState::Clockwise, 0),
        event(SpindleState::Off, 1),
    ];
    let mut b = a.clone();
    let c = compare(side(&a), side(&b), &options(0.001));
    assert!(c.equal(), "{:?}", c.differences);
    b.events.swap(0, 1);
    b.events[0].before_contour = 0;
    b.events[1].before_contour = 1;
    let c = compare(side(&a), side(&b), &options(0.001));
    assert_eq!(codes(&c), ["events"]);
    let Difference::Events(m) = &c.differences[0] else {
        unreachable!()
    };
    assert_eq!(m.index, 0);
    assert_eq!(
        m.names,
        [
            Some("spindle_cw".to_string()),
            Some("spindle_off".to_string())
        ]
    );
    // The same event at another place: moved.
    let mut b = a.clone();
    b.events[1].before_contour = 0;
    let c = compare(side(&a), side(&b), &options(0.001));
    assert!(c.equal(), "(0, 0) is where the square starts and ends");
    // Not compared where one side carries no events.
    let none = Side {
        carries_events: false,
        ..side(&b)
    };
    assert!(compare(side(&a), none, &options(0.001)).events.is_none());
}

#[test]
fn inches_convert_and_counts_compare_in_counts() {
    let a = square(None, 1.0, [0.0; 2]);
    let mut b = a.clone();
    b.units = Units::Inch;
    for c in &mut b.contours {
        c.start.iter_mut().for_each(|x| *x /= 25.4);
        c.ends.iter_mut().for_each(|x| *x /= 25.4);
    }
    let c = compare(side(&a), side(&b), &options(1e-9));
    assert!(c.equal(), "{:?}", c.differences);
    // Half a count apart at 1000 counts/mm: within 1 count, beyond 0.4.
    let shifted = square(None, 1.0, [0.0005, 0.0]);
    let mut counts = options(1.0);
    counts.counts_per_unit = [(Axis::X, 1000.0), (Axis::Y, 1000.0)].into();
    let c = compare(side(&a), side(&shifted), &counts);
    assert!(c.equal() && c.in_counts && (c.aligned.value - 0.5).abs() < 1e-9);
    counts.tolerance = 0.4;
    assert_eq!(
        codes(&compare(side(&a), side(&shifted), &counts)),
        ["position"]
    );
}

#[test]
fn triggers_compare_by_place_or_time() {
    let a = square(None, 1.0, [0.0; 2]);
    let with = |t: &'static [usize]| Side {
        triggers: Some(t),
        ..side(&a)
    };
    let c = compare(with(&[1, 2]), with(&[1, 2]), &options(0.001));
    assert!(c.equal());
    let c = compare(with(&[1, 2]), with(&[1, 3]), &options(0.001));
    let Some(Difference::Triggers(m)) = c.differences.first() else {
        panic!("{:?}", c.differences)
    };
    assert_eq!((m.index, m.times), (1, [3.0, 4.5]));
    let c = compare(with(&[1, 2]), with(&[1]), &options(0.001));
    assert_eq!(codes(&c), ["triggers"]);
}

#[test]
fn a_profile_keeps_the_largest_difference_of_each_bin() {
    let (a, b) = (square(None, 1.0, [0.0; 2]), square(None, 1.0, [0.001, 0.0]));
    let mut o = options(0.002);
    o.profile_bins = 12;
    let c = compare(side(&a), side(&b), &o);
    assert_eq!(c.profile.len(), 12);
    assert!(
        c.profile.iter().all(|d| (d - 0.001).abs() < 1e-9),
        "{:?}",
        c.profile
    );
}
