//! Differential tests of the G-code dialect against LinuxCNC's own interpreter, `rs274`.
//!
//! Every program in `tests/dialect/*.ngc` runs through `rs274 -g` and through
//! `pvtc compile --format toolpath`; the two must give the same motion: every element's
//! kind (rapid, feed, arc), end point, arc centre, plane and turn direction, and feed,
//! and every dwell, within 1e-4 mm. Random programs from a generator over the dialect
//! are compared the same way.
//!
//! rs274 prints program coordinates with the offsets as separate calls; this file turns
//! them into machine coordinates as LinuxCNC's canonical layer does (G92 offset, XY
//! rotation, work offset, tool length offset), in millimetres. It drops rs274's
//! zero-length straight moves, which pvtc drops with a warning, and passes over a move
//! of pvtc's shorter than what rs274 prints (under `G20`, a move of 0.001 mm prints as
//! none).
//!
//! Sidecar files next to `NAME.ngc`: `NAME.tbl`, a tool table (rs274 `-t`, pvtc
//! `--tool-table`); `NAME.ini`, an ini file for rs274 (`-i`, rs274 then runs in the
//! program's folder, so that a relative SUBROUTINE_PATH names a folder beside it);
//! `NAME.args`, extra pvtc arguments, one per line (pvtc runs in the program's
//! folder). Without rs274 (Debian package linuxcnc-uspace) each test says SKIPPED;
//! with `PVTC_REQUIRE_RS274=1` (set by `.ci/run`) it fails instead.

#[path = "dialect/compare.rs"]
mod compare;
#[path = "dialect/generated.rs"]
mod generated;
#[path = "dialect/generated_compensation.rs"]
mod generated_compensation;
#[path = "dialect/generated_control_flow.rs"]
mod generated_control_flow;
#[path = "dialect/generated_timing.rs"]
mod generated_timing;
#[path = "dialect/pvtc.rs"]
mod pvtc;
#[path = "dialect/rs274.rs"]
mod rs274;

use compare::difference;
use pvtc::{pvtc_diagnostics, pvtc_moves};
use rs274::{rs274_moves, rs274_run, Canon};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// How close the two readings must be, in the program's units: rs274 prints four
/// decimals of the units in force, and a machine coordinate read from it sums two
/// printed numbers (the position and an offset), each up to half the last digit off.
/// Under an XY rotation the sum is widened by the move's `spread`.
const TOLERANCE: f64 = 1e-4;

/// How many random cases a generated test runs: `PROPTEST_CASES` where set (a longer
/// search for a rare failure), else the test's own count.
fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(default)
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One motion or timing-relevant event the two interpreters agree on, in machine
/// coordinates, millimetres.
#[derive(Debug, Clone, PartialEq)]
enum Move {
    Straight {
        rapid: bool,
        end: [f64; 6],
        /// Millimetres per minute, as LinuxCNC's canonical layer converts the feed (in
        /// the units in force when it is set); a synchronised move's pitch × S.
        feed: f64,
        /// The path control mode the move runs in.
        control: Control,
        /// The minutes a feed move that turns a rotary axis takes (0 for the others),
        /// compared in place of its feed: LinuxCNC feeds it along X Y Z alone, pvtc
        /// along the path over every axis.
        minutes: f64,
        /// Millimetres per unit of the program at this move (0 where unknown).
        unit: f64,
        /// How far the XY rotation spreads rs274's rounding of X and Y onto one axis:
        /// `|cos θ| + |sin θ|`, 1 unrotated, up to √2 (0 where unknown).
        spread: f64,
    },
    Arc {
        plane: &'static str,
        end: [f64; 6],
        center: [f64; 2],
        /// Signed as rs274 prints it: +n counter-clockwise, −n clockwise, n − 1 extra turns.
        rotation: i64,
        feed: f64,
        control: Control,
        /// Millimetres per unit of the program at this move (0 where unknown).
        unit: f64,
        /// How far the XY rotation spreads rs274's rounding of X and Y onto one axis:
        /// `|cos θ| + |sin θ|`, 1 unrotated, up to √2 (0 where unknown).
        spread: f64,
    },
    Dwell(f64),
    /// M3 (`cw`), M4 (`ccw`), M5 (`off`).
    Spindle(&'static str),
    /// S, rpm.
    Speed(f64),
    /// M7 (`mist`), M8 (`flood`), M9 (`off`).
    Coolant(&'static str),
}

/// The path control mode a move runs in: G61 (`exact_path`), G61.1 (`exact_stop`),
/// G64 (`continuous`) with P and Q, millimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Control {
    mode: &'static str,
    p: f64,
    q: f64,
}

impl Default for Control {
    /// G64 without P or Q, as both start.
    fn default() -> Self {
        Control {
            mode: "continuous",
            p: 0.0,
            q: 0.0,
        }
    }
}

/// Where rs274 is, or why the tests cannot run.
fn rs274() -> Result<&'static str, String> {
    let found = Command::new("rs274")
        .arg("-h")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok();
    if found {
        return Ok("rs274");
    }
    let why = "rs274 is not installed (apt-get install linuxcnc-uspace)".to_string();
    if std::env::var_os("PVTC_REQUIRE_RS274").is_some() {
        panic!("{why}, and PVTC_REQUIRE_RS274 is set");
    }
    Err(why)
}

/// A sidecar of `program` with another extension, if it exists: beside the program, or
/// for a program kept outside the project (LinuxCNC's installed examples) in
/// `tests/dialect/linuxcnc/`.
fn sidecar(program: &Path, extension: &str) -> Option<PathBuf> {
    let path = program.with_extension(extension);
    let kept = program.file_name().map(|name| {
        root()
            .join("tests/dialect/linuxcnc")
            .join(name)
            .with_extension(extension)
    });
    [Some(path), kept]
        .into_iter()
        .flatten()
        .find(|p| p.exists())
}

/// Compares one program; the failure, described.
fn compare(rs274: &str, program: &Path) -> Result<usize, String> {
    if let Some(expected) = sidecar(program, "error") {
        return compare_refusal(rs274, program, &expected);
    }
    compare_with(&rs274_moves(rs274, program)?, program)
}

/// Compares pvtc's reading of `program` with `theirs`, rs274's.
fn compare_with(theirs: &[Move], program: &Path) -> Result<usize, String> {
    let ours = pvtc_moves(program)?;
    match difference(&ours, theirs) {
        None => Ok(ours.len()),
        Some(d) => Err(format!("{}: {d}", program.display())),
    }
}

/// Compares a program rs274 refuses (`NAME.error`: rs274's message on its first line,
/// pvtc's code on its second): rs274 fails with that message at a line, pvtc reports
/// that code at the same line, and where pvtc still compiles (a warning), its motion is
/// the motion rs274 printed.
fn compare_refusal(rs274: &str, program: &Path, expected: &Path) -> Result<usize, String> {
    let expected = std::fs::read_to_string(expected).expect("error sidecar");
    let mut expected = expected.lines();
    let (message, code) = (expected.next().unwrap_or(""), expected.next().unwrap_or(""));
    let run = rs274_run(rs274, program)?;
    let failure = run.failure.unwrap_or_default();
    let what = |d: &str| format!("{}: {d}", program.display());
    if !failure.contains(message) {
        return Err(what(&format!("rs274 does not say {message:?}: {failure}")));
    }
    // rs274 echoes the block it stopped at after its message.
    let block = failure.trim_end().lines().last().unwrap_or("").trim();
    let text = std::fs::read_to_string(program).expect("program");
    let (ok, diagnostics) = pvtc_diagnostics(program);
    let line = diagnostics
        .iter()
        .find(|(c, _)| c == code)
        .map(|(_, line)| *line)
        .ok_or_else(|| what(&format!("pvtc does not report {code}: {diagnostics:?}")))?;
    let pvtc_block = text
        .lines()
        .nth(line.saturating_sub(1))
        .unwrap_or("")
        .trim();
    if pvtc_block != block {
        return Err(what(&format!(
            "pvtc reports {code} at {pvtc_block:?}, rs274 at {block:?}"
        )));
    }
    if !ok {
        return Ok(0);
    }
    let ours = pvtc_moves(program)?;
    match difference(&ours, &run.moves) {
        None => Ok(ours.len()),
        Some(d) => Err(what(&d)),
    }
}

/// Compares a program given as text (a generated one), written to a temporary file.
fn compare_text(rs274: &str, text: &str) -> Result<usize, String> {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("random.ngc");
    std::fs::write(&path, text).expect("written");
    compare(rs274, &path)
}

/// Compares a random program with rs274; none to compare with (SKIPPED) without it.
fn compare_random(text: &str) -> Result<usize, String> {
    match rs274() {
        Ok(rs274) => compare_text(rs274, text),
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            Ok(0)
        }
    }
}

fn dialect_programs() -> Vec<PathBuf> {
    let dir = root().join("tests/dialect");
    let mut programs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    programs.sort();
    programs
}

#[test]
fn every_dialect_program_moves_as_rs274_moves() {
    let rs274 = match rs274() {
        Ok(rs274) => rs274,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let programs = dialect_programs();
    assert!(programs.len() >= 10, "the dialect programs are there");
    let mut failures = Vec::new();
    let mut compared = 0;
    for program in &programs {
        match compare(rs274, program) {
            Ok(moves) => compared += moves,
            Err(failure) => failures.push(failure),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} programs differ from rs274:\n{}",
        failures.len(),
        programs.len(),
        failures.join("\n\n")
    );
    eprintln!(
        "{} programs, {compared} moves agree with rs274",
        programs.len()
    );
}

/// The comparison itself finds a difference: a program read differently must fail.
#[test]
fn the_comparison_sees_a_moved_end_point_a_turn_and_a_feed() {
    let rapid = Move::Straight {
        rapid: false,
        end: [1.0, 2.0, 0.0, 0.0, 0.0, 0.0],
        feed: 100.0,
        control: Control::default(),
        minutes: 0.0,
        unit: 1.0,
        spread: 1.0,
    };
    let mut moved = rapid.clone();
    if let Move::Straight { end, .. } = &mut moved {
        end[1] += 2e-4;
    }
    assert!(difference(std::slice::from_ref(&rapid), std::slice::from_ref(&moved)).is_some());
    // Turned by 45°, rs274's reading may be √2 · 1e-4 off; 2e-4 is still a difference.
    if let Move::Straight { spread, .. } = &mut moved {
        *spread = std::f64::consts::SQRT_2;
    }
    assert!(difference(std::slice::from_ref(&rapid), &[moved]).is_some());
    let mut slower = rapid.clone();
    if let Move::Straight { feed, .. } = &mut slower {
        *feed = 99.0;
    }
    assert!(difference(std::slice::from_ref(&rapid), &[slower]).is_some());
    assert!(difference(std::slice::from_ref(&rapid), &[]).is_some());
    let arc = |rotation| Move::Arc {
        plane: "XY",
        end: [0.0; 6],
        center: [1.0, 0.0],
        rotation,
        feed: 1.0,
        control: Control::default(),
        unit: 1.0,
        spread: 1.0,
    };
    assert!(difference(&[arc(1)], &[arc(-1)]).is_some());
    assert!(difference(&[arc(2)], &[arc(2)]).is_none());
    // A move of pvtc's that rs274 prints as none (within its tolerance of the end
    // before it) is passed over, in inches at 25.4 times the reach; one beyond is seen.
    let nudged = |by: f64, unit: f64| match &rapid {
        Move::Straight { end, feed, .. } => Move::Straight {
            rapid: false,
            end: [end[0] + by, end[1], end[2], 0.0, 0.0, 0.0],
            feed: *feed,
            control: Control::default(),
            minutes: 0.0,
            unit,
            spread: 1.0,
        },
        _ => unreachable!(),
    };
    let after = |unit: f64| [rapid.clone(), nudged(0.0, unit)];
    let ours = [rapid.clone(), nudged(0.002, 0.0), nudged(0.0, 0.0)];
    assert!(difference(&ours, &after(25.4)).is_none());
    assert!(difference(&ours, &after(1.0)).is_some());
    let far = [rapid.clone(), nudged(0.003, 0.0), nudged(0.0, 0.0)];
    assert!(difference(&far, &after(25.4)).is_some());
    let last = [nudged(0.0, 0.0), nudged(0.002, 0.0)];
    assert!(difference(&last, &[nudged(0.0, 25.4)]).is_none());
}

#[test]
fn canonical_calls_become_machine_moves() {
    let text = "\
    1 N..... USE_LENGTH_UNITS(CANON_UNITS_INCHES)
    2 N..... SET_G5X_OFFSET(2, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    3 N..... SET_FEED_RATE(10.0000)
    4 N..... STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    5 N..... SELECT_PLANE(CANON_PLANE_XZ)
    6 N..... ARC_FEED(0.0000, 3.0000, 0.5000, 2.0000, -2, 0.2500, 0.0000, 0.0000, 0.0000)
    7 N..... DWELL(1.5000)";
    let moves = Canon::default().read(text);
    let expected = vec![
        Move::Straight {
            rapid: false,
            end: [50.8, 0.0, 0.0, 0.0, 0.0, 0.0],
            feed: 254.0,
            control: Control::default(),
            minutes: 0.0,
            unit: 25.4,
            spread: 1.0,
        },
        Move::Arc {
            plane: "ZX",
            end: [101.6, 6.35, 0.0, 0.0, 0.0, 0.0],
            center: [12.7, 76.2],
            rotation: -2,
            feed: 254.0,
            control: Control::default(),
            unit: 25.4,
            spread: 1.0,
        },
        Move::Dwell(1.5),
    ];
    assert_eq!(difference(&moves, &expected), None, "{moves:?}");
}

/// Under an XY rotation the rounding of the printed position and G92 offset adds on one
/// axis: rs274's `rotation_g92_polar_arc.ngc` reads 1.0e-4 mm from the exact centre, within
/// the spread of −35.3° (1.39e-4) but not within 1e-4.
#[test]
fn a_rotation_spreads_the_rounding_onto_one_axis() {
    let text = "\
    1 N..... SET_G92_OFFSET(13.1163, -34.1690, 0.0000, 0.0000, 0.0000, 0.0000)
    2 N..... SET_XY_ROTATION(-35.3000)
    3 N..... SET_FEED_RATE(500.0000)
    4 N..... ARC_FEED(-0.4326, -0.3695, 20.9549, -24.9730, 1, 3.0000, 0.0000, 0.0000, 0.0000)";
    let moves = Canon::default().read(text);
    let Some(Move::Arc { spread, .. }) = moves.first() else {
        panic!("one arc: {moves:?}");
    };
    let turned = libm::sincos(-35.3f64.to_radians());
    assert!((spread - (turned.0.abs() + turned.1.abs())).abs() < 1e-12);
    // The exact arc: the polar point 36.6 at −69° as the G92 offset, I J from it, turned.
    let exact = Move::Arc {
        plane: "XY",
        end: [-9.606743379330767, -35.51755740071774, 3.0, 0.0, 0.0, 0.0],
        center: [-6.368968635336675, -67.95635466191612],
        rotation: 1,
        feed: 500.0,
        control: Control::default(),
        unit: 0.0,
        spread: 0.0,
    };
    assert_eq!(difference(std::slice::from_ref(&exact), &moves), None);
    let mut unturned = moves.clone();
    if let Some(Move::Arc { spread, .. }) = unturned.first_mut() {
        *spread = 1.0;
    }
    assert!(difference(&[exact], &unturned).is_some());
}

/// LinuxCNC's own sample programs (`../shared/corpus/linuxcnc`, see its README) that
/// rs274 runs to the end move as rs274 moves them.
#[test]
fn corpus_programs_move_as_rs274_moves() {
    let rs274 = match rs274() {
        Ok(rs274) => rs274,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let dir = root().join("../shared/corpus/linuxcnc");
    if !dir.is_dir() {
        eprintln!("SKIPPED: the corpus folder {} is absent", dir.display());
        return;
    }
    let runs = [
        "3D_Chips.ngc",
        "3dtest.ngc",
        "arcspiral.ngc",
        "lathe_pawn.ngc",
        "tort.ngc",
    ];
    let failures: Vec<String> = runs
        .iter()
        .filter_map(|name| compare(rs274, &dir.join(name)).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// The start of the V-carve OpenVoronoi's TTT writes, `G20 F6` in one block on a metric
/// machine: rs274's SET_FEED_RATE(6.0000) comes before USE_LENGTH_UNITS(INCHES), so
/// LinuxCNC cuts at 6 mm/min (566 s for the part). pvtc's planned motion peaks at that
/// feed: measured on the PVT cubic of a long straight move, rest to rest, as written.
#[test]
fn the_vcarve_g20_f6_feeds_at_rs274s_set_feed_rate() {
    let rs274 = match rs274() {
        Ok(rs274) => rs274,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let program = dir.path().join("vcarve.ngc");
    let text = "(TTT V-carve start)\nG20 F6\nG0 Z0.1\nG1 X1 Y0.5 Z-0.05\nG1 X2\nM2\n";
    std::fs::write(&program, text).expect("written");
    let theirs = rs274_moves(rs274, &program).expect("rs274 runs it");
    let Some(Move::Straight { feed, .. }) = theirs.last() else {
        panic!("a last straight move: {theirs:?}");
    };
    assert!(
        (feed - 6.0).abs() < 1e-9,
        "rs274's feed is 6 mm/min: {feed}"
    );
    let output = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .arg("compile")
        .arg(&program)
        .args(["--format", "json"])
        .output()
        .expect("pvtc runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let mm = if json["units"] == "in" { 25.4 } else { 1.0 };
    let contour = json["contours"]
        .as_array()
        .and_then(|c| c.last())
        .expect("a contour");
    let segments = contour["segments"].as_array().expect("segments");
    let (before, last) = (&segments[segments.len() - 2], &segments[segments.len() - 1]);
    let peak = hermite_peak_speed(
        &before["p"],
        &before["v"],
        &last["p"],
        &last["v"],
        &last["t"],
    );
    let planned = peak * mm * 60.0;
    assert!(
        (planned - feed).abs() < 1e-3 * feed,
        "pvtc plans {planned} mm/min where LinuxCNC feeds {feed} mm/min"
    );
}

/// An arc whose end misses its start's circle within LinuxCNC's rule is the spiral
/// LinuxCNC runs (posemath's `pmCirclePoint`: the radius grows linearly with the angle):
/// pvtc's planned motion, sampled on every written PVT cubic, stays within the path
/// tolerance of that spiral, where the circle through the start is 0.04 mm off midway.
#[test]
fn a_spiral_arc_is_planned_as_linuxcnc_runs_it() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let program = dir.path().join("spiral.ngc");
    // Radius 100 to 100.08 over a half turn (0.08 %: within 0.1 %).
    std::fs::write(
        &program,
        "G21 G17 F3000\nG0 X100 Y0\nG3 X-100.08 Y0 I-100 J0\nM2\n",
    )
    .expect("written");
    let output = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .arg("compile")
        .arg(&program)
        .args(["--format", "json", "--tolerance", "0.001"])
        .output()
        .expect("pvtc runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let contour = &json["contours"][1];
    assert_eq!(contour["kind"], "feed");
    let spiral = |p: [f64; 2]| {
        let angle = libm::atan2(p[1], p[0]).rem_euclid(std::f64::consts::TAU);
        let radius = 100.0 + 0.08 * angle / std::f64::consts::PI;
        (libm::hypot(p[0], p[1]) - radius).abs()
    };
    let (mut worst, mut circle) = (0.0f64, 0.0f64);
    let mut from = contour["start"].clone();
    let mut v_from = serde_json::json!([0.0, 0.0]);
    for piece in contour["segments"].as_array().expect("segments") {
        for k in 0..=50 {
            let s = f64::from(k) / 50.0;
            let p = hermite_point(&from, &v_from, &piece["p"], &piece["v"], &piece["t"], s);
            worst = worst.max(spiral(p));
            circle = circle.max((libm::hypot(p[0], p[1]) - 100.0).abs());
        }
        from = piece["p"].clone();
        v_from = piece["v"].clone();
    }
    assert!(worst <= 0.001 + 1e-9, "{worst} mm from the spiral");
    assert!(circle > 0.04, "the spiral is no circle: {circle}");
}

/// The position (X, Y) at `s` (0 to 1) of the cubic (Hermite) piece from `p0` at `v0` to
/// `p1` at `v1` in `t` seconds.
fn hermite_point(
    p0: &serde_json::Value,
    v0: &serde_json::Value,
    p1: &serde_json::Value,
    v1: &serde_json::Value,
    t: &serde_json::Value,
    s: f64,
) -> [f64; 2] {
    let n = |v: &serde_json::Value, i: usize| v[i].as_f64().expect("a number");
    let t = t.as_f64().expect("a time");
    let (h00, h10) = (
        2.0 * s * s * s - 3.0 * s * s + 1.0,
        s * s * s - 2.0 * s * s + s,
    );
    let (h01, h11) = (-2.0 * s * s * s + 3.0 * s * s, s * s * s - s * s);
    std::array::from_fn(|i| {
        h00 * n(p0, i) + h10 * t * n(v0, i) + h01 * n(p1, i) + h11 * t * n(v1, i)
    })
}

/// The peak speed of the cubic (Hermite) piece from position `p0` at velocity `v0` to
/// `p1` at `v1` in `t` seconds, sampled at a thousand instants.
fn hermite_peak_speed(
    p0: &serde_json::Value,
    v0: &serde_json::Value,
    p1: &serde_json::Value,
    v1: &serde_json::Value,
    t: &serde_json::Value,
) -> f64 {
    let axis = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .expect("numbers")
            .iter()
            .map(|x| x.as_f64().expect("a number"))
            .collect()
    };
    let (p0, v0, p1, v1) = (axis(p0), axis(v0), axis(p1), axis(v1));
    let t = t.as_f64().expect("a time");
    (0..=1000)
        .map(|k| {
            let s = f64::from(k) / 1000.0;
            // d/dt of the Hermite basis on [0, t].
            let speed2: f64 = (0..p0.len())
                .map(|i| {
                    let (a, b) = (p0[i], p1[i]);
                    let (va, vb) = (v0[i], v1[i]);
                    let dp = (6.0 * s * s - 6.0 * s) * (a - b) / t
                        + (3.0 * s * s - 4.0 * s + 1.0) * va
                        + (3.0 * s * s - 2.0 * s) * vb;
                    dp * dp
                })
                .sum();
            speed2.sqrt()
        })
        .fold(0.0, f64::max)
}

/// Where Debian's linuxcnc-uspace installs LinuxCNC's example programs (GPL-2.0, read
/// where they are, not copied).
const EXAMPLES: &str = "/usr/share/linuxcnc/ncfiles";

/// The examples rs274 runs to their end that pvtc refuses, each with the code it refuses
/// it with; the README's dialect section says why.
const REFUSED_EXAMPLES: [(&str, &str); 1] = [
    // 7803 probing moves: each trip point only the machine knows (rs274 takes the target).
    ("smartprobe.ngc", "pvtc::gcode::probe"),
];

/// Every example program of LinuxCNC's that rs274 runs to its end and that moves, read
/// the same by pvtc (with the sidecars of `tests/dialect/linuxcnc/`: rs274's built-in
/// tools as a table, the probe results rs274 simulates, `--spindle-rpm-exact` for the
/// threading programs), or refused with the code [`REFUSED_EXAMPLES`] gives. Prints the
/// count and the list.
#[test]
fn installed_linuxcnc_examples_move_as_rs274_moves() {
    let rs274 = match rs274() {
        Ok(rs274) => rs274,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let Ok(entries) = std::fs::read_dir(EXAMPLES) else {
        eprintln!("SKIPPED: LinuxCNC's examples are not in {EXAMPLES}");
        return;
    };
    let mut programs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    programs.sort();
    let (mut agree, mut refused, mut failures) = (Vec::new(), Vec::new(), Vec::new());
    for program in &programs {
        let name = program.file_name().unwrap_or_default().to_string_lossy();
        let Ok(run) = rs274_run(rs274, program) else {
            continue;
        };
        let moves = run
            .moves
            .iter()
            .any(|m| matches!(m, Move::Straight { .. } | Move::Arc { .. }));
        if run.failure.is_some() || !moves {
            continue;
        }
        match REFUSED_EXAMPLES.iter().find(|(n, _)| *n == name) {
            Some((_, code)) => match pvtc_diagnostics(program) {
                (false, found) if found.iter().any(|(c, _)| c == code) => {
                    refused.push(name.to_string())
                }
                (_, found) => failures.push(format!("{name}: not refused with {code}: {found:?}")),
            },
            None => match compare_with(&run.moves, program) {
                Ok(_) => agree.push(name.to_string()),
                Err(failure) => failures.push(failure),
            },
        }
    }
    let total = agree.len() + refused.len() + failures.len();
    eprintln!(
        "{} of {total} examples rs274 runs to the end agree: {}; refused: {}",
        agree.len(),
        agree.join(", "),
        refused.join(", ")
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(total >= 20, "the examples are there: {total}");
}
