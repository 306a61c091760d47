//! rs274's side of the differential tests: running `rs274 -g` on a program and reading
//! its canonical calls as machine moves, as LinuxCNC's canonical layer makes them.

use super::*;

/// rs274's canonical motion for `program`, or its error message.
pub(crate) fn rs274_moves(rs274: &str, program: &Path) -> Result<Vec<Move>, String> {
    let run = rs274_run(rs274, program)?;
    match run.failure {
        Some(failure) => Err(failure),
        None => Ok(run.moves),
    }
}

/// What rs274 did with a program: the motion it printed (up to its error, if any) and
/// its error message.
pub(crate) struct Rs274Run {
    pub(crate) moves: Vec<Move>,
    pub(crate) failure: Option<String>,
}

/// Runs rs274 on `program`; `Err` when it could not run it.
///
/// Two rs274 processes at once can kill each other with SIGBUS (they share memory), so
/// this test's runs take turns, and a run killed by a signal (another test process's
/// rs274, say) is tried again.
pub(crate) fn rs274_run(rs274: &str, program: &Path) -> Result<Rs274Run, String> {
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
pub(crate) struct MachineTurn(Option<PathBuf>);

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
pub(crate) struct Killed(String);

pub(crate) fn rs274_once(rs274: &str, program: &Path) -> Result<Result<Rs274Run, String>, Killed> {
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

/// The state of LinuxCNC's canonical layer (`emccanon.cc`) that turns program into machine
/// coordinates and feeds into millimetres per minute.
#[derive(Default)]
pub(crate) struct Canon {
    /// Millimetres per program unit (0 before USE_LENGTH_UNITS means 1).
    mm: f64,
    g5x: [f64; 6],
    g92: [f64; 6],
    tool: [f64; 6],
    rotation_deg: f64,
    plane: &'static str,
    /// The feed, millimetres per minute (per revolution under G95): LinuxCNC converts the
    /// number of SET_FEED_RATE with the units in force when it is called.
    feed: f64,
    /// Millimetres per program unit when the feed was set (a feed of rotary axes alone
    /// is its number, in degrees per minute).
    feed_unit: f64,
    /// G95: the feed is per revolution.
    per_revolution: bool,
    /// The pitch of a synchronised move (START_SPEED_FEED_SYNC), millimetres per turn.
    pitch: Option<f64>,
    /// The last SET_SPINDLE_SPEED, rpm.
    rpm: f64,
    /// G96 (SET_SPINDLE_MODE with a maximum speed): S is a surface speed, which pvtc
    /// hands on as no spindle speed.
    surface_speed: bool,
    control: Control,
    /// The last machine position, millimetres.
    at: [f64; 6],
    /// Millimetres per unit of the work, G92 and tool offsets when last printed.
    offset_unit: [f64; 3],
}

impl Canon {
    pub(crate) fn read(mut self, text: &str) -> Vec<Move> {
        self.mm = 1.0;
        self.feed_unit = 1.0;
        self.plane = "XY";
        let mut moves = Vec::new();
        let calls: Vec<(&str, &str)> = text.lines().filter_map(call).collect();
        for &(name, args) in program_calls(&calls) {
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
                "SET_FEED_RATE" => {
                    self.feed = numbers[0] * self.mm;
                    self.feed_unit = self.mm;
                }
                "SET_FEED_MODE" => self.per_revolution = numbers.get(1) == Some(&1.0),
                "START_SPEED_FEED_SYNC" => self.pitch = Some(numbers[0] * self.mm),
                "STOP_SPEED_FEED_SYNCH" => self.pitch = None,
                "SET_SPINDLE_MODE" => self.surface_speed = numbers.get(1) > Some(&0.0),
                "SET_SPINDLE_SPEED" if !self.surface_speed => {
                    self.rpm = numbers[1];
                    moves.push(Move::Speed(self.rpm));
                }
                "SET_MOTION_CONTROL_MODE" => {
                    self.control.mode = match args {
                        a if a.contains("EXACT_PATH") => "exact_path",
                        a if a.contains("EXACT_STOP") => "exact_stop",
                        _ => "continuous",
                    };
                    self.control.p = numbers.first().map_or(0.0, |p| p * self.mm);
                }
                "SET_NAIVECAM_TOLERANCE" => self.control.q = numbers[0] * self.mm,
                "DWELL" => moves.push(Move::Dwell(numbers[0])),
                "START_SPINDLE_CLOCKWISE" => moves.push(Move::Spindle("cw")),
                "START_SPINDLE_COUNTERCLOCKWISE" => moves.push(Move::Spindle("ccw")),
                "STOP_SPINDLE_TURNING" => moves.push(Move::Spindle("off")),
                "MIST_ON" => moves.push(Move::Coolant("mist")),
                "FLOOD_ON" => moves.push(Move::Coolant("flood")),
                // M9 prints MIST_OFF then FLOOD_OFF: one coolant off.
                "MIST_OFF" => moves.push(Move::Coolant("off")),
                // rs274 alone has a probing move trip at its target.
                "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" | "STRAIGHT_PROBE" => {
                    let end = self.machine(&numbers[..6]);
                    moves.extend(self.straight(name == "STRAIGHT_TRAVERSE", end));
                }
                // RIGID_TAP(x, y, z): in to the point and back out, synchronised.
                "RIGID_TAP" => {
                    let back = self.at;
                    let mut bottom = back;
                    let program =
                        self.machine(&[numbers[0], numbers[1], numbers[2], 0.0, 0.0, 0.0]);
                    bottom[..3].copy_from_slice(&program[..3]);
                    moves.extend(self.straight(false, bottom));
                    moves.extend(self.straight(false, back));
                }
                "ARC_FEED" => moves.push(self.arc(&numbers)),
                _ => {}
            }
        }
        moves
    }

    /// A straight move to `end`, unless it is where the last move ended.
    fn straight(&mut self, rapid: bool, end: [f64; 6]) -> Option<Move> {
        let moved = end.iter().zip(&self.at).any(|(a, b)| (a - b).abs() > 1e-9);
        let minutes = match rapid {
            true => 0.0,
            false => self.rotary_minutes(&end),
        };
        self.at = end;
        moved.then(|| Move::Straight {
            rapid,
            end,
            feed: self.feed_now(),
            control: self.control,
            minutes,
            unit: self.unit(),
            spread: self.spread(),
        })
    }

    /// The minutes a feed move to `end` that turns a rotary axis takes, as LinuxCNC's
    /// canonical layer times it: its X Y Z length over the feed, or with X Y Z still its
    /// rotary length over the feed's number in degrees per minute; 0 for other moves.
    fn rotary_minutes(&self, end: &[f64; 6]) -> f64 {
        let length = |r: std::ops::Range<usize>| {
            r.map(|i| (end[i] - self.at[i]).powi(2)).sum::<f64>().sqrt()
        };
        let (linear, rotary) = (length(0..3), length(3..6));
        match (rotary > 1e-9, linear > 1e-9) {
            (false, _) => 0.0,
            (true, true) => linear / self.feed_now(),
            (true, false) => rotary / (self.feed_now() / self.feed_unit),
        }
    }

    /// The feed of a feed move now, millimetres per minute: a synchronised move's pitch
    /// times S, G95's feed per revolution times S, else the feed.
    fn feed_now(&self) -> f64 {
        match (self.pitch, self.per_revolution) {
            (Some(pitch), _) => pitch * self.rpm,
            (None, true) => self.feed * self.rpm,
            (None, false) => self.feed,
        }
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
            feed: self.feed_now(),
            control: self.control,
            unit: self.unit(),
            spread: self.spread(),
        }
    }
}

pub(crate) fn plane_axes(plane: &str) -> (usize, usize, usize) {
    match plane {
        "ZX" => (2, 0, 1),
        "YZ" => (1, 2, 0),
        _ => (0, 1, 2),
    }
}

/// The calls of the program itself: those before the reset the program end makes
/// (M2/M30 set G54, no rotation, G94, F0, the spindle and coolant off before
/// PROGRAM_END), which pvtc does not hand on.
fn program_calls<'a>(calls: &'a [(&'a str, &'a str)]) -> &'a [(&'a str, &'a str)] {
    let Some(end) = calls.iter().position(|(name, _)| *name == "PROGRAM_END") else {
        return calls;
    };
    let reset = calls[..end]
        .iter()
        .rposition(|(name, _)| *name == "SET_G5X_OFFSET")
        .unwrap_or(end);
    &calls[..reset]
}

/// `   12 N..... NAME(ARGS)` (or `N102  ` where the block has an N word) as (NAME, ARGS).
pub(crate) fn call(line: &str) -> Option<(&str, &str)> {
    let (_, rest) = line.trim_start().split_once(' ')?;
    let (_, rest) = rest.trim_start().split_once(' ')?;
    let (name, args) = rest.split_once('(')?;
    let args = &args[..args.rfind(')')?];
    Some((name.trim(), args))
}

/// Every number in a canonical call's arguments, in order.
pub(crate) fn numbers(args: &str) -> Vec<f64> {
    args.split([',', ' '])
        .filter_map(|w| w.trim().parse::<f64>().ok())
        .collect()
}
