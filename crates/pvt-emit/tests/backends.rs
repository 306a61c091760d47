//! Back-end tests on a small hand-made program: exact text, round trips, validation.

use pvt_core::{Axis, Interpolation, Motion, PvtContour, PvtProgram, Units};
use pvt_emit::{emit_to_vec, json, EmitOptions, Format, StreamError};

fn program() -> PvtProgram {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0, 0.0]);
    c.push(
        &[10.0, 0.0],
        &[70.71067811865476, 70.71067811865476],
        0.2,
        3,
    );
    c.push(&[10.0, 10.0], &[0.0, 0.0], 0.2005, 4);
    PvtProgram {
        axes: vec![Axis::X, Axis::Y],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

fn options() -> EmitOptions {
    EmitOptions {
        source: "corner.ngc".into(),
        settings: vec![("planner".into(), "contour".into())],
        ..Default::default()
    }
}

fn text(format: Format) -> String {
    String::from_utf8(emit_to_vec(&program(), format, &options()).unwrap()).unwrap()
}

#[test]
fn pmac_lines_carry_time_then_positions_and_velocities() {
    let t = text(Format::Pmac);
    let body: Vec<&str> = t.lines().filter(|l| !l.starts_with(';')).collect();
    assert_eq!(
        body,
        [
            "OPEN PROG 1 CLEAR",
            "ABS",
            "PVT200.0000",
            "TA200.0000 X10.000000000:70.710678119 Y0.000000000:70.710678119",
            "TA200.5000 X10.000000000:0.000000000 Y10.000000000:0.000000000",
            "CLOSE"
        ]
    );
    assert!(t.contains("; warning: 1 of 2 piece times are not whole ms"));
}

#[test]
fn json_reads_back_bit_for_bit() {
    let t = text(Format::Json);
    let value: serde_json::Value = serde_json::from_str(&t).unwrap();
    assert_eq!(value["axes"], serde_json::json!(["X", "Y"]));
    assert_eq!(value["contours"][0]["kind"], "feed");
    assert_eq!(value["contours"][0]["segments"][1]["line"], 4);
    assert_eq!(json::read(&t).unwrap(), program());
}

/// Every event reads back as it was written, so `pvtc check` on a JSON program knows where
/// the machine rests (a dwell, a pause, a tool change) as it does on the source.
#[test]
fn json_reads_events_back() {
    use pvt_core::{CoolantState, EventKind, ProgramEvent, SpindleState};
    let kinds = [
        EventKind::Dwell { seconds: 0.25 },
        EventKind::Pause { optional: false },
        EventKind::Pause { optional: true },
        EventKind::Spindle {
            state: SpindleState::Clockwise,
        },
        EventKind::Spindle {
            state: SpindleState::CounterClockwise,
        },
        EventKind::Spindle {
            state: SpindleState::Off,
        },
        EventKind::SpindleSpeed { rpm: 12000.0 },
        EventKind::Coolant {
            state: CoolantState::Mist,
        },
        EventKind::Coolant {
            state: CoolantState::Flood,
        },
        EventKind::Coolant {
            state: CoolantState::Off,
        },
        EventKind::ToolSelect { tool: 7 },
        EventKind::ToolChange,
        EventKind::Message {
            text: "check \"part\" 1".into(),
        },
    ];
    let code = |code, p, e, q| {
        let words = pvt_core::CodeWords { p, e, q, l: None };
        EventKind::machine_code(code, words).expect("an I/O or user M code")
    };
    let kinds = [
        kinds.to_vec(),
        vec![
            code(62, Some(1.0), None, None),
            code(67, None, Some(0.0), Some(-2.5)),
            code(101, Some(4.0), None, Some(5.0)),
        ],
    ]
    .concat();
    let mut p = program();
    p.events = kinds
        .iter()
        .enumerate()
        .map(|(i, kind)| ProgramEvent {
            before_contour: usize::from(i >= 6),
            kind: kind.clone(),
            line: 10 + i as u32,
        })
        .collect();
    let t = String::from_utf8(emit_to_vec(&p, Format::Json, &options()).unwrap()).unwrap();
    assert_eq!(json::read(&t).unwrap(), p);
    let unknown = t.replacen("\"event\": \"tool_change\"", "\"event\": \"teleport\"", 1);
    let err = json::read(&unknown).unwrap_err().to_string();
    assert!(
        err.contains("event 12: unknown event \"teleport\""),
        "{err}"
    );
    // A code's name and number agree.
    let renamed = t.replacen("\"event\": \"user_m_code\"", "\"event\": \"wait_input\"", 1);
    assert_ne!(renamed, t);
    assert!(json::read(&renamed).is_err(), "M101 is not wait_input");
    // A dwell needs its seconds.
    let bare = t.replacen(", \"seconds\": 0.25", "", 1);
    assert_ne!(bare, t);
    let err = json::read(&bare).unwrap_err().to_string();
    assert!(
        err.contains("event 1: unknown event \"dwell\" or a value it needs is missing"),
        "{err}"
    );
    // Events come in the order of the contours they precede: the first moved after the
    // second.
    let first = "{\"before_contour\": 0, \"event\": \"dwell\"";
    assert!(t.contains(first), "{t}");
    let out_of_order = t.replacen(first, "{\"before_contour\": 1, \"event\": \"dwell\"", 1);
    let err = json::read(&out_of_order).unwrap_err().to_string();
    assert!(err.contains("event 2: before contour 0"), "{err}");
}

/// A piece time that is zero or negative is refused when read, not checked as an
/// infinite acceleration or out of order.
#[test]
fn json_refuses_a_piece_time_that_is_not_positive() {
    let t = text(Format::Json);
    let value: serde_json::Value = serde_json::from_str(&t).unwrap();
    let time = value["contours"][0]["segments"][1]["t"].to_string();
    for bad in ["0.0", "-0.2"] {
        let edited = t.replacen(&format!("\"t\": {time}"), &format!("\"t\": {bad}"), 1);
        assert_ne!(edited, t, "the second piece's time was not found");
        let err = json::read(&edited).unwrap_err().to_string();
        assert!(
            err.contains("contour 1, segment 2: time") && err.contains("not a positive"),
            "{err}"
        );
    }
}

#[test]
fn movepvt_declares_interleaved_arrays() {
    let t = text(Format::MovePvt);
    let body = &t[t.find("#define PVTC_AXIS_COUNT").unwrap()..];
    let expected = "#define PVTC_AXIS_COUNT 2

/* contour 1: feed */
static double pvtc_c1_start[PVTC_AXIS_COUNT] = {
    0.0, 0.0,
};
static double pvtc_c1_position[] = {
    10.0, 0.0,
    10.0, 10.0,
};
static double pvtc_c1_velocity[] = {
    70.71067811865476, 70.71067811865476,
    0.0, 0.0,
};
static double pvtc_c1_time[] = {
    0.2,
    0.2005,
};
#define PVTC_C1_POINTS ((long)(sizeof pvtc_c1_time / sizeof pvtc_c1_time[0]))

#define PVTC_CONTOUR_COUNT 1
";
    assert!(body.starts_with(expected), "{body}");
    assert!(body.contains("{\"feed\", PVTC_C1_POINTS, pvtc_c1_start, pvtc_c1_position, pvtc_c1_velocity, pvtc_c1_time},"));
}

#[test]
fn pmac_refuses_pt_and_json_marks_it() {
    let mut p = program();
    p.interpolation = Interpolation::Pt;
    assert!(matches!(
        emit_to_vec(&p, Format::Pmac, &options()),
        Err(StreamError::Unsupported(Interpolation::Pt))
    ));
    let t = String::from_utf8(emit_to_vec(&p, Format::Json, &options()).unwrap()).unwrap();
    assert!(t.contains("\"interpolation\": \"pt\""));
    assert_eq!(json::read(&t).unwrap().interpolation, Interpolation::Pt);
}

#[test]
fn nan_and_non_positive_times_never_reach_an_output() {
    for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
        let mut p = program();
        p.contours[0].durations[1] = bad;
        for format in Format::ALL {
            match emit_to_vec(&p, format, &options()) {
                Err(StreamError::Invalid(e)) => {
                    assert_eq!((e.contour, e.segment, e.line), (1, 2, 4))
                }
                other => panic!("{format:?} with time {bad}: {other:?}"),
            }
        }
    }
    let mut p = program();
    p.contours[0].velocities[0] = f64::NAN;
    assert!(matches!(
        emit_to_vec(&p, Format::Json, &options()),
        Err(StreamError::Invalid(_))
    ));
}

#[test]
fn pmac_refuses_a_piece_over_4095_ms_that_others_take() {
    let mut p = program();
    p.contours[0].durations[1] = 4.095;
    assert!(emit_to_vec(&p, Format::Pmac, &options()).is_ok());
    p.contours[0].durations[1] = 4.0951;
    match emit_to_vec(&p, Format::Pmac, &options()) {
        Err(StreamError::Invalid(e)) => {
            assert_eq!((e.contour, e.segment, e.line), (1, 2, 4));
            assert!(e.what.contains("longest"), "{}", e.what);
            assert!(!e.internal && !e.to_string().contains("internal"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    for format in [Format::Json, Format::MovePvt] {
        assert!(emit_to_vec(&p, format, &options()).is_ok(), "{format:?}");
    }
}

#[test]
fn events_come_out_at_rest_between_contours() {
    use pvt_core::{EventKind, ProgramEvent, SpindleState};
    let mut p = program();
    p.events = vec![
        ProgramEvent {
            before_contour: 0,
            kind: EventKind::SpindleSpeed { rpm: 12000.0 },
            line: 1,
        },
        ProgramEvent {
            before_contour: 0,
            kind: EventKind::Dwell { seconds: 0.5 },
            line: 2,
        },
        ProgramEvent {
            before_contour: 1,
            kind: EventKind::Spindle {
                state: SpindleState::Off,
            },
            line: 9,
        },
    ];
    let pmac = String::from_utf8(emit_to_vec(&p, Format::Pmac, &options()).unwrap()).unwrap();
    let lines: Vec<&str> = pmac.lines().collect();
    let dwell = lines
        .iter()
        .position(|l| *l == "DWELL500.0000 ; G4 from line 2")
        .unwrap();
    let first_piece = lines.iter().position(|l| l.starts_with("TA")).unwrap();
    let off = lines
        .iter()
        .position(|l| *l == "; event spindle_off from line 9")
        .unwrap();
    assert!(dwell < first_piece && first_piece < off, "{pmac}");
    assert!(pmac.contains("; event spindle_speed from line 1: 12000 rpm"));

    let json = String::from_utf8(emit_to_vec(&p, Format::Json, &options()).unwrap()).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        v["events"][1],
        serde_json::json!({"before_contour": 0, "event": "dwell", "line": 2, "seconds": 0.5})
    );
    assert_eq!(v["events"][2]["before_contour"], 1);
    assert_eq!(v["events"][2]["event"], "spindle_off");

    let c = String::from_utf8(emit_to_vec(&p, Format::MovePvt, &options()).unwrap()).unwrap();
    let event = c.find("/* event at rest: spindle_off (line 9) */").unwrap();
    assert!(
        c.find("#define PVTC_C1_POINTS").unwrap() < event,
        "the contour is closed before the event"
    );
}

#[test]
fn pt_motion_becomes_movept_arrays_without_velocities() {
    let mut p = program();
    p.interpolation = Interpolation::Pt;
    // PT velocities are each piece's chord / time, which MovePT computes itself.
    p.contours[0].velocities = vec![50.0, 0.0, 0.0, 49.875_311_720_698_25];
    let c = String::from_utf8(emit_to_vec(&p, Format::MovePvt, &options()).unwrap()).unwrap();
    assert!(
        c.starts_with("/* MovePT arrays generated by pvtc from corner.ngc"),
        "{c}"
    );
    assert!(
        c.contains(" *   MovePT(pvtc_cN_position, pvtc_cN_time, PVTC_CN_POINTS, -1, false, true);")
    );
    assert!(!c.contains("_velocity[]") && !c.contains("MovePVT("), "{c}");
    assert!(c.contains("static double pvtc_c1_position[] = {\n    10.0, 0.0,\n    10.0, 10.0,\n};"));
    assert!(c.contains("static double pvtc_c1_time[] = {\n    0.2,\n    0.2005,\n};"));
    assert!(c.contains("pvtc_c1_position, 0, pvtc_c1_time},"), "{c}");
    assert!(matches!(
        emit_to_vec(&p, Format::Pmac, &options()),
        Err(StreamError::Unsupported(Interpolation::Pt))
    ));
}
