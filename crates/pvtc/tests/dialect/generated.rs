//! Random programs over the dialect both interpreters run: lines and rapids, arcs in
//! every plane by centre with helical motion and extra turns, absolute and incremental
//! distances, unit switches, feeds, dwells and G92 offsets.

use super::*;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Step {
    Straight {
        rapid: bool,
        to: [f64; 3],
    },
    Arc {
        clockwise: bool,
        radius: f64,
        from: f64,
        sweep: f64,
        rise: f64,
        turns: u32,
    },
    Plane(usize),
    Incremental(bool),
    Inches(bool),
    Feed(f64),
    Dwell(f64),
    Offset([f64; 2]),
    /// A canned cycle then G80: the code (G73 G81 G82 G83 G85 G89), G99, the hole
    /// (absolute, or the step under G91), R from the start, the depth, Q, L.
    Cycle {
        code: usize,
        to_r: bool,
        hole: [f64; 2],
        r: f64,
        depth: f64,
        q: f64,
        repeats: u32,
    },
    /// A G1 to polar `@` radius, `^` angle (degrees), in G17.
    Polar {
        radius: f64,
        angle: f64,
    },
    /// `G10 L2 P1 R` (degrees) then a G1 back to the program position, read anew in
    /// the turned frame.
    Rotation(f64),
}

fn step() -> impl Strategy<Value = Step> {
    let coordinate = || (-500i32..500).prop_map(|v| f64::from(v) / 10.0);
    prop_oneof![
        6 => (any::<bool>(), [coordinate(), coordinate(), coordinate()])
            .prop_map(|(rapid, to)| Step::Straight { rapid, to }),
        4 => (any::<bool>(), 1u32..400, 0u32..360, 1u32..359, -50i32..50, 0u32..7).prop_map(
            |(clockwise, r, from, sweep, rise, turns)| Step::Arc {
                clockwise,
                radius: f64::from(r) / 10.0,
                from: f64::from(from),
                sweep: f64::from(sweep),
                rise: f64::from(rise) / 10.0,
                turns,
            }
        ),
        1 => (0usize..3).prop_map(Step::Plane),
        1 => any::<bool>().prop_map(Step::Incremental),
        1 => any::<bool>().prop_map(Step::Inches),
        1 => (1u32..3000).prop_map(|f| Step::Feed(f64::from(f))),
        1 => (1u32..20).prop_map(|p| Step::Dwell(f64::from(p) / 4.0)),
        1 => [coordinate(), coordinate()].prop_map(Step::Offset),
        2 => (0usize..6, any::<bool>(), [coordinate(), coordinate()], 0u32..150, 1u32..200, 5u32..80, 1u32..4)
            .prop_map(|(code, to_r, hole, r, depth, q, repeats)| Step::Cycle {
                code,
                to_r,
                hole,
                // Never 0: R must not round onto the start level.
                r: f64::from(r) / 10.0 - 4.95,
                depth: f64::from(depth) / 10.0,
                q: f64::from(q) / 10.0,
                repeats,
            }),
        1 => (1u32..500, -360i32..360).prop_map(|(r, a)| Step::Polar {
            radius: f64::from(r) / 10.0,
            angle: f64::from(a),
        }),
        1 => (-1800i32..1800).prop_map(|a| Step::Rotation(f64::from(a) / 10.0)),
    ]
}

/// The program text; the position is tracked in program units to place arcs.
fn program(steps: &[Step]) -> String {
    // A first move, so that every program has motion.
    let mut text = String::from("G21 G90 G17 G94 F500\nG1 X1 Y2 Z3\n");
    let mut at = [1.0f64, 2.0, 3.0];
    let (mut plane, mut incremental, mut inches) = (0usize, false, false);
    let mut rotated = false;
    let words = ["X", "Y", "Z"];
    for step in steps {
        match step {
            Step::Straight { rapid, to } => {
                let code = if *rapid { "G0" } else { "G1" };
                text.push_str(code);
                for (i, v) in to.iter().enumerate() {
                    let written = if incremental { v - at[i] } else { *v };
                    text.push_str(&format!(" {}{written:.4}", words[i]));
                }
                text.push('\n');
                at = *to;
            }
            Step::Arc {
                clockwise,
                radius,
                from,
                sweep,
                rise,
                turns,
            } => {
                if rotated && plane != 0 {
                    continue; // pvtc refuses G18/G19 arcs in a rotated system
                }
                let (a, b, n) = [(0, 1, 2), (2, 0, 1), (1, 2, 0)][plane];
                let from = from.to_radians();
                let sweep = if *clockwise { -sweep } else { *sweep }.to_radians();
                let centre = [
                    at[a] - radius * libm::cos(from),
                    at[b] - radius * libm::sin(from),
                ];
                let mut end = at;
                end[a] = centre[0] + radius * libm::cos(from + sweep);
                end[b] = centre[1] + radius * libm::sin(from + sweep);
                end[n] += rise;
                let end = end.map(|v| (v * 1e4).round() / 1e4);
                let code = if *clockwise { "G2" } else { "G3" };
                text.push_str(code);
                for (i, v) in end.iter().enumerate() {
                    let written = if incremental { v - at[i] } else { *v };
                    text.push_str(&format!(" {}{written:.4}", words[i]));
                }
                let centre_words = ["I", "J", "K"];
                text.push_str(&format!(" {}{:.6}", centre_words[a], centre[0] - at[a]));
                text.push_str(&format!(" {}{:.6}", centre_words[b], centre[1] - at[b]));
                if *turns > 0 {
                    text.push_str(&format!(" P{}", turns + 1));
                }
                text.push('\n');
                at = end;
            }
            Step::Plane(p) => {
                plane = *p;
                text.push_str(["G17\n", "G18\n", "G19\n"][plane]);
            }
            Step::Incremental(on) => {
                incremental = *on;
                text.push_str(if *on { "G91\n" } else { "G90\n" });
            }
            Step::Inches(on) => {
                if *on != inches {
                    let scale = if *on { 1.0 / 25.4 } else { 25.4 };
                    at = at.map(|v| v * scale);
                }
                inches = *on;
                text.push_str(if *on { "G20\n" } else { "G21\n" });
            }
            Step::Feed(f) => text.push_str(&format!("F{f}\n")),
            Step::Dwell(p) => text.push_str(&format!("G4 P{p}\n")),
            Step::Offset([x, y]) => {
                text.push_str(&format!("G92 X{x:.4} Y{y:.4}\n"));
                at[0] = *x;
                at[1] = *y;
            }
            Step::Cycle {
                code,
                to_r,
                hole,
                r,
                depth,
                q,
                repeats,
            } => {
                // Drilling along the plane's normal: Z in G17, Y in G18, X in G19.
                let (a, b, n) = [(0, 1, 2), (2, 0, 1), (1, 2, 0)][plane];
                let name = ["G73", "G81", "G82", "G83", "G85", "G89"][*code];
                let retract = if *to_r { "G99" } else { "G98" };
                let level = at[n] + r;
                let (first, second, r_word, bottom_word, count) = if incremental {
                    (hole[0], hole[1], *r, -depth, *repeats)
                } else {
                    (hole[0], hole[1], level, level - depth, 1)
                };
                text.push_str(&format!(
                    "{retract} {name} {}{first:.4} {}{second:.4} {}{bottom_word:.4} R{r_word:.4}",
                    words[a], words[b], words[n]
                ));
                match name {
                    "G73" | "G83" => text.push_str(&format!(" Q{q:.4}")),
                    "G82" | "G89" => text.push_str(" P0.25"),
                    _ => {}
                }
                if incremental {
                    text.push_str(&format!(" L{count}"));
                }
                text.push_str("\nG80\n");
                if incremental {
                    at[a] += first * f64::from(count);
                    at[b] += second * f64::from(count);
                } else {
                    at[a] = first;
                    at[b] = second;
                }
                // G98 ends at the start level, or R when the start is below it.
                at[n] = if *to_r { level } else { at[n].max(level) };
            }
            Step::Polar { radius, angle } => {
                if plane == 0 && !incremental {
                    text.push_str(&format!("G1 @{radius:.4} ^{angle:.4}\n"));
                    let rad = angle.to_radians();
                    at[0] = radius * libm::cos(rad);
                    at[1] = radius * libm::sin(rad);
                }
            }
            Step::Rotation(angle) => {
                rotated = *angle != 0.0;
                text.push_str(&format!(
                    "G10 L2 P1 R{angle:.1}\nG90 G17 G1 X{:.4} Y{:.4} Z{:.4}\n",
                    at[0], at[1], at[2]
                ));
                text.push_str(["", "G18\n", "G19\n"][plane]);
                if incremental {
                    text.push_str("G91\n");
                }
            }
        }
    }
    text.push_str("M2\n");
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(48), ..ProptestConfig::default() })]

    #[test]
    fn random_programs_move_as_rs274_moves(steps in prop::collection::vec(step(), 1..24)) {
        let text = program(&steps);
        let compared = compare_random(&text);
        prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
    }
}
