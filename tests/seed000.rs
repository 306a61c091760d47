//! The contour planner against an independent implementation of seed 000, through the
//! whole pipeline: G-code text in, JSON out, compared segment by segment.

use proptest::prelude::*;
use pvtc_tests::{close, compile_gcode_to_program, root, seed000};

/// Compares a single-contour program with seed 000 run on the same points.
fn assert_matches_seed000(program: &pvt_core::PvtProgram, points: &[[f64; 2]], vspec: f64) {
    let expected = seed000(points, vspec);
    assert_eq!(program.contours.len(), 1, "one feed contour");
    let contour = &program.contours[0];
    assert_eq!(contour.len(), expected.len());
    let scale = vspec.max(1.0);
    for (i, (seg, want)) in contour.segments().zip(&expected).enumerate() {
        assert!(
            close(seg.duration, want.t, 1e-6, 0.0),
            "segment {i}: t {} vs {}",
            seg.duration,
            want.t
        );
        for k in 0..2 {
            assert!(
                close(seg.end[k], want.p[k], 1e-6, 1e-9),
                "segment {i} p[{k}]"
            );
            assert!(
                close(seg.velocity[k], want.v[k], 1e-6, 1e-9 * scale),
                "segment {i} v[{k}]: {} vs {}",
                seg.velocity[k],
                want.v[k]
            );
        }
    }
}

#[test]
fn octagon_matches_seed_000() {
    let text = std::fs::read_to_string(root().join("samples/gcode/an208_octagon.ngc")).unwrap();
    let program = compile_gcode_to_program("an208_octagon.ngc", &text);
    assert_eq!(program.axes.len(), 2);
    let mut points = vec![[0.0, 0.0]];
    for line in text
        .lines()
        .filter(|l| !l.starts_with('(') && l.contains('X'))
    {
        let word = |letter: char| -> f64 {
            let i = line.find(letter).unwrap() + 1;
            line[i..]
                .split_whitespace()
                .next()
                .unwrap()
                .parse()
                .unwrap()
        };
        points.push([word('X'), word('Y')]);
    }
    assert_eq!(points.len(), 9);
    assert_matches_seed000(&program, &points, 1_200_000.0 / 60.0);
}

fn polyline_program(points: &[[f64; 2]], feed: f64) -> String {
    let mut text = format!(
        "G21 G90\nG0 X{} Y{}\nG1 F{feed}\n",
        points[0][0], points[0][1]
    );
    for p in &points[1..] {
        text.push_str(&format!("X{} Y{}\n", p[0], p[1]));
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any G1 polyline at any feed: points on a 0.001 grid, no repeats, no reversals.
    #[test]
    fn any_g1_polyline_matches_seed_000(
        raw in prop::collection::vec((-100_000i64..100_000, -100_000i64..100_000), 3..40),
        feed_milli in 1_000i64..100_000_000,
    ) {
        let mut points: Vec<[f64; 2]> = Vec::new();
        for (x, y) in raw {
            let p = [x as f64 / 1000.0, y as f64 / 1000.0];
            let keep = match points.as_slice() {
                [.., a, b] => {
                    let (u, w) = ([b[0] - a[0], b[1] - a[1]], [p[0] - b[0], p[1] - b[1]]);
                    let cross = u[0] * w[1] - u[1] * w[0];
                    let dot = u[0] * w[0] + u[1] * w[1];
                    p != *b && !(cross == 0.0 && dot < 0.0)
                }
                [b] => p != *b,
                [] => true,
            };
            if keep { points.push(p); }
        }
        prop_assume!(points.len() >= 3 && points[0] != [0.0, 0.0]);
        let feed = feed_milli as f64 / 1000.0;
        let program = compile_gcode_to_program("random.ngc", &polyline_program(&points, feed));
        // The rapid to the first point is its own contour; the feed contour follows.
        prop_assert_eq!(program.contours.len(), 2);
        let feed_only = pvt_core::PvtProgram { contours: vec![program.contours[1].clone()], ..program };
        assert_matches_seed000(&feed_only, &points, feed / 60.0);
    }
}
