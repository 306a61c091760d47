//! The interactive HTML view: one self-contained page of a program's motion (or two,
//! compared), for `pvtc plot -o FILE.html` and `pvtc diff -o FILE.html`.
//!
//! Owns the page: the motions' spans as compact streams (`encode`), the programmed
//! path, the machine limits, the findings to list and the difference against time as
//! one deflated, base64 block inside the HTML, the lines' text and the programmed path
//! as a second (read once the page has drawn the motion), with the page's own
//! script (`view.js`) and style (`view.css`) inlined. The page asks for nothing over a
//! network and opens offline: the script inflates the block with the browser's
//! `DecompressionStream`, decodes the streams and draws on canvases (the path in 3D,
//! position, velocity, acceleration and jerk against time, min and max per pixel). It
//! must not plan or check: the CLI gives it what `check` and `compare` found.

mod encode;

use pvt_core::discretize::flatten_contour;
use pvt_core::{Axis, AxisLimits, ChordTolerance, Motion as Travel, PvtProgram, Toolpath, Units};
use std::collections::BTreeMap;
use std::io::Write;

pub use encode::TIME_QUANTUM;

/// The page's script, inlined.
const SCRIPT: &str = include_str!("view.js");
/// The page's style, inlined.
const STYLE: &str = include_str!("view.css");

/// Most points of the programmed path drawn (beyond them its contours are left out).
const MAX_PROGRAMMED_POINTS: usize = 2_000_000;
/// Longest text of a line shown, characters.
const MAX_LINE_TEXT: usize = 160;

/// One motion to show.
#[derive(Debug, Clone, Copy)]
pub struct Motion<'a> {
    /// Its name (the file it was read from).
    pub name: &'a str,
    /// The program.
    pub program: &'a PvtProgram,
    /// The text whose lines the pieces name (hover shows each piece's line).
    pub text: &'a str,
}

/// Something to list and jump to: a limit exceeded, a slowest spot, a peak.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// What it is, for people.
    pub label: String,
    /// When, seconds on its motion's time line (dwells included).
    pub time: f64,
    /// The line there.
    pub line: u32,
    /// Which motion (0 or 1).
    pub motion: usize,
    /// Whether it is a violation (drawn in red).
    pub violation: bool,
}

/// The difference of two motions against time, drawn under their plots.
#[derive(Debug, Clone, PartialEq)]
pub struct DifferenceProfile {
    /// The largest difference in each of equal bins over `[0, end]`.
    pub bins: Vec<f64>,
    /// The end of the last bin, seconds.
    pub end: f64,
    /// The tolerance, drawn as a line.
    pub tolerance: f64,
    /// The unit of the difference (`mm`, `in` or `counts`).
    pub unit: String,
}

/// What the page shows besides the motions.
#[derive(Debug, Clone, Default)]
pub struct ViewOptions<'a> {
    /// The page's title.
    pub title: String,
    /// The machine file's limits, drawn at ± each.
    pub limits: BTreeMap<Axis, AxisLimits>,
    /// The programmed path (of the first motion), drawn beside the motion in 3D.
    pub programmed: Option<&'a Toolpath>,
    /// What to list.
    pub findings: Vec<Finding>,
    /// The difference against time (for a comparison).
    pub difference: Option<DifferenceProfile>,
}

/// `t` seconds of `program`'s motion as a time on the view's time line, where each
/// dwell takes its time (`check` and the piece times count motion alone).
pub fn with_dwells(program: &PvtProgram, t: f64) -> f64 {
    let mut clock = 0.0;
    let mut added = 0.0;
    let mut events = program.events.iter().peekable();
    for (c, contour) in program.contours.iter().enumerate() {
        while let Some(e) = events.next_if(|e| e.before_contour <= c) {
            if let pvt_core::EventKind::Dwell { seconds } = e.kind {
                if clock <= t {
                    added += seconds.max(0.0);
                }
            }
        }
        clock += contour.total_time();
        if clock > t {
            break;
        }
    }
    t + added
}

/// Each axis' largest absolute position and velocity over the programs (each in the
/// first's units).
fn magnitudes(motions: &[Motion<'_>], axes: &[Axis], scales: &[f64]) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0f64, 0.0f64); axes.len()];
    for (m, s) in motions.iter().zip(scales) {
        let program = m.program;
        for (k, axis) in axes.iter().enumerate() {
            let Some(i) = program.axes.iter().position(|a| a == axis) else {
                continue;
            };
            let dim = program.axes.len();
            let s = if axis.is_rotary() { 1.0 } else { *s };
            for c in &program.contours {
                let positions =
                    std::iter::once(c.start[i]).chain(c.ends.iter().skip(i).step_by(dim).copied());
                out[k].0 = positions.fold(out[k].0, |a, x| a.max(x.abs() * s));
                let velocities = c.velocities.iter().skip(i).step_by(dim);
                out[k].1 = velocities.fold(out[k].1, |a, x| a.max(x.abs() * s));
            }
        }
    }
    out
}

/// The lines the pieces and events of `m` name, with their text (at most
/// [`MAX_LINE_TEXT`] characters each): the lines as varints of their differences, then
/// the texts, each ended by a line feed. Returns how many lines and the bytes of each part.
fn line_texts(m: &Motion<'_>, out: &mut Vec<u8>) -> (usize, usize, usize) {
    let mut wanted: Vec<u32> = m
        .program
        .contours
        .iter()
        .flat_map(|c| c.lines.iter().copied())
        .chain(m.program.events.iter().map(|e| e.line))
        .filter(|l| *l > 0)
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let (mut lines, mut texts) = (Vec::new(), String::new());
    let (mut want, mut last, mut count) = (wanted.into_iter().peekable(), 0, 0);
    for (n, text) in pvt_core::text::numbered_lines(m.text) {
        let Some(&next) = want.peek() else { break };
        if n as u32 == next {
            encode::varint(&mut lines, i64::from(next) - last);
            last = i64::from(next);
            texts.extend(
                text.chars()
                    .take(MAX_LINE_TEXT)
                    .map(|c| if c == '\n' { ' ' } else { c }),
            );
            texts.push('\n');
            count += 1;
            want.next();
        }
    }
    out.extend_from_slice(&lines);
    out.extend_from_slice(texts.as_bytes());
    (count, lines.len(), texts.len())
}

/// The programmed path on `axes` as polylines, flattened within `tolerance`.
fn programmed(toolpath: &Toolpath, axes: &[Axis], tolerance: f64, q: f64) -> (Vec<u8>, usize) {
    let mut out = Vec::new();
    let mut last = vec![0i64; axes.len()];
    let (mut points, mut count) = (0, 0);
    let tolerance =
        ChordTolerance::new(tolerance.max(ChordTolerance::SMALLEST)).expect("a positive tolerance");
    for contour in toolpath.contours.iter().filter(|c| !c.elements.is_empty()) {
        let line = flatten_contour(contour, axes, tolerance);
        points += line.len();
        if points > MAX_PROGRAMMED_POINTS {
            break;
        }
        let rapid = contour.motion == Travel::Rapid;
        encode::polyline(&mut out, &line.coords, axes.len(), rapid, q, &mut last);
        count += 1;
    }
    (out, count)
}

/// The page of `motions` (one, or two compared), as HTML bytes.
pub fn page(motions: &[Motion<'_>], options: &ViewOptions<'_>) -> Vec<u8> {
    let units = motions
        .first()
        .map_or(Units::Millimetre, |m| m.program.units);
    let axes: Vec<Axis> = Axis::ALL
        .into_iter()
        .filter(|a| motions.iter().any(|m| m.program.axes.contains(a)))
        .collect();
    let unit_scales: Vec<f64> = motions
        .iter()
        .map(|m| m.program.units.mm_per_unit() / units.mm_per_unit())
        .collect();
    let largest = magnitudes(motions, &axes, &unit_scales);
    let q = encode::Quanta::new(&largest);
    let largest_position = largest.iter().fold(0.0f64, |a, l| a.max(l.0));
    let mut blob = Vec::new();
    // The lines' text and the programmed path, a block of their own: the page reads it
    // after it first draws the motion.
    let mut later = Vec::new();
    let mut metas = Vec::new();
    for (m, unit) in motions.iter().zip(&unit_scales) {
        let scale: Vec<f64> = axes
            .iter()
            .map(|a| if a.is_rotary() { 1.0 } else { *unit })
            .collect();
        let e = encode::motion(m.program, &axes, &scale, &q);
        blob.extend_from_slice(&e.bytes);
        let (lines, line_bytes, text_bytes) = line_texts(m, &mut later);
        metas.push(serde_json::json!({
            "name": m.name,
            "spans": e.spans,
            "pieces": m.program.segment_count(),
            "bytes": e.bytes.len(),
            "start": e.start,
            "pt": encode::is_pt(m.program),
            "texts": {"lines": lines, "lineBytes": line_bytes, "textBytes": text_bytes},
        }));
    }
    let path = options.programmed.map(|t| {
        let tolerance = largest_position.max(1e-3) / 4000.0;
        let scale = t.units.mm_per_unit() / units.mm_per_unit();
        let step = q.position.iter().fold(0.0f64, |a, x| a.max(*x));
        let (bytes, polylines) = programmed(t, &axes, tolerance, step / scale);
        later.extend_from_slice(&bytes);
        serde_json::json!({"bytes": bytes.len(), "polylines": polylines, "scale": scale, "step": step})
    });
    let meta = serde_json::json!({
        "title": options.title,
        "units": units.name(),
        "axes": axes.iter().map(|a| a.to_string()).collect::<Vec<_>>(),
        "quanta": {"position": q.position, "velocity": q.velocity, "time": encode::TIME_QUANTUM},
        "block": encode::BLOCK,
        "motions": metas,
        "programmed": path,
        "limits": limits_json(&options.limits, &axes),
        "findings": options.findings.iter().map(|f| serde_json::json!({
            "label": f.label, "time": f.time, "line": f.line, "motion": f.motion,
            "violation": f.violation,
        })).collect::<Vec<_>>(),
        "difference": options.difference.as_ref().map(|d| serde_json::json!({
            "bins": d.bins, "end": d.end, "tolerance": d.tolerance, "unit": d.unit,
        })),
    });
    let meta = serde_json::to_vec(&meta).expect("JSON");
    let mut raw = Vec::with_capacity(4 + meta.len() + blob.len());
    raw.extend_from_slice(&(meta.len() as u32).to_le_bytes());
    raw.extend_from_slice(&meta);
    raw.extend_from_slice(&blob);
    let (data, later) = (deflate(&raw), deflate(&later));
    html(
        &options.title,
        [&encode::base64(&data), &encode::base64(&later)],
    )
}

fn limits_json(limits: &BTreeMap<Axis, AxisLimits>, axes: &[Axis]) -> serde_json::Value {
    let map: serde_json::Map<String, serde_json::Value> = axes
        .iter()
        .filter_map(|a| limits.get(a).map(|l| (a, l)))
        .map(|(a, l)| {
            (
                a.to_string(),
                serde_json::json!({"velocity": l.velocity, "acceleration": l.acceleration, "jerk": l.jerk}),
            )
        })
        .collect();
    serde_json::Value::Object(map)
}

fn deflate(bytes: &[u8]) -> Vec<u8> {
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::new(6));
    z.write_all(bytes).expect("writing into memory");
    z.finish().expect("writing into memory")
}

/// Text safe inside HTML.
fn escaped(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The page: `data` (the motions) and `later` (the lines' text and the programmed
/// path), each deflated and in base64, with the script and style.
fn html(title: &str, [data, later]: [&str; 2]) -> Vec<u8> {
    let size = data.len() + later.len() + SCRIPT.len() + STYLE.len() + 4096;
    let mut out = String::with_capacity(size);
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    out.push_str("<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:\">\n");
    out.push_str("<link rel=\"icon\" href=\"data:,\">\n");
    out.push_str(&format!("<title>{}</title>\n<style>\n", escaped(title)));
    out.push_str(STYLE);
    out.push_str(
        "</style>\n</head>\n<body>\n<script type=\"application/octet-stream\" id=\"pvtc-data\">",
    );
    out.push_str(data);
    out.push_str("</script>\n<script type=\"application/octet-stream\" id=\"pvtc-later\">");
    out.push_str(later);
    out.push_str("</script>\n<script>\n");
    out.push_str(SCRIPT);
    out.push_str("</script>\n</body>\n</html>\n");
    out.into_bytes()
}
