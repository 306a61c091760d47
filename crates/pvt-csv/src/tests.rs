//! Unit tests of the CSV front end: columns, rows and their diagnostics.

use super::*;
use proptest::prelude::*;
use pvt_core::{check_program, plan_timed, CheckOptions, PlanOptions, Planner};

const STEP: &str = include_str!("../../../samples/csv/an208_step.csv");
const ZIGZAG: &str = include_str!("../../../samples/csv/an208_zigzag.csv");
const OCTAGON: &str = include_str!("../../../samples/csv/an208_octagon.csv");

fn read(text: &str) -> PointSeries {
    read_points(text, Units::Millimetre).unwrap()
}

fn codes(text: &str) -> Vec<(&'static str, u32, u32)> {
    let errors = read_points(text, Units::Millimetre).unwrap_err();
    errors
        .diagnostics
        .iter()
        .map(|d| (d.code(), d.line, d.column))
        .collect()
}

#[test]
fn samples_hold_seed_001_series() {
    let step = read(STEP);
    assert_eq!(step.axes, vec![Axis::X]);
    assert_eq!(
        step.points.coords,
        vec![0.0, 0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0, 5000.0]
    );
    assert_eq!(step.points.durations, vec![0.25; 7]);
    assert_eq!(step.points.velocities, Some(vec![0.0; 8]));
    let zigzag = read(ZIGZAG);
    assert_eq!(zigzag.axes, vec![Axis::X, Axis::Y]);
    assert_eq!(
        zigzag.points.coords,
        vec![0.0, 0.0, 5000.0, 0.0, 0.0, 10000.0, 5000.0, 1000.0]
    );
    assert_eq!(
        zigzag.points.velocities.as_deref().unwrap()[2..4],
        [20000.0, 0.0]
    );
    let octagon = read(OCTAGON);
    assert_eq!(octagon.points.len(), 9);
    assert!(octagon.points.velocities.is_none());
    for i in 0..9 {
        let p = octagon.points.point(i);
        assert!(((p[0] * p[0] + (p[1] - 5000.0) * (p[1] - 5000.0)).sqrt() - 5000.0).abs() < 1e-9);
    }
    assert_eq!(octagon.points.lines[0], 6);
}

#[test]
fn pt_step_from_csv_reaches_4e7() {
    let step = read(STEP);
    let options = PlanOptions {
        planner: Planner::Pt,
        ..PlanOptions::default()
    };
    let program = plan_timed(&step.points, step.axes.clone(), step.units, &options)
        .unwrap()
        .program;
    let report = check_program(&program, Some(&step.toolpath()), &CheckOptions::default());
    let x = report.axis(Axis::X).unwrap();
    assert!((x.sampled_acceleration.value / 4.0e7 - 1.0).abs() < 1e-6);
    assert!(report.max_path_error().unwrap() < 1e-9);
}

#[test]
fn dt_columns_any_case_and_comments() {
    let s = read("# made by hand\n\nDT , X, vX\n0.5, 1, 0\n# dwell next\n0.25, 3, 2\n0.25, 3, 0\n");
    assert_eq!(s.start_time, 0.5);
    assert_eq!(s.points.durations, vec![0.25, 0.25]);
    assert_eq!(s.points.lines, vec![6, 7]);
    assert_eq!(s.points.velocities, Some(vec![0.0, 2.0, 0.0]));
    let tp = s.toolpath();
    assert_eq!(tp.contours[0].elements[0].feed, 8.0);
    assert_eq!(tp.contours[0].elements[1].feed, 0.0);
}

#[test]
fn every_bad_row_is_reported() {
    let text = "t,x,y\n0,0,0\n1,2\n2,abc,1\n3,inf,NaN\n2.5,1,1\n4,1,1\n";
    assert_eq!(
        codes(text),
        vec![
            ("pvtc::csv::wrong_field_count", 3, 1),
            ("pvtc::csv::not_a_number", 4, 3),
            ("pvtc::csv::not_finite", 5, 3),
            ("pvtc::csv::not_finite", 5, 7),
        ]
    );
    assert_eq!(
        codes("t,x\n0,0\n1,1\n1,2\n0.5,3\n"),
        vec![
            ("pvtc::csv::non_increasing_time", 4, 1),
            ("pvtc::csv::non_increasing_time", 5, 1)
        ]
    );
    assert_eq!(
        codes("dt,x\n0,0\n0,1\n"),
        vec![("pvtc::csv::non_increasing_time", 3, 1)]
    );
}

#[test]
fn header_errors() {
    assert_eq!(codes(""), vec![("pvtc::csv::missing_header", 1, 1)]);
    assert_eq!(
        codes("# only\n0,1\n"),
        vec![("pvtc::csv::missing_header", 2, 1)]
    );
    assert_eq!(codes("t,x,q\n"), vec![("pvtc::csv::unknown_column", 1, 5)]);
    // A byte order mark is not a column (the same count as G-code's, pvt_core::text).
    assert_eq!(
        codes("\u{feff}t,x,q\n"),
        vec![("pvtc::csv::unknown_column", 1, 5)]
    );
    assert_eq!(
        codes("t,x,dt\n"),
        vec![("pvtc::csv::duplicate_column", 1, 5)]
    );
    assert_eq!(codes("x,y\n"), vec![("pvtc::csv::no_time_column", 1, 1)]);
    assert_eq!(
        codes("t,vx\n"),
        vec![
            ("pvtc::csv::no_axis_column", 1, 1),
            ("pvtc::csv::incomplete_velocities", 1, 3)
        ]
    );
    assert_eq!(
        codes("t,x,y,vx\n"),
        vec![("pvtc::csv::incomplete_velocities", 1, 1)]
    );
    assert_eq!(
        codes("t,x\n# nothing\n"),
        vec![("pvtc::csv::no_rows", 1, 4)]
    );
}

#[test]
fn diagnostics_render_with_code_and_label() {
    use miette::Diagnostic;
    let errors = read_points("t,x\n0,zz\n", Units::Inch).unwrap_err();
    let d = &errors.diagnostics[0];
    assert_eq!(
        Diagnostic::code(d).unwrap().to_string(),
        "pvtc::csv::not_a_number"
    );
    assert_eq!(d.span, 6..8);
    assert_eq!(d.labels().unwrap().count(), 1);
}

proptest! {
    #[test]
    fn never_panics_on_any_text(text in "\\PC{0,200}") {
        let _ = read_points(&text, Units::Millimetre);
    }

    #[test]
    fn never_panics_on_csv_like_text(
        rows in proptest::collection::vec(
            proptest::collection::vec(prop_oneof!["t", "dt", "x", "Y", "vx", "q", "", "1", "-2.5", "nan", "1e400", "0", " 3 ", "#"], 0..6),
            0..8,
        )
    ) {
        let text: String = rows.iter().map(|r| r.join(",") + "\r\n").collect();
        if let Ok(series) = read_points(&text, Units::Millimetre) {
            prop_assert!(series.points.validate().is_ok() || series.points.velocities.is_some());
        }
    }
}

#[test]
fn a_trigger_column_is_read_and_kept_out_of_the_motion() {
    let plain = read("t,x\n0,0\n1,5\n2,5\n");
    let triggered = read("t,x,trigger\n0,0,0\n1,5,1\n2,5,0\n");
    assert_eq!(plain.points, triggered.points);
    assert_eq!(
        codes("t,x,trigger\n0,0,0\n1,5,0.5\n"),
        vec![("pvtc::csv::bad_trigger", 3, 5)]
    );
}
