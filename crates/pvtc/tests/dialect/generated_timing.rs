//! Random programs over what decides a part's time, compared with rs274 feed by feed:
//! F, S and G20/G21 in one block, unit switches between F and the moves, G93 inverse
//! time and G94, spindle and coolant events, G61/G61.1/G64 with P and Q, M70/M72 around
//! mode changes, a subroutine that feeds under M73, and canned cycles, over lines and
//! arcs in G17.

use super::*;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Step {
    /// G0 or G1 to X Y Z (program units of the moment, absolute).
    Line { rapid: bool, to: [f64; 3] },
    /// A counter-clockwise or clockwise arc in G17 of this radius from here, by I J.
    Arc {
        clockwise: bool,
        radius: f64,
        sweep: f64,
    },
    /// `G20`/`G21` with F (and S) in the same block: F (and S) read in the old units.
    UnitsAndFeed {
        inches: bool,
        feed: f64,
        speed: Option<u32>,
    },
    /// A units switch on its own line.
    Units(bool),
    /// F alone.
    Feed(f64),
    /// `G93 G1 … F` then `G94 F` (G94 sets the feed to 0, so it brings its F).
    InverseTime {
        to: [f64; 3],
        minutes: f64,
        feed: f64,
    },
    /// `S… M3`, `M4`, `M5`.
    Spindle { speed: u32, direction: usize },
    /// M7, M8, M9.
    Coolant(usize),
    /// G61, G61.1, G64, `G64 P`, `G64 P Q`.
    PathControl { mode: usize, p: f64, q: f64 },
    /// M70, then units, F and G91 changed, then M72: all restored.
    SaveRestore { inches: bool, feed: f64 },
    /// `o<feed> call [F] [X] [Y]`: under M73, G90, that F and a G1 there.
    Call { feed: f64, to: [f64; 2] },
    /// A G81 or G83 hole below here, then G80.
    Cycle { peck: bool, depth: f64 },
    /// G4 P.
    Dwell(f64),
}

fn step() -> impl Strategy<Value = Step> {
    let coordinate = || (-300i32..300).prop_map(|v| f64::from(v) / 10.0);
    let feed = || (1u32..2000).prop_map(f64::from);
    prop_oneof![
        5 => (any::<bool>(), [coordinate(), coordinate(), coordinate()])
            .prop_map(|(rapid, to)| Step::Line { rapid, to }),
        3 => (any::<bool>(), 10u32..200, 10u32..300).prop_map(|(clockwise, r, sweep)| Step::Arc {
            clockwise,
            radius: f64::from(r) / 10.0,
            sweep: f64::from(sweep),
        }),
        2 => (any::<bool>(), feed(), prop::option::of(100u32..5000))
            .prop_map(|(inches, feed, speed)| Step::UnitsAndFeed { inches, feed, speed }),
        1 => any::<bool>().prop_map(Step::Units),
        1 => feed().prop_map(Step::Feed),
        1 => ([coordinate(), coordinate(), coordinate()], 1u32..50, feed())
            .prop_map(|(to, m, feed)| Step::InverseTime { to, minutes: f64::from(m) / 10.0, feed }),
        1 => (100u32..5000, 0usize..3).prop_map(|(speed, direction)| Step::Spindle { speed, direction }),
        1 => (0usize..3).prop_map(Step::Coolant),
        1 => (0usize..5, 1u32..100, 1u32..100).prop_map(|(mode, p, q)| Step::PathControl {
            mode,
            p: f64::from(p) / 1000.0,
            q: f64::from(q) / 1000.0,
        }),
        1 => (any::<bool>(), feed()).prop_map(|(inches, feed)| Step::SaveRestore { inches, feed }),
        1 => (feed(), [coordinate(), coordinate()]).prop_map(|(feed, to)| Step::Call { feed, to }),
        1 => (any::<bool>(), 10u32..100).prop_map(|(peck, d)| Step::Cycle {
            peck,
            depth: f64::from(d) / 10.0,
        }),
        1 => (1u32..8).prop_map(|p| Step::Dwell(f64::from(p) / 4.0)),
    ]
}

/// Where a program is: the position and units, program units.
struct State {
    at: [f64; 3],
    inches: bool,
}

impl State {
    /// Switches the units, the position read anew.
    fn units(&mut self, inches: bool) -> &'static str {
        if inches != self.inches {
            let scale = if inches { 1.0 / 25.4 } else { 25.4 };
            self.at = self.at.map(|v| v * scale);
        }
        self.inches = inches;
        if inches {
            "G20"
        } else {
            "G21"
        }
    }
}

/// The text of one step, the state moved on.
fn step_text(step: &Step, state: &mut State) -> String {
    let xyz = |p: [f64; 3]| format!("X{:.4} Y{:.4} Z{:.4}", p[0], p[1], p[2]);
    match step {
        Step::Line { rapid, to } => {
            state.at = *to;
            format!("{} {}\n", if *rapid { "G0" } else { "G1" }, xyz(*to))
        }
        Step::Arc {
            clockwise,
            radius,
            sweep,
        } => {
            // Centre to the −X side of here; the end `sweep` degrees round.
            let [x, y, z] = state.at;
            let centre = [x - radius, y];
            let turn = if *clockwise { -sweep } else { *sweep }.to_radians();
            let end = [
                centre[0] + radius * libm::cos(turn),
                centre[1] + radius * libm::sin(turn),
            ]
            .map(|v| (v * 1e4).round() / 1e4);
            state.at = [end[0], end[1], z];
            let code = if *clockwise { "G2" } else { "G3" };
            format!("{code} X{:.4} Y{:.4} I{:.4} J0\n", end[0], end[1], -radius)
        }
        Step::UnitsAndFeed {
            inches,
            feed,
            speed,
        } => {
            let units = state.units(*inches);
            let speed = speed.map_or(String::new(), |s| format!(" S{s}"));
            format!("{units} F{feed}{speed}\n")
        }
        Step::Units(inches) => format!("{}\n", state.units(*inches)),
        Step::Feed(f) => format!("F{f}\n"),
        Step::InverseTime { to, minutes, feed } => {
            state.at = *to;
            format!("G93 G1 {} F{}\nG94 F{feed}\n", xyz(*to), 1.0 / minutes)
        }
        Step::Spindle { speed, direction } => match direction {
            0 => format!("S{speed} M3\n"),
            1 => format!("M4 S{speed}\n"),
            _ => "M5\n".into(),
        },
        Step::Coolant(c) => ["M7\n", "M8\n", "M9\n"][*c].into(),
        Step::PathControl { mode, p, q } => match mode {
            0 => "G61\n".into(),
            1 => "G61.1\n".into(),
            2 => "G64\n".into(),
            3 => format!("G64 P{p}\n"),
            _ => format!("G64 P{p} Q{q}\n"),
        },
        Step::SaveRestore { inches, feed } => {
            let units = if *inches { "G20" } else { "G21" };
            format!("M70\n{units}\nF{feed}\nG91\nM72\n")
        }
        Step::Call { feed, to } => {
            state.at[0] = to[0];
            state.at[1] = to[1];
            format!("o<feed> call [{feed}] [{:.4}] [{:.4}]\n", to[0], to[1])
        }
        Step::Cycle { peck, depth } => {
            let [x, y, z] = state.at;
            let q = if *peck { " Q0.7" } else { "" };
            let code = if *peck { "G83" } else { "G81" };
            format!(
                "G98 {code} X{x:.4} Y{y:.4} Z{:.4} R{:.4}{q}\nG80\n",
                z - depth,
                z + 0.5
            )
        }
        Step::Dwell(p) => format!("G4 P{p}\n"),
    }
}

fn program(steps: &[Step]) -> String {
    let mut text = String::from(
        "o<feed> sub\nM73\nG90\nF#1\nG1 X#2 Y#3\no<feed> endsub\n\
         G21 G90 G17 G94 F500\nG1 X1 Y2 Z3\n",
    );
    let mut state = State {
        at: [1.0, 2.0, 3.0],
        inches: false,
    };
    for step in steps {
        text.push_str(&step_text(step, &mut state));
    }
    text.push_str("M2\n");
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(32), ..ProptestConfig::default() })]

    #[test]
    fn random_timing_programs_move_and_feed_as_rs274(steps in prop::collection::vec(step(), 1..20)) {
        let text = program(&steps);
        let compared = compare_random(&text);
        prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
    }
}
