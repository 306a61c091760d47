//! The route of `pvtc compile`, single or batch ([`compile_to`]), and its streaming path:
//! G-code elements go straight through pvt-core's [`PlanStage`] (every planner) into a
//! back end, in bounded memory, whatever the program's length; a drawing or a series goes
//! through the same stage into a collector, then to the same writer.
//!
//! Owns the glue between the G-code front end's sink interface, pvt-core's
//! [`PlanStage`] and pvt-emit's [`Checked`] writer. It must not parse, plan or format:
//! each of those stays in its crate, so the streamed output is byte-identical to the
//! in-memory path's.

use pvt_core::{
    plan::PlanError, Axis, Element, EventKind, Motion, PieceSink, PieceSplitter, PlanOptions,
    PlanReport, PlanStage, ProgramEvent, SegmentRef, ToolpathSink,
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

/// Where the plan stage's pieces go: through the splitter (PMAC's longest piece) into
/// the back end, counted; the first write error is kept and later pieces are dropped.
pub struct WriterSink<W: ProgramWriter> {
    writer: Checked<W>,
    /// Segments written, their time, and those whose time is not a whole millisecond.
    pub totals: Totals,
    splitter: Option<PieceSplitter>,
    error: Option<StreamError>,
}

impl<W: ProgramWriter> PieceSink for WriterSink<W> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        if self.error.is_none() {
            self.error = self.writer.contour(motion, start, line).err();
        }
        if let Some(splitter) = self.splitter.as_mut() {
            splitter.start(start);
        }
    }

    fn piece(&mut self, seg: &SegmentRef<'_>) {
        let (writer, totals, error) = (&mut self.writer, &mut self.totals, &mut self.error);
        let mut write = |piece: &SegmentRef<'_>| {
            totals.add_segment(piece.duration);
            if error.is_none() {
                *error = writer.segment(piece).err();
            }
        };
        match self.splitter.as_mut() {
            Some(splitter) => splitter.push(seg, &mut write),
            None => write(seg),
        }
    }

    fn event(&mut self, event: &ProgramEvent) {
        if self.error.is_none() {
            self.error = self.writer.event(event).err();
        }
    }
}

/// A G-code sink that plans and writes as elements arrive: pvt-core's [`PlanStage`] into
/// a [`WriterSink`], noting the axes the elements move.
pub struct PlanningSink<W: ProgramWriter> {
    stage: PlanStage<WriterSink<W>>,
    /// The axes the elements moved, to check the header's axes against.
    moved: MovedAxes,
}

impl<W: ProgramWriter> PlanningSink<W> {
    /// A sink planning with `options` on `axes` into `writer` (already begun), cutting
    /// pieces longer than `max_piece` seconds along their cubic (on `grid` where their
    /// time is on it).
    pub fn new(
        writer: Checked<W>,
        axes: Vec<Axis>,
        options: PlanOptions,
        max_piece: Option<f64>,
        grid: Option<f64>,
    ) -> Result<PlanningSink<W>, PlanError> {
        let sink = WriterSink {
            writer,
            totals: Totals::default(),
            splitter: max_piece.map(|max| PieceSplitter::new(max, grid)),
            error: None,
        };
        Ok(PlanningSink {
            stage: PlanStage::new(axes, options, sink)?,
            moved: MovedAxes::default(),
        })
    }

    /// Ends the program: the back end, the totals and the plan report, or the first
    /// failure.
    pub fn finish(self) -> Result<(W, Totals, PlanReport), StreamFailure> {
        let (sink, report) = self.stage.finish().map_err(StreamFailure::Plan)?;
        if let Some(e) = sink.error {
            return Err(StreamFailure::Emit(e));
        }
        let writer = sink.writer.finish().map_err(StreamFailure::Emit)?;
        Ok((writer, sink.totals, report))
    }
}

impl<W: ProgramWriter> ToolpathSink for PlanningSink<W> {
    fn element(&mut self, motion: Motion, element: &Element) {
        self.moved.note(element);
        self.stage.element(motion, element);
    }
    fn end_contour(&mut self) {
        self.stage.end_contour();
    }
    fn event(&mut self, event: &EventKind, line: u32) {
        self.stage.event(event, line);
    }
    fn path_tolerance(&mut self, tolerance: f64) {
        self.stage.path_tolerance(tolerance);
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

impl ToolpathSink for MovedAxes {
    fn element(&mut self, _: Motion, element: &Element) {
        self.note(element);
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &EventKind, _: u32) {}
}

fn open(
    path: &std::path::Path,
) -> Result<std::io::BufReader<std::fs::File>, crate::options::Failure> {
    std::fs::File::open(path)
        .map(|f| std::io::BufReader::with_capacity(1 << 18, f))
        .map_err(|error| read_failure(path, error))
}

fn read_failure(path: &std::path::Path, error: std::io::Error) -> crate::options::Failure {
    crate::options::Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    }
}

thread_local! {
    /// Passes of the G-code front end over an input run on this thread.
    static PASSES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// How many passes of the G-code front end over an input (each a parse, and a plan
/// where one is made) this thread has run: the evidence tests take of the route a
/// compile took (one pass into a file or the null device, two into a pipe).
pub fn front_end_passes() -> usize {
    PASSES.with(std::cell::Cell::get)
}

/// One pass of the G-code front end over the file into `sink`; its errors as reports.
pub(crate) fn compile_read(
    path: &std::path::Path,
    name: &str,
    gcode: &pvt_gcode::GcodeOptions,
    sink: &mut dyn pvt_gcode::ToolpathSink,
) -> Result<pvt_gcode::StreamSummary, crate::options::Failure> {
    PASSES.with(|passes| passes.set(passes.get() + 1));
    pvt_gcode::compile_read(&mut open(path)?, gcode, sink)
        .map_err(|error| read_failure(path, error))?
        .map_err(|errors| crate::options::Failure::Input(reports(path, name, errors.diagnostics)))
}

/// Diagnostics as reports, each with the lines of the file around it (read again, a
/// few lines kept per diagnostic, so memory stays flat however long the file).
pub(crate) fn reports(
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
            // An empty file still names its one line.
            None => miette::Report::new(d)
                .with_source_code(miette::NamedSource::new(name, String::new())),
        })
        .collect()
}

/// A planning error as a report labelling its whole source line, as the in-memory path
/// labels it ([`crate::options`]'s `at_line`), with the lines around it cut from the file.
fn plan_failure(path: &std::path::Path, name: &str, e: &PlanError) -> crate::options::Failure {
    let span = open(path).ok().and_then(|mut input| {
        crate::excerpt::line_span(&mut input, e.line())
            .ok()
            .flatten()
    });
    let excerpt = span.clone().and_then(|s| {
        let mut input = open(path).ok()?;
        crate::excerpt::cut(&mut input, &[s]).ok()?.pop().flatten()
    });
    let report = match (span, excerpt) {
        (Some(span), Some(excerpt)) if e.line() > 0 => miette::miette!(
            code = e.code().to_string(),
            labels = vec![miette::LabeledSpan::at(span, "this line")],
            "{e}"
        )
        .with_source_code(miette::NamedSource::new(name, excerpt)),
        _ => miette::miette!(code = e.code().to_string(), "{name}: {e}"),
    };
    crate::options::Failure::Input(vec![report])
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
    outcome: Result<(Totals, PlanReport), StreamFailure>,
}

/// Compiles the input at `input` (`-`: standard input) into `out` and returns its
/// warnings and notes: the one route of `pvtc compile`, single or batch.
///
/// G-code streams in bounded memory (standard input is spooled to a temporary file
/// first); a drawing or a point series is read whole and planned through the same stage
/// into a collector. With `deny_warnings`, a warning fails the run before anything is
/// written; a failure leaves `out` for the caller to discard.
pub fn compile_to(
    input: &std::path::Path,
    options: &crate::options::CompileOptions,
    deny_warnings: bool,
    out: &mut Target<'_>,
) -> Result<Vec<miette::Report>, crate::options::Failure> {
    if options.input == crate::options::InputKind::Gcode {
        let input = crate::input::spool(input)?;
        return compile_streaming(&input.path, &input.name, options, deny_warnings, out);
    }
    let source = crate::options::Source::read(input)?;
    let compiled = crate::settings::compile(&source, options)?;
    let warnings = deny(compiled.warnings, deny_warnings)?;
    std::io::Write::write_all(out, &compiled.bytes).map_err(|error| {
        crate::options::Failure::Io {
            path: "<output>".into(),
            action: "write",
            error,
        }
    })?;
    Ok(warnings)
}

/// Compiles the G-code file at `path` into `out` in constant memory and returns the
/// warnings; the bytes are those [`crate::compile`] gives.
///
/// The header needs the moved axes and the units before the first piece. Into a file
/// (an output file, or standard output redirected to one), a lexical
/// [`pvt_gcode::prescan`] guesses them and one pass plans and writes; when the compile
/// finds otherwise, the file is cut back and a second pass writes again. The null device
/// is such a file. Into a stream (a pipe, a terminal), which cannot start over, a first
/// pass plans into nothing, checking the program and finding them, and a second writes.
pub fn compile_streaming(
    path: &std::path::Path,
    name: &str,
    options: &crate::options::CompileOptions,
    deny_warnings: bool,
    out: &mut Target<'_>,
) -> Result<Vec<miette::Report>, crate::options::Failure> {
    if out.is_file_at(path) {
        return Err(crate::options::Failure::Usage(format!(
            "standard output is the input file {}: pvtc would read what it writes",
            path.display()
        )));
    }
    let gcode = crate::front::gcode_options(options);
    let prescan = pvt_gcode::prescan(&mut open(path)?).map_err(|e| read_failure(path, e))?;
    let mut layout = Layout::guess(&prescan, &gcode);
    if !out.can_restart() {
        // A stream cannot start over: a first pass plans the whole program into nothing,
        // so that a pipe never receives a program that an error, or a warning under
        // --deny-warnings, would cut short. It finds the axes and units too (checking
        // again under them when the prescan guessed otherwise).
        let mut nothing = std::io::sink();
        let mut null = Target::Stream(&mut nothing);
        let mut check = write_pass(path, name, options, &gcode, &layout, &mut null)?;
        if check.layout != layout {
            layout = check.layout.clone();
            check = write_pass(path, name, options, &gcode, &layout, &mut null)?;
        }
        deny(outcome_warnings(path, name, options, check)?, deny_warnings)?;
    }
    let mut pass = write_pass(path, name, options, &gcode, &layout, out)?;
    if pass.layout != layout {
        let restart = |error| crate::options::Failure::Io {
            path: "<output>".into(),
            action: "rewrite",
            error,
        };
        out.restart().map_err(restart)?;
        pass = write_pass(path, name, options, &gcode, &pass.layout.clone(), out)?;
    }
    deny(outcome_warnings(path, name, options, pass)?, deny_warnings)
}

/// The warnings, or, when any is a warning and `deny_warnings`, a failure holding them
/// (sources and labels kept) and one error saying nothing was written.
pub(crate) fn deny(
    warnings: Vec<miette::Report>,
    deny_warnings: bool,
) -> Result<Vec<miette::Report>, crate::options::Failure> {
    let is_warning = |r: &miette::Report| r.severity() == Some(miette::Severity::Warning);
    let count = warnings.iter().filter(|r| is_warning(r)).count();
    if !deny_warnings || count == 0 {
        return Ok(warnings);
    }
    let mut reports: Vec<miette::Report> = warnings.into_iter().filter(is_warning).collect();
    reports.push(miette::miette!(
        code = "pvtc::deny_warnings",
        "{count} warning(s) and --deny-warnings; nothing was written"
    ));
    Err(crate::options::Failure::Input(reports))
}

/// What a pass ended with: its warnings, notes and summary, or its failure.
fn outcome_warnings(
    path: &std::path::Path,
    name: &str,
    options: &crate::options::CompileOptions,
    pass: Pass,
) -> Result<Vec<miette::Report>, crate::options::Failure> {
    let (totals, report) = match pass.outcome {
        Ok(done) => done,
        Err(StreamFailure::Plan(e)) => return Err(plan_failure(path, name, &e)),
        Err(StreamFailure::Emit(e)) => return Err(crate::settings::emit_failure(e, options, None)),
    };
    let mut warnings = reports(path, name, pass.warnings);
    warnings.extend(crate::settings::plan_notes(&report, options));
    warnings.extend(crate::settings::summary_note(
        &report,
        &totals,
        pass.layout.units,
    ));
    if options.format == pvt_emit::Format::Pmac {
        warnings.extend(crate::settings::fractional_ms_report(
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
    options: &crate::options::CompileOptions,
    gcode: &pvt_gcode::GcodeOptions,
    layout: &Layout,
    out: &mut Target<'_>,
) -> Result<Pass, crate::options::Failure> {
    let plan_options = crate::settings::plan_options(options, layout.units, &layout.axes)?;
    crate::settings::check_pmac_axes(options, &layout.axes)?;
    let interpolation = plan_options.interpolation();
    let emit_options = crate::settings::emit_options(
        options,
        name,
        crate::settings::settings(options, layout.units),
        layout.units,
    );
    let buffered = std::io::BufWriter::with_capacity(1 << 16, out);
    let mut writer = Checked::new(options.format.writer(buffered));
    let header = pvt_emit::Header {
        axes: &layout.axes,
        units: layout.units,
        interpolation,
        options: &emit_options,
    };
    let failed = |failure| Pass {
        layout: layout.clone(),
        warnings: Vec::new(),
        outcome: Err(failure),
    };
    if let Err(e) = writer.begin(&header) {
        return Ok(failed(StreamFailure::Emit(e)));
    }
    let max_piece = options.format.max_piece_seconds();
    let grid = crate::settings::split_grid(options);
    let mut sink =
        match PlanningSink::new(writer, layout.axes.clone(), plan_options, max_piece, grid) {
            Ok(sink) => sink,
            Err(e) => return Ok(failed(StreamFailure::Plan(e))),
        };
    let summary = compile_read(path, name, gcode, &mut sink)?;
    let found = Layout {
        axes: sink.moved.axes(),
        units: summary.units,
    };
    Ok(Pass {
        layout: found,
        warnings: summary.warnings,
        outcome: sink.finish().map(|(_, totals, report)| (totals, report)),
    })
}
