//! Every sample compiled to every controller format and read back with a reader written
//! from the vendor's documentation (`controllers.rs`): positions, velocities and times
//! round-trip within the format's precision, and each text obeys its controller's rules
//! (PMAC whole milliseconds without `--quantize`, Galil even samples and its 255-segment
//! buffer before `BT`, Zaber tenths of a millisecond, XPS elements of at least 100 µs
//! ending at rest).

use pvt_core::{EventKind, PvtProgram};
use pvt_emit::Format;
use pvtc::{compile, CompileOptions, Source};
use pvtc_tests::controllers::{
    read_csv, read_galil, read_pmac, read_xps, read_zaber, Motion, Piece,
};
use pvtc_tests::{root, samples};

const SCALE: f64 = 1000.0;

fn options(sample: &str, format: Format) -> CompileOptions {
    let mut asked = pvtc::Asked::default();
    if sample.ends_with(".dxf") {
        asked.feed = Some(1200.0);
    }
    if format.caps().scaled {
        asked.counts_per_unit = pvt_core::Axis::ALL.iter().map(|a| (*a, SCALE)).collect();
    }
    pvtc::settings::compile_options(&asked, sample, format)
}

/// The pieces the program holds, a dwell as a piece at rest where it happens.
fn planned(program: &PvtProgram) -> Motion {
    let mut pieces = Vec::new();
    let mut at = program
        .contours
        .first()
        .map(|c| c.start.clone())
        .unwrap_or_default();
    let mut events = program.events.iter().peekable();
    let rest = |pieces: &mut Vec<Piece>, at: &[f64], kind: &EventKind| {
        if let EventKind::Dwell { seconds } = kind {
            if *seconds > 0.0 {
                pieces.push(Piece {
                    time: *seconds,
                    end: at.to_vec(),
                    velocity: vec![0.0; at.len()],
                });
            }
        }
    };
    for (i, contour) in program.contours.iter().enumerate() {
        while let Some(e) = events.next_if(|e| e.before_contour <= i) {
            rest(&mut pieces, &at, &e.kind);
        }
        for seg in contour.segments() {
            pieces.push(Piece {
                time: seg.duration,
                end: seg.end.to_vec(),
                velocity: seg.velocity.to_vec(),
            });
            at = seg.end.to_vec();
        }
    }
    for e in events {
        rest(&mut pieces, &at, &e.kind);
    }
    merge_rests(pieces)
}

/// Consecutive pieces at rest (no displacement, zero velocity) as one.
fn merge_rests(pieces: Vec<Piece>) -> Motion {
    let mut out: Vec<Piece> = Vec::new();
    for p in pieces {
        let still = |q: &Piece| q.velocity.iter().all(|v| *v == 0.0);
        if let Some(last) = out.last_mut() {
            if still(last) && still(&p) && last.end == p.end {
                last.time += p.time;
                continue;
            }
        }
        out.push(p);
    }
    Motion {
        pieces: out,
        ..Motion::default()
    }
}

/// Precision of a format: position, velocity (program units) and time (s) of a piece,
/// and of a rest's time (rounded up to the controller's grid).
fn precision(format: Format) -> (f64, f64, f64, f64) {
    match format {
        Format::Pmac => (5e-7, 5e-7, 5e-8, 5e-8),
        Format::PowerPmac => (5e-7, 5e-7, 5e-10, 5e-10),
        Format::Galil => (0.5 / SCALE, 0.5 / SCALE, 1e-9, 2.0 / 1024.0),
        Format::Zaber => (0.5 / SCALE, 0.5 / (SCALE * 1.6384), 1e-9, 1e-4),
        _ => (1e-9, 0.0, 1e-12, 1e-12),
    }
}

fn read(format: Format, text: &str, program: &PvtProgram) -> Motion {
    let start = program
        .contours
        .first()
        .map(|c| c.start.clone())
        .unwrap_or_else(|| vec![0.0; program.axes.len()]);
    let scale = vec![SCALE; program.axes.len()];
    let motion = match format {
        Format::Pmac | Format::PowerPmac => read_pmac(text, &start),
        Format::Xps => read_xps(text, &start),
        Format::Csv => read_csv(text),
        Format::Zaber => read_zaber(text, &scale),
        Format::Galil => {
            let (motion, facts) = read_galil(text, &start, &scale);
            let n = facts.samples.len();
            assert_eq!(facts.before_begin, n.min(255), "BT after the buffer's 255");
            for t in facts.samples {
                assert!(t % 2 == 0 && (2..=2048).contains(&t), "t = {t} samples");
            }
            motion
        }
        _ => unreachable!(),
    };
    merge_rests(motion.pieces)
}

fn rules(format: Format, text: &str, motion: &Motion) {
    for p in &motion.pieces {
        let dwell = p.velocity.iter().all(|v| *v == 0.0);
        match format {
            Format::Pmac => {
                let ms = p.time * 1000.0;
                assert!((ms - libm::round(ms)).abs() < 1e-6, "PMAC piece of {ms} ms");
                assert!(dwell || p.time <= 4.095 + 1e-12, "PMAC piece of {ms} ms");
            }
            Format::Zaber => {
                let tenths = p.time * 1e4;
                assert!((tenths - libm::round(tenths)).abs() < 1e-6, "{} s", p.time);
            }
            Format::Xps => assert!(p.time >= 1e-4, "XPS element of {} s", p.time),
            _ => {}
        }
    }
    if format == Format::Pmac {
        assert!(!text.contains("warning"), "a PMAC warning in the text");
    }
    if format == Format::Xps {
        let last = motion.pieces.last().unwrap();
        assert!(last.velocity.iter().all(|v| *v == 0.0), "XPS -70");
    }
}

fn round_trips(sample: &str, format: Format) {
    let bytes = std::fs::read(root().join(sample)).unwrap();
    let source = Source {
        name: sample.into(),
        bytes,
    };
    let compiled = compile(&source, &options(sample, format))
        .unwrap_or_else(|f| panic!("{sample} {}: {:?}", format.name(), f.codes()));
    let text = String::from_utf8(compiled.bytes).unwrap();
    let expected = planned(&compiled.program);
    let actual = read(format, &text, &compiled.program);
    rules(format, &text, &actual);
    if format != Format::Csv {
        reads_back_as_the_controller_does(format, &text, &compiled.program, &actual);
    }
    let (dp, dv, dt, rest_dt) = precision(format);
    let name = format.name();
    assert_eq!(
        actual.pieces.len(),
        expected.pieces.len(),
        "{sample} {name}: pieces"
    );
    for (k, (a, e)) in actual.pieces.iter().zip(&expected.pieces).enumerate() {
        let at_rest = e.velocity.iter().all(|v| *v == 0.0);
        let tol_t = if at_rest { rest_dt } else { dt };
        assert!(
            a.time >= e.time - dt && a.time - e.time <= tol_t + dt,
            "{sample} {name} piece {k}: time {} for {}",
            a.time,
            e.time
        );
        for i in 0..e.end.len() {
            let near = |x: f64, y: f64, d: f64| (x - y).abs() <= d + 1e-12 * (1.0 + y.abs());
            assert!(
                near(a.end[i], e.end[i], dp),
                "{sample} {name} piece {k} axis {i}: position {} for {}",
                a.end[i],
                e.end[i]
            );
            assert!(
                near(a.velocity[i], e.velocity[i], dv),
                "{sample} {name} piece {k} axis {i}: velocity {} for {}",
                a.velocity[i],
                e.velocity[i]
            );
        }
    }
}

/// What `pvtc check` verifies (pvt-emit's `read_back`) is what the independent reader
/// finds in the text: the same pieces (an XPS file starts at 0: shifted by the start).
fn reads_back_as_the_controller_does(
    format: Format,
    text: &str,
    program: &PvtProgram,
    actual: &Motion,
) {
    let hint = pvt_emit::readback::ReadHint {
        units: program.units,
        counts_per_unit: pvt_core::Axis::ALL.iter().map(|a| (*a, SCALE)).collect(),
    };
    let back = pvt_emit::readback::read_back(format, text, &hint)
        .unwrap_or_else(|e| panic!("{}: {e}", format.name()));
    if !matches!(format, Format::Xps | Format::Zaber) {
        // The XPS file and the Zaber commands name no axes: they are read as X, Y, ….
        assert_eq!(back.axes, program.axes, "{}", format.name());
    }
    let got = planned(&back);
    assert_eq!(got.pieces.len(), actual.pieces.len(), "{}", format.name());
    let shift: Vec<f64> = match format {
        Format::Xps => program.contours[0].start.clone(),
        _ => vec![0.0; program.axes.len()],
    };
    for (g, a) in got.pieces.iter().zip(&actual.pieces) {
        let near = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + y.abs());
        assert!(
            near(g.time, a.time),
            "{}: {} s for {} s",
            format.name(),
            g.time,
            a.time
        );
        for (i, s) in shift.iter().enumerate() {
            assert!(near(g.end[i] + s, a.end[i]), "{}", format.name());
            assert!(near(g.velocity[i], a.velocity[i]), "{}", format.name());
        }
    }
}

fn every_format(kind: &str, extension: &str) {
    for sample in samples(kind, extension) {
        for format in [
            Format::Pmac,
            Format::Xps,
            Format::Galil,
            Format::Zaber,
            Format::PowerPmac,
            Format::Csv,
        ] {
            round_trips(&sample, format);
        }
    }
}

#[test]
fn gcode_samples_read_back_in_every_controller_format() {
    every_format("gcode", ".ngc");
}

#[test]
fn dxf_samples_read_back_in_every_controller_format() {
    every_format("dxf", ".dxf");
}

#[test]
fn csv_samples_read_back_in_every_controller_format() {
    every_format("csv", ".csv");
}

mod rules_over_random_programs {
    //! Random programs of lines and rapids on a mill with travel limits: every controller
    //! format's text, read back, obeys its controller's rules, recomputed here from p, v
    //! and T: time grid, shortest and longest piece, travel (the cubic between the
    //! knots), and for the XPS, the exact table and the formats in whole counts (Galil,
    //! Zaber: the cubic the controller builds from the rounded counts) the velocity and
    //! acceleration limits.

    use super::*;
    use proptest::prelude::*;
    use pvtc_tests::controllers::{cubic_peaks, cubic_range};

    const MACHINE: &str = "units = \"mm\"\n\
        [axes.X]\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n\
        min_position = -60.0\nmax_position = 60.0\ncounts_per_unit = 1000\n\
        [axes.Y]\nmax_velocity = 80.0\nmax_acceleration = 800.0\n\
        min_position = -60.0\nmax_position = 60.0\ncounts_per_unit = 1000\n";

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

    fn check(format: Format, text: &str, program: &PvtProgram) {
        let motion = read(format, text, program);
        rules(format, text, &motion);
        let caps = format.caps();
        let mut at: Vec<(f64, f64)> = program.contours[0]
            .start
            .iter()
            .map(|p| (*p, 0.0))
            .collect();
        let limits = [(100.0, 1000.0), (80.0, 800.0)];
        for piece in &motion.pieces {
            let t = piece.time;
            assert!(
                t >= caps.min_piece_seconds * (1.0 - 1e-9),
                "{}: {t}",
                format.name()
            );
            if let Some(max) = caps.max_piece_seconds {
                let dwell = piece.velocity.iter().all(|v| *v == 0.0);
                assert!(dwell || t <= max * (1.0 + 1e-9), "{}: {t}", format.name());
            }
            for (i, (p0, v0)) in at.iter_mut().enumerate() {
                let (p1, v1) = (piece.end[i], piece.velocity[i]);
                let (lo, hi) = cubic_range(*p0, *v0, p1, v1, t);
                let slack = 1e-3; // a count of the formats written in counts
                assert!(
                    lo >= -60.0 - slack && hi <= 60.0 + slack,
                    "{}: travel {lo}..{hi}",
                    format.name()
                );
                // Galil and Zaber: the cubic of the whole counts read back.
                if matches!(
                    format,
                    Format::Xps | Format::Csv | Format::Galil | Format::Zaber
                ) {
                    let (v, a) = cubic_peaks(*p0, *v0, p1, v1, t);
                    let (vmax, amax) = limits[i];
                    assert!(v <= vmax * (1.0 + 1e-6), "{}: |v| {v}", format.name());
                    assert!(a <= amax * (1.0 + 1e-6), "{}: |a| {a}", format.name());
                }
                *p0 = p1;
                *v0 = v1;
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        #[test]
        fn controller_rules_hold_over_random_programs(
            points in prop::collection::vec((-500i32..=500, -500i32..=500, prop::bool::weighted(0.2)), 1..12),
            feed in 100u32..6000,
        ) {
            let dir = tempfile::tempdir().unwrap();
            let machine_path = dir.path().join("m.toml");
            std::fs::write(&machine_path, MACHINE).unwrap();
            let machine = pvtc::machine::Machine::read(&machine_path).unwrap();
            let source = Source::from_text("random.ngc", &gcode(&points, feed));
            for format in [Format::Pmac, Format::Xps, Format::Galil, Format::Zaber, Format::PowerPmac, Format::Csv] {
                let mut o = CompileOptions::new(format);
                // The grid the command line gives with a machine file (for Galil and
                // Zaber, long enough for whole counts to keep the limits).
                o.quantize = pvtc::settings::default_quantum(format, Some(&machine), &[]);
                o.machine = Some(machine.clone());
                let compiled = match compile(&source, &o) {
                    Ok(c) => c,
                    Err(f) => panic!("{}: {:?}", format.name(), f.codes()),
                };
                if compiled.program.contours.is_empty() {
                    continue;
                }
                check(format, &String::from_utf8(compiled.bytes).unwrap(), &compiled.program);
            }
        }
    }
}
