//! `check` of one source entity of thousands of elements: a 4,000-vertex LWPOLYLINE
//! (every element on one DXF line), made here. Its path error must be the largest
//! distance from the motion to the polyline that the independent reference measures
//! (`reference::deviation`). The time it takes is a figure of the README (`pvtc
//! check`), not of this test.

use pvt_core::{check_program, CheckOptions};
use pvt_emit::Format;
use pvtc::{CompileOptions, InputKind, Source};
use pvtc_tests::reference;

/// Vertices of the polyline: a sine wave sampled every 0.5 mm, with a bulge (an arc) on
/// every `bulge_every`-th segment when given.
fn vertices(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| (i as f64 * 0.5, 5.0 * libm::sin(i as f64 * 0.05)))
        .collect()
}

/// A DXF of the polyline as one LWPOLYLINE.
fn drawing(n: usize, bulge_every: Option<usize>) -> String {
    let mut out = String::from(
        "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n",
    );
    out += &format!("0\nLWPOLYLINE\n5\n2F\n8\nCUT\n90\n{n}\n70\n0\n");
    for (i, (x, y)) in vertices(n).iter().enumerate() {
        out += &format!("10\n{x}\n20\n{y}\n");
        if bulge_every.is_some_and(|k| i % k == 0) {
            out += "42\n0.2\n";
        }
    }
    out + "0\nENDSEC\n0\nEOF\n"
}

fn plan(text: &str) -> (pvt_core::PvtProgram, pvt_core::Toolpath) {
    let mut options = CompileOptions::new(Format::Json);
    options.input = InputKind::Dxf;
    options.feed = Some(1200.0);
    let source = Source::from_text("polyline.dxf", text);
    let (planned, toolpath, _) =
        pvtc::plan(&source, &options).unwrap_or_else(|f| panic!("{:?}", f.codes()));
    (planned.program, toolpath)
}

/// The check's path error against the reference's largest sampled distance: the check
/// refines its worst sample, the reference samples 48 points a piece, so they agree
/// closely, and neither exceeds the tolerance the planner kept.
fn assert_matches_reference(program: &pvt_core::PvtProgram, toolpath: &pvt_core::Toolpath) {
    let report = check_program(program, Some(toolpath), &CheckOptions::default());
    let checked = report.max_path_error().unwrap();
    let tolerance = pvt_core::ChordTolerance::DEFAULT_MM;
    let measured = reference::deviation(program, toolpath, 10.0 * tolerance).error;
    assert!(checked <= tolerance * (1.0 + 1e-9), "{checked}");
    assert!(
        (checked - measured).abs() <= 0.02 * measured,
        "check {checked}, reference {measured}"
    );
}

#[test]
fn a_4000_vertex_polyline_is_checked_against_every_element() {
    let (program, toolpath) = plan(&drawing(4000, None));
    assert_eq!(
        toolpath
            .contours
            .iter()
            .map(|c| c.elements.len())
            .sum::<usize>(),
        3999
    );
    assert_matches_reference(&program, &toolpath);
}

#[test]
fn a_polyline_of_bulges_is_checked_against_its_arcs() {
    let (program, toolpath) = plan(&drawing(600, Some(2)));
    assert_matches_reference(&program, &toolpath);
}
