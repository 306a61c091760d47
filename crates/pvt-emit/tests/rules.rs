//! Controller rules on hand-made programs: each refusal has its code and names the
//! contour, the piece and the source line; nothing is written.

use pvt_core::{Axis, Interpolation, Motion, PvtContour, PvtProgram, Units};
use pvt_emit::{emit_to_vec, AxisSetup, EmitOptions, Format, StreamError};

/// One contour on X from 0 at rest through `pieces` (end, velocity, time, source line).
fn program(pieces: &[(f64, f64, f64, u32)]) -> PvtProgram {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
    for &(p, v, t, line) in pieces {
        c.push(&[p], &[v], t, line);
    }
    PvtProgram {
        axes: vec![Axis::X],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

fn with_x(setup: AxisSetup) -> EmitOptions {
    EmitOptions {
        source: "t.ngc".into(),
        axes: [(Axis::X, setup)].into_iter().collect(),
        ..Default::default()
    }
}

/// The code, contour, segment and line of the refusal.
fn refusal(
    p: &PvtProgram,
    format: Format,
    options: &EmitOptions,
) -> (&'static str, usize, usize, u32) {
    match emit_to_vec(p, format, options) {
        Err(StreamError::Invalid(e)) => (e.code, e.contour, e.segment, e.line),
        other => panic!("{other:?}"),
    }
}

const RISE_AND_STOP: [(f64, f64, f64, u32); 2] = [(1.0, 2.0, 1.0, 5), (2.0, 0.0, 1.0, 6)];

#[test]
fn a_piece_under_the_xps_shortest_is_refused_at_its_line() {
    let p = program(&[(1.0, 0.0, 1e-5, 7)]);
    let r = refusal(&p, Format::Xps, &EmitOptions::default());
    assert_eq!(r, ("pvtc::emit::piece_too_short", 1, 1, 7));
    // The same piece is fine where the format takes any time.
    assert!(emit_to_vec(&p, Format::Csv, &EmitOptions::default()).is_ok());
}

#[test]
fn a_time_off_the_galil_grid_is_refused() {
    let p = program(&[(1.0, 0.0, 0.003, 9)]);
    let options = with_x(AxisSetup {
        counts_per_unit: Some(1000.0),
        ..Default::default()
    });
    assert_eq!(
        refusal(&p, Format::Galil, &options),
        ("pvtc::emit::piece_time_off_grid", 1, 1, 9)
    );
    // 2 samples of 1/1024 s is on it.
    let on = program(&[(1.0, 0.0, 2.0 / 1024.0, 9)]);
    assert!(emit_to_vec(&on, Format::Galil, &options).is_ok());
}

#[test]
fn counts_formats_need_counts_per_unit() {
    let p = program(&RISE_AND_STOP);
    for format in [Format::Galil, Format::Zaber] {
        match emit_to_vec(&p, format, &EmitOptions::default()) {
            Err(StreamError::MissingScale(_, Axis::X)) => {}
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn travel_limits_hold_between_the_knots_in_every_format() {
    // From 0 to 1 in 1 s ending at -3 units/s: the cubic overshoots above 1 (to 1.28 at
    // t = 0.8 s) between the knots, which are both within the travel.
    let p = program(&[(1.0, -3.0, 1.0, 4), (0.5, 0.0, 1.0, 5)]);
    let options = with_x(AxisSetup {
        min_position: Some(-1.0),
        max_position: Some(1.1),
        counts_per_unit: Some(1000.0),
        ..Default::default()
    });
    for format in Format::ALL {
        assert_eq!(
            refusal(&p, format, &options),
            ("pvtc::emit::travel_limit", 1, 1, 4),
            "{}",
            format.name()
        );
    }
    let roomy = with_x(AxisSetup {
        max_position: Some(1.3),
        ..options.axes[&Axis::X]
    });
    assert!(emit_to_vec(&p, Format::Xps, &roomy).is_ok());
}

#[test]
fn the_xps_verification_codes_are_checked_here() {
    let p = program(&RISE_AND_STOP);
    // The first piece ends at 2 units/s: over 1.5.
    let slow = with_x(AxisSetup {
        max_velocity: Some(1.5),
        ..Default::default()
    });
    let (code, ..) = refusal(&p, Format::Xps, &slow);
    assert_eq!(code, "pvtc::emit::velocity_limit");
    let gentle = with_x(AxisSetup {
        max_acceleration: Some(1.0),
        ..Default::default()
    });
    let (code, ..) = refusal(&p, Format::Xps, &gentle);
    assert_eq!(code, "pvtc::emit::acceleration_limit");
    let message = match emit_to_vec(&p, Format::Xps, &gentle) {
        Err(e) => e.to_string(),
        Ok(_) => unreachable!(),
    };
    assert!(message.contains("-69"), "{message}");
    // The other formats leave these limits to the planner.
    assert!(emit_to_vec(&p, Format::PowerPmac, &gentle).is_ok());
    let moving = program(&[(1.0, 2.0, 1.0, 5)]);
    let (code, contour, _, line) = refusal(&moving, Format::Xps, &EmitOptions::default());
    assert_eq!((code, contour, line), ("pvtc::emit::not_at_rest", 1, 5));
}

#[test]
fn every_format_declares_its_rules() {
    for format in Format::ALL {
        let caps = format.caps();
        assert_eq!(caps.max_piece_seconds, format.max_piece_seconds());
        if let Some(q) = caps.default_quantum {
            assert!(caps.min_piece_seconds <= q, "{}", format.name());
        }
    }
    assert_eq!(Format::Pmac.caps().default_quantum, Some(0.001));
    assert_eq!(Format::Galil.caps().buffer_depth, Some(255));
}

#[test]
fn a_piece_over_the_limit_in_whole_counts_is_refused_at_its_line() {
    // 0.0006 mm in 2 samples from rest to rest: planned |a| = 6·0.0006/T² ≈ 944 mm/s²,
    // under 1000; in whole counts (1000/mm) the controller moves 1 count, 6·0.001/T²
    // ≈ 1573 mm/s², over it (Zaber: 2 ms, 900 and 1500 mm/s²).
    let t = 2.0 / 1024.0;
    let p = program(&[(0.0006, 0.0, t, 12)]);
    let planned = 6.0 * 0.0006 / (t * t);
    assert!(planned < 1000.0);
    let options = with_x(AxisSetup {
        counts_per_unit: Some(1000.0),
        max_acceleration: Some(1000.0),
        ..Default::default()
    });
    for format in [Format::Galil, Format::Zaber] {
        let t = if format == Format::Zaber { 0.002 } else { t };
        let p = program(&[(0.0006, 0.0, t, 12)]);
        assert_eq!(
            refusal(&p, format, &options),
            ("pvtc::emit::counts_over_limit", 1, 1, 12),
            "{}",
            format.name()
        );
    }
    // 0.0004 mm rounds to no count at all: nothing moves, nothing is over.
    let still = program(&[(0.0004, 0.0, t, 12)]);
    assert!(emit_to_vec(&still, Format::Galil, &options).is_ok());
    // Where the format writes exact numbers the same piece is kept.
    assert!(emit_to_vec(&p, Format::Csv, &options).is_ok());
}
