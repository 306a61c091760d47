//! PMAC motion program text in PVT mode (seeds 000 and 003).
//!
//! Owns the PMAC spelling of a program. One line per segment:
//!
//! ```text
//! TA12.3456 X10.000000000:100.000000000 Y0.000000000:0.000000000
//! ```
//!
//! - positions: absolute (`ABS`), program units, 9 decimals;
//! - velocities: signed, units per second, 9 decimals — this assumes the coordinate
//!   system's feedrate time unit `Ix90 = 1000` (ms per time unit: PMAC's default; `Isx90`
//!   on Turbo PMAC);
//! - why 9 decimals: a constant sent to PMAC is decimal ASCII text, and Turbo PMAC stores
//!   every motion-program constant as a 48-bit floating-point value, a 36-bit mantissa and
//!   a 12-bit exponent (Turbo PMAC User Manual, "Turbo PMAC Computational Features":
//!   "All constants used in these statements are stored as 48-bit floating-point values";
//!   "Receiving Values"); Power PMAC reads IEEE doubles. Neither section gives a limit on
//!   the digits of a constant's decimal text. At 9 decimals the text rounds a position by at most
//!   5·10⁻¹⁰ units, which is below the 48-bit float's own step (2⁻³⁵ of the value) at
//!   every position above about 17 units, so the text's rounding does not matter to the
//!   motion: [`crate::Format::position_resolution`] is [`POSITION_RESOLUTION`] (10⁻⁹),
//!   and the room the planner keeps for it at a knot's acceleration step on a 1 ms grid
//!   is 10⁻⁹·6·2/T² = 0.012 units/s², a thousandth of what 6 decimals needed;
//! - piece time: `TA` in milliseconds with 4 decimals, written *before* the axis words.
//!   Seed 000 prints `TA` after them, but PMAC takes each piece's time from the most
//!   recently executed `PVT` or `TA` statement, so a trailing `TA` would time the next
//!   piece. PMAC rounds `TA` to whole milliseconds without an error (seed 003), so pvtc
//!   plans on a 1 ms grid unless told otherwise ([`CAPS`]); the count of times that are
//!   not whole is stated at the end of the program. On Turbo PMAC, `TA`
//!   times PVT pieces only with `I42 = 1` (then 1 ms resolution); under the default
//!   `I42 = 0` only `PVT` and `TM` do, with a range of 0–4095.9998 ms.
//! - no piece is longer than [`MAX_PIECE_SECONDS`] (4095 ms, within Turbo PMAC's range
//!   under either `I42`): the pipeline cuts longer ones along their cubic
//!   (`pvt_core::split`) and [`crate::Checked`] refuses any that reaches this writer.
//!
//! Every contour starts and ends at rest; consecutive contours chain, so the whole program
//! is one `OPEN PROG n CLEAR … CLOSE` block ([`PmacSettings::program`], 1 by default), or
//! with [`PmacSettings::rotary`] the coordinate system's rotary buffer (`DEFINE ROT n`,
//! `B0`, `OPEN ROT`, `CLEAR` … `CLOSE`, then `R`), which the host streams as it empties:
//! a program of any length in a buffer of fixed size (Turbo PMAC User Manual, "Rotary
//! Motion Program Buffers"; PMAC Software Reference, `OPEN ROTARY`, `DEFINE ROTARY`).
//! With [`PmacSettings::coord`] the block is preceded by the on-line commands that address
//! the coordinate system (`&1`) and define its axes (`#1->1000X`).
//!
//! Events: by default comments (a `DWELL` for G4). With [`PmacEvents::Commands`] they are
//! PMAC's machine-tool-style commands: M-codes as `M03` (a call of PROG 1001 at N3000,
//! which the machine's integrator writes), tools as `T5` (PROG 1002), the spindle speed
//! as `S12000`, M0 as `STOP`, a message as `SEND"…"`; each is followed by a fresh
//! `PVT` line, because a called routine may change the move mode. The grammar of what is written is
//! `grammars/pmac.ebnf`. PMAC has no PT move of this kind, so PT programs are refused.
//!
//! Triggers (`--trigger-every`, [`crate::triggers`]): the piece is cut at the trigger and
//! a synchronous assignment `M1==1` (then `M1==0` at the next, so every trigger is an
//! edge) is written after the piece that ends there. PMAC evaluates it when it reads the
//! line and holds the assignment "until the beginning of the move immediately following
//! it" (PMAC User Manual, "Writing Programs for PMAC", Synchronous M-Variable Assignment,
//! <https://www.manualshelf.com/manual/delta-tau/pmac/user-manual-english/page-237.html>;
//! the forms `==`, `&=`, `|=`, `^=` in "Computational Features",
//! <http://www.manualshelf.com/manual/delta-tau/pmac-vme/user-s-manual-english/page-180.html>).
//! `M1` must be defined as the output bit (`M1->Y:…`); a trigger at the very end of the
//! program has no move after it.
//! It must not plan or round times.

use crate::gather::Gathered;
use crate::number::{write_usual_fixed, FIXED_SLOT};
use crate::triggers::TriggerSupport;
use crate::writer::{Header, PieceLine, PieceLines, ProgramWriter, Totals};
use pvt_core::{Axis, CoolantState, EventKind, Motion, ProgramEvent, SegmentRef, SpindleState};
use std::io::{self, Write};

/// Largest PMAC motion program number.
pub const MAX_PROGRAM: u32 = 32767;
/// The programs PMAC calls for G, M, T and D codes (1000–1003): not for a part program.
pub const RESERVED_PROGRAMS: std::ops::RangeInclusive<u32> = 1000..=1003;
/// Largest coordinate system number (Turbo PMAC has 16).
pub const MAX_COORD: u32 = 16;
/// Largest motor number (Turbo PMAC has 32).
pub const MAX_MOTOR: u32 = 32;

/// How events (spindle, coolant, tool, pause, message) are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PmacEvents {
    /// As comments (`; event spindle_cw from line 5`); G4 as `DWELL`.
    #[default]
    Comments,
    /// As PMAC commands: `M03`, `T5`, `S12000`, `STOP`, `SEND"…"`, `DWELL`.
    Commands,
}

/// One axis definition statement, `#{motor}->{scale}{axis}`: motor `motor` is axis `axis`
/// at `scale` counts per program unit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AxisDefinition {
    /// Motor number, 1 to [`MAX_MOTOR`].
    pub motor: u32,
    /// Counts per unit, as written (a positive decimal number).
    pub scale: String,
    /// The axis.
    pub axis: Axis,
}

impl AxisDefinition {
    /// Reads `#1->1000X` (motor 1 is X at 1000 counts per unit).
    pub fn parse(text: &str) -> Result<AxisDefinition, String> {
        let bad = || {
            format!(
                "expected an axis definition like #1->1000X (motor 1 is X at 1000 counts per \
                 unit), not {text:?}"
            )
        };
        let rest = text.trim().strip_prefix('#').ok_or_else(bad)?;
        let (motor, def) = rest.split_once("->").ok_or_else(bad)?;
        let motor: u32 = motor.parse().map_err(|_| bad())?;
        if !(1..=MAX_MOTOR).contains(&motor) {
            return Err(format!("motor #{motor} is out of range: 1 to {MAX_MOTOR}"));
        }
        let mut chars = def.chars();
        let axis = chars
            .next_back()
            .and_then(Axis::from_letter)
            .ok_or_else(bad)?;
        let scale = chars.as_str();
        let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
        let decimal = match scale.split_once('.') {
            Some((whole, fraction)) => digits(whole) && digits(fraction),
            None => digits(scale),
        };
        let positive = scale.parse::<f64>().is_ok_and(|s| s > 0.0 && s.is_finite());
        if !decimal || !positive {
            return Err(format!(
                "the scale of {text:?} must be a positive number of counts per unit, like 1000"
            ));
        }
        Ok(AxisDefinition {
            motor,
            scale: scale.to_string(),
            axis,
        })
    }
}

impl std::fmt::Display for AxisDefinition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "#{}->{}{}", self.motor, self.scale, self.axis)
    }
}

/// What a PMAC program is set up with besides its motion.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PmacSettings {
    /// Motion program number, `OPEN PROG n`.
    pub program: u32,
    /// Coordinate system addressed (`&n`) before the program, if any.
    pub coord: Option<u32>,
    /// Axis definitions written after `&n`.
    pub axes: Vec<AxisDefinition>,
    /// How events are written.
    pub events: PmacEvents,
    /// A rotary buffer of this many words instead of `OPEN PROG`, streamed by the host.
    pub rotary: Option<u32>,
}

impl Default for PmacSettings {
    fn default() -> PmacSettings {
        PmacSettings {
            program: 1,
            coord: None,
            axes: Vec::new(),
            events: PmacEvents::Comments,
            rotary: None,
        }
    }
}

impl PmacSettings {
    /// Checks the numbers and that no motor or axis is defined twice.
    pub fn validate(&self) -> Result<(), String> {
        if self.program == 0 || self.program > MAX_PROGRAM {
            return Err(format!(
                "PMAC program {} is out of range: 1 to {MAX_PROGRAM}",
                self.program
            ));
        }
        if RESERVED_PROGRAMS.contains(&self.program) {
            return Err(format!(
                "PMAC program {} is one PMAC calls for G, M, T and D codes (1000 to 1003): \
                 choose another number",
                self.program
            ));
        }
        if let Some(cs) = self.coord {
            if cs == 0 || cs > MAX_COORD {
                return Err(format!(
                    "coordinate system &{cs} is out of range: 1 to {MAX_COORD}"
                ));
            }
        }
        for (i, a) in self.axes.iter().enumerate() {
            for b in &self.axes[..i] {
                if a.motor == b.motor {
                    return Err(format!("motor #{} is defined twice ({b} and {a})", a.motor));
                }
                if a.axis == b.axis {
                    return Err(format!("axis {} is defined twice ({b} and {a})", a.axis));
                }
            }
        }
        Ok(())
    }

    /// The moved axes no definition names, when definitions are given.
    pub fn undefined_axes(&self, moved: &[Axis]) -> Vec<Axis> {
        if self.axes.is_empty() {
            return Vec::new();
        }
        moved
            .iter()
            .copied()
            .filter(|m| !self.axes.iter().any(|d| d.axis == *m))
            .collect()
    }
}

/// Decimals of positions and velocities (see the module doc for why 9).
pub const POSITION_DECIMALS: usize = 9;
/// The step of a written position: one unit of its last decimal.
pub const POSITION_RESOLUTION: f64 = 1e-9;
const _: () = assert!(
    POSITION_DECIMALS == 9,
    "POSITION_RESOLUTION is 10^-POSITION_DECIMALS"
);
/// Decimals of piece times in milliseconds.
pub const TIME_DECIMALS: usize = 4;

/// The M-variable a trigger toggles (`--trigger-every`), by a synchronous assignment:
/// `M1==1` is held until the move that follows it starts (PMAC User Manual,
/// "Synchronous M-Variable Assignment"), so the output changes at the trigger's knot.
pub const TRIGGER_OUTPUT: &str = "M1";
/// Longest piece time written, seconds: 4095 ms, the whole milliseconds of Turbo PMAC's
/// PVT time range under `I42 = 0` (0–4095.9998 ms; `I42 = 1` allows more).
pub const MAX_PIECE_SECONDS: f64 = 4.095;

/// Turbo PMAC's rules: piece times in whole milliseconds (`TA` rounds to them, seed 003),
/// so `--quantize` is 1 ms by default; none under 0.5 ms (which `TA` would round to no
/// time at all) or over [`MAX_PIECE_SECONDS`]; absolute positions in program units.
pub const CAPS: crate::rules::Caps = crate::rules::Caps {
    controller: "Turbo PMAC",
    time_quantum: Some(0.001),
    quantum_required: false,
    default_quantum: Some(0.001),
    min_piece_seconds: 0.0005,
    max_piece_seconds: Some(MAX_PIECE_SECONDS),
    positions: crate::rules::Positions::Absolute,
    position_unit: "program units",
    velocity_unit: "program units/s (Ix90 = 1000)",
    scaled: false,
    buffer_depth: None,
    verifies: false,
    triggers: TriggerSupport::Written,
    velocity_per_count: 1.0,
};

/// Bytes of text gathered before they are written.
const LINE_BATCH: usize = 64 * 1024;

/// Streams a PMAC PVT motion program to `W`.
pub struct PmacWriter<W> {
    out: W,
    axes: Vec<Axis>,
    /// Each axis' letter, as written before its position.
    letters: Vec<u8>,
    line: Gathered,
    totals: Totals,
    events: PmacEvents,
    /// A command event was written since the last piece: the next piece restates `PVT`.
    reenter_pvt: bool,
    /// The trigger output's level after the last trigger.
    trigger_level: bool,
}

impl<W: Write> PmacWriter<W> {
    /// A writer into `out`, which gets the text in batches of 64 KiB.
    pub fn new(out: W) -> PmacWriter<W> {
        PmacWriter {
            out,
            axes: Vec::new(),
            letters: Vec::new(),
            line: Gathered::with_capacity(LINE_BATCH + 1024),
            totals: Totals::default(),
            events: PmacEvents::Comments,
            reenter_pvt: false,
            trigger_level: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.out
    }

    /// Hands the text gathered so far to `out` once there is a batch of it: a batch at
    /// least as large as a `BufWriter`'s default buffer goes straight through it.
    fn flush_line(&mut self) -> io::Result<()> {
        if self.line.len() >= LINE_BATCH {
            self.write_gathered()?;
        }
        Ok(())
    }

    /// A piece's line with a number [`piece_line`] does not write (a position or velocity
    /// of 4.5·10⁶ units or more, a piece time of a day or more): each number in room of
    /// its own.
    #[cold]
    fn wide_segment(&mut self, ms: f64, seg: &SegmentRef<'_>) -> io::Result<()> {
        let t = &mut self.line;
        t.push_slice(b"TA");
        t.fixed::<TIME_DECIMALS>(ms);
        for ((axis, p), v) in self.axes.iter().zip(seg.end).zip(seg.velocity) {
            t.push_slice(&[b' ', axis.letter() as u8]);
            t.fixed::<POSITION_DECIMALS>(*p);
            t.push(b':');
            t.fixed::<POSITION_DECIMALS>(*v);
        }
        t.push(b'\n');
        self.flush_line()
    }

    /// Before the program's first piece, and the first after a command: `PVT` with the
    /// piece's time (`ms`), which PMAC takes for the pieces after it.
    #[inline]
    fn enter_pvt(&mut self, ms: f64) {
        if self.totals.segments == 0 || self.reenter_pvt {
            self.reenter_pvt = false;
            self.line.push_slice(b"PVT");
            self.line.fixed::<TIME_DECIMALS>(ms);
            self.line.push(b'\n');
        }
    }

    fn write_gathered(&mut self) -> io::Result<()> {
        self.out.write_all(self.line.text())?;
        self.line.clear();
        Ok(())
    }
}

impl<W: Write> ProgramWriter for PmacWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.axes = header.axes.to_vec();
        self.letters = self.axes.iter().map(|a| a.letter() as u8).collect();
        let units = header.units.name();
        let t = &mut self.line;
        writeln!(
            t,
            "; PMAC PVT motion program generated by pvtc from {}",
            header.options.source
        )?;
        for (name, value) in &header.options.settings {
            writeln!(t, "; {name}: {value}")?;
        }
        let axes: Vec<String> = self.axes.iter().map(|a| a.to_string()).collect();
        writeln!(
            t,
            "; axes: {}; positions in {units}, absolute",
            axes.join(" ")
        )?;
        writeln!(
            t,
            "; velocities in {units}/s: requires Ix90=1000 (the default; Isx90 on Turbo PMAC)"
        )?;
        t.push_slice(
            b"; piece times: TA in ms, set before each piece's axis words; none over 4095 ms\n",
        );
        t.push_slice(
            b"; Turbo PMAC: requires I42=1, so that TA times PVT pieces (under I42=0 it does not)\n",
        );
        if header.options.triggers.is_some() {
            writeln!(
                t,
                "; triggers: {TRIGGER_OUTPUT} toggles at each (synchronous {TRIGGER_OUTPUT}==1 / {TRIGGER_OUTPUT}==0: \
                 at the start of the next move); define {TRIGGER_OUTPUT} as the output bit"
            )?;
        }
        let pmac = &header.options.pmac;
        self.events = pmac.events;
        if pmac.events == PmacEvents::Commands {
            t.push_slice(
                b"; events: PMAC commands; M-codes call PROG 1001, T-codes PROG 1002 (machine-specific)\n",
            );
        }
        if let Some(words) = pmac.rotary {
            writeln!(
                t,
                "; rotary buffer of {words} words (one per value): no gather buffer may exist (DELETE GATHER);\n\
                 ; send the lines after OPEN ROT as the buffer empties (PR: lines ahead; I16/I17: BREQ), then R"
            )?;
        }
        // A rotary buffer belongs to a coordinate system: &1 unless one is given.
        if let Some(cs) = pmac.coord.or(pmac.rotary.map(|_| 1)) {
            writeln!(t, "&{cs}")?;
            for def in &pmac.axes {
                writeln!(t, "{def}")?;
            }
        }
        match pmac.rotary {
            Some(words) => writeln!(t, "DEFINE ROT {words}\nB0\nOPEN ROT\nCLEAR\nABS")?,
            None => writeln!(t, "OPEN PROG {} CLEAR\nABS", pmac.program)?,
        }
        self.flush_line()
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        self.totals.add_contour();
        let t = &mut self.line;
        write!(
            t,
            "; contour {} ({}) from",
            self.totals.contours,
            motion.name()
        )?;
        for (axis, p) in self.axes.iter().zip(start) {
            t.push(b' ');
            t.push(axis.letter() as u8);
            t.fixed::<POSITION_DECIMALS>(*p);
        }
        t.push(b'\n');
        self.flush_line()
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        let ms = seg.duration * 1000.0;
        self.enter_pvt(ms);
        let dim = self.axes.len().min(seg.end.len()).min(seg.velocity.len());
        let room = self.line.room(line_room(dim));
        match piece_line(room, &self.letters, ms, seg) {
            (len, Some(whole_ms)) => {
                self.totals.add_printed_segment(seg.duration, whole_ms);
                self.line.advance(len);
            }
            // What was written is left as room, and the line written number by number.
            _ => {
                self.totals.add_segment(seg.duration);
                return self.wide_segment(ms, seg);
            }
        }
        self.flush_line()
    }

    fn piece_lines(&self) -> Option<PieceLines> {
        Some(PieceLines::Pmac(PmacLines {
            letters: self.letters.clone(),
        }))
    }

    fn segment_with_line(&mut self, seg: &SegmentRef<'_>, line: PieceLine<'_>) -> io::Result<()> {
        self.enter_pvt(seg.duration * 1000.0);
        self.totals.add_printed_segment(seg.duration, line.whole_ms);
        self.line.push_slice(line.text);
        self.flush_line()
    }

    fn trigger(&mut self) -> io::Result<()> {
        self.trigger_level = !self.trigger_level;
        let level = u8::from(self.trigger_level);
        writeln!(self.line, "{TRIGGER_OUTPUT}=={level}")?;
        self.flush_line()
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if self.events == PmacEvents::Commands {
            if let Some(command) = command(&event.kind) {
                writeln!(
                    self.line,
                    "{command} ; {} from line {}",
                    event.kind.name(),
                    event.line
                )?;
                self.reenter_pvt = true;
                return self.flush_line();
            }
        }
        let t = &mut self.line;
        match &event.kind {
            EventKind::Dwell { seconds } => {
                t.push_slice(b"DWELL");
                t.fixed::<TIME_DECIMALS>(seconds * 1000.0);
                writeln!(t, " ; G4 from line {}", event.line)?;
            }
            kind => {
                // M-codes are machine-specific on a PMAC: the event is stated, not guessed.
                write!(t, "; event {} from line {}", kind.name(), event.line)?;
                match kind {
                    EventKind::SpindleSpeed { rpm } => write!(t, ": {rpm} rpm")?,
                    EventKind::ToolSelect { tool } => write!(t, ": T{tool}")?,
                    EventKind::Message { text } => write!(t, ": {}", text.replace('\n', " "))?,
                    EventKind::MachineCode { .. } => {
                        write!(t, ": {}", kind.code_written().unwrap_or_default())?
                    }
                    _ => {}
                }
                t.push(b'\n');
            }
        }
        self.flush_line()
    }

    fn caps(&self) -> crate::rules::Caps {
        crate::Format::Pmac.caps()
    }

    fn finish(&mut self) -> io::Result<()> {
        let n = self.totals;
        let t = &mut self.line;
        writeln!(
            t,
            "; {} contours, {} segments, total time {:.4} s",
            n.contours, n.segments, n.time
        )?;
        if n.fractional_ms > 0 {
            writeln!(
                t,
                "; warning: {} of {} piece times are not whole ms; PMAC rounds TA to whole ms",
                n.fractional_ms, n.segments
            )?;
        }
        t.push_slice(b"CLOSE\n");
        self.write_gathered()?;
        self.out.flush()
    }
}

/// A PMAC piece's line written apart from the writer ([`PieceLines::Pmac`]):
/// `piece_line` with the program's axis letters, the same bytes the writer's `segment`
/// writes.
#[derive(Debug, Clone)]
pub struct PmacLines {
    letters: Vec<u8>,
}

impl PmacLines {
    /// [`PieceLines::write`] for PMAC text.
    #[inline]
    pub(crate) fn write(&self, seg: &SegmentRef<'_>, room: &mut [u8]) -> Option<(usize, bool)> {
        match piece_line(room, &self.letters, seg.duration * 1000.0, seg) {
            (len, Some(whole_ms)) => Some((len, whole_ms)),
            _ => None,
        }
    }

    /// Room [`piece_line`] takes on these axes.
    pub(crate) fn room(&self) -> usize {
        line_room(self.letters.len())
    }
}

/// Room one axis' words take in [`piece_line`]: a space, the letter, the position, a
/// colon and the velocity.
const AXIS_WORD_ROOM: usize = 2 + FIXED_SLOT + 1 + FIXED_SLOT;

/// Room [`piece_line`] takes on `axes` axes: `TA`, the time, each axis' words and the
/// newline.
const fn line_room(axes: usize) -> usize {
    2 + FIXED_SLOT + axes * AXIS_WORD_ROOM + 1
}

/// Writes a piece's line, `TA<ms> X<position>:<velocity> …` and its newline, at the start
/// of `room` (at least [`line_room`] of its axes long) and returns
/// its length and, when every number is a usual one ([`write_usual_fixed`]), whether the
/// time is printed as whole milliseconds (its decimals all zeros); `None` when one is
/// not, the room then holding nothing of meaning.
#[inline(always)]
fn piece_line(
    room: &mut [u8],
    letters: &[u8],
    ms: f64,
    seg: &SegmentRef<'_>,
) -> (usize, Option<bool>) {
    room[..2].copy_from_slice(b"TA");
    let (len, mut usual) = write_usual_fixed::<TIME_DECIMALS>(&mut room[2..], ms);
    let mut at = 2 + len;
    // A usual time has a point and TIME_DECIMALS (4) decimals: the text's last four bytes.
    let decimals: [u8; TIME_DECIMALS] = room[at - TIME_DECIMALS..at].try_into().unwrap_or([0; 4]);
    let whole_ms = decimals == [b'0'; TIME_DECIMALS];
    for ((letter, p), v) in letters.iter().zip(seg.end).zip(seg.velocity) {
        room[at] = b' ';
        room[at + 1] = *letter;
        let (len, p_usual) = write_coordinate(&mut room[at + 2..], *p);
        at += 2 + len;
        room[at] = b':';
        let (len, v_usual) = write_coordinate(&mut room[at + 1..], *v);
        at += 1 + len;
        usual &= p_usual & v_usual;
    }
    room[at] = b'\n';
    (at + 1, usual.then_some(whole_ms))
}

/// A position or velocity as [`write_usual_fixed`] writes it with
/// [`POSITION_DECIMALS`]: an exact zero (an axis at rest, or at 0), common in a program,
/// at once.
#[inline(always)]
fn write_coordinate(slot: &mut [u8], x: f64) -> (usize, bool) {
    const ZERO: &[u8; 2 + POSITION_DECIMALS] = b"0.000000000";
    if x == 0.0 {
        slot[..ZERO.len()].copy_from_slice(ZERO);
        return (ZERO.len(), true);
    }
    write_usual_fixed::<POSITION_DECIMALS>(slot, x)
}

/// The PMAC command an event is written as under [`PmacEvents::Commands`]; none for a
/// dwell, which is always `DWELL`.
fn command(kind: &EventKind) -> Option<String> {
    Some(match kind {
        EventKind::Dwell { .. } => return None,
        EventKind::Pause { optional: false } => "STOP".to_string(),
        EventKind::Pause { optional: true } => "M01".to_string(),
        EventKind::Spindle { state } => match state {
            SpindleState::Clockwise => "M03",
            SpindleState::CounterClockwise => "M04",
            SpindleState::Off => "M05",
        }
        .to_string(),
        EventKind::SpindleSpeed { rpm } => format!("S{rpm}"),
        EventKind::Coolant { state } => match state {
            CoolantState::Mist => "M07",
            CoolantState::Flood => "M08",
            CoolantState::Off => "M09",
        }
        .to_string(),
        EventKind::ToolSelect { tool } => format!("T{tool}"),
        EventKind::ToolChange => "M06".to_string(),
        // Called as PROG 1001 N(code × 1000); the routine READs the words.
        EventKind::MachineCode { .. } => return kind.code_written(),
        EventKind::Message { text } => {
            let text: String = text
                .chars()
                .map(|c| {
                    if c == '"' {
                        '\''
                    } else if c.is_control() {
                        ' '
                    } else {
                        c
                    }
                })
                .collect();
            format!("SEND\"{text}\"")
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::number::push_fixed;
    use crate::EmitOptions;
    use proptest::prelude::*;
    use pvt_core::{Interpolation, Units};

    /// A piece's line as each number alone writes it: `TA`, the time, then each axis.
    fn reference_line(axes: &[Axis], ms: f64, end: &[f64], velocity: &[f64]) -> Vec<u8> {
        let mut t = b"TA".to_vec();
        push_fixed::<TIME_DECIMALS>(&mut t, ms);
        for ((axis, p), v) in axes.iter().zip(end).zip(velocity) {
            t.extend_from_slice(&[b' ', axis.letter() as u8]);
            push_fixed::<POSITION_DECIMALS>(&mut t, *p);
            t.push(b':');
            push_fixed::<POSITION_DECIMALS>(&mut t, *v);
        }
        t.push(b'\n');
        t
    }

    /// A PMAC writer into memory, begun on `axes` in mm with the default options.
    fn begun(axes: &[Axis]) -> PmacWriter<Vec<u8>> {
        let options = EmitOptions::default();
        let header = Header {
            axes,
            units: Units::Millimetre,
            interpolation: Interpolation::Pvt,
            options: &options,
        };
        let mut writer = PmacWriter::new(Vec::new());
        writer.begin(&header).unwrap();
        writer
    }

    /// A value of a piece: usual coordinates, large ones past the usual range and 2^53,
    /// and (for a writer without [`crate::Checked`] in front) NaN and infinities.
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            40 => -1e4..1e4f64,
            4 => Just(0.0),
            2 => Just(-0.0),
            1 => -1e7..1e7f64,
            1 => -1e20..1e20f64,
            1 => Just(f64::NAN),
            1 => Just(f64::NEG_INFINITY),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        /// Every piece's line is the numbers each written alone, whether the line is
        /// written at once or number by number; nothing written for a refused line is
        /// kept.
        #[test]
        fn piece_lines_are_their_numbers(
            pieces in proptest::collection::vec(
                (proptest::collection::vec((value(), value()), 3), 1e-4..10.0f64),
                1..40,
            )
        ) {
            let axes = [Axis::X, Axis::Y, Axis::Z];
            let mut writer = begun(&axes);
            writer.contour(Motion::Feed, &[0.0; 3]).unwrap();
            let before = writer.line.len();
            let mut expected = Vec::new();
            for (i, (axis_values, seconds)) in pieces.iter().enumerate() {
                let (end, velocity): (Vec<f64>, Vec<f64>) = axis_values.iter().copied().unzip();
                let ms = seconds * 1000.0;
                if i == 0 {
                    expected.extend_from_slice(b"PVT");
                    push_fixed::<TIME_DECIMALS>(&mut expected, ms);
                    expected.push(b'\n');
                }
                expected.extend(reference_line(&axes, ms, &end, &velocity));
                let seg = SegmentRef { end: &end, velocity: &velocity, duration: *seconds, line: 1 };
                writer.segment(&seg).unwrap();
            }
            prop_assert_eq!(
                String::from_utf8_lossy(&writer.line.text()[before..]),
                String::from_utf8_lossy(&expected)
            );
        }

        /// A line written apart from the writer ([`PmacLines`]), where it is written,
        /// and taken with its piece is the line the writer writes, and the program's
        /// totals are the same; pieces of times in whole and in fractional ms, usual
        /// numbers and others (which are left to the writer).
        #[test]
        fn lines_written_apart_are_the_writers_own(
            pieces in proptest::collection::vec(
                (proptest::collection::vec((value(), value()), 3),
                 prop_oneof![1e-4..10.0f64, (1..5000u32).prop_map(|ms| f64::from(ms) / 1000.0)]),
                1..40,
            )
        ) {
            let axes = [Axis::X, Axis::Y, Axis::Z];
            let (mut own, mut apart) = (begun(&axes), begun(&axes));
            for writer in [&mut own, &mut apart] {
                writer.contour(Motion::Feed, &[0.0; 3]).unwrap();
            }
            let lines = apart.piece_lines().expect("PMAC lines are written apart");
            let mut room = vec![0; lines.room()];
            let mut written = 0;
            for (i, (axis_values, seconds)) in pieces.iter().enumerate() {
                let (end, velocity): (Vec<f64>, Vec<f64>) = axis_values.iter().copied().unzip();
                let seg = SegmentRef { end: &end, velocity: &velocity, duration: *seconds, line: 1 };
                if i == 2 {
                    // A command between pieces: the next piece restates PVT either way.
                    let event = ProgramEvent { before_contour: 1, kind: EventKind::ToolChange, line: 1 };
                    for writer in [&mut own, &mut apart] {
                        writer.events = PmacEvents::Commands;
                        writer.event(&event).unwrap();
                    }
                }
                own.segment(&seg).unwrap();
                match lines.write(&seg, &mut room) {
                    Some((len, whole_ms)) => {
                        written += 1;
                        let reference = reference_line(&axes, seconds * 1000.0, &end, &velocity);
                        prop_assert_eq!(
                            String::from_utf8_lossy(&room[..len]),
                            String::from_utf8_lossy(&reference)
                        );
                        let line = PieceLine { text: &room[..len], whole_ms };
                        apart.segment_with_line(&seg, line).unwrap();
                    }
                    None => apart.segment(&seg).unwrap(),
                }
            }
            own.finish().unwrap();
            apart.finish().unwrap();
            let (own, apart) = (own.into_inner(), apart.into_inner());
            prop_assert_eq!(String::from_utf8_lossy(&apart), String::from_utf8_lossy(&own));
            // The usual numbers are most of them, and all of them are written apart.
            let usual = |x: f64| x.abs() < 4.5e6;
            let all_usual = pieces.iter().all(|(values, _)| values.iter().all(|(p, v)| usual(*p) && usual(*v)));
            prop_assert!(!all_usual || written == pieces.len());
        }
    }
}
