//! Reading an emitted program back into the PVT pieces its controller executes, for
//! `pvtc check` and `pvtc diff`: what is verified is then the text the controller receives.
//!
//! Owns the readers of Turbo PMAC text (`PVT`/`TA` ms, `X{p}:{v}`, `DWELL`, the
//! `; contour N (kind) from …` comments, the events as comments or commands, the
//! `M1==` triggers), Power PMAC text (`pvt` ms, `// … contour from …`, `dwell`, the
//! triggers), MovePVT C arrays (`pvtc_cN_start`, `_position`, `_velocity`, `_time`, the
//! `event at rest` comments), the XPS
//! trajectory file (relative; it starts at 0 on every axis, and names no axes or units:
//! the first axes of `X Y Z A B C` in the units given), Galil PV commands (the header's
//! axes, counts per unit and start), Zaber PVT commands (microsteps at the counts per
//! unit given; the sequence starts where the axes are, taken as 0; the `io set do`
//! triggers) and the CSV table (`t,X,vX,…`, absolute times, the `trigger` column).
//! Each piece keeps the line of the text it was read from, so a peak is
//! reported where it is written. Times, positions and velocities are those of the text,
//! converted back to program units and seconds. It must not plan or repair: a line it
//! cannot read is an error naming the line.

use crate::Format;
use pvt_core::{
    Axis, EventKind, Interpolation, Motion, ProgramEvent, PvtContour, PvtProgram, Units,
};
use std::collections::BTreeMap;

/// A text that is not what the format writes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {what}")]
pub struct ReadBackError {
    /// 1-based line of the text.
    pub line: usize,
    /// What is wrong.
    pub what: String,
}

impl ReadBackError {
    /// Stable code of this error.
    pub const CODE: &'static str = "pvtc::check::read_back";
}

/// What a text does not say about itself: units and counts per unit of each axis.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadHint {
    /// Units of a text that names none (XPS, Zaber).
    pub units: Units,
    /// Counts per unit (Zaber, or a Galil text without its header).
    pub counts_per_unit: BTreeMap<Axis, f64>,
}

/// The format a file name's extension says was written, for the formats read back.
pub fn format_of(name: &str) -> Option<Format> {
    let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
    [
        Format::Pmac,
        Format::MovePvt,
        Format::Xps,
        Format::Galil,
        Format::Zaber,
        Format::PowerPmac,
    ]
    .into_iter()
    .find(|f| f.extension() == ext)
}

/// Reads `text`, written in `format`, back into a program.
pub fn read_back(format: Format, text: &str, hint: &ReadHint) -> Result<PvtProgram, ReadBackError> {
    read_program(format, text, hint).map(|read| read.program)
}

/// A program read back, with what its text says besides the motion.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadProgram {
    /// The motion, and the events the text states.
    pub program: PvtProgram,
    /// Whether the format states events other than dwells, with their values (Turbo
    /// PMAC, MovePVT); the others state none (XPS, Zaber, the CSV table) or their names
    /// alone (Power PMAC, Galil), and none are read.
    pub carries_events: bool,
    /// The triggers, each as the number of pieces before it, for a format that writes
    /// them (PMAC, Power PMAC, Zaber, the CSV table; none found: empty); `None` for the
    /// others.
    pub triggers: Option<Vec<usize>>,
}

impl ReadProgram {
    /// The program as pvt-core's comparison takes it, with what its format carries.
    pub fn side(&self) -> pvt_core::compare::Side<'_> {
        pvt_core::compare::Side {
            program: &self.program,
            carries_events: self.carries_events,
            triggers: self.triggers.as_deref(),
        }
    }
}

/// Reads `text`, written in `format`, back into a program with its events and triggers.
pub fn read_program(
    format: Format,
    text: &str,
    hint: &ReadHint,
) -> Result<ReadProgram, ReadBackError> {
    let builder = match format {
        Format::Pmac => read_pmac(text, EventsRead::Stated)?,
        Format::PowerPmac => read_pmac(text, EventsRead::NamesOnly)?,
        Format::MovePvt => read_movepvt(text, hint)?,
        Format::Xps => read_xps(text, hint)?,
        Format::Galil => read_galil(text, hint)?,
        Format::Zaber => read_zaber(text, hint)?,
        Format::Csv => read_table(text, hint)?,
        Format::Json => {
            return Err(bad(0, "a JSON program is read by `json::read`".into()));
        }
    };
    let carries_events = matches!(format, Format::Pmac | Format::MovePvt);
    let written = matches!(format.caps().triggers, crate::TriggerSupport::Written);
    let triggers = written.then(|| builder.triggers.clone());
    Ok(ReadProgram {
        program: builder.finish(),
        carries_events,
        triggers,
    })
}

/// Whether a PMAC text's events are read: Turbo PMAC states each with its values, Power
/// PMAC names them alone (and only its dwells are read).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum EventsRead {
    Stated,
    NamesOnly,
}

/// Whether `text` is a table written by `--format csv` (its first line `t` and a
/// position and velocity column per axis, `X,vX`, with a last `trigger` column after
/// `--trigger-every`), rather than a point-time series to compile.
pub fn is_table(text: &str) -> bool {
    let Some(first) = text.lines().next() else {
        return false;
    };
    let mut columns: Vec<&str> = first.trim_end().split(',').collect();
    if columns.last() == Some(&"trigger") {
        columns.pop();
    }
    let axes = &columns[1.min(columns.len())..];
    columns.first() == Some(&"t")
        && !axes.is_empty()
        && axes.len().is_multiple_of(2)
        && axes.chunks(2).all(|pair| {
            let letter = pair[0];
            letter.len() == 1
                && Axis::ALL.iter().any(|a| a.to_string() == letter)
                && pair[1] == format!("v{letter}")
        })
}

fn bad(line: usize, what: String) -> ReadBackError {
    ReadBackError { line, what }
}

fn number(s: &str, line: usize) -> Result<f64, ReadBackError> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| bad(line, format!("{s:?} is not a number")))
}

/// The program being read: contours as they start, pieces, events and triggers.
struct Builder {
    program: PvtProgram,
    at: Vec<f64>,
    /// Pieces read so far.
    pieces: usize,
    /// The pieces before each trigger.
    triggers: Vec<usize>,
}

impl Builder {
    fn new(axes: Vec<Axis>, units: Units) -> Builder {
        Builder {
            pieces: 0,
            triggers: Vec::new(),
            at: vec![0.0; axes.len()],
            program: PvtProgram {
                axes,
                units,
                interpolation: Interpolation::Pvt,
                contours: Vec::new(),
                events: Vec::new(),
            },
        }
    }

    fn start(&mut self, motion: Motion, start: Vec<f64>) {
        self.at.clone_from(&start);
        self.program.contours.push(PvtContour::new(motion, start));
    }

    fn piece(
        &mut self,
        end: &[f64],
        velocity: &[f64],
        seconds: f64,
        line: usize,
    ) -> Result<(), ReadBackError> {
        if end.len() != self.at.len() || velocity.len() != self.at.len() {
            return Err(bad(
                line,
                format!("{} axes, not {}", end.len(), self.at.len()),
            ));
        }
        if seconds.is_nan() || seconds <= 0.0 {
            return Err(bad(line, format!("a piece of {seconds} s")));
        }
        if self.program.contours.is_empty() {
            self.start(Motion::Feed, self.at.clone());
        }
        let contour = self.program.contours.last_mut().expect("started");
        contour.push(end, velocity, seconds, line as u32);
        self.at = end.to_vec();
        self.pieces += 1;
        Ok(())
    }

    fn event(&mut self, kind: EventKind, line: usize) {
        self.program.events.push(ProgramEvent {
            before_contour: self.program.contours.len(),
            kind,
            line: line as u32,
        });
    }

    fn dwell(&mut self, seconds: f64, line: usize) {
        self.event(EventKind::Dwell { seconds }, line);
    }

    fn trigger(&mut self) {
        self.triggers.push(self.pieces);
    }

    /// The program, without contours that hold no piece (each event then before the
    /// contour it preceded, counted among those kept).
    fn finish(self) -> PvtProgram {
        let mut program = self.program;
        let kept: Vec<usize> = program
            .contours
            .iter()
            .scan(0, |n, c| {
                let before = *n;
                *n += usize::from(!c.is_empty());
                Some(before)
            })
            .collect();
        let count = program.contours.iter().filter(|c| !c.is_empty()).count();
        for e in &mut program.events {
            e.before_contour = kept.get(e.before_contour).copied().unwrap_or(count);
        }
        program.contours.retain(|c| !c.is_empty());
        program
    }
}

/// An event as a text states it: its name and what follows the name (`12000 rpm`, `T2`,
/// `M64 P3`, the message, `1.5 s`), or a Turbo PMAC command (`S12000`, `T2`,
/// `SEND"…"`, `M64 P3`); `None` for a name no event has or a value that is not one.
fn event_stated(name: &str, value: &str) -> Option<EventKind> {
    if let Some(kind) = EventKind::without_value(name) {
        return Some(kind);
    }
    let value = value.trim();
    let number = |s: &str| s.trim().parse::<f64>().ok().filter(|x| x.is_finite());
    match name {
        "dwell" => Some(EventKind::Dwell {
            seconds: number(value.strip_suffix(" s")?)?,
        }),
        "spindle_speed" => Some(EventKind::SpindleSpeed {
            rpm: number(value.strip_suffix(" rpm").or(value.strip_prefix('S'))?)?,
        }),
        "tool_select" => Some(EventKind::ToolSelect {
            tool: value.strip_prefix('T')?.parse().ok()?,
        }),
        "message" => Some(EventKind::Message {
            text: value
                .strip_prefix("SEND\"")
                .and_then(|v| v.strip_suffix('"'))
                .unwrap_or(value)
                .to_string(),
        }),
        _ => {
            let mut words = value.split_whitespace();
            let code = words.next()?.strip_prefix('M')?.parse().ok()?;
            let mut given = pvt_core::CodeWords::default();
            for word in words {
                let x = number(word.get(1..)?)?;
                match word.chars().next()? {
                    'P' => given.p = Some(x),
                    'Q' => given.q = Some(x),
                    'E' => given.e = Some(x),
                    'L' => given.l = Some(x),
                    _ => return None,
                }
            }
            EventKind::machine_code(code, given).filter(|k| k.name() == name)
        }
    }
}

fn units_named(s: &str) -> Option<Units> {
    [Units::Millimetre, Units::Inch]
        .into_iter()
        .find(|u| u.name() == s)
}

/// `axes: X Y; positions in mm, …` in a comment: the axes and units.
fn axes_comment(text: &str) -> Option<(Vec<Axis>, Units)> {
    let rest = text
        .lines()
        .find_map(|l| l.split_once("axes: ").map(|(_, r)| r))?;
    let (letters, rest) = rest.split_once(';')?;
    let axes = letters
        .split_whitespace()
        .map(|a| a.chars().next().and_then(Axis::from_letter))
        .collect::<Option<Vec<_>>>()?;
    let units = rest
        .trim()
        .strip_prefix("positions in ")?
        .split([',', ' '])
        .next()?;
    Some((axes, units_named(units)?))
}

/// `X1.5 Y2` words after `from` in a contour comment.
fn positions_after_from(
    comment: &str,
    axes: &[Axis],
    line: usize,
) -> Result<Vec<f64>, ReadBackError> {
    let words = comment.split_once(" from").map_or("", |(_, w)| w);
    let mut at = vec![0.0; axes.len()];
    for word in words.split_whitespace() {
        let axis = word.chars().next().and_then(Axis::from_letter);
        let i = axes.iter().position(|a| Some(*a) == axis);
        match i {
            Some(i) => at[i] = number(&word[1..], line)?,
            None => return Err(bad(line, format!("{word:?} names no axis of the program"))),
        }
    }
    Ok(at)
}

fn motion_named(comment: &str) -> Motion {
    if comment.contains("rapid") {
        Motion::Rapid
    } else {
        Motion::Feed
    }
}

/// Turbo PMAC and Power PMAC text (which name their axes and units).
fn read_pmac(text: &str, events: EventsRead) -> Result<Builder, ReadBackError> {
    let (axes, units) =
        axes_comment(text).ok_or_else(|| bad(1, "no `axes: … positions in …` comment".into()))?;
    let mut b = Builder::new(axes.clone(), units);
    let mut time = None;
    let trigger = format!("{}==", crate::pmac::TRIGGER_OUTPUT);
    for (n, raw) in pvt_core::text::numbered_lines(text) {
        let (code, comment) = match raw.find([';', '/']) {
            Some(k) => raw.split_at(k),
            None => (raw, ""),
        };
        if comment.contains("contour") && comment.contains(" from") {
            let start = positions_after_from(comment, &axes, n)?;
            b.start(motion_named(comment), start);
        }
        if events == EventsRead::Stated {
            if let Some(kind) = pmac_event(code.trim(), comment, n)? {
                b.event(kind, n);
                continue;
            }
        }
        let upper = code.trim().to_ascii_uppercase();
        if upper.starts_with(&trigger) {
            b.trigger();
            continue;
        }
        if let Some(ms) = upper.strip_prefix("DWELL") {
            b.dwell(number(ms, n)? / 1000.0, n);
            continue;
        }
        let mut words = upper.split_whitespace().peekable();
        for timer in ["PVT", "TA"] {
            if let Some(ms) = words.peek().and_then(|w| w.strip_prefix(timer)) {
                time = Some(number(ms, n)? / 1000.0);
                words.next();
            }
        }
        let mut end = b.at.clone();
        let mut velocity = vec![0.0; axes.len()];
        let mut moved = false;
        for word in words {
            let Some((p, v)) = word.get(1..).and_then(|w| w.split_once(':')) else {
                break; // a command (OPEN PROG, ABS, M03, …): not a move
            };
            let axis = word.chars().next().and_then(Axis::from_letter);
            let Some(k) = axes.iter().position(|a| Some(*a) == axis) else {
                break; // `SEND"a:b"` and the like: not a move
            };
            end[k] = number(p, n)?;
            velocity[k] = number(v, n)?;
            moved = true;
        }
        if moved {
            let t = time.ok_or_else(|| bad(n, "a move before any PVT or TA time".into()))?;
            b.piece(&end, &velocity, t, n)?;
        }
    }
    Ok(b)
}

/// A Turbo PMAC event line: `; event NAME from line N[: VALUE]`, or a command with the
/// event's name after it, `CMD ; NAME from line N` (a dwell is read as `DWELL`).
fn pmac_event(code: &str, comment: &str, line: usize) -> Result<Option<EventKind>, ReadBackError> {
    let comment = comment.trim_start_matches([';', ' ']);
    let (name, value) = if let Some(rest) = comment.strip_prefix("event ") {
        let (name, after) = rest.split_once(" from line ").unwrap_or((rest, ""));
        (name, after.split_once(": ").map_or("", |(_, v)| v))
    } else if !code.is_empty() && comment.contains(" from line ") {
        let name = comment.split(" from line ").next().unwrap_or("");
        if name == "G4" {
            return Ok(None);
        }
        (name, code)
    } else {
        return Ok(None);
    };
    event_stated(name, value)
        .map(Some)
        .ok_or_else(|| bad(line, format!("{name:?} {value:?} is no event")))
}

/// The numbers of every `static double NAME[…] = { … };` array of a C text, by name.
fn c_arrays(text: &str) -> Result<BTreeMap<String, (usize, Vec<f64>)>, ReadBackError> {
    let mut arrays = BTreeMap::new();
    let mut open: Option<(String, usize, Vec<f64>)> = None;
    for (n, line) in pvt_core::text::numbered_lines(text) {
        if let Some((name, first, values)) = open.as_mut() {
            if line.starts_with("};") {
                let (name, first, values) = (std::mem::take(name), *first, std::mem::take(values));
                arrays.insert(name, (first, values));
                open = None;
            } else {
                for x in line.split(',').filter(|x| !x.trim().is_empty()) {
                    values.push(number(x, n)?);
                }
            }
        } else if let Some(rest) = line.strip_prefix("static double ") {
            let name = rest.split('[').next().unwrap_or("").to_string();
            open = Some((name, n, Vec::new()));
        }
    }
    Ok(arrays)
}

/// MovePVT arrays as C source.
fn read_movepvt(text: &str, hint: &ReadHint) -> Result<Builder, ReadBackError> {
    let axes_line = text
        .lines()
        .find_map(|l| l.strip_prefix(" * axes: "))
        .ok_or_else(|| bad(1, "no ` * axes:` line".into()))?;
    let axes = axes_line
        .split(" (")
        .next()
        .unwrap_or("")
        .split_whitespace()
        .map(|a| a.chars().next().and_then(Axis::from_letter))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| bad(1, format!("axes {axes_line:?}")))?;
    let units = text
        .lines()
        .find_map(|l| l.strip_prefix(" * position: "))
        .and_then(|r| units_named(r.split(';').next().unwrap_or("")))
        .unwrap_or(hint.units);
    let arrays = c_arrays(text)?;
    let mut b = Builder::new(axes.clone(), units);
    let events = movepvt_events(text)?;
    let dim = axes.len();
    for c in 1.. {
        for (kind, line) in events.iter().filter(|e| e.0 == c).map(|e| (&e.1, e.2)) {
            b.event(kind.clone(), line);
        }
        let Some((first, start)) = arrays.get(&format!("pvtc_c{c}_start")) else {
            break;
        };
        let get = |what: &str| {
            arrays
                .get(&format!("pvtc_c{c}_{what}"))
                .ok_or_else(|| bad(*first, format!("contour {c} has no {what} array")))
        };
        let ((_, position), (first_v, velocity), (first_t, time)) =
            (get("position")?, get("velocity")?, get("time")?);
        if position.len() != time.len() * dim || velocity.len() != position.len() {
            return Err(bad(
                *first_v,
                format!("contour {c}: array lengths disagree"),
            ));
        }
        b.start(Motion::Feed, start.clone());
        for (k, t) in time.iter().enumerate() {
            let r = k * dim..(k + 1) * dim;
            b.piece(&position[r.clone()], &velocity[r], *t, first_t + 1 + k)?;
        }
    }
    Ok(b)
}

/// The `/* event at rest: NAME VALUE (line N) */` comments of a MovePVT text, each with
/// the contour it comes before (1-based, as the arrays are named: one more than the
/// start arrays above it) and its text line.
fn movepvt_events(text: &str) -> Result<Vec<(usize, EventKind, usize)>, ReadBackError> {
    let mut contour = 1;
    let mut found = Vec::new();
    for (n, line) in pvt_core::text::numbered_lines(text) {
        if line.starts_with("static double pvtc_c") && line.contains("_start[") {
            contour += 1;
        }
        let Some(rest) = line.strip_prefix("/* event at rest: ") else {
            continue;
        };
        let rest = rest.trim_end_matches(" */");
        let stated = rest.rsplit_once(" (line ").map_or(rest, |(s, _)| s);
        let (name, value) = stated.split_once(' ').unwrap_or((stated, ""));
        let kind =
            event_stated(name, value).ok_or_else(|| bad(n, format!("{stated:?} is no event")))?;
        found.push((contour, kind, n));
    }
    Ok(found)
}

/// The XPS trajectory file: `dt, dX, vX, …`, relative, from 0.
fn read_xps(text: &str, hint: &ReadHint) -> Result<Builder, ReadBackError> {
    let dim = text.lines().next().map_or(0, |l| l.split(',').count() / 2);
    let axes: Vec<Axis> = Axis::ALL.iter().copied().take(dim).collect();
    let mut b = Builder::new(axes, hint.units);
    for (n, line) in pvt_core::text::numbered_lines(text) {
        let f = line
            .split(',')
            .map(|x| number(x, n))
            .collect::<Result<Vec<_>, _>>()?;
        if f.len() != 1 + 2 * dim {
            return Err(bad(n, format!("{} fields, not {}", f.len(), 1 + 2 * dim)));
        }
        let end: Vec<f64> = (0..dim).map(|k| b.at[k] + f[1 + 2 * k]).collect();
        let velocity: Vec<f64> = (0..dim).map(|k| f[2 + 2 * k]).collect();
        b.piece(&end, &velocity, f[0], n)?;
    }
    Ok(b)
}

/// Counts per unit of `axes` from the hint.
fn hinted_scales(axes: &[Axis], hint: &ReadHint) -> Result<Vec<f64>, ReadBackError> {
    axes.iter()
        .map(|a| {
            hint.counts_per_unit
                .get(a)
                .copied()
                .ok_or_else(|| bad(1, format!("axis {a} needs --counts-per-unit")))
        })
        .collect()
}

/// Galil `PVa=p,v,t` commands: the header's `axes:` and `start at` comments, else the
/// hint's counts and a start at 0.
fn read_galil(text: &str, hint: &ReadHint) -> Result<Builder, ReadBackError> {
    let mut axes = Vec::new();
    let mut scales = Vec::new();
    let mut units = hint.units;
    if let Some(map) = text.lines().find_map(|l| l.strip_prefix("' axes: ")) {
        for part in map.split(", ") {
            // `X->A at 1000 counts/mm`
            let axis = part
                .chars()
                .next()
                .and_then(Axis::from_letter)
                .ok_or_else(|| bad(1, format!("{part:?}")))?;
            let (count, unit) = part
                .split(" at ")
                .nth(1)
                .and_then(|r| r.split_once(" counts/"))
                .ok_or_else(|| bad(1, format!("{part:?}")))?;
            axes.push(axis);
            scales.push(number(count, 1)?);
            units = units_named(unit).unwrap_or(units);
        }
    }
    let mut columns: Vec<Vec<(i64, i64, i64, usize)>> = Vec::new();
    let mut start_counts: Vec<i64> = Vec::new();
    for (n, line) in pvt_core::text::numbered_lines(text) {
        if let Some(at) = line.strip_prefix("' start at ") {
            let counts = at.split(' ').next().unwrap_or("");
            start_counts = counts
                .split(',')
                .map(|c| c.parse::<i64>().map_err(|_| bad(n, format!("{counts:?}"))))
                .collect::<Result<_, _>>()?;
        }
        let Some(rest) = line.strip_prefix("PV") else {
            continue;
        };
        let letter = rest
            .bytes()
            .next()
            .filter(u8::is_ascii_uppercase)
            .ok_or_else(|| bad(n, line.into()))?;
        let k = usize::from(letter - b'A');
        let values = rest
            .get(2..)
            .unwrap_or("")
            .split(',')
            .map(|x| {
                x.trim()
                    .parse::<i64>()
                    .map_err(|_| bad(n, format!("{line:?}")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let [p, v, t] = values[..] else {
            return Err(bad(n, format!("{line:?}: not p,v,t")));
        };
        if columns.len() <= k {
            columns.resize(k + 1, Vec::new());
        }
        if t > 0 {
            columns[k].push((p, v, t, n));
        }
    }
    if axes.is_empty() {
        axes = Axis::ALL.iter().copied().take(columns.len()).collect();
        scales = hinted_scales(&axes, hint)?;
    }
    columns.resize(axes.len(), Vec::new());
    start_counts.resize(axes.len(), 0);
    let mut b = Builder::new(axes.clone(), units);
    let mut counts = start_counts;
    b.start(
        Motion::Feed,
        counts
            .iter()
            .zip(&scales)
            .map(|(c, s)| *c as f64 / s)
            .collect(),
    );
    for k in 0..columns[0].len() {
        let (_, _, t, n) = columns[0][k];
        let mut velocity = Vec::new();
        for (a, column) in columns.iter().enumerate() {
            let &(p, v, ta, _) = column
                .get(k)
                .ok_or_else(|| bad(n, format!("axis {} has fewer segments", axes[a])))?;
            if ta != t {
                return Err(bad(
                    n,
                    format!(
                        "segment {} lasts {t} samples on one axis, {ta} on another",
                        k + 1
                    ),
                ));
            }
            counts[a] += p;
            velocity.push(v as f64 / scales[a]);
        }
        let end: Vec<f64> = counts
            .iter()
            .zip(&scales)
            .map(|(c, s)| *c as f64 / s)
            .collect();
        b.piece(
            &end,
            &velocity,
            t as f64 / crate::galil::SAMPLES_PER_SECOND,
            n,
        )?;
    }
    Ok(b)
}

/// Zaber `pvt 1 point abs p … v … t …` commands, at the hint's microsteps per unit.
fn read_zaber(text: &str, hint: &ReadHint) -> Result<Builder, ReadBackError> {
    let dim = text
        .lines()
        .find_map(|l| l.strip_prefix("pvt 1 setup store 1 "))
        .and_then(|n| n.trim().parse::<usize>().ok())
        .ok_or_else(|| bad(1, "no `pvt 1 setup store 1 N` line".into()))?;
    let axes: Vec<Axis> = Axis::ALL.iter().copied().take(dim).collect();
    let scales = hinted_scales(&axes, hint)?;
    let mut b = Builder::new(axes, hint.units);
    let trigger = format!("pvt 1 io set do {} ", crate::zaber::TRIGGER_CHANNEL);
    for (n, line) in pvt_core::text::numbered_lines(text) {
        if line.starts_with(&trigger) {
            b.trigger();
            continue;
        }
        let Some(rest) = line.strip_prefix("pvt 1 point abs p ") else {
            continue;
        };
        let parse = || -> Option<(Vec<f64>, Vec<f64>, f64)> {
            let (p, rest) = rest.split_once(" v ")?;
            let (v, t) = rest.split_once(" t ")?;
            let ints = |s: &str| {
                s.split(' ')
                    .map(|x| x.parse::<i64>().ok().map(|x| x as f64))
                    .collect::<Option<Vec<_>>>()
            };
            Some((ints(p)?, ints(v)?, t.trim().parse::<f64>().ok()?))
        };
        let (p, v, ms) = parse().ok_or_else(|| bad(n, format!("{line:?}")))?;
        if p.len() != dim || v.len() != dim {
            return Err(bad(n, format!("{line:?}: not {dim} axes")));
        }
        let end: Vec<f64> = p.iter().zip(&scales).map(|(p, s)| p / s).collect();
        let velocity: Vec<f64> = v
            .iter()
            .zip(&scales)
            .map(|(v, s)| v / (s * crate::zaber::NATIVE_VELOCITY))
            .collect();
        b.piece(&end, &velocity, ms / 1000.0, n)?;
    }
    Ok(b)
}

/// The CSV table of `--format csv`: `t,X,vX,…[,trigger]`, absolute times, in the
/// hint's units; the first row is the start (a rest before it when its time is not 0),
/// every other row a piece's end.
fn read_table(text: &str, hint: &ReadHint) -> Result<Builder, ReadBackError> {
    if !is_table(text) {
        return Err(bad(1, "not a `t,X,vX,…` header".into()));
    }
    let header: Vec<&str> = text
        .lines()
        .next()
        .unwrap_or("")
        .trim_end()
        .split(',')
        .collect();
    let triggered = header.last() == Some(&"trigger");
    let dim = (header.len() - 1 - usize::from(triggered)) / 2;
    let axes: Vec<Axis> = (0..dim)
        .filter_map(|k| header[1 + 2 * k].chars().next().and_then(Axis::from_letter))
        .collect();
    let mut b = Builder::new(axes, hint.units);
    let mut clock: Option<f64> = None;
    for (n, line) in pvt_core::text::numbered_lines(text).skip(1) {
        let f = line
            .trim_end()
            .split(',')
            .map(|x| number(x, n))
            .collect::<Result<Vec<_>, _>>()?;
        if f.len() != header.len() {
            return Err(bad(n, format!("{} fields, not {}", f.len(), header.len())));
        }
        let end: Vec<f64> = (0..dim).map(|k| f[1 + 2 * k]).collect();
        let velocity: Vec<f64> = (0..dim).map(|k| f[2 + 2 * k]).collect();
        match clock {
            None => {
                b.start(Motion::Feed, end.clone());
                if f[0] > 0.0 {
                    b.piece(&end, &velocity, f[0], n)?;
                }
            }
            Some(before) => b.piece(&end, &velocity, f[0] - before, n)?,
        }
        clock = Some(f[0]);
        if triggered && f[f.len() - 1] == 1.0 {
            b.trigger();
        }
    }
    Ok(b)
}
