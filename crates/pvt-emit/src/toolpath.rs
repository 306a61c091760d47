//! The interpreted toolpath as JSON lines (`pvtc compile --format toolpath`).
//!
//! Owns the `toolpath` format, version 1: one JSON object per line for every element,
//! contour end, event and path tolerance a front end hands on, in program order, and a
//! last line with the units. It is the front end's reading of the program before any
//! planning, for users debugging a post-processor and for the differential tests against
//! LinuxCNC's `rs274`. It must not plan, and it writes numbers as they are (shortest
//! round-trip decimals), so the same program always gives the same bytes.
//!
//! Lines, each an object with a `kind`:
//! - `line`: `line` (source line), `motion` (`feed`/`rapid`), `start`, `end` (X Y Z A B
//!   C, machine coordinates in output units), `feed` (units per minute: the programmed
//!   feed, G93's worked out, or the rapid rate);
//! - `arc`: the same, plus `plane` (`XY`, `ZX`, `YZ`), `center` (the plane's first and
//!   second coordinates), `direction` (`cw`, `ccw`) and `turns` (extra full turns);
//! - `bezier`: the same as `line`, plus `plane` and `controls` (the cubic's two inner
//!   control points, each in the plane's first and second coordinates; the other axes
//!   move linearly with the curve's parameter);
//! - `end_contour`: the machine comes to rest;
//! - `event`: `line`, `event` (its name, as every output names it) and its value, if any
//!   (`seconds`, `rpm`, `tool`, `text`);
//! - `path_tolerance`: `tolerance`, from the next contour on (G64 P);
//! - `path_control`: `control` (`exact_path` G61, `exact_stop` G61.1, `continuous` G64,
//!   with its `tolerance` P and `naive_cam_tolerance` Q, output units), from the next
//!   move on;
//! - `end`: `units` (`mm`, `in`), `elements` and `events` (counts). A file without it
//!   was cut short.

use pvt_core::{
    ArcDirection, Element, ElementKind, EventKind, Motion, PathControl, Plane, ToolpathSink, Units,
};
use serde_json::{json, Value};
use std::io::Write;

/// A [`ToolpathSink`] writing the `toolpath` format to `out`.
///
/// The sink's methods cannot fail, so the first write error is kept and every later
/// write skipped; [`ToolpathWriter::finish`] returns it.
pub struct ToolpathWriter<W: Write> {
    out: W,
    error: Option<std::io::Error>,
    elements: u64,
    events: u64,
}

impl<W: Write> ToolpathWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> ToolpathWriter<W> {
        ToolpathWriter {
            out,
            error: None,
            elements: 0,
            events: 0,
        }
    }

    /// Writes the `end` line in `units` and flushes; the first write error, if any.
    pub fn finish(mut self, units: Units) -> std::io::Result<W> {
        let end = json!({
            "kind": "end",
            "units": units.name(),
            "elements": self.elements,
            "events": self.events,
        });
        self.line(&end);
        if let Some(error) = self.error.take() {
            return Err(error);
        }
        self.out.flush()?;
        Ok(self.out)
    }

    fn line(&mut self, value: &Value) {
        if self.error.is_some() {
            return;
        }
        let written = serde_json::to_writer(&mut self.out, value)
            .map_err(std::io::Error::from)
            .and_then(|()| self.out.write_all(b"\n"));
        if let Err(error) = written {
            self.error = Some(error);
        }
    }
}

/// An element as its `line`, `arc` or `bezier` object.
pub fn element_value(motion: Motion, element: &Element) -> Value {
    let motion = match motion {
        Motion::Rapid => "rapid",
        Motion::Feed => "feed",
    };
    let mut value = json!({
        "kind": "line",
        "line": element.span.line,
        "motion": motion,
        "start": element.start,
        "end": element.end,
        "feed": element.feed * 60.0,
    });
    if let ElementKind::Arc(arc) = &element.kind {
        value["kind"] = json!("arc");
        value["plane"] = json!(plane_name(arc.plane));
        value["center"] = json!(arc.center);
        value["direction"] = json!(match arc.direction {
            ArcDirection::Clockwise => "cw",
            ArcDirection::CounterClockwise => "ccw",
        });
        value["turns"] = json!(arc.extra_turns);
    }
    if let ElementKind::Bezier(bezier) = &element.kind {
        value["kind"] = json!("bezier");
        value["plane"] = json!(plane_name(bezier.plane));
        value["controls"] = json!(bezier.controls);
    }
    value
}

fn plane_name(plane: Plane) -> &'static str {
    match plane {
        Plane::XY => "XY",
        Plane::ZX => "ZX",
        Plane::YZ => "YZ",
    }
}

/// An event as its `event` object.
pub fn event_value(event: &EventKind, line: u32) -> Value {
    let mut value = json!({ "kind": "event", "line": line, "event": event.name() });
    match event {
        EventKind::Dwell { seconds } => value["seconds"] = json!(seconds),
        EventKind::SpindleSpeed { rpm } => value["rpm"] = json!(rpm),
        EventKind::ToolSelect { tool } => value["tool"] = json!(tool),
        EventKind::Message { text } => value["text"] = json!(text),
        EventKind::MachineCode { code, words } => {
            value["code"] = json!(code);
            let named = [
                ("p", words.p),
                ("q", words.q),
                ("e", words.e),
                ("l", words.l),
            ];
            for (name, v) in named {
                if let Some(v) = v {
                    value[name] = json!(v);
                }
            }
        }
        EventKind::Pause { .. }
        | EventKind::Spindle { .. }
        | EventKind::Coolant { .. }
        | EventKind::ToolChange => {}
    }
    value
}

impl<W: Write> ToolpathSink for ToolpathWriter<W> {
    fn element(&mut self, motion: Motion, element: &Element) {
        self.elements += 1;
        self.line(&element_value(motion, element));
    }

    fn end_contour(&mut self) {
        self.line(&json!({ "kind": "end_contour" }));
    }

    fn event(&mut self, event: &EventKind, line: u32) {
        self.events += 1;
        self.line(&event_value(event, line));
    }

    fn path_tolerance(&mut self, tolerance: f64) {
        self.line(&json!({ "kind": "path_tolerance", "tolerance": tolerance }));
    }

    fn path_control(&mut self, control: &PathControl) {
        self.line(&path_control_value(control));
    }
}

/// A path control mode as its `path_control` object.
pub fn path_control_value(control: &PathControl) -> Value {
    let mut value = json!({ "kind": "path_control", "control": control.name() });
    if let PathControl::Continuous {
        tolerance,
        naive_cam_tolerance,
    } = control
    {
        value["tolerance"] = json!(tolerance);
        value["naive_cam_tolerance"] = json!(naive_cam_tolerance);
    }
    value
}

/// Hands a whole [`pvt_core::Toolpath`] to `sink` in program order, as a streaming front
/// end would ([`pvt_core::traverse::replay`], the one traversal).
pub fn replay(toolpath: &pvt_core::Toolpath, sink: &mut dyn ToolpathSink) {
    pvt_core::traverse::replay(toolpath, sink);
}

#[cfg(test)]
mod tests {
    use super::*;
    use pvt_core::{Arc, Span};

    fn element(kind: ElementKind) -> Element {
        Element {
            kind,
            start: [0.0; 6],
            end: [1.0, 0.5, 0.0, 0.0, 0.0, 0.0],
            feed: 100.0,
            span: Span {
                start: 0,
                end: 1,
                line: 7,
            },
        }
    }

    #[test]
    fn writes_one_object_per_line_and_an_end_line() {
        let mut writer = ToolpathWriter::new(Vec::new());
        writer.element(Motion::Feed, &element(ElementKind::Line));
        let arc = Arc {
            plane: Plane::ZX,
            center: [0.25, 0.5],
            direction: ArcDirection::Clockwise,
            extra_turns: 1,
        };
        writer.element(Motion::Feed, &element(ElementKind::Arc(arc)));
        writer.end_contour();
        writer.event(&EventKind::Dwell { seconds: 1.5 }, 9);
        let bytes = writer.finish(Units::Inch).expect("in memory");
        let text = String::from_utf8(bytes).expect("utf-8");
        let lines: Vec<Value> = text
            .lines()
            .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
            .collect();
        assert_eq!(lines.len(), 5);
        assert_eq!(lines[0]["kind"], "line");
        assert_eq!(lines[0]["line"], 7);
        assert_eq!(lines[0]["feed"], 6000.0);
        assert_eq!(lines[0]["end"], json!([1.0, 0.5, 0.0, 0.0, 0.0, 0.0]));
        assert_eq!(lines[1]["kind"], "arc");
        assert_eq!(lines[1]["plane"], "ZX");
        assert_eq!(lines[1]["center"], json!([0.25, 0.5]));
        assert_eq!(lines[1]["direction"], "cw");
        assert_eq!(lines[1]["turns"], 1);
        assert_eq!(lines[2]["kind"], "end_contour");
        assert_eq!(lines[3]["event"], "dwell");
        assert_eq!(lines[3]["seconds"], 1.5);
        assert_eq!(
            lines[4],
            json!({"kind": "end", "units": "in", "elements": 2, "events": 1})
        );
    }
}
