//! Random closed profiles under cutter-radius compensation, compared with rs274: star
//! polygons (convex when every corner is on one circle, concave otherwise) whose edges
//! are lines or arcs bulging either way, cut with the tool left or right, clockwise or
//! counter-clockwise, in G17 or G18, with entry and exit moves. Where rs274 refuses a
//! profile (the tool gouges), pvtc must refuse it at the same line with a compensation
//! code.

use super::*;
use proptest::prelude::*;
use proptest::strategy::ValueTree;

#[derive(Debug, Clone)]
struct Profile {
    /// Corners: angle in degrees (sorted when drawn) and distance from the centre.
    corners: Vec<(f64, f64)>,
    /// Per edge: `None` a line, or an arc (clockwise, radius as a multiple of half
    /// the chord, ≥ 1).
    edges: Vec<Option<(bool, f64)>>,
    left: bool,
    reverse: bool,
    lathe: bool,
    diameter: f64,
}

fn profile() -> impl Strategy<Value = Profile> {
    (3usize..9, any::<bool>()).prop_flat_map(|(n, convex)| {
        let radius = if convex {
            Just(20.0).boxed()
        } else {
            (80u32..250).prop_map(|r| f64::from(r) / 10.0).boxed()
        };
        let arc = prop::option::weighted(0.4, (any::<bool>(), 105u32..400))
            .prop_map(|a| a.map(|(cw, k)| (cw, f64::from(k) / 100.0)));
        (
            prop::collection::vec((0u32..3600, radius), n),
            prop::collection::vec(arc, n),
            any::<bool>(),
            any::<bool>(),
            any::<bool>(),
            5u32..40,
        )
            .prop_map(|(corners, edges, left, reverse, lathe, d)| Profile {
                corners: corners
                    .into_iter()
                    .map(|(a, r)| (f64::from(a) / 10.0, r))
                    .collect(),
                edges,
                left,
                reverse,
                lathe,
                diameter: f64::from(d) / 10.0,
            })
    })
}

/// The program text of a profile.
fn program(profile: &Profile) -> String {
    let mut corners = profile.corners.clone();
    corners.sort_by(|a, b| a.0.total_cmp(&b.0));
    corners.dedup_by(|a, b| (a.0 - b.0).abs() < 5.0);
    if profile.reverse {
        corners.reverse();
    }
    let points: Vec<[f64; 2]> = corners
        .iter()
        .map(|(a, r)| {
            let (sin, cos) = libm::sincos(a.to_radians());
            [r * cos, r * sin].map(|v| (v * 1e4).round() / 1e4)
        })
        .collect();
    let (plane, first, second) = if profile.lathe {
        ("G18", "Z", "X")
    } else {
        ("G17", "X", "Y")
    };
    let code = if profile.left { "G41.1" } else { "G42.1" };
    let [sx, sy] = [points[0][0] * 1.8, points[0][1] * 1.8];
    let mut text = format!(
        "G21 G90 {plane} G94 F500\nG0 {first}{sx:.4} {second}{sy:.4}\n{code} D{:.1}\n\
         G1 {first}{:.4} {second}{:.4}\n",
        profile.diameter, points[0][0], points[0][1]
    );
    for (i, edge) in profile.edges.iter().take(points.len()).enumerate() {
        let [x, y] = points[(i + 1) % points.len()];
        match edge {
            None => text.push_str(&format!("G1 {first}{x:.4} {second}{y:.4}\n")),
            Some((cw, k)) => {
                let [px, py] = points[i];
                let r = k * libm::hypot(x - px, y - py) / 2.0;
                let g = if *cw { "G2" } else { "G3" };
                text.push_str(&format!("{g} {first}{x:.4} {second}{y:.4} R{r:.4}\n"));
            }
        }
    }
    text.push_str(&format!("G40\nG0 {first}{sx:.4} {second}{sy:.4}\nM2\n"));
    text
}

/// The line of `text` that rs274's failure names (its last line is the block).
fn refused_lines(text: &str, failure: &str) -> Vec<usize> {
    let block = failure.trim_end().lines().last().unwrap_or("").trim();
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.trim() == block)
        .map(|(i, _)| i + 1)
        .collect()
}

/// `Ok(true)` when both ran and agree, `Ok(false)` when both refused at one line.
fn compare_profile(rs274: &str, text: &str) -> Result<bool, String> {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("profile.ngc");
    std::fs::write(&path, text).expect("written");
    let ours = pvtc_moves(&path);
    match (rs274_moves(rs274, &path), ours) {
        (Ok(theirs), Ok(ours)) => match difference(&ours, &theirs) {
            None => Ok(true),
            Some(d) => Err(d),
        },
        (Err(failure), Err(refusal)) => {
            let lines = refused_lines(text, &failure);
            let at = lines
                .iter()
                .any(|l| refusal.contains(&format!("profile.ngc:{l}:")));
            let coded = [
                "compensation_entry",
                "tool_radius_over_arc",
                "concave_corner",
            ]
            .iter()
            .any(|c| refusal.contains(&format!("pvtc::gcode::{c}")));
            match at && coded {
                true => Ok(false),
                false => Err(format!("both refuse, differently:\n{failure}\n{refusal}")),
            }
        }
        (Err(failure), Ok(_)) => Err(format!("rs274 refuses, pvtc does not: {failure}")),
        (Ok(_), Err(refusal)) => Err(format!("pvtc refuses, rs274 does not: {refusal}")),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(96), ..ProptestConfig::default() })]

    #[test]
    fn random_compensated_profiles_move_as_rs274_moves(profile in profile()) {
        let rs274 = match rs274() {
            Ok(rs274) => rs274,
            Err(why) => {
                eprintln!("SKIPPED: {why}");
                return Ok(());
            }
        };
        let text = program(&profile);
        let compared = compare_profile(rs274, &text);
        prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
    }
}

/// The generator makes profiles both interpreters run, not only refusals.
#[test]
fn most_random_profiles_compile() {
    if rs274().is_err() {
        eprintln!("SKIPPED: no rs274");
        return;
    }
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let mut ran = 0;
    for _ in 0..24 {
        let profile = profile()
            .new_tree(&mut runner)
            .expect("a profile")
            .current();
        let text = program(&profile);
        match compare_profile("rs274", &text) {
            Ok(true) => ran += 1,
            Ok(false) => {}
            Err(d) => panic!("{text}\n{d}"),
        }
    }
    assert!(ran >= 12, "only {ran} of 24 profiles ran in both");
}
