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

/// One motion the two interpreters agree on, in machine coordinates, millimetres.
#[derive(Debug, Clone, PartialEq)]
enum Move {
    Straight {
        rapid: bool,
        end: [f64; 6],
        feed: f64,
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
        /// Millimetres per unit of the program at this move (0 where unknown).
        unit: f64,
        /// How far the XY rotation spreads rs274's rounding of X and Y onto one axis:
        /// `|cos θ| + |sin θ|`, 1 unrotated, up to √2 (0 where unknown).
        spread: f64,
    },
    Dwell(f64),
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

/// rs274's canonical motion for `program`, or its error message.
fn rs274_moves(rs274: &str, program: &Path) -> Result<Vec<Move>, String> {
    let run = rs274_run(rs274, program)?;
    match run.failure {
        Some(failure) => Err(failure),
        None => Ok(run.moves),
    }
}

/// What rs274 did with a program: the motion it printed (up to its error, if any) and
/// its error message.
struct Rs274Run {
    moves: Vec<Move>,
    failure: Option<String>,
}

/// Runs rs274 on `program`; `Err` when it could not run it.
///
/// Two rs274 processes at once can kill each other with SIGBUS (they share memory), so
/// this test's runs take turns, and a run killed by a signal (another test process's
/// rs274, say) is tried again.
fn rs274_run(rs274: &str, program: &Path) -> Result<Rs274Run, String> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let _machine_turn = MachineTurn::take();
    let mut tries = 0;
    loop {
        let run = rs274_once(rs274, program);
        tries += 1;
        match run {
            Err(Killed(why)) if tries < 8 => {
                eprintln!("rs274 was killed ({why}); trying again");
                std::thread::sleep(std::time::Duration::from_millis(50 * tries));
            }
            Err(Killed(why)) => return Err(why),
            Ok(run) => return run,
        }
    }
}

/// A turn among every process on this machine that runs rs274 (other test binaries,
/// other checkouts): rs274 keeps its tool table in shared memory, so a run beside another
/// can find the other's table ("Requested tool 1 not found"). The turn is a directory
/// created atomically; one older than 30 s is taken as left behind by a killed process.
struct MachineTurn(Option<PathBuf>);

impl MachineTurn {
    fn take() -> MachineTurn {
        let path = std::env::temp_dir().join("pvtc-rs274-turn");
        for _ in 0..1200 {
            if std::fs::create_dir(&path).is_ok() {
                return MachineTurn(Some(path));
            }
            let age = std::fs::metadata(&path)
                .and_then(|m| m.modified())
                .map(|t| t.elapsed().unwrap_or_default());
            if age.is_ok_and(|age| age > std::time::Duration::from_secs(30)) {
                let _ = std::fs::remove_dir(&path);
                continue;
            }
            std::thread::sleep(std::time::Duration::from_millis(25));
        }
        // Waited 30 s: run without the turn (a failure then says what rs274 said).
        MachineTurn(None)
    }
}

impl Drop for MachineTurn {
    fn drop(&mut self) {
        if let Some(path) = &self.0 {
            let _ = std::fs::remove_dir(path);
        }
    }
}

/// An rs274 run that a signal ended, or that lost its tool table to another run.
struct Killed(String);

fn rs274_once(rs274: &str, program: &Path) -> Result<Result<Rs274Run, String>, Killed> {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = dir.path().join("canon.txt");
    let mut command = Command::new(rs274);
    if let Some(table) = sidecar(program, "tbl") {
        command.arg("-t").arg(table);
    }
    // With an ini, rs274 runs in the program's folder: a relative SUBROUTINE_PATH
    // there is relative to the folder (pvtc's `.args` too: pvtc runs there).
    let mut cwd = dir.path().to_path_buf();
    if let Some(ini) = sidecar(program, "ini") {
        command.arg("-i").arg(ini);
        cwd = program.parent().expect("a folder").to_path_buf();
    }
    let output = command
        .arg("-g")
        .arg(program)
        .arg(&out)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .output()
        .expect("rs274 runs");
    let failure = format!(
        "rs274 failed ({}) on {}: {}{}",
        output.status,
        program.display(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    if output.status.code().is_none() {
        return Err(Killed(failure));
    }
    let lost_table = String::from_utf8_lossy(&output.stderr)
        .contains("not found in the tool table")
        || String::from_utf8_lossy(&output.stdout).contains("not found in the tool table");
    if !output.status.success() && lost_table && sidecar(program, "tbl").is_some() {
        return Err(Killed(failure));
    }
    let failed = !output.status.success();
    let Ok(text) = std::fs::read_to_string(&out) else {
        return Ok(Err(failure));
    };
    Ok(Ok(Rs274Run {
        moves: Canon::default().read(&text),
        failure: failed.then_some(failure),
    }))
}

/// The state of LinuxCNC's canonical layer that turns program into machine coordinates.
#[derive(Default)]
struct Canon {
    /// Millimetres per program unit (0 before USE_LENGTH_UNITS means 1).
    mm: f64,
    g5x: [f64; 6],
    g92: [f64; 6],
    tool: [f64; 6],
    rotation_deg: f64,
    plane: &'static str,
    /// The feed number, program units per minute.
    feed: f64,
    /// The last machine position, millimetres.
    at: [f64; 6],
    /// Millimetres per unit of the work, G92 and tool offsets when last printed.
    offset_unit: [f64; 3],
}

impl Canon {
    fn read(mut self, text: &str) -> Vec<Move> {
        self.mm = 1.0;
        self.plane = "XY";
        let mut moves = Vec::new();
        for line in text.lines() {
            let Some((name, args)) = call(line) else {
                continue;
            };
            let numbers = numbers(args);
            match name {
                "USE_LENGTH_UNITS" => {
                    self.mm = if args.contains("INCH") { 25.4 } else { 1.0 };
                }
                "SET_G5X_OFFSET" => {
                    self.g5x = self.lengths(&numbers[1..]);
                    self.offset_unit[0] = self.mm;
                }
                "SET_G92_OFFSET" => {
                    self.g92 = self.lengths(&numbers);
                    self.offset_unit[1] = self.mm;
                }
                "SET_XY_ROTATION" => self.rotation_deg = numbers[0],
                "USE_TOOL_LENGTH_OFFSET" => {
                    self.tool = self.lengths(&numbers);
                    self.offset_unit[2] = self.mm;
                }
                "SELECT_PLANE" => {
                    self.plane = match args {
                        a if a.contains("XZ") => "ZX",
                        a if a.contains("YZ") => "YZ",
                        _ => "XY",
                    }
                }
                // The number is read in the units in force at each move.
                "SET_FEED_RATE" => self.feed = numbers[0],
                "DWELL" => moves.push(Move::Dwell(numbers[0])),
                "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => {
                    let end = self.machine(&numbers[..6]);
                    let moved = end.iter().zip(&self.at).any(|(a, b)| (a - b).abs() > 1e-9);
                    self.at = end;
                    if moved {
                        moves.push(Move::Straight {
                            rapid: name == "STRAIGHT_TRAVERSE",
                            end,
                            feed: self.feed * self.mm,
                            unit: self.unit(),
                            spread: self.spread(),
                        });
                    }
                }
                "ARC_FEED" => moves.push(self.arc(&numbers)),
                _ => {}
            }
        }
        moves
    }

    /// Millimetres per unit of the coarsest number in a move's machine position.
    fn unit(&self) -> f64 {
        self.offset_unit.iter().fold(self.mm, |a, b| a.max(*b))
    }

    /// How far the rotation mixes the rounding of the printed X and Y (the position's
    /// and the G92 offset's, both turned) into one machine axis: an error `(e, e)` turned
    /// by θ is `e (cos θ − sin θ)`, `e (sin θ + cos θ)`, at most `e (|cos θ| + |sin θ|)`.
    fn spread(&self) -> f64 {
        let (sin, cos) = libm::sincos(self.rotation_deg.to_radians());
        sin.abs() + cos.abs()
    }

    /// Program lengths to millimetres (rotary axes stay degrees).
    fn lengths(&self, values: &[f64]) -> [f64; 6] {
        let mut out = [0.0; 6];
        for (i, v) in values.iter().take(6).enumerate() {
            out[i] = if i < 3 { v * self.mm } else { *v };
        }
        out
    }

    /// A program position as LinuxCNC's canon makes it a machine position: plus the G92
    /// offset, rotated about the work origin, plus the work and tool offsets.
    fn machine(&self, program: &[f64]) -> [f64; 6] {
        let mut p = self.lengths(program);
        for (v, g92) in p.iter_mut().zip(&self.g92) {
            *v += g92;
        }
        let (sin, cos) = libm::sincos(self.rotation_deg.to_radians());
        let (x, y) = (p[0], p[1]);
        p[0] = x * cos - y * sin;
        p[1] = x * sin + y * cos;
        for ((v, g5x), tool) in p.iter_mut().zip(&self.g5x).zip(&self.tool) {
            *v += g5x + tool;
        }
        p
    }

    /// ARC_FEED(first_end, second_end, first_centre, second_centre, rotation,
    /// normal_end, a, b, c), the plane's axes in G17/G18/G19 order.
    fn arc(&mut self, n: &[f64]) -> Move {
        let (first, second, normal) = plane_axes(self.plane);
        let mut end = [0.0; 6];
        end[first] = n[0];
        end[second] = n[1];
        end[normal] = n[5];
        end[3..6].copy_from_slice(&n[6..9]);
        let mut centre = end;
        centre[first] = n[2];
        centre[second] = n[3];
        let end = self.machine(&end);
        let centre = self.machine(&centre);
        self.at = end;
        Move::Arc {
            plane: self.plane,
            end,
            center: [centre[first], centre[second]],
            rotation: n[4] as i64,
            feed: self.feed * self.mm,
            unit: self.unit(),
            spread: self.spread(),
        }
    }
}

fn plane_axes(plane: &str) -> (usize, usize, usize) {
    match plane {
        "ZX" => (2, 0, 1),
        "YZ" => (1, 2, 0),
        _ => (0, 1, 2),
    }
}

/// `   12 N..... NAME(ARGS)` (or `N102  ` where the block has an N word) as (NAME, ARGS).
fn call(line: &str) -> Option<(&str, &str)> {
    let (_, rest) = line.trim_start().split_once(' ')?;
    let (_, rest) = rest.trim_start().split_once(' ')?;
    let (name, args) = rest.split_once('(')?;
    let args = &args[..args.rfind(')')?];
    Some((name.trim(), args))
}

/// Every number in a canonical call's arguments, in order.
fn numbers(args: &str) -> Vec<f64> {
    args.split([',', ' '])
        .filter_map(|w| w.trim().parse::<f64>().ok())
        .collect()
}

/// pvtc's reading of `program` as moves, or its diagnostics.
fn pvtc_moves(program: &Path) -> Result<Vec<Move>, String> {
    let mut command = Command::new(env!("CARGO_BIN_EXE_pvtc"));
    command
        .arg("compile")
        .arg(program)
        .args(["--format", "toolpath"])
        .current_dir(program.parent().expect("a folder"))
        .env("NO_COLOR", "1");
    if let Some(table) = sidecar(program, "tbl") {
        command.arg("--tool-table").arg(table);
    }
    if let Some(args) = sidecar(program, "args") {
        let text = std::fs::read_to_string(args).expect("args file");
        command.args(text.lines().map(str::trim).filter(|l| !l.is_empty()));
    }
    let output = command.output().expect("pvtc runs");
    if !output.status.success() {
        return Err(format!(
            "pvtc failed on {}:\n{}",
            program.display(),
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    Ok(toolpath_moves(&String::from_utf8_lossy(&output.stdout)))
}

/// The `--format toolpath` lines as moves, in millimetres.
fn toolpath_moves(text: &str) -> Vec<Move> {
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect();
    let end = lines.last().expect("an end line");
    assert_eq!(end["kind"], "end", "the toolpath output is complete");
    let mm = if end["units"] == "in" { 25.4 } else { 1.0 };
    let position = |v: &serde_json::Value| -> [f64; 6] {
        let mut p = [0.0; 6];
        for (i, x) in p.iter_mut().enumerate() {
            let value = v[i].as_f64().expect("a number");
            *x = if i < 3 { value * mm } else { value };
        }
        p
    };
    let mut moves = Vec::new();
    let mut last_line = None;
    for line in &lines {
        let feed = line["feed"].as_f64().unwrap_or(0.0) * mm;
        match line["kind"].as_str() {
            Some("line") => moves.push(Move::Straight {
                rapid: line["motion"] == "rapid",
                end: position(&line["end"]),
                feed,
                unit: 0.0,
                spread: 0.0,
            }),
            Some("arc") => {
                let turns = line["turns"].as_i64().expect("turns") + 1;
                let arc = Move::Arc {
                    plane: match line["plane"].as_str() {
                        Some("ZX") => "ZX",
                        Some("YZ") => "YZ",
                        _ => "XY",
                    },
                    end: position(&line["end"]),
                    center: [
                        line["center"][0].as_f64().expect("centre") * mm,
                        line["center"][1].as_f64().expect("centre") * mm,
                    ],
                    rotation: if line["direction"] == "cw" {
                        -turns
                    } else {
                        turns
                    },
                    feed,
                    unit: 0.0,
                    spread: 0.0,
                };
                // pvtc hands an arc of many turns on a turn at a time: the parts of one
                // block (one source line, one centre) are one arc, as rs274 prints it.
                // (Two arcs of one line with two centres, a compensated arc and the arc
                // around the corner after it, stay two.)
                let part_of_last = last_line == Some(&line["line"]);
                match (moves.last_mut(), part_of_last) {
                    (Some(last), true) if same_centre(last, &arc) => join_turns(last, arc),
                    _ => moves.push(arc),
                }
            }
            Some("event") if line["event"] == "dwell" => {
                moves.push(Move::Dwell(line["seconds"].as_f64().expect("seconds")))
            }
            _ => {}
        }
        last_line = (line["kind"] == "arc").then_some(&line["line"]);
    }
    moves
}

/// Whether `last` is an arc about the centre of the arc `next`.
fn same_centre(last: &Move, next: &Move) -> bool {
    match (last, next) {
        (Move::Arc { center: a, .. }, Move::Arc { center: b, .. }) => close(a, b, 1.0),
        _ => false,
    }
}

/// `next`, the next turn of the arc `last` is part of, joined to it: its end and its turn.
fn join_turns(last: &mut Move, next: Move) {
    let (
        Move::Arc {
            end,
            center,
            rotation,
            ..
        },
        Move::Arc {
            end: next_end,
            center: next_center,
            rotation: next_rotation,
            ..
        },
    ) = (last, next)
    else {
        return;
    };
    debug_assert!(close(center, &next_center, 1.0));
    *end = next_end;
    *rotation += next_rotation;
}

/// Whether `a` and `b` agree within [`TOLERANCE`] of `unit` millimetres (at least 1).
fn close(a: &[f64], b: &[f64], unit: f64) -> bool {
    let tolerance = TOLERANCE * unit.max(1.0);
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

/// Whether two moves agree; a rapid's feed is the machine's, not the program's.
fn same(ours: &Move, theirs: &Move) -> bool {
    match (ours, theirs) {
        (
            Move::Straight {
                rapid, end, feed, ..
            },
            Move::Straight {
                rapid: r,
                end: e,
                feed: f,
                unit,
                spread,
            },
        ) => {
            rapid == r
                && close(end, e, unit * spread.max(1.0))
                && (*rapid || close(&[*feed], &[*f], *unit))
        }
        (
            Move::Arc {
                plane,
                end,
                center,
                rotation,
                feed,
                ..
            },
            Move::Arc {
                plane: p,
                end: e,
                center: c,
                rotation: r,
                feed: f,
                unit,
                spread,
            },
        ) => {
            plane == p
                && rotation == r
                && close(end, e, unit * spread.max(1.0))
                && close(center, c, unit * spread.max(1.0))
                && close(&[*feed], &[*f], *unit)
        }
        (Move::Dwell(a), Move::Dwell(b)) => (a - b).abs() <= 1e-6,
        _ => false,
    }
}

/// The first difference between the two readings, described, or `None`.
///
/// rs274's reading drops a straight move whose printed end is the end before it (see
/// [`Move::Straight`]'s parse), so a move of pvtc's that rs274 prints as none, one whose
/// every axis is within what rs274 prints of pvtc's end before it (its [`TOLERANCE`] of
/// the units of rs274's next move), is passed over: `G20 G91 X-0.0394` from X1 mm ends
/// 0.00076 mm before X0, and a `G90 X0` after it moves 0.00076 mm, printed as no move.
fn difference(ours: &[Move], theirs: &[Move]) -> Option<String> {
    let (mut i, mut j) = (0, 0);
    let mut at: Option<[f64; 6]> = None;
    let end = |m: &Move| match m {
        Move::Straight { end, .. } | Move::Arc { end, .. } => Some(*end),
        Move::Dwell(_) => None,
    };
    while i < ours.len() {
        let theirs_next = theirs.get(j).or(theirs.last());
        let unit = match theirs_next {
            Some(Move::Straight { unit, .. } | Move::Arc { unit, .. }) => *unit,
            _ => 1.0,
        };
        let unprinted = match (&ours[i], at) {
            (Move::Straight { end, .. }, Some(at)) => close(end, &at, unit),
            _ => false,
        };
        match theirs.get(j) {
            Some(t) if same(&ours[i], t) => j += 1,
            _ if unprinted => {}
            Some(t) => return Some(format!("move {i}:\n  pvtc:  {:?}\n  rs274: {t:?}", ours[i])),
            None => break,
        }
        at = end(&ours[i]).or(at);
        i += 1;
    }
    (i != ours.len() || j != theirs.len()).then(|| {
        format!(
            "pvtc has {} moves, rs274 {}; the first extra: {:?}",
            ours.len(),
            theirs.len(),
            ours.get(i).or(theirs.get(j))
        )
    })
}

/// Compares one program; the failure, described.
fn compare(rs274: &str, program: &Path) -> Result<usize, String> {
    if let Some(expected) = sidecar(program, "error") {
        return compare_refusal(rs274, program, &expected);
    }
    let theirs = rs274_moves(rs274, program)?;
    let ours = pvtc_moves(program)?;
    match difference(&ours, &theirs) {
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

/// Whether pvtc compiles `program`, and its diagnostics as (code, line).
fn pvtc_diagnostics(program: &Path) -> (bool, Vec<(String, usize)>) {
    let output = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .arg("compile")
        .arg(program)
        .args([
            "--format",
            "toolpath",
            "--diagnostics",
            "json",
            "-o",
            "/dev/null",
        ])
        .output()
        .expect("pvtc runs");
    let diagnostics = String::from_utf8_lossy(&output.stderr)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .map(|d| {
            let code = d["code"].as_str().unwrap_or("").to_owned();
            (code, d["line"].as_u64().unwrap_or(0) as usize)
        })
        .collect();
    (output.status.success(), diagnostics)
}

/// Compares a program given as text (a generated one), written to a temporary file.
fn compare_text(rs274: &str, text: &str) -> Result<usize, String> {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("random.ngc");
    std::fs::write(&path, text).expect("written");
    compare(rs274, &path)
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
            unit: 25.4,
            spread: 1.0,
        },
        Move::Arc {
            plane: "ZX",
            end: [101.6, 6.35, 0.0, 0.0, 0.0, 0.0],
            center: [12.7, 76.2],
            rotation: -2,
            feed: 254.0,
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

/// Random programs over the dialect both interpreters run: lines and rapids, arcs in
/// every plane by centre with helical motion and extra turns, absolute and incremental
/// distances, unit switches, feeds, dwells and G92 offsets.
mod generated {
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
            let rs274 = match rs274() {
                Ok(rs274) => rs274,
                Err(why) => {
                    eprintln!("SKIPPED: {why}");
                    return Ok(());
                }
            };
            let text = program(&steps);
            let compared = compare_text(rs274, &text);
            prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
        }
    }
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

/// LinuxCNC's example programs as installed with rs274 (`/usr/share/linuxcnc/ncfiles`,
/// GPL-2.0, read where they are, not copied): polar canned cycles (`polar.ngc`,
/// `hole-circle.ngc`) and a tool change with G43 in one block (`skeleton.ngc`) move as
/// rs274 moves them.
#[test]
fn installed_linuxcnc_examples_move_as_rs274_moves() {
    let rs274 = match rs274() {
        Ok(rs274) => rs274,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let dir = Path::new("/usr/share/linuxcnc/ncfiles");
    let runs = ["polar.ngc", "hole-circle.ngc", "skeleton.ngc"];
    let present: Vec<PathBuf> = runs
        .iter()
        .map(|n| dir.join(n))
        .filter(|p| p.exists())
        .collect();
    if present.len() < runs.len() {
        eprintln!(
            "SKIPPED: LinuxCNC's examples are not all in {}",
            dir.display()
        );
        return;
    }
    let failures: Vec<String> = present
        .iter()
        .filter_map(|path| compare(rs274, path).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Random O-word programs: conditionals, counted and conditional loops with `continue`,
/// and calls of a subroutine, nested, over moves that read `#<_x>` and a parameter.
/// (`break` is left to `tests/dialect/oword_while_nested.ngc`: in rs274, a `break` of a
/// `while` makes every later `do` loop run once, a quirk pvtc does not copy.)
mod generated_control_flow {
    use super::*;
    use proptest::prelude::*;

    #[derive(Debug, Clone)]
    enum Node {
        /// `G1` by (dx, dy) tenths from the position read through `#<_x>`, `#<_y>`.
        Move(i32, i32),
        /// `#<v> = [#<v> + k]`.
        Add(i32),
        /// `o<step> call [arg]`: a relative step of (arg, arg / 2).
        Call(i32),
        If(i32, Vec<Node>, Vec<Node>),
        Repeat(u32, Vec<Node>),
        /// Runs `times` times, skipping the rest of its body after `skip_after` iterations.
        While(u32, Option<u32>, Vec<Node>),
        DoWhile(u32, Vec<Node>),
    }

    fn node() -> impl Strategy<Value = Node> {
        let leaf = prop_oneof![
            3 => (-30i32..30, -30i32..30).prop_map(|(dx, dy)| Node::Move(dx, dy)),
            1 => (-3i32..4).prop_map(Node::Add),
            1 => (-20i32..20).prop_map(Node::Call),
        ];
        leaf.prop_recursive(3, 24, 4, |inner| {
            let body = prop::collection::vec(inner.clone(), 1..4);
            prop_oneof![
                (-3i32..4, body.clone(), prop::collection::vec(inner, 0..3))
                    .prop_map(|(limit, then, otherwise)| Node::If(limit, then, otherwise)),
                (0u32..3, body.clone()).prop_map(|(times, body)| Node::Repeat(times, body)),
                (0u32..3, prop::option::of(0u32..3), body.clone())
                    .prop_map(|(times, at, body)| Node::While(times, at, body)),
                (1u32..3, body).prop_map(|(times, body)| Node::DoWhile(times, body)),
            ]
        })
    }

    fn render(nodes: &[Node], labels: &mut u32, text: &mut String) {
        for node in nodes {
            let mut label = || {
                *labels += 1;
                *labels
            };
            match node {
                Node::Move(dx, dy) => text.push_str(&format!(
                    "G1 X[#<_x> + {}] Y[#<_y> + {} + #<v> / 10]\n",
                    f64::from(*dx) / 10.0,
                    f64::from(*dy) / 10.0
                )),
                Node::Add(k) => text.push_str(&format!("#<v> = [#<v> + {k}]\n")),
                Node::Call(arg) => {
                    text.push_str(&format!("o<step> call [{}]\n", f64::from(*arg) / 10.0))
                }
                Node::If(limit, then, otherwise) => {
                    let l = label();
                    text.push_str(&format!("o{l} if [#<v> GT {limit}]\n"));
                    render(then, labels, text);
                    if !otherwise.is_empty() {
                        text.push_str(&format!("o{l} else\n"));
                        render(otherwise, labels, text);
                    }
                    text.push_str(&format!("o{l} endif\n"));
                }
                Node::Repeat(times, body) => {
                    let l = label();
                    text.push_str(&format!("o{l} repeat [{times}]\n"));
                    render(body, labels, text);
                    text.push_str(&format!("o{l} endrepeat\n"));
                }
                Node::While(times, at, body) => {
                    let l = label();
                    text.push_str(&format!("#<w{l}> = 0\no{l} while [#<w{l}> LT {times}]\n"));
                    text.push_str(&format!("#<w{l}> = [#<w{l}> + 1]\n"));
                    if let Some(at) = at {
                        let b = label();
                        text.push_str(&format!(
                            "o{b} if [#<w{l}> GT {at}]\no{l} continue\no{b} endif\n"
                        ));
                    }
                    render(body, labels, text);
                    text.push_str(&format!("o{l} endwhile\n"));
                }
                Node::DoWhile(times, body) => {
                    let l = label();
                    text.push_str(&format!("#<w{l}> = 0\no{l} do\n#<w{l}> = [#<w{l}> + 1]\n"));
                    render(body, labels, text);
                    text.push_str(&format!("o{l} while [#<w{l}> LT {times}]\n"));
                }
            }
        }
    }

    fn program(nodes: &[Node]) -> String {
        let mut text = String::from(
            "G21 G90 G17 G94 F300\nG1 X1 Y1\n#<v> = 0\n\
             o<step> sub\nG91 G1 X#1 Y[#1 / 2]\nG90\no<step> endsub\n",
        );
        render(nodes, &mut 0, &mut text);
        text.push_str("M2\n");
        text
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: cases(32), ..ProptestConfig::default() })]

        #[test]
        fn random_control_flow_moves_as_rs274_moves(nodes in prop::collection::vec(node(), 1..6)) {
            let rs274 = match rs274() {
                Ok(rs274) => rs274,
                Err(why) => {
                    eprintln!("SKIPPED: {why}");
                    return Ok(());
                }
            };
            let text = program(&nodes);
            let compared = compare_text(rs274, &text);
            prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
        }
    }
}

/// Random closed profiles under cutter-radius compensation, compared with rs274: star
/// polygons (convex when every corner is on one circle, concave otherwise) whose edges
/// are lines or arcs bulging either way, cut with the tool left or right, clockwise or
/// counter-clockwise, in G17 or G18, with entry and exit moves. Where rs274 refuses a
/// profile (the tool gouges), pvtc must refuse it at the same line with a compensation
/// code.
mod generated_compensation {
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
}
