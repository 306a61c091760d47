//! The pvtc JSON program document, version 1: writer and reader.
//!
//! Owns the JSON spelling of a program, for tools. Layout (one segment per line):
//!
//! ```json
//! {
//!   "format": "pvtc-program",
//!   "version": 1,
//!   "source": "samples/gcode/octagon.ngc",
//!   "settings": {"planner": "contour (seed 000)", "chord tolerance": "0.001 mm"},
//!   "units": "mm",
//!   "velocity_units": "mm/s",
//!   "time_units": "s",
//!   "axes": ["X", "Y"],
//!   "total_time": 1.2,
//!   "contours": [
//!     {"kind": "feed", "start": [0.0, 0.0], "segments": [
//!       {"p": [1.0, 0.0], "v": [10.0, 0.0], "t": 0.15, "line": 4}
//!     ]}
//!   ],
//!   "events": [
//!     {"before_contour": 1, "event": "dwell", "line": 5, "seconds": 0.5}
//!   ]
//! }
//! ```
//!
//! `axes` lists the axes the program moves in X Y Z A B C order; `p` is a segment's end
//! position, `v` its end velocity (units/s), `t` its duration (s) and `line` the source
//! line it came from. An event happens at rest before contour `before_contour` (the number
//! of contours: after the last), named as `EventKind::name` names it, with its value
//! (`seconds`, `rpm`, `tool`, `text`) where it has one. Numbers are shortest round-trip,
//! so a program, events included, reads back bit for bit.
//! A change that breaks a reader of these fields bumps `version`.
//!
//! With `--trigger-every` ([`crate::triggers`]) the document also has `"triggers"`, after
//! `"events"`: one `{"t": …, "p": […]}` per trigger, its time from the start of the
//! motion (s; dwells add none) and where the axes are; the segments are cut at them.

use crate::gather::{Gathered, TextOut};
use crate::number::push_exact;
use crate::writer::{Header, ProgramWriter, Totals};
use pvt_core::{
    Axis, CodeWords, EventKind, Interpolation, Motion, ProgramEvent, PvtContour, PvtProgram,
    SegmentRef, Units,
};
use serde::Deserialize;
use std::io::{self, Write};

/// Value of the `format` field.
pub const FORMAT: &str = "pvtc-program";
/// Value of the `version` field written by this crate.
pub const VERSION: u32 = 1;

/// Bytes of text gathered before they are written.
const TEXT_BATCH: usize = 64 * 1024;

/// Streams a pvtc JSON document to `W`.
pub struct JsonWriter<W> {
    out: W,
    text: Gathered,
    totals: Totals,
    /// Every event of the program, as JSON objects, printed after the contours: memory
    /// grows with the number of events (not of pieces).
    events: Vec<String>,
    /// Every trigger, as a JSON object; `None` without `--trigger-every`.
    triggers: Option<Vec<String>>,
    /// Where the axes are after the last segment.
    at: Vec<f64>,
}

impl<W: Write> JsonWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> JsonWriter<W> {
        JsonWriter {
            out,
            text: Gathered::with_capacity(TEXT_BATCH + 1024),
            totals: Totals::default(),
            events: Vec::new(),
            triggers: None,
            at: Vec::new(),
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.out
    }

    fn flush_text(&mut self) -> io::Result<()> {
        self.out.write_all(self.text.text())?;
        self.text.clear();
        Ok(())
    }

    /// [`Self::flush_text`] once a batch of text is gathered: each piece's text is not
    /// copied into the output's buffer on its own.
    fn flush_batch(&mut self) -> io::Result<()> {
        if self.text.len() >= TEXT_BATCH {
            self.flush_text()?;
        }
        Ok(())
    }

    fn end_contour(&mut self) {
        if self.totals.contours > 0 {
            self.text.push_str("\n    ]}");
        }
    }
}

impl<W: Write> ProgramWriter for JsonWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.triggers = header.options.triggers.map(|_| Vec::new());
        let units = header.units.name();
        let t = &mut self.text;
        t.push_str(&format!(
            "{{\n  \"format\": \"{FORMAT}\",\n  \"version\": {VERSION},\n"
        ));
        t.push_str(&format!(
            "  \"source\": {},\n  \"settings\": {{",
            quote(&header.options.source)
        ));
        for (i, (name, value)) in header.options.settings.iter().enumerate() {
            t.push_str(if i == 0 { "" } else { ", " });
            t.push_str(&format!("{}: {}", quote(name), quote(value)));
        }
        t.push_str(&format!(
            "}},\n  \"units\": \"{units}\",\n  \"velocity_units\": \"{units}/s\",\n"
        ));
        t.push_str(&format!(
            "  \"time_units\": \"s\",\n  \"interpolation\": \"{}\",\n",
            interpolation_name(header.interpolation)
        ));
        let axes: Vec<String> = header.axes.iter().map(|a| format!("\"{a}\"")).collect();
        t.push_str(&format!(
            "  \"axes\": [{}],\n  \"contours\": [",
            axes.join(", ")
        ));
        self.flush_text()
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        self.end_contour();
        let first = self.totals.contours == 0;
        self.totals.add_contour();
        self.text.push_str(if first {
            "\n    {\"kind\": "
        } else {
            ",\n    {\"kind\": "
        });
        self.text.push_str(&quote(motion.name()));
        self.text.push_str(", \"start\": ");
        list(&mut self.text, start);
        self.at = start.to_vec();
        self.text.push_str(", \"segments\": [");
        self.flush_text()
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        let t = &mut self.text;
        if self.totals.segments_in_contour > 0 {
            t.push(b',');
        }
        t.push_slice(b"\n      {\"p\": ");
        self.totals.add_segment(seg.duration);
        if self.triggers.is_some() {
            self.at.clear();
            self.at.extend_from_slice(seg.end);
        }
        list(t, seg.end);
        t.push_slice(b", \"v\": ");
        list(t, seg.velocity);
        t.push_slice(b", \"t\": ");
        t.exact(seg.duration);
        t.push_slice(b", \"line\": ");
        t.push_short(itoa::Buffer::new().format(seg.line).as_bytes());
        t.push(b'}');
        self.flush_batch()
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        let mut e = format!(
            "{{\"before_contour\": {}, \"event\": \"{}\", \"line\": {}",
            self.totals.contours,
            event.kind.name(),
            event.line
        );
        match &event.kind {
            EventKind::Dwell { seconds } => {
                e.push_str(", \"seconds\": ");
                push_exact(&mut e, *seconds);
            }
            EventKind::SpindleSpeed { rpm } => {
                e.push_str(", \"rpm\": ");
                push_exact(&mut e, *rpm);
            }
            EventKind::ToolSelect { tool } => e.push_str(&format!(", \"tool\": {tool}")),
            EventKind::Message { text } => e.push_str(&format!(", \"text\": {}", quote(text))),
            EventKind::MachineCode { code, words } => {
                e.push_str(&format!(", \"code\": {code}"));
                let named = [
                    ("p", words.p),
                    ("q", words.q),
                    ("e", words.e),
                    ("l", words.l),
                ];
                for (name, value) in named {
                    if let Some(v) = value {
                        e.push_str(&format!(", \"{name}\": "));
                        push_exact(&mut e, v);
                    }
                }
            }
            _ => {}
        }
        e.push('}');
        self.events.push(e);
        Ok(())
    }

    fn trigger(&mut self) -> io::Result<()> {
        let mut e = String::from("{\"t\": ");
        push_exact(&mut e, self.totals.time);
        e.push_str(", \"p\": ");
        list(&mut e, &self.at);
        e.push('}');
        self.triggers.get_or_insert_with(Vec::new).push(e);
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.end_contour();
        self.text.push_str("\n  ],\n  \"events\": [");
        for (i, e) in self.events.iter().enumerate() {
            self.text
                .push_str(if i == 0 { "\n    " } else { ",\n    " });
            self.text.push_str(e);
        }
        self.text
            .push_str(if self.events.is_empty() { "]" } else { "\n  ]" });
        if let Some(triggers) = &self.triggers {
            self.text.push_str(",\n  \"triggers\": [");
            for (i, e) in triggers.iter().enumerate() {
                self.text
                    .push_str(if i == 0 { "\n    " } else { ",\n    " });
                self.text.push_str(e);
            }
            self.text
                .push_str(if triggers.is_empty() { "]" } else { "\n  ]" });
        }
        self.text.push_str(&format!(
            ",\n  \"segment_count\": {},\n  \"total_time\": ",
            self.totals.segments
        ));
        self.text.exact(self.totals.time);
        self.text.push_str("\n}\n");
        self.flush_text()?;
        self.out.flush()
    }

    fn supports(&self, _: Interpolation) -> bool {
        true
    }

    fn caps(&self) -> crate::Caps {
        crate::Format::Json.caps()
    }
}

fn interpolation_name(i: Interpolation) -> &'static str {
    match i {
        Interpolation::Pvt => "pvt",
        Interpolation::Pt => "pt",
    }
}

fn quote(s: &str) -> String {
    serde_json::to_string(s).expect("a string always serializes")
}

#[inline]
fn list<T: TextOut>(text: &mut T, values: &[f64]) {
    text.put("[");
    for (i, x) in values.iter().enumerate() {
        if i > 0 {
            text.put(", ");
        }
        text.exact(*x);
    }
    text.put("]");
}

/// Why a JSON document is not a pvtc program.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// Not JSON, or not the document's shape.
    #[error("not a pvtc JSON program: {0}")]
    Json(#[from] serde_json::Error),
    /// Valid JSON with a value this version does not accept.
    #[error("not a pvtc JSON program: {0}")]
    Content(String),
}

#[derive(Deserialize)]
struct Document {
    format: String,
    version: u32,
    units: String,
    #[serde(default)]
    interpolation: Option<String>,
    axes: Vec<String>,
    contours: Vec<ContourDocument>,
    #[serde(default)]
    events: Vec<EventDocument>,
    #[serde(default)]
    triggers: Vec<TriggerDocument>,
}

#[derive(Deserialize)]
struct TriggerDocument {
    t: f64,
}

#[derive(Deserialize)]
struct EventDocument {
    before_contour: usize,
    event: String,
    #[serde(default)]
    line: u32,
    seconds: Option<f64>,
    rpm: Option<f64>,
    tool: Option<u32>,
    text: Option<String>,
    code: Option<u16>,
    p: Option<f64>,
    q: Option<f64>,
    e: Option<f64>,
    l: Option<f64>,
}

impl EventDocument {
    /// The event this object spells, as [`EventKind::name`] names it (the one place the
    /// names are spelled); `None` when the name is unknown or a value it needs is missing.
    fn kind(&self) -> Option<EventKind> {
        if let Some(kind) = EventKind::without_value(&self.event) {
            return Some(kind);
        }
        let words = CodeWords {
            p: self.p,
            q: self.q,
            e: self.e,
            l: self.l,
        };
        if let Some(kind) = self
            .code
            .and_then(|code| EventKind::machine_code(code, words))
        {
            return (kind.name() == self.event).then_some(kind);
        }
        Some(match self.event.as_str() {
            "dwell" => EventKind::Dwell {
                seconds: self.seconds.filter(|s| s.is_finite() && *s >= 0.0)?,
            },
            "spindle_speed" => EventKind::SpindleSpeed { rpm: self.rpm? },
            "tool_select" => EventKind::ToolSelect { tool: self.tool? },
            "message" => EventKind::Message {
                text: self.text.clone()?,
            },
            _ => return None,
        })
    }
}

#[derive(Deserialize)]
struct ContourDocument {
    kind: String,
    start: Vec<f64>,
    segments: Vec<SegmentDocument>,
}

#[derive(Deserialize)]
struct SegmentDocument {
    p: Vec<f64>,
    v: Vec<f64>,
    t: f64,
    #[serde(default)]
    line: u32,
}

/// Reads a pvtc JSON program document (version 1).
pub fn read(text: &str) -> Result<PvtProgram, ReadError> {
    read_with_triggers(text).map(|(program, _)| program)
}

/// Reads a pvtc JSON program document (version 1) with its triggers, each as the number
/// of pieces before it (the pieces are cut at every trigger, so each fires at a piece's
/// end: the one whose end is its time).
pub fn read_with_triggers(text: &str) -> Result<(PvtProgram, Vec<usize>), ReadError> {
    let doc: Document = serde_json::from_str(text)?;
    let times: Vec<f64> = doc.triggers.iter().map(|t| t.t).collect();
    let program = program_of(doc)?;
    let mut ends = program
        .contours
        .iter()
        .flat_map(|c| c.durations.iter())
        .scan(0.0, |clock, t| {
            *clock += t;
            Some(*clock)
        })
        .enumerate()
        .peekable();
    let mut triggers = Vec::with_capacity(times.len());
    let mut before = 0;
    for t in times {
        while let Some((i, _)) = ends.next_if(|(_, end)| *end <= t + 1e-9 * t.abs().max(1.0)) {
            before = i + 1;
        }
        triggers.push(before);
    }
    Ok((program, triggers))
}

/// The program a document holds.
fn program_of(doc: Document) -> Result<PvtProgram, ReadError> {
    let bad = |what: String| ReadError::Content(what);
    if doc.format != FORMAT || doc.version != VERSION {
        return Err(bad(format!(
            "format {:?} version {} (expected {FORMAT:?} version {VERSION})",
            doc.format, doc.version
        )));
    }
    let units = match doc.units.as_str() {
        "mm" => Units::Millimetre,
        "in" => Units::Inch,
        other => return Err(bad(format!("unknown units {other:?}"))),
    };
    let interpolation = match doc.interpolation.as_deref() {
        None | Some("pvt") => Interpolation::Pvt,
        Some("pt") => Interpolation::Pt,
        Some(other) => return Err(bad(format!("unknown interpolation {other:?}"))),
    };
    let mut axes = Vec::with_capacity(doc.axes.len());
    for name in &doc.axes {
        let mut chars = name.chars();
        match (chars.next().and_then(Axis::from_letter), chars.next()) {
            (Some(axis), None) => axes.push(axis),
            _ => return Err(bad(format!("unknown axis {name:?}"))),
        }
    }
    let dim = axes.len();
    let mut contours = Vec::with_capacity(doc.contours.len());
    for (c, cd) in doc.contours.into_iter().enumerate() {
        let motion = match cd.kind.as_str() {
            "feed" => Motion::Feed,
            "rapid" => Motion::Rapid,
            other => return Err(bad(format!("contour {}: unknown kind {other:?}", c + 1))),
        };
        if cd.start.len() != dim {
            return Err(bad(format!(
                "contour {}: start has {} values for {dim} axes",
                c + 1,
                cd.start.len()
            )));
        }
        let mut contour = PvtContour::new(motion, cd.start);
        for (i, s) in cd.segments.iter().enumerate() {
            if s.p.len() != dim || s.v.len() != dim {
                return Err(bad(format!(
                    "contour {}, segment {}: p and v need {dim} values",
                    c + 1,
                    i + 1
                )));
            }
            if !(s.t.is_finite() && s.t > 0.0) {
                return Err(bad(format!(
                    "contour {}, segment {}: time {} is not a positive number of seconds",
                    c + 1,
                    i + 1,
                    s.t
                )));
            }
            contour.push(&s.p, &s.v, s.t, s.line);
        }
        contours.push(contour);
    }
    let mut events = Vec::with_capacity(doc.events.len());
    for (i, e) in doc.events.iter().enumerate() {
        let kind = e.kind().ok_or_else(|| {
            bad(format!(
                "event {}: unknown event {:?} or a value it needs is missing",
                i + 1,
                e.event
            ))
        })?;
        let earliest = events.last().map_or(0, |p: &ProgramEvent| p.before_contour);
        if e.before_contour > contours.len() || e.before_contour < earliest {
            return Err(bad(format!(
                "event {}: before contour {} (of {}, and not before an earlier event's)",
                i + 1,
                e.before_contour,
                contours.len()
            )));
        }
        events.push(ProgramEvent {
            before_contour: e.before_contour,
            kind,
            line: e.line,
        });
    }
    Ok(PvtProgram {
        axes,
        units,
        interpolation,
        contours,
        events,
    })
}
