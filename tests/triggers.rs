//! `--trigger-every`: each format that takes triggers, read back with the readers written
//! from the vendors' documentation (`controllers.rs`); where each trigger fires is
//! recomputed here from the written pieces: the motion time before it (the sum of the
//! piece times) and the path before it (each written cubic sampled densely, the length
//! of the X Y Z motion summed over chords). Formats without a place for triggers refuse
//! with a coded error.

use pvt_emit::{Format, TriggerEvery};
use pvtc::{compile, CompileOptions, Source};
use pvtc_tests::controllers::{read_csv, read_pmac, read_zaber, Motion, Piece};
use pvtc_tests::root;

const SAMPLES: [&str; 3] = [
    "samples/gcode/grbl_r_arcs.ngc",
    "samples/gcode/quad_circle_arc.ngc",
    "samples/gcode/linuxcnc_helix.ngc",
];

fn compiled(sample: &str, format: Format, every: TriggerEvery) -> (String, pvt_core::PvtProgram) {
    let source = Source {
        name: sample.into(),
        bytes: std::fs::read(root().join(sample)).unwrap(),
    };
    compiled_source(&source, format, every)
}

fn compiled_source(
    source: &Source,
    format: Format,
    every: TriggerEvery,
) -> (String, pvt_core::PvtProgram) {
    let sample = &source.name;
    let mut o = CompileOptions::new(format);
    o.triggers = Some(every);
    if format.caps().scaled {
        o.counts_per_unit = pvt_core::Axis::ALL.iter().map(|a| (*a, 1000.0)).collect();
    }
    let c = compile(source, &o).unwrap_or_else(|f| panic!("{sample}: {:?}", f.codes()));
    (String::from_utf8(c.bytes).unwrap(), c.program)
}

fn read(format: Format, text: &str, program: &pvt_core::PvtProgram) -> Motion {
    let start = program.contours[0].start.clone();
    match format {
        Format::Pmac | Format::PowerPmac => read_pmac(text, &start),
        Format::Zaber => read_zaber(text, &vec![1000.0; start.len()]),
        Format::Csv => read_csv(text),
        _ => unreachable!(),
    }
}

/// Motion time and X Y Z path at every knot (knot k: after k pieces), a dwell (with
/// `dwells`, a piece at rest where it is) adding neither; and the largest speed of the
/// pieces beside it.
fn clock(start: &[f64], pieces: &[Piece], linear: usize, dwells: bool) -> Vec<(f64, f64, f64)> {
    let mut at: Vec<(f64, f64)> = start.iter().map(|p| (*p, 0.0)).collect();
    let (mut time, mut path) = (0.0, 0.0);
    let mut knots: Vec<(f64, f64, f64)> = vec![(0.0, 0.0, 0.0)];
    for piece in pieces {
        let still = dwells
            && piece.velocity.iter().all(|v| *v == 0.0)
            && at.iter().zip(&piece.end).all(|((p, _), e)| p == e);
        let mut fastest: f64 = 0.0;
        if !still {
            let t = piece.time;
            let n = 400;
            let mut last: Option<Vec<f64>> = None;
            for k in 0..=n {
                let s = t * k as f64 / n as f64;
                let (p, v): (Vec<f64>, Vec<f64>) = at
                    .iter()
                    .zip(piece.end.iter().zip(&piece.velocity))
                    .take(linear)
                    .map(|((p0, v0), (p1, v1))| hermite(*p0, *v0, *p1, *v1, t, s))
                    .unzip();
                fastest = fastest.max(v.iter().map(|v| v * v).sum::<f64>().sqrt());
                if let Some(q) = &last {
                    path += p
                        .iter()
                        .zip(q)
                        .map(|(a, b)| (a - b).powi(2))
                        .sum::<f64>()
                        .sqrt();
                }
                last = Some(p);
            }
            time += t;
        }
        if let Some(k) = knots.last_mut() {
            k.2 = k.2.max(fastest);
        }
        knots.push((time, path, fastest));
        for (i, a) in at.iter_mut().enumerate() {
            *a = (piece.end[i], piece.velocity[i]);
        }
    }
    knots
}

/// Position and velocity at `s` of the cubic from (p0, v0) to (p1, v1) in `t`.
fn hermite(p0: f64, v0: f64, p1: f64, v1: f64, t: f64, s: f64) -> (f64, f64) {
    let d = p1 - p0;
    let a0 = 6.0 * d / (t * t) - (4.0 * v0 + 2.0 * v1) / t;
    let j = 6.0 * (v0 + v1) / (t * t) - 12.0 * d / (t * t * t);
    (
        p0 + v0 * s + a0 * s * s / 2.0 + j * s * s * s / 6.0,
        v0 + a0 * s + j * s * s / 2.0,
    )
}

fn linear_axes(program: &pvt_core::PvtProgram) -> usize {
    program.axes.iter().filter(|a| !a.is_rotary()).count()
}

#[test]
fn time_triggers_fall_every_t_of_motion_in_every_format_that_takes_them() {
    for sample in SAMPLES {
        for format in [Format::Pmac, Format::PowerPmac, Format::Zaber, Format::Csv] {
            let every = 0.05;
            let (text, program) = compiled(sample, format, TriggerEvery::Seconds(every));
            let motion = read(format, &text, &program);
            let start = &program.contours[0].start;
            let knots = clock(start, &motion.pieces, linear_axes(&program), true);
            let total = knots.last().unwrap().0;
            let name = format.name();
            let expected = libm::floor(total / every + 1e-9) as usize;
            assert_eq!(
                motion.triggers.len(),
                expected,
                "{sample} {name}: {total} s"
            );
            for (k, knot) in motion.triggers.iter().enumerate() {
                let t = knots[*knot].0;
                let want = (k + 1) as f64 * every;
                // Whole quanta (PMAC 1 ms, Zaber 0.1 ms): every trigger on its time.
                assert!(
                    (t - want).abs() < 1e-9,
                    "{sample} {name} trigger {k}: {t} s"
                );
            }
        }
        // JSON lists each trigger's time and position.
        let (text, _) = compiled(sample, Format::Json, TriggerEvery::Seconds(0.05));
        let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        let triggers = doc["triggers"].as_array().unwrap();
        let total = doc["total_time"].as_f64().unwrap();
        assert_eq!(triggers.len(), libm::floor(total / 0.05 + 1e-9) as usize);
        for (k, t) in triggers.iter().enumerate() {
            let t = t["t"].as_f64().unwrap();
            assert!(
                (t - (k + 1) as f64 * 0.05).abs() < 1e-9,
                "{sample} json: {t}"
            );
        }
    }
}

#[test]
fn distance_triggers_fall_every_n_of_path_within_half_a_quantum_of_motion() {
    for sample in SAMPLES {
        for (format, quantum) in [(Format::Pmac, 1e-3), (Format::Csv, 0.0)] {
            let every = 2.0;
            let (text, program) = compiled(sample, format, TriggerEvery::Distance(every));
            let motion = read(format, &text, &program);
            let start = &program.contours[0].start;
            let knots = clock(start, &motion.pieces, linear_axes(&program), true);
            let total = knots.last().unwrap().1;
            let name = format.name();
            let expected = libm::floor(total / every + 1e-9) as usize;
            assert_eq!(motion.triggers.len(), expected, "{sample} {name}: {total}");
            for (k, knot) in motion.triggers.iter().enumerate() {
                let (_, s, speed) = knots[*knot];
                let want = (k + 1) as f64 * every;
                // Off the exact point by the time rounding to the grid, at most half a
                // quantum of the fastest motion beside the knot; 1e-6 for the sampling.
                let room = speed * quantum / 2.0 + 1e-6 * (1.0 + want);
                assert!(
                    (s - want).abs() <= room,
                    "{sample} {name} trigger {k}: path {s} for {want} (room {room})"
                );
            }
        }
    }
}

#[test]
fn pmac_text_with_triggers_follows_the_pmac_grammar() {
    let text = std::fs::read_to_string(root().join("grammars/pmac.ebnf")).unwrap();
    let grammar = pvtc_tests::ebnf::Grammar::parse(&text).unwrap();
    for every in [TriggerEvery::Distance(3.0), TriggerEvery::Seconds(1e-4)] {
        let (pmac, _) = compiled(SAMPLES[0], Format::Pmac, every);
        assert!(pmac.contains("M1==1"));
        assert!(grammar.matches("program", &pmac), "{pmac}");
    }
}

#[test]
fn cutting_at_triggers_keeps_the_motion() {
    // The table with triggers: every row lies on the cubics of the table without them.
    let sample = SAMPLES[0];
    let plain = compiled(sample, Format::Csv, TriggerEvery::Seconds(1e9));
    let cut = compiled(sample, Format::Csv, TriggerEvery::Distance(0.7));
    let start = plain.1.contours[0].start.clone();
    let (plain, cut) = (read_csv(&plain.0), read_csv(&cut.0));
    assert!(plain.triggers.is_empty() && !cut.triggers.is_empty());
    assert!(cut.pieces.len() > plain.pieces.len());
    let (mut t0, mut at, mut i) = (0.0, start.clone(), 0);
    let mut t_cut = 0.0;
    let mut at_plain: Vec<(f64, f64)> = start.iter().map(|p| (*p, 0.0)).collect();
    for piece in &cut.pieces {
        t_cut += piece.time;
        while t0 + plain.pieces[i].time < t_cut - 1e-12 {
            t0 += plain.pieces[i].time;
            at_plain = plain.pieces[i]
                .end
                .iter()
                .zip(&plain.pieces[i].velocity)
                .map(|(p, v)| (*p, *v))
                .collect();
            i += 1;
        }
        let p = &plain.pieces[i];
        for (axis, (p0, v0)) in at_plain.iter().enumerate() {
            let (x, v) = hermite(*p0, *v0, p.end[axis], p.velocity[axis], p.time, t_cut - t0);
            assert!((x - piece.end[axis]).abs() < 1e-9, "axis {axis} at {t_cut}");
            assert!((v - piece.velocity[axis]).abs() < 1e-6 * (1.0 + v.abs()));
        }
        at = piece.end.clone();
    }
    assert_eq!(at, plain.pieces.last().unwrap().end);
}

#[test]
fn formats_without_a_place_for_triggers_refuse_them() {
    let source = Source::from_text("p.ngc", "G21 G90\nG1 X5 Y0 F600\nM2\n");
    for format in [Format::Xps, Format::Galil, Format::MovePvt] {
        let mut o = CompileOptions::new(format);
        o.triggers = Some(TriggerEvery::Seconds(0.01));
        o.counts_per_unit = pvt_core::Axis::ALL.iter().map(|a| (*a, 1000.0)).collect();
        let codes = match compile(&source, &o) {
            Ok(_) => panic!("{} took triggers", format.name()),
            Err(f) => f.codes(),
        };
        assert!(
            codes.iter().any(|c| c == "pvtc::emit::no_triggers"),
            "{}: {codes:?}",
            format.name()
        );
    }
}

mod over_random_programs {
    //! Random programs of lines and rapids: in every format that takes triggers, with
    //! random intervals of time or path, the triggers read back are where they belong.

    use super::*;
    use proptest::prelude::*;

    fn gcode(points: &[(i32, i32, bool)], feed: u32) -> String {
        let mut text = format!("G21 G90\nG0 X0 Y0\nG1 F{feed}\n");
        for (x, y, rapid) in points {
            let word = if *rapid { "G0" } else { "G1" };
            text.push_str(&format!(
                "{word} X{} Y{}\n",
                *x as f64 / 10.0,
                *y as f64 / 10.0
            ));
        }
        text + "M2\n"
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        #[test]
        fn triggers_fall_where_they_belong(
            points in prop::collection::vec((-500i32..=500, -500i32..=500, prop::bool::weighted(0.2)), 1..8),
            feed in 100u32..6000,
            path in prop::bool::ANY,
            every in 5u32..200,
        ) {
            let source = Source::from_text("random.ngc", &gcode(&points, feed));
            // Path: 0.5 to 20 mm (above the fastest motion, 100 mm/s, times 1 ms);
            // time: 5 to 200 ms, whole quanta of every format.
            let every = match path {
                true => TriggerEvery::Distance(every as f64 / 10.0),
                false => TriggerEvery::Seconds(every as f64 / 1000.0),
            };
            for (format, quantum) in [(Format::Pmac, 1e-3), (Format::Zaber, 1e-4), (Format::Csv, 0.0)] {
                let (text, program) = compiled_source(&source, format, every);
                if program.contours.is_empty() {
                    continue;
                }
                let motion = read(format, &text, &program);
                // No dwells: a piece that whole counts leave at rest is motion.
                let knots = clock(&program.contours[0].start, &motion.pieces, 2, false);
                let name = format.name();
                let (total, interval) = match every {
                    TriggerEvery::Distance(n) => (knots.last().unwrap().1, n),
                    TriggerEvery::Seconds(t) => (knots.last().unwrap().0, t),
                };
                let expected = libm::floor(total / interval + 1e-9) as usize;
                prop_assert!(
                    motion.triggers.len().abs_diff(expected) <= usize::from(total / interval - expected as f64 > 1.0 - 1e-6),
                    "{name}: {} triggers for {total} / {interval}", motion.triggers.len()
                );
                for (k, knot) in motion.triggers.iter().enumerate() {
                    let (t, s, speed) = knots[*knot];
                    let want = (k + 1) as f64 * interval;
                    // Zaber's whole microsteps (1000/mm) move each knot by up to half a
                    // step per axis: each piece's length by up to 2·√2/2000 mm.
                    let counts = if format == Format::Zaber { *knot as f64 * 1.5e-3 } else { 0.0 };
                    let (got, room) = match every {
                        TriggerEvery::Distance(_) => (s, speed * quantum / 2.0 + counts + 1e-6 * (1.0 + want)),
                        TriggerEvery::Seconds(_) => (t, 1e-9 * (1.0 + want)),
                    };
                    prop_assert!((got - want).abs() <= room, "{name} trigger {k}: {got} for {want}");
                }
            }
        }
    }
}
