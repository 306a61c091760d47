//! G5 and G5.1 splines: the Bézier each block makes, against LinuxCNC's definition
//! written out here (G5: control points start + (I, J) and end + (P, Q), a G5 without
//! I J taking the previous P Q negated; G5.1: the quadratic through start + (I, J),
//! evaluated in its own Bernstein form), random control points included; the refusals
//! with their codes at their lines; and, against LinuxCNC's `rs274`, which blocks it
//! accepts and how many points each curve it hands on has (`NURBS_FEED(4, …)` for G5,
//! `(3, …)` for G5.1: `rs274 -g` prints no control points, so the shape is checked
//! against the definition). Without rs274 the differential test says SKIPPED; with
//! `PVTC_REQUIRE_RS274=1` it fails instead.

mod common;

use common::bezier_elements;

use proptest::prelude::*;
use pvt_core::{Element, ElementKind};
use pvt_gcode::{compile, GcodeOptions};

/// The cubic's point at `u` from its Bernstein form.
fn cubic(p: [[f64; 2]; 4], u: f64) -> [f64; 2] {
    let s = 1.0 - u;
    let w = [s * s * s, 3.0 * s * s * u, 3.0 * s * u * u, u * u * u];
    [0, 1].map(|k| (0..4).map(|i| w[i] * p[i][k]).sum())
}

fn points_of(e: &Element) -> [[f64; 2]; 4] {
    let ElementKind::Bezier(b) = e.kind else {
        panic!("not a Bézier: {e:?}");
    };
    [
        [e.start[0], e.start[1]],
        b.controls[0],
        b.controls[1],
        [e.end[0], e.end[1]],
    ]
}

fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
}

#[test]
fn g5_continues_and_g51_is_its_quadratic() {
    let e = bezier_elements(
        "G21 G17 G90 F600\nG0 X1 Y2\nG5 I5 J10 P-5 Q10 X10 Y0\nG5 P-5 Q-10 X20 Y0\nG5.1 I5 J5 X30 Y0\n",
    );
    assert_eq!(e.len(), 3);
    assert_eq!(
        points_of(&e[0]),
        [[1.0, 2.0], [6.0, 12.0], [5.0, 10.0], [10.0, 0.0]]
    );
    // I J left out: the previous P Q negated, from this block's start.
    assert_eq!(
        points_of(&e[1]),
        [[10.0, 0.0], [15.0, -10.0], [15.0, -10.0], [20.0, 0.0]]
    );
    let q = [[20.0, 0.0], [25.0, 5.0], [30.0, 0.0]];
    for k in 0..=32 {
        let u = f64::from(k) / 32.0;
        let s = 1.0 - u;
        let want = [0, 1].map(|c| s * s * q[0][c] + 2.0 * s * u * q[1][c] + u * u * q[2][c]);
        assert!(close(cubic(points_of(&e[2]), u), want, 1e-12));
    }
}

#[test]
fn inches_and_incremental_scale_the_offsets() {
    // Millimetres out (the first units); the spline block in inches, incremental.
    let e = bezier_elements("G21 G17 F600\nG0 X0 Y0\nG20 G91\nG5 I1 J1 P-1 Q1 X2 Y0\n");
    let p = points_of(&e[0]);
    assert!(close(p[1], [25.4, 25.4], 1e-12) && close(p[2], [25.4, 25.4], 1e-12));
    assert!(close(p[3], [50.8, 0.0], 1e-12));
}

fn errors(source: &str) -> Vec<(&'static str, usize)> {
    let errors = compile(source, &GcodeOptions::default()).expect_err("the program must fail");
    errors
        .diagnostics
        .iter()
        .map(|d| {
            let line = source[..d.span().start].matches('\n').count() + 1;
            (d.code().trim_start_matches("pvtc::gcode::"), line)
        })
        .collect()
}

#[test]
fn refusals_have_their_codes_at_their_lines() {
    let head = "G21 G90 G17 F100\nG0 X0 Y0\n";
    let cases = [
        ("G5 X10 Y0 Z1 I1 J1 P1 Q1\n", ("unsupported", 3)),
        ("G18\nG5 X10 Y0 I1 J1 P1 Q1\n", ("unsupported", 4)),
        ("G5 X10 Y0 I1 P1 Q1\n", ("missing_word", 3)),
        ("G5 X10 Y0 I1 J1 P1\n", ("missing_word", 3)),
        ("G5 X10 Y0 P1 Q1\n", ("missing_word", 3)),
        ("G5.1 X10 Y0 I1\n", ("missing_word", 3)),
        (
            "G41.1 D1\nG1 X5 Y-5\nG5 I5 J10 P-5 Q10 X10 Y0\n",
            ("compensation_conflict", 5),
        ),
    ];
    for (body, want) in cases {
        let source = format!("{head}{body}M2\n");
        assert_eq!(errors(&source), [want], "{body}");
    }
}

/// A random run of G5 (with or without I J after the first) and G5.1 blocks.
fn program() -> impl Strategy<Value = Vec<(u8, [f64; 6])>> {
    prop::collection::vec((0u8..3, prop::array::uniform6(-20.0..20.0f64)), 1..6)
}

fn text(blocks: &[(u8, [f64; 6])]) -> String {
    let mut s = String::from("G21 G17 G90 F600\nG0 X0 Y0\n");
    let (mut x, mut y) = (0.0, 0.0);
    let round = |v: f64| (v * 1e4).round() / 1e4;
    for (i, (kind, v)) in blocks.iter().enumerate() {
        let (ex, ey) = (round(x + v[4]), round(y + v[5]));
        let line = match kind {
            0 => format!("G5.1 X{ex:.4} Y{ey:.4} I{:.4} J{:.4}", v[0], v[1]),
            1 if i > 0 && blocks[..i].iter().any(|b| b.0 != 0) => {
                format!("G5 X{ex:.4} Y{ey:.4} P{:.4} Q{:.4}", v[2], v[3])
            }
            _ => format!(
                "G5 X{ex:.4} Y{ey:.4} I{:.4} J{:.4} P{:.4} Q{:.4}",
                v[0], v[1], v[2], v[3]
            ),
        };
        s += &line;
        s.push('\n');
        (x, y) = (ex, ey);
    }
    s + "M2\n"
}

/// The expected control points of each block, from the definition.
fn expected(blocks: &[(u8, [f64; 6])]) -> Vec<[[f64; 2]; 4]> {
    let round = |v: f64| (v * 1e4).round() / 1e4;
    let (mut at, mut last_pq) = ([0.0, 0.0], None::<[f64; 2]>);
    let mut out = Vec::new();
    for (i, (kind, v)) in blocks.iter().enumerate() {
        let end = [round(at[0] + v[4]), round(at[1] + v[5])];
        let (ij, pq) = ([round(v[0]), round(v[1])], [round(v[2]), round(v[3])]);
        let points = if *kind == 0 {
            let q = [at[0] + ij[0], at[1] + ij[1]];
            let third = |a: [f64; 2]| {
                [
                    a[0] + 2.0 / 3.0 * (q[0] - a[0]),
                    a[1] + 2.0 / 3.0 * (q[1] - a[1]),
                ]
            };
            [at, third(at), third(end), end]
        } else {
            let continues = *kind == 1 && i > 0 && blocks[..i].iter().any(|b| b.0 != 0);
            let first = match (continues, last_pq) {
                (true, Some(p)) => [-p[0], -p[1]],
                _ => ij,
            };
            last_pq = Some(pq);
            [
                at,
                [at[0] + first[0], at[1] + first[1]],
                [end[0] + pq[0], end[1] + pq[1]],
                end,
            ]
        };
        out.push(points);
        at = end;
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every block's Bézier, evaluated densely, is the one the definition gives.
    #[test]
    fn random_splines_are_the_defined_curves(blocks in program()) {
        let source = text(&blocks);
        let got: Vec<Element> = bezier_elements(&source);
        let want = expected(&blocks);
        prop_assert_eq!(got.len(), want.len());
        for (e, w) in got.iter().zip(&want) {
            for k in 0..=16 {
                let u = f64::from(k) / 16.0;
                prop_assert!(close(cubic(points_of(e), u), cubic(*w, u), 1e-9), "{}", source);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// rs274 accepts every random spline program pvtc accepts, with one curve of 4
    /// points per G5 and of 3 per G5.1.
    #[test]
    fn rs274_reads_the_same_curves(blocks in program()) {
        let source = text(&blocks);
        let Some(reading) = common::rs274_nurbs_counts(&source, "splines-random") else {
            eprintln!("SKIPPED: rs274 is not installed");
            return Ok(());
        };
        let counts = reading.map_err(|e| TestCaseError::fail(format!("{source}\n{e}")))?;
        let ours: Vec<usize> = blocks.iter().map(|b| if b.0 == 0 { 3 } else { 4 }).collect();
        prop_assert_eq!(counts, ours, "{}", source);
        prop_assert_eq!(bezier_elements(&source).len(), blocks.len());
    }
}

/// The programs pvtc refuses, rs274 refuses too (the one LinuxCNC's documentation
/// calls an error, a first G5 without I J, is refused by pvtc alone: rs274 2.9 takes
/// stale values).
#[test]
fn rs274_refuses_what_pvtc_refuses() {
    let head = "G21 G90 G17 F100\nG0 X0 Y0\n";
    for body in [
        "G5 X10 Y0 Z1 I1 J1 P1 Q1\n",
        "G18\nG5 X10 Y0 I1 J1 P1 Q1\n",
        "G5 X10 Y0 I1 P1 Q1\n",
        "G5 X10 Y0 I1 J1 P1\n",
        "G5.1 X10 Y0 I1\n",
        "G41.1 D1\nG1 X5 Y-5\nG5 I5 J10 P-5 Q10 X10 Y0\n",
    ] {
        let source = format!("{head}{body}M2\n");
        let Some(reading) = common::rs274_nurbs_counts(&source, "splines-refused") else {
            eprintln!("SKIPPED: rs274 is not installed");
            return;
        };
        assert!(reading.is_err(), "rs274 accepts {body}");
        assert!(compile(&source, &GcodeOptions::default()).is_err());
    }
}
