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
    Axis, ChordTolerance, Element, ElementKind, EventKind, Motion, PieceSplitter, ProgramEvent,
    SegmentRef,
};
use pvt_emit::stream::Totals;
use pvt_emit::{Checked, ProgramWriter, StreamError};

use crate::output::Target;

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
    /// The axes the elements moved, to check the header's axes against.
    moved: MovedAxes,
    /// Segments written, their time, and those whose time is not a whole millisecond.
    pub totals: Totals,
    /// Cuts pieces longer than the format takes (PMAC), as [`crate::pipeline::fit_pieces`].
    splitter: Option<PieceSplitter>,
}

impl<W: ProgramWriter> PlanningSink<W> {
    /// A sink writing to `writer` (already begun) on `axes`, cutting pieces longer than
    /// `max_piece` seconds along their cubic (on `grid` where their time is on it).
    pub fn new(
        writer: Checked<W>,
        axes: Vec<Axis>,
        tolerance: ChordTolerance,
        max_piece: Option<f64>,
        grid: Option<f64>,
    ) -> PlanningSink<W> {
        let dim = axes.len();
        PlanningSink {
            writer,
            axes,
            tolerance,
            contour: None,
            contours: 0,
            point: vec![0.0; dim],
            failure: None,
            moved: MovedAxes::default(),
            totals: Totals::default(),
            splitter: max_piece.map(|max| PieceSplitter::new(max, grid)),
        }
    }

    /// Adds one element of a contour of kind `motion`.
    pub fn element(&mut self, motion: Motion, element: &Element) {
        self.moved.note(element);
        if self.failure.is_some() {
            return;
        }
        if self.contour.is_none() {
            let start = project(&element.start, &self.axes);
            if let Err(e) = self.writer.contour(motion, &start, element.span.line) {
                self.failure = Some(StreamFailure::Emit(e));
                return;
            }
            if let Some(splitter) = self.splitter.as_mut() {
                splitter.start(&start);
            }
            self.contour = Some(ContourStream::new(&start));
            self.contours += 1;
        }
        let line = element.span.line;
        match &element.kind {
            ElementKind::Line => self.push_position(&element.end, element.feed, line),
            ElementKind::Arc(arc) => {
                for p in arc_positions(arc, &element.start, &element.end, self.tolerance) {
                    self.push_position(&p, element.feed, line);
                }
            }
        }
    }

    /// Pushes position `p` on the sink's axes, through a reused buffer.
    fn push_position(&mut self, p: &pvt_core::Position, feed: f64, line: u32) {
        for (slot, axis) in self.point.iter_mut().zip(&self.axes) {
            *slot = p[axis.index()];
        }
        let point = std::mem::take(&mut self.point);
        self.push(&point, feed, line);
        self.point = point;
    }

    fn push(&mut self, point: &[f64], feed: f64, line: u32) {
        let (Some(contour), None) = (self.contour.as_mut(), self.failure.as_ref()) else {
            return;
        };
        let mut out = Out {
            writer: &mut self.writer,
            totals: &mut self.totals,
            splitter: self.splitter.as_mut(),
            error: None,
        };
        let result = contour.push(point, feed, line, &mut |seg| out.segment(&seg));
        let emit_error = out.error;
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
        let mut out = Out {
            writer: &mut self.writer,
            totals: &mut self.totals,
            splitter: self.splitter.as_mut(),
            error: None,
        };
        contour.finish(&mut |seg| out.segment(&seg));
        self.failure = out.error.map(StreamFailure::Emit);
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
    /// Notes the axes `element` moves.
    pub fn note(&mut self, element: &Element) {
        element.mark_moved_axes(&mut self.moved);
    }

    /// The moved axes in X Y Z A B C order, as [`pvt_core::Toolpath::moved_axes`] gives them.
    pub fn axes(&self) -> Vec<Axis> {
        Axis::ALL
            .into_iter()
            .filter(|a| self.moved[a.index()])
            .collect()
    }
}

/// Where the planner's segments go: through the splitter (if any) into the writer,
/// counted; the first write error is kept and later segments are dropped.
struct Out<'a, W: ProgramWriter> {
    writer: &'a mut Checked<W>,
    totals: &'a mut Totals,
    splitter: Option<&'a mut PieceSplitter>,
    error: Option<StreamError>,
}

impl<W: ProgramWriter> Out<'_, W> {
    fn segment(&mut self, seg: &SegmentRef<'_>) {
        let (writer, totals, error) = (&mut *self.writer, &mut *self.totals, &mut self.error);
        let mut write = |piece: &SegmentRef<'_>| {
            totals.add_segment(piece.duration);
            if error.is_none() {
                *error = writer.segment(piece).err();
            }
        };
        match self.splitter.as_deref_mut() {
            Some(splitter) => splitter.push(seg, &mut write),
            None => write(seg),
        }
    }
}

impl pvt_gcode::ToolpathSink for MovedAxes {
    fn element(&mut self, _: Motion, element: &Element) {
        self.note(element);
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &EventKind, _: u32) {}
}

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
        .map_err(|error| read_failure(path, error))
}

fn read_failure(path: &std::path::Path, error: std::io::Error) -> crate::Failure {
    crate::Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    }
}

/// One pass of the G-code front end over the file into `sink`; its errors as reports.
fn compile_read(
    path: &std::path::Path,
    name: &str,
    gcode: &pvt_gcode::GcodeOptions,
    sink: &mut dyn pvt_gcode::ToolpathSink,
) -> Result<pvt_gcode::StreamSummary, crate::Failure> {
    pvt_gcode::compile_read(&mut open(path)?, gcode, sink)
        .map_err(|error| read_failure(path, error))?
        .map_err(|errors| crate::Failure::Input(reports(path, name, errors.diagnostics)))
}

/// Diagnostics as reports, each with the lines of the file around it (read again, a
/// few lines kept per diagnostic, so memory stays flat however long the file).
fn reports(
    path: &std::path::Path,
    name: &str,
    diagnostics: Vec<pvt_gcode::GcodeDiagnostic>,
) -> Vec<miette::Report> {
    let spans: Vec<_> = diagnostics.iter().map(|d| d.span()).collect();
    let excerpts = match open(path) {
        Ok(mut input) => crate::excerpt::cut(&mut input, &spans).unwrap_or_default(),
        Err(_) => Vec::new(),
    };
    let mut excerpts = excerpts.into_iter();
    diagnostics
        .into_iter()
        .map(|d| match excerpts.next().flatten() {
            Some(excerpt) => {
                miette::Report::new(d).with_source_code(miette::NamedSource::new(name, excerpt))
            }
            None => miette::Report::new(d),
        })
        .collect()
}

/// What the header fixes before the first piece is written.
#[derive(Debug, Clone, PartialEq)]
struct Layout {
    axes: Vec<Axis>,
    units: pvt_core::Units,
}

impl Layout {
    /// The layout a [`pvt_gcode::Prescan`] suggests under `gcode`'s units option.
    fn guess(prescan: &pvt_gcode::Prescan, gcode: &pvt_gcode::GcodeOptions) -> Layout {
        Layout {
            axes: Axis::ALL
                .into_iter()
                .filter(|a| prescan.axis_words[a.index()])
                .collect(),
            units: gcode.units.or(prescan.units).unwrap_or_default(),
        }
    }
}

/// One pass over the file that plans and writes under a layout.
struct Pass {
    /// The layout the program really has.
    layout: Layout,
    warnings: Vec<pvt_gcode::GcodeDiagnostic>,
    outcome: Result<Totals, StreamFailure>,
}

/// Compiles the G-code file at `path` into `out` in constant memory and returns the
/// warnings; the bytes are those [`crate::compile`] gives.
///
/// The header needs the moved axes and the units before the first piece. Into a file
/// (an output file, or standard output redirected to one), a lexical
/// [`pvt_gcode::prescan`] guesses them and one pass plans and writes; when the compile
/// finds otherwise, the file is cut back and a second pass writes again. Into a stream
/// (a pipe, a terminal), which cannot start over, a first pass finds them and a second
/// writes.
pub fn compile_streaming(
    path: &std::path::Path,
    name: &str,
    options: &crate::CompileOptions,
    out: &mut Target<'_>,
) -> Result<Vec<miette::Report>, crate::Failure> {
    if out.is_file_at(path) {
        return Err(crate::Failure::Usage(format!(
            "standard output is the input file {}: pvtc would read what it writes",
            path.display()
        )));
    }
    let gcode = crate::front::gcode_options(options);
    let layout = if out.can_restart() {
        let prescan = pvt_gcode::prescan(&mut open(path)?).map_err(|e| read_failure(path, e))?;
        Layout::guess(&prescan, &gcode)
    } else {
        let mut moved = MovedAxes::default();
        let summary = compile_read(path, name, &gcode, &mut moved)?;
        Layout {
            axes: moved.axes(),
            units: summary.units,
        }
    };
    let mut pass = write_pass(path, name, options, &gcode, &layout, out)?;
    if pass.layout != layout {
        let restart = |error| crate::Failure::Io {
            path: "<output>".into(),
            action: "rewrite",
            error,
        };
        out.restart().map_err(restart)?;
        pass = write_pass(path, name, options, &gcode, &pass.layout.clone(), out)?;
    }
    let totals = match pass.outcome {
        Ok(totals) => totals,
        Err(StreamFailure::Plan(e)) => {
            return Err(crate::Failure::Input(vec![miette::miette!(
                code = e.code().to_string(),
                "{name}: {e}"
            )]))
        }
        Err(StreamFailure::Emit(e)) => return Err(crate::pipeline::emit_failure(e, options, None)),
    };
    let mut warnings = reports(path, name, pass.warnings);
    if options.format == pvt_emit::Format::Pmac {
        warnings.extend(crate::pipeline::fractional_ms_report(
            totals.fractional_ms,
            totals.segments,
        ));
    }
    Ok(warnings)
}

/// Plans and writes the program under `layout`; G-code errors fail the pass, a planning
/// or writing failure is returned in [`Pass::outcome`] with the layout found.
fn write_pass(
    path: &std::path::Path,
    name: &str,
    options: &crate::CompileOptions,
    gcode: &pvt_gcode::GcodeOptions,
    layout: &Layout,
    out: &mut Target<'_>,
) -> Result<Pass, crate::Failure> {
    let tolerance = options
        .tolerance
        .unwrap_or(layout.units.from_mm(ChordTolerance::DEFAULT_MM));
    let tolerance =
        ChordTolerance::new(tolerance).expect("the CLI accepts only positive tolerances");
    let emit_options = pvt_emit::EmitOptions {
        source: name.to_owned(),
        settings: crate::pipeline::settings(options, layout.units),
        program_number: 1,
    };
    let buffered = std::io::BufWriter::with_capacity(1 << 16, out);
    let mut writer = Checked::new(options.format.writer(buffered));
    let header = pvt_emit::Header {
        axes: &layout.axes,
        units: layout.units,
        interpolation: pvt_core::Interpolation::Pvt,
        options: &emit_options,
    };
    let begun = writer.begin(&header);
    let mut sink = PlanningSink::new(
        writer,
        layout.axes.clone(),
        tolerance,
        options.format.max_piece_seconds(),
        crate::pipeline::split_grid(options),
    );
    if let Err(e) = begun {
        sink.failure = Some(StreamFailure::Emit(e));
    }
    let summary = compile_read(path, name, gcode, &mut sink)?;
    let found = Layout {
        axes: sink.moved.axes(),
        units: summary.units,
    };
    let totals = sink.totals;
    Ok(Pass {
        layout: found,
        warnings: summary.warnings,
        outcome: sink.finish().map(|_| totals),
    })
}
