//! The streaming path: G-code elements go straight through discretization and the contour
//! planner into a back end, in constant memory, whatever the program's length.
//!
//! Owns the glue between the G-code front end's sink interface, pvt-core's
//! [`ContourStream`] and pvt-emit's [`Checked`] writer. It must not parse, plan or format:
//! each of those stays in its crate, so the streamed output is byte-identical to the
//! in-memory path's.

use pvt_core::discretize::{arc_positions, project};
use pvt_core::{
    plan::{ContourStream, PlanError},
    Axis, ChordTolerance, Element, ElementKind, EventKind, Motion, ProgramEvent,
};
use pvt_emit::stream::Totals;
use pvt_emit::{Checked, ProgramWriter, StreamError};

/// Why streaming stopped.
#[derive(Debug)]
pub enum StreamFailure {
    /// A planner error (a bad feed or point).
    Plan(PlanError),
    /// A back end refused a value or could not write.
    Emit(StreamError),
}

/// A G-code sink that plans and writes as elements arrive.
pub struct PlanningSink<W: ProgramWriter> {
    writer: Checked<W>,
    axes: Vec<Axis>,
    tolerance: ChordTolerance,
    contour: Option<ContourStream>,
    /// Contours started, for placing events.
    contours: usize,
    point: Vec<f64>,
    failure: Option<StreamFailure>,
    /// Segments written, their time, and those whose time is not a whole millisecond.
    pub totals: Totals,
}

impl<W: ProgramWriter> PlanningSink<W> {
    /// A sink writing to `writer` (already begun) on `axes`.
    pub fn new(writer: Checked<W>, axes: Vec<Axis>, tolerance: ChordTolerance) -> PlanningSink<W> {
        let dim = axes.len();
        PlanningSink {
            writer,
            axes,
            tolerance,
            contour: None,
            contours: 0,
            point: vec![0.0; dim],
            failure: None,
            totals: Totals::default(),
        }
    }

    /// Adds one element of a contour of kind `motion`.
    pub fn element(&mut self, motion: Motion, element: &Element) {
        if self.failure.is_some() {
            return;
        }
        if self.contour.is_none() {
            let start = project(&element.start, &self.axes);
            if let Err(e) = self.writer.contour(motion, &start, element.span.line) {
                self.failure = Some(StreamFailure::Emit(e));
                return;
            }
            self.contour = Some(ContourStream::new(&start));
            self.contours += 1;
        }
        let line = element.span.line;
        match &element.kind {
            ElementKind::Line => {
                let end = project(&element.end, &self.axes);
                self.push(&end, element.feed, line);
            }
            ElementKind::Arc(arc) => {
                for p in arc_positions(arc, &element.start, &element.end, self.tolerance) {
                    for (slot, axis) in self.point.iter_mut().zip(&self.axes) {
                        *slot = p[axis.index()];
                    }
                    let point = std::mem::take(&mut self.point);
                    self.push(&point, element.feed, line);
                    self.point = point;
                }
            }
        }
    }

    fn push(&mut self, point: &[f64], feed: f64, line: u32) {
        let (Some(contour), None) = (self.contour.as_mut(), self.failure.as_ref()) else {
            return;
        };
        let (writer, totals) = (&mut self.writer, &mut self.totals);
        let mut emit_error = None;
        let result = contour.push(point, feed, line, &mut |seg| {
            totals.add_segment(seg.duration);
            if emit_error.is_none() {
                emit_error = writer.segment(&seg).err();
            }
        });
        self.failure = match (result, emit_error) {
            (Err(e), _) => Some(StreamFailure::Plan(e)),
            (Ok(()), Some(e)) => Some(StreamFailure::Emit(e)),
            (Ok(()), None) => None,
        };
    }

    /// Ends the current contour at rest.
    pub fn end_contour(&mut self) {
        let Some(mut contour) = self.contour.take() else {
            return;
        };
        if self.failure.is_some() {
            return;
        }
        let (writer, totals) = (&mut self.writer, &mut self.totals);
        let mut emit_error = None;
        contour.finish(&mut |seg| {
            totals.add_segment(seg.duration);
            if emit_error.is_none() {
                emit_error = writer.segment(&seg).err();
            }
        });
        self.failure = emit_error.map(StreamFailure::Emit);
    }

    /// Writes an event at rest (ending any open contour first).
    pub fn event(&mut self, kind: &EventKind, line: u32) {
        self.end_contour();
        if self.failure.is_some() {
            return;
        }
        let event = ProgramEvent {
            before_contour: self.contours,
            kind: kind.clone(),
            line,
        };
        if let Err(e) = self.writer.event(&event) {
            self.failure = Some(StreamFailure::Emit(e));
        }
    }

    /// Ends the program; returns the back end or the first failure.
    pub fn finish(mut self) -> Result<W, StreamFailure> {
        self.end_contour();
        if let Some(f) = self.failure {
            return Err(f);
        }
        self.writer.finish().map_err(StreamFailure::Emit)
    }
}

impl<W: ProgramWriter> pvt_gcode::ToolpathSink for PlanningSink<W> {
    fn element(&mut self, motion: Motion, element: &Element) {
        PlanningSink::element(self, motion, element);
    }
    fn end_contour(&mut self) {
        PlanningSink::end_contour(self);
    }
    fn event(&mut self, event: &EventKind, line: u32) {
        PlanningSink::event(self, event, line);
    }
}

/// A sink that only notes which axes move (pass 1 of streaming: the header needs them).
#[derive(Debug, Default)]
pub struct MovedAxes {
    moved: [bool; pvt_core::AXIS_COUNT],
}

impl MovedAxes {
    /// The moved axes in X Y Z A B C order, as [`pvt_core::Toolpath::moved_axes`] gives them.
    pub fn axes(&self) -> Vec<Axis> {
        Axis::ALL
            .into_iter()
            .filter(|a| self.moved[a.index()])
            .collect()
    }
}

impl pvt_gcode::ToolpathSink for MovedAxes {
    fn element(&mut self, _: Motion, element: &Element) {
        element.mark_moved_axes(&mut self.moved);
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &EventKind, _: u32) {}
}

/// Largest file whose text is held to show source lines under its diagnostics.
const MAX_SOURCE_FOR_REPORTS: u64 = 64 << 20;

/// Whether `path` and `options` can take the streaming path: a G-code file (not standard
/// input) planned by the contour planner without quantization.
pub fn can_stream(path: &std::path::Path, options: &crate::CompileOptions) -> bool {
    path != std::path::Path::new("-")
        && options.input == crate::InputKind::Gcode
        && options.planner == pvt_core::Planner::Contour
        && options.quantize.is_none()
}

fn open(path: &std::path::Path) -> Result<std::io::BufReader<std::fs::File>, crate::Failure> {
    std::fs::File::open(path)
        .map(|f| std::io::BufReader::with_capacity(1 << 18, f))
        .map_err(|error| crate::Failure::Io {
            path: path.to_path_buf(),
            action: "read",
            error,
        })
}

/// Diagnostics as reports, with the source attached when the file is small enough.
fn reports(
    path: &std::path::Path,
    name: &str,
    diagnostics: Vec<pvt_gcode::GcodeDiagnostic>,
) -> Vec<miette::Report> {
    let small = std::fs::metadata(path)
        .map(|m| m.len() <= MAX_SOURCE_FOR_REPORTS)
        .unwrap_or(false);
    let source = small
        .then(|| std::fs::read(path).ok())
        .flatten()
        .map(|bytes| crate::Source {
            name: name.to_owned(),
            bytes,
        });
    diagnostics
        .into_iter()
        .map(|d| match &source {
            Some(s) => miette::Report::new(d).with_source_code(s.named_text()),
            None => miette::Report::new(d),
        })
        .collect()
}

/// Compiles the G-code file at `path` into `out` in two passes over the file and
/// constant memory: the first finds every error and the moved axes, the second plans and
/// writes. Returns the warnings. The bytes are those [`crate::compile`] gives.
pub fn compile_streaming(
    path: &std::path::Path,
    name: &str,
    options: &crate::CompileOptions,
    out: &mut dyn std::io::Write,
) -> Result<Vec<miette::Report>, crate::Failure> {
    let gcode = crate::front::gcode_options(options);
    let io = |error| crate::Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    };
    let mut axes = MovedAxes::default();
    let summary = match pvt_gcode::compile_read(&mut open(path)?, &gcode, &mut axes).map_err(io)? {
        Ok(summary) => summary,
        Err(errors) => {
            return Err(crate::Failure::Input(reports(
                path,
                name,
                errors.diagnostics,
            )))
        }
    };
    let mut warnings = reports(path, name, summary.warnings);
    let units = summary.units;
    let tolerance = options
        .tolerance
        .unwrap_or(units.from_mm(ChordTolerance::DEFAULT_MM));
    let tolerance =
        ChordTolerance::new(tolerance).expect("the CLI accepts only positive tolerances");
    let emit_options = pvt_emit::EmitOptions {
        source: name.to_owned(),
        settings: crate::pipeline::settings(options, units),
        program_number: 1,
    };
    let axes = axes.axes();
    let buffered = std::io::BufWriter::with_capacity(1 << 16, out);
    let mut writer = Checked::new(options.format.writer(buffered));
    let header = pvt_emit::Header {
        axes: &axes,
        units,
        interpolation: pvt_core::Interpolation::Pvt,
        options: &emit_options,
    };
    writer
        .begin(&header)
        .map_err(|e| crate::pipeline::emit_failure(e, options, None))?;
    let mut sink = PlanningSink::new(writer, axes, tolerance);
    if let Err(errors) = pvt_gcode::compile_read(&mut open(path)?, &gcode, &mut sink).map_err(io)? {
        return Err(crate::Failure::Input(reports(
            path,
            name,
            errors.diagnostics,
        )));
    }
    let totals = sink.totals;
    match sink.finish() {
        Ok(_) => {}
        Err(StreamFailure::Plan(e)) => {
            return Err(crate::Failure::Input(vec![miette::miette!(
                code = e.code().to_string(),
                "{name}: {e}"
            )]))
        }
        Err(StreamFailure::Emit(e)) => return Err(crate::pipeline::emit_failure(e, options, None)),
    }
    if options.format == pvt_emit::Format::Pmac {
        warnings.extend(crate::pipeline::fractional_ms_report(
            totals.fractional_ms,
            totals.segments,
        ));
    }
    Ok(warnings)
}
