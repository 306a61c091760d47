//! The one compile route of pvtc: every input kind goes into the same planning sink
//! ([`PlanningSink`]: pvt-core's [`PlanStage`]) and its pieces into the same writer
//! ([`WriterSink`]: the PMAC splitter and pvt-emit's [`Checked`] writer). G-code streams
//! from its file in bounded memory, whatever the program's length
//! ([`compile_streaming`]; the front end, the planner and the writer each on a thread
//! where [`crate::pipeline::threaded`] says so); a drawing, a series, or any source held
//! in memory is read whole by its front end and pushed into the same sink ([`compile`]).
//! [`compile_to`] is `pvtc compile`'s entry, single or batch; [`plan`] plans without
//! writing, for `check` and `plot`. Plan and emit errors become reports here, once.
//!
//! Owns the glue between the front ends, pvt-core's [`PlanStage`] and pvt-emit's
//! [`Checked`] writer, and the notes on what planning did. It must not parse, plan,
//! format or apply a default: each of those stays in its crate, and every default in
//! [`crate::settings`].

use crate::front::{self, Input};
use crate::options::{at_line, CompileOptions, Failure, InputKind, Source, VelocitySource};
use crate::output::Target;
use crate::pipeline::PieceWriter;
use crate::settings::{emit_options, header_lines, plan_options, split_grid};
use miette::{Report, Severity};
use pvt_core::{
    plan::PlanError, plan_timed, plan_toolpath_report, Axis, Element, EventKind, Motion, PieceSink,
    PieceSplitter, PlanOptions, PlanReport, PlanStage, Planned, Planner, ProgramEvent, PvtContour,
    PvtProgram, SegmentRef, Timing, Toolpath, ToolpathSink, Units,
};
use pvt_emit::writer::Totals;
use pvt_emit::{Checked, Format, PieceLine, PieceLines, ProgramWriter, StreamError};
use std::path::PathBuf;

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
    /// The program written, piece by piece, when it is kept ([`compile`]).
    kept: Option<PvtProgram>,
}

impl<W: ProgramWriter> PieceSink for WriterSink<W> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        if self.error.is_none() {
            self.error = self.writer.contour(motion, start, line).err();
        }
        if let Some(program) = self.kept.as_mut() {
            program
                .contours
                .push(PvtContour::new(motion, start.to_vec()));
        }
        if let Some(splitter) = self.splitter.as_mut() {
            splitter.start(start);
        }
    }

    fn piece(&mut self, seg: &SegmentRef<'_>) {
        self.write_piece(seg, None);
    }

    fn event(&mut self, event: &ProgramEvent) {
        if self.error.is_none() {
            self.error = self.writer.event(event).err();
        }
        if let Some(program) = self.kept.as_mut() {
            program.events.push(event.clone());
        }
    }
}

impl<W: ProgramWriter> PieceWriter for WriterSink<W> {
    fn piece_lines(&self) -> Option<PieceLines> {
        self.writer.piece_lines()
    }

    fn piece_with_line(&mut self, piece: &SegmentRef<'_>, line: PieceLine<'_>) {
        self.write_piece(piece, Some(line));
    }
}

impl<W: ProgramWriter> WriterSink<W> {
    /// Writes `seg` through the splitter, with its `line` where one was written ahead
    /// and the splitter passes the piece whole (a piece it cuts is written part by part).
    #[inline]
    fn write_piece(&mut self, seg: &SegmentRef<'_>, line: Option<PieceLine<'_>>) {
        let (writer, totals, error) = (&mut self.writer, &mut self.totals, &mut self.error);
        let mut kept = self.kept.as_mut().and_then(|p| p.contours.last_mut());
        let mut write = |piece: &SegmentRef<'_>, line: Option<PieceLine<'_>>| {
            match line {
                Some(line) => totals.add_printed_segment(piece.duration, line.whole_ms),
                None => totals.add_segment(piece.duration),
            }
            if let Some(contour) = kept.as_mut() {
                contour.push(piece.end, piece.velocity, piece.duration, piece.line);
            }
            if error.is_none() {
                let written = match line {
                    Some(line) => writer.segment_with_line(piece, line),
                    None => writer.segment(piece),
                };
                if let Err(e) = written {
                    *error = Some(e);
                }
            }
        };
        match self.splitter.as_mut() {
            Some(splitter) if line.is_some() && splitter.passes_whole(seg) => {
                splitter.push(seg, &mut |piece| write(piece, line))
            }
            Some(splitter) => splitter.push(seg, &mut |piece| write(piece, None)),
            None => write(seg, line),
        }
    }

    /// A sink writing into `writer` (already begun), cutting pieces longer than
    /// `max_piece` seconds along their cubic (on `grid` where their time is on it), and
    /// keeping the program written into `kept` when it is given.
    fn new(
        writer: Checked<W>,
        max_piece: Option<f64>,
        grid: Option<f64>,
        kept: Option<PvtProgram>,
    ) -> WriterSink<W> {
        WriterSink {
            writer,
            totals: Totals::default(),
            splitter: max_piece.map(|max| PieceSplitter::new(max, grid)),
            error: None,
            kept,
        }
    }

    /// Ends the program the planner ended with `planned` (its report, or its first
    /// error): the back end, the totals, the report and the program kept (empty when
    /// none is), or the first failure, the planner's before the writer's.
    fn end(
        self,
        planned: Result<PlanReport, PlanError>,
    ) -> Result<(W, Totals, PlanReport, PvtProgram), StreamFailure> {
        let report = planned.map_err(StreamFailure::Plan)?;
        if let Some(e) = self.error {
            return Err(StreamFailure::Emit(e));
        }
        let writer = self.writer.finish().map_err(StreamFailure::Emit)?;
        let kept = self.kept.unwrap_or_else(|| PvtProgram {
            axes: Vec::new(),
            units: Units::default(),
            interpolation: pvt_core::Interpolation::Pvt,
            contours: Vec::new(),
            events: Vec::new(),
        });
        Ok((writer, self.totals, report, kept))
    }
}

/// The sink the planner hands its pieces to: a [`WriterSink`] on the planner's thread,
/// or the hand-over to the writer's ([`crate::pipeline::planner_aside`]). Every route
/// plans into this one type, so that the planner's code exists once in the program.
pub struct Outlet<'a>(pub &'a mut dyn PieceSink);

impl PieceSink for Outlet<'_> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        self.0.contour(motion, start, line);
    }
    fn piece(&mut self, piece: &SegmentRef<'_>) {
        self.0.piece(piece);
    }
    fn event(&mut self, event: &ProgramEvent) {
        self.0.event(event);
    }
}

/// A G-code sink that plans as elements arrive: pvt-core's [`PlanStage`] into an
/// [`Outlet`], noting the axes the elements move.
pub struct PlanningSink<'a> {
    stage: PlanStage<Outlet<'a>>,
    /// The axes the elements moved, to check the header's axes against.
    moved: MovedAxes,
}

impl<'a> PlanningSink<'a> {
    /// A sink planning with `options` on `axes` into `sink`.
    pub fn new(
        sink: &'a mut dyn PieceSink,
        axes: Vec<Axis>,
        options: PlanOptions,
    ) -> Result<PlanningSink<'a>, PlanError> {
        Ok(PlanningSink {
            stage: PlanStage::new(axes, options, Outlet(sink))?,
            moved: MovedAxes::default(),
        })
    }

    /// Ends the plan (the open contour's pieces go to the sink): the axes moved, and the
    /// plan's report or its first error.
    pub fn end(self) -> (MovedAxes, Result<PlanReport, PlanError>) {
        (self.moved, self.stage.finish().map(|(_, report)| report))
    }
}

impl ToolpathSink for PlanningSink<'_> {
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

/// Opens `path` for reading through a buffer of 64 KiB: a read of that size takes a
/// negligible share of a line's parsing, and a larger buffer is resident for the whole
/// compile.
pub(crate) fn open(path: &std::path::Path) -> Result<std::io::BufReader<std::fs::File>, Failure> {
    std::fs::File::open(path)
        .map(|f| std::io::BufReader::with_capacity(1 << 16, f))
        .map_err(|error| read_failure(path, error))
}

pub(crate) fn read_failure(path: &std::path::Path, error: std::io::Error) -> Failure {
    Failure::Io {
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
/// The front end runs on a thread of its own where [`crate::pipeline::threaded`] says
/// so, `sink` always on this one; the pass is counted on this thread either way.
pub(crate) fn compile_read(
    path: &std::path::Path,
    name: &str,
    gcode: &pvt_gcode::GcodeOptions,
    sink: &mut dyn pvt_gcode::ToolpathSink,
) -> Result<pvt_gcode::StreamSummary, Failure> {
    let read = front_end(path, gcode)?;
    let read = match crate::pipeline::threaded() {
        true => crate::pipeline::in_two_threads(read, sink),
        false => read(sink),
    };
    read_summary(path, name, read)
}

/// What the G-code front end returns from a pass.
type FrontEnd = std::io::Result<Result<pvt_gcode::StreamSummary, pvt_gcode::GcodeErrors>>;

/// One pass of the G-code front end over the file, opened and counted, ready to run
/// into the sink it is given, on whichever thread.
fn front_end<'a>(
    path: &std::path::Path,
    gcode: &'a pvt_gcode::GcodeOptions,
) -> Result<impl FnOnce(&mut dyn pvt_gcode::ToolpathSink) -> FrontEnd + Send + 'a, Failure> {
    PASSES.with(|passes| passes.set(passes.get() + 1));
    let mut input = open(path)?;
    Ok(move |sink: &mut dyn pvt_gcode::ToolpathSink| {
        pvt_gcode::compile_read(&mut input, gcode, sink)
    })
}

/// A front end's pass: its summary, or its read failure or G-code errors as reports.
fn read_summary(
    path: &std::path::Path,
    name: &str,
    read: FrontEnd,
) -> Result<pvt_gcode::StreamSummary, Failure> {
    read.map_err(|error| read_failure(path, error))?
        .map_err(|errors| Failure::Input(reports(path, name, errors.diagnostics)))
}

/// What a pass planned: the front end's summary, the axes the elements moved, and the
/// planner's report or first error.
type Streamed = (
    pvt_gcode::StreamSummary,
    MovedAxes,
    Result<PlanReport, PlanError>,
);

/// One pass over the file: the front end into the planner with `options` on `axes`, its
/// pieces into `writer`; what it planned, or (inner) the planner's refusal of `options`,
/// before the file is read. Where [`crate::pipeline::threaded`] says so, the planner
/// runs on a thread of its own, the front end and `writer` on this one
/// ([`crate::pipeline::planner_aside`]), with the calls, pieces and failures of one
/// thread.
fn stream_pass(
    path: &std::path::Path,
    name: &str,
    gcode: &pvt_gcode::GcodeOptions,
    writer: &mut dyn PieceWriter,
    axes: &[Axis],
    options: PlanOptions,
) -> Result<Result<Streamed, PlanError>, Failure> {
    if let Err(e) = pvt_core::plan::check_options(&options) {
        return Ok(Err(e));
    }
    let read = front_end(path, gcode)?;
    let plan = |pieces: &mut dyn PieceSink, calls: crate::pipeline::Calls<'_>| {
        plan_calls(pieces, calls, axes, &options)
    };
    let threaded = match crate::pipeline::threaded() {
        true => crate::pipeline::planner_aside(read, plan, axes.len(), writer),
        false => Err(read),
    };
    let (read, (moved, planned)) = match threaded {
        Ok(streamed) => streamed,
        // On this thread alone (where no thread started, nothing ran).
        Err(read) => {
            let (mut read, mut result) = (Some(read), None);
            let planned = plan(writer, &mut |sink| {
                if let Some(read) = read.take() {
                    result = Some(read(sink));
                }
            });
            (result.expect("plan_calls makes the calls"), planned)
        }
    };
    Ok(Ok((read_summary(path, name, read)?, moved, planned)))
}

/// Plans the front end's `calls` with `options` on `axes` into `pieces`: the axes the
/// elements moved, and the plan's report or first error. The calls are made whatever
/// the plan: where the options are refused (which [`pvt_core::plan::check_options`]
/// has ruled out before), the front end still runs, its elements only noted.
fn plan_calls(
    pieces: &mut dyn PieceSink,
    calls: crate::pipeline::Calls<'_>,
    axes: &[Axis],
    options: &PlanOptions,
) -> (MovedAxes, Result<PlanReport, PlanError>) {
    match PlanningSink::new(pieces, axes.to_vec(), options.clone()) {
        Ok(mut planning) => {
            calls(&mut planning);
            planning.end()
        }
        Err(e) => {
            let mut moved = MovedAxes::default();
            calls(&mut moved);
            (moved, Err(e))
        }
    }
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
fn plan_failure(path: &std::path::Path, name: &str, e: &PlanError) -> Failure {
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
    Failure::Input(vec![report])
}

/// What the header fixes before the first piece is written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    pub(crate) axes: Vec<Axis>,
    pub(crate) units: pvt_core::Units,
}

impl Layout {
    /// The layout a [`pvt_gcode::Prescan`] suggests under `gcode`'s units option.
    pub(crate) fn guess(prescan: &pvt_gcode::Prescan, gcode: &pvt_gcode::GcodeOptions) -> Layout {
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
pub(crate) struct Pass {
    /// The layout the program really has.
    pub(crate) layout: Layout,
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
    options: &CompileOptions,
    deny_warnings: bool,
    out: &mut Target<'_>,
) -> Result<Vec<miette::Report>, Failure> {
    if options.input == InputKind::Gcode {
        let input = crate::input::spool(input)?;
        return compile_streaming(&input.path, &input.name, options, deny_warnings, out);
    }
    let source = Source::read(input)?;
    let compiled = compile_whole(&source, options, false)?;
    let warnings = crate::report::deny(compiled.warnings, deny_warnings)?;
    std::io::Write::write_all(out, &compiled.bytes).map_err(|error| Failure::Io {
        path: "<output>".into(),
        action: "write",
        error,
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
/// is such a file. The command line gives a stream (a pipe, a terminal) a temporary file
/// to fill in its place ([`crate::output::write_stream`]); into a stream itself
/// ([`Target::Stream`], where no temporary file can be made), which cannot start over,
/// a first pass plans and checks the program as the back end would without making its
/// text, finding them, and a second writes.
pub fn compile_streaming(
    path: &std::path::Path,
    name: &str,
    options: &CompileOptions,
    deny_warnings: bool,
    out: &mut Target<'_>,
) -> Result<Vec<miette::Report>, Failure> {
    if out.is_file_at(path) {
        return Err(Failure::Usage(format!(
            "standard output is the input file {}: pvtc would read what it writes",
            path.display()
        )));
    }
    let gcode = crate::front::gcode_options(options);
    let prescan = pvt_gcode::prescan(&mut open(path)?).map_err(|e| read_failure(path, e))?;
    let mut layout = Layout::guess(&prescan, &gcode);
    if !out.can_restart() {
        // A stream cannot start over: a first pass plans and checks the whole program
        // (every refusal of the back end's, without its text), so that a pipe never
        // receives a program that an error, or a warning under --deny-warnings, would
        // cut short. It finds the axes and units too (checking again under them when the
        // prescan guessed otherwise).
        let mut check = write_pass(path, name, options, &gcode, &layout, Out::Checks)?;
        if check.layout != layout {
            layout = check.layout.clone();
            check = write_pass(path, name, options, &gcode, &layout, Out::Checks)?;
        }
        crate::report::deny(outcome_warnings(path, name, options, check)?, deny_warnings)?;
    }
    let mut pass = write_pass(path, name, options, &gcode, &layout, Out::Text(out))?;
    if pass.layout != layout {
        let restart = |error| Failure::Io {
            path: "<output>".into(),
            action: "rewrite",
            error,
        };
        out.restart().map_err(restart)?;
        pass = write_pass(
            path,
            name,
            options,
            &gcode,
            &pass.layout.clone(),
            Out::Text(out),
        )?;
    }
    crate::report::deny(outcome_warnings(path, name, options, pass)?, deny_warnings)
}

/// What a pass ended with: its warnings, notes and summary, or its failure.
pub(crate) fn outcome_warnings(
    path: &std::path::Path,
    name: &str,
    options: &CompileOptions,
    pass: Pass,
) -> Result<Vec<miette::Report>, Failure> {
    let (totals, report) = match pass.outcome {
        Ok(done) => done,
        Err(StreamFailure::Plan(e)) => return Err(plan_failure(path, name, &e)),
        Err(StreamFailure::Emit(e)) => return Err(emit_failure(e, options, None)),
    };
    let mut warnings = reports(path, name, pass.warnings);
    warnings.extend(plan_notes(&report, options));
    warnings.extend(summary_note(&report, &totals, pass.layout.units));
    if options.format == pvt_emit::Format::Pmac {
        warnings.extend(fractional_ms_report(totals.fractional_ms, totals.segments));
    }
    Ok(warnings)
}

/// Where a pass's pieces go, behind the format's checks ([`Checked`]).
pub(crate) enum Out<'o, 't> {
    /// The format's text, into a target.
    Text(&'o mut Target<'t>),
    /// Nowhere: the format's checks alone ([`pvt_emit::Unwritten`]).
    Checks,
    /// A back end of the caller's (the pieces kept as arrays: [`crate::embed`]),
    /// checked as the format's writer would be ([`pvt_emit::Collected`]).
    Into(Box<dyn ProgramWriter + 'o>),
}

/// Plans and writes the program under `layout` into `out` (its text, its checks alone, or
/// a caller's back end); G-code errors fail the pass, a planning or writing failure is
/// returned in [`Pass::outcome`] with the layout found.
pub(crate) fn write_pass(
    path: &std::path::Path,
    name: &str,
    options: &CompileOptions,
    gcode: &pvt_gcode::GcodeOptions,
    layout: &Layout,
    out: Out<'_, '_>,
) -> Result<Pass, Failure> {
    let plan_options = plan_options(options, layout.units, &layout.axes)?;
    check_pmac_axes(options, &layout.axes)?;
    let interpolation = plan_options.interpolation();
    let emit_options = emit_options(
        options,
        name,
        header_lines(options, layout.units),
        layout.units,
    );
    let back_end = match out {
        Out::Text(out) => options
            .format
            .writer(std::io::BufWriter::with_capacity(1 << 16, out)),
        Out::Checks => Box::new(pvt_emit::Unwritten(options.format.writer(std::io::sink()))),
        Out::Into(into) => Box::new(pvt_emit::Collected {
            format: options.format.writer(std::io::sink()),
            into,
        }),
    };
    let mut writer = Checked::new(back_end);
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
    let mut writer = WriterSink::new(writer, max_piece, split_grid(options), None);
    let streamed = stream_pass(path, name, gcode, &mut writer, &layout.axes, plan_options)?;
    let (summary, moved, planned) = match streamed {
        Ok(streamed) => streamed,
        Err(e) => return Ok(failed(StreamFailure::Plan(e))),
    };
    let found = Layout {
        axes: moved.axes(),
        units: summary.units,
    };
    Ok(Pass {
        layout: found,
        warnings: summary.warnings,
        outcome: writer
            .end(planned)
            .map(|(_, totals, report, _)| (totals, report)),
    })
}

/// Refuses PMAC axis definitions that leave a moved axis undefined
/// (`pvtc::pmac::undefined_axis`): the controller would not move it.
fn check_pmac_axes(options: &CompileOptions, moved: &[pvt_core::Axis]) -> Result<(), Failure> {
    if options.format != Format::Pmac {
        return Ok(());
    }
    let missing = options.pmac.undefined_axes(moved);
    if missing.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = missing.iter().map(|a| a.to_string()).collect();
    Err(Failure::Input(vec![miette::miette!(
        code = "pvtc::pmac::undefined_axis",
        help = "add a definition like --pmac-axis '#3->1000Z' for each, or leave out --pmac-axis",
        "the program moves {} but no --pmac-axis defines {}",
        names.join(" "),
        if names.len() == 1 { "it" } else { "them" },
    )]))
}

/// A successful compilation.
#[derive(Debug)]
pub struct Compiled {
    /// The output, exactly as it is to be written.
    pub bytes: Vec<u8>,
    /// The planned program.
    pub program: PvtProgram,
    /// The geometry the program was planned from (for checking and plotting).
    pub toolpath: Toolpath,
    /// What planning changed.
    pub report: PlanReport,
    /// Warnings, ready to print.
    pub warnings: Vec<Report>,
}

/// Reads `source` whole with its front end, `--velocities` applied to a series.
fn read_whole(source: &Source, options: &CompileOptions) -> Result<(Input, Vec<Report>), Failure> {
    let (mut input, mut warnings) = front::read(source, options)?;
    if let Input::Series(series) = &mut input {
        warnings.extend(choose_velocities(&mut series.points, options)?);
    }
    Ok((input, warnings))
}

/// Reads and plans `source` into a program, without writing any format: the same front
/// end and stage as [`compile`], into pvt-core's collector (`check`, `plot`).
pub fn plan(
    source: &Source,
    options: &CompileOptions,
) -> Result<(Planned, Toolpath, Vec<Report>), Failure> {
    let (input, mut warnings) = read_whole(source, options)?;
    let moved = match &input {
        Input::Toolpath(t) => t.moved_axes(),
        Input::Series(s) => s.axes.clone(),
    };
    let plan_options = plan_options(options, input.units(), &moved)?;
    let (planned, toolpath) = match input {
        Input::Toolpath(toolpath) => (plan_toolpath_report(&toolpath, &plan_options), toolpath),
        Input::Series(series) => (
            plan_timed(
                &series.points,
                series.axes.clone(),
                series.units,
                &plan_options,
            ),
            series.toolpath(),
        ),
    };
    let planned = planned.map_err(|e| plan_failure_in(source, &e))?;
    warnings.extend(plan_notes(&planned.report, options));
    Ok((planned, toolpath, warnings))
}

/// A planning error as a report labelling its whole line of `source`.
fn plan_failure_in(source: &Source, e: &PlanError) -> Failure {
    let report = if e.line() == 0 {
        miette::miette!(code = e.code().to_string(), "{e}")
    } else {
        at_line(e.code(), &e.to_string(), e.line(), source).with_source_code(source.named_text())
    };
    Failure::Input(vec![report])
}

/// Applies `--velocities` to a series: drops its velocity columns for `plan` (with a
/// note), refuses `file` when it has none or the planner takes no velocities, and says
/// which velocities a velocity method uses, and when a planner replaces the series' times.
fn choose_velocities(
    points: &mut pvt_core::TimedPoints,
    options: &CompileOptions,
) -> Result<Vec<Report>, Failure> {
    let planner = options.planner;
    let name = planner.name();
    let given = points.velocities.is_some();
    let mut notes = Vec::new();
    match options.velocities {
        Some(VelocitySource::Plan) if given => {
            points.velocities = None;
            notes.push(miette::miette!(
                severity = Severity::Advice,
                code = "pvtc::plan::velocity_columns_ignored",
                "the series' velocity columns are ignored (--velocities plan): the {name} planner chooses the velocities"
            ));
        }
        Some(VelocitySource::File) if !given => {
            return Err(Failure::Usage(
                "--velocities file: the series has no velocity columns (v<axis>, e.g. vx)".into(),
            ));
        }
        Some(VelocitySource::File) if !planner.is_velocity_method() => {
            return Err(Failure::Usage(format!(
                "--velocities file does nothing with the {name} planner, which chooses its own \
                 velocities: use chord-forward, chord-back, const-accel or spline"
            )));
        }
        None if given && planner.is_velocity_method() => notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::file_velocities",
            help = format!("pass --velocities plan to use the {name} method's velocities instead"),
            "the velocities are the series' velocity columns, as given, not the {name} method's"
        )),
        _ => {}
    }
    if matches!(planner, Planner::Contour | Planner::Path) {
        notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::times_replaced",
            help = "pt, chord-forward, chord-back, const-accel and spline keep the series' times",
            "the {name} planner chooses its own piece times: the series' times only set each segment's speed (chord / time)"
        ));
    }
    Ok(notes)
}

/// What the path planner achieved, for standard error: pieces, the path error bound and
/// the total time against the time at the feeds; `None` for the other planners.
fn summary_note(report: &PlanReport, totals: &Totals, units: Units) -> Option<Report> {
    let error = report.path_error?;
    // A point series has no feed to compare with: its pieces come from the points.
    let ratio = match report.feed_time > 0.0 {
        true => format!(" ({:.3} x length / feed)", totals.time / report.feed_time),
        false => String::new(),
    };
    Some(miette::miette!(
        severity = Severity::Advice,
        code = "pvtc::plan::summary",
        "{} pieces; path error at most {error:.6} {}; total time {:.4} s{ratio}",
        totals.segments,
        units.name(),
        totals.time
    ))
}

/// Compiles `source`, held in memory, into the bytes of `options.format`, keeping the
/// program written.
pub fn compile(source: &Source, options: &CompileOptions) -> Result<Compiled, Failure> {
    compile_whole(source, options, true)
}

/// The route of a source read whole: its front end's toolpath or series pushed into the
/// planning sink, written into memory (so that a failure or `--deny-warnings` leaves the
/// target untouched), the program kept when `keep`.
fn compile_whole(
    source: &Source,
    options: &CompileOptions,
    keep: bool,
) -> Result<Compiled, Failure> {
    let (input, mut warnings) = read_whole(source, options)?;
    let (axes, units) = match &input {
        Input::Toolpath(t) => (t.moved_axes(), t.units),
        Input::Series(s) => (s.axes.clone(), s.units),
    };
    let plan_options = whole_plan_options(&input, options, units, &axes, source)?;
    let interpolation = plan_options.interpolation();
    let emit_options = emit_options(options, &source.name, header_lines(options, units), units);
    let mut bytes = Vec::new();
    let mut writer = Checked::new(options.format.writer(&mut bytes));
    let header = pvt_emit::Header {
        axes: &axes,
        units,
        interpolation,
        options: &emit_options,
    };
    let begun = writer.begin(&header);
    let (max_piece, grid) = (options.format.max_piece_seconds(), split_grid(options));
    let kept = keep.then(|| PvtProgram {
        axes: axes.clone(),
        units,
        interpolation,
        contours: Vec::new(),
        events: Vec::new(),
    });
    let mut sink = WriterSink::new(writer, max_piece, grid, kept);
    let mut planning = PlanningSink::new(&mut sink, axes.clone(), plan_options)
        .map_err(|e| plan_failure_in(source, &e))?;
    push_whole(&input, &mut planning);
    let (_, planned) = planning.end();
    // The writer (which borrows `bytes`) is dropped here.
    let finished = sink
        .end(planned)
        .map(|(_, totals, report, program)| (totals, report, program));
    let (totals, report, program) = match finished {
        Err(StreamFailure::Plan(e)) => return Err(plan_failure_in(source, &e)),
        Ok((totals, report, program)) => (totals, report, Ok(program)),
        Err(StreamFailure::Emit(e)) => (Totals::default(), PlanReport::default(), Err(e)),
    };
    check_pmac_axes(options, &axes)?;
    begun.map_err(|e| emit_failure(e, options, Some(source)))?;
    let program = program.map_err(|e| emit_failure(e, options, Some(source)))?;
    warnings.extend(whole_notes(&report, &totals, units, options));
    Ok(Compiled {
        bytes,
        program,
        toolpath: match input {
            Input::Toolpath(toolpath) => toolpath,
            Input::Series(series) => series.toolpath(),
        },
        report,
        warnings,
    })
}

/// The planner's options for an input read whole: a series is timed by its own times
/// and checked as `pvt_core::plan_timed` checks it (finite points, positive times, one
/// coordinate per axis).
fn whole_plan_options(
    input: &Input,
    options: &CompileOptions,
    units: Units,
    axes: &[Axis],
    source: &Source,
) -> Result<PlanOptions, Failure> {
    let mut plan_options = plan_options(options, units, axes)?;
    if let Input::Series(series) = input {
        plan_options.timing = Timing::FromFeed;
        let failed = |e: PlanError| plan_failure_in(source, &e);
        series.points.validate().map_err(failed)?;
        if axes.len() != series.points.dim {
            return Err(failed(PlanError::BadShape));
        }
    }
    Ok(plan_options)
}

/// Pushes an input read whole into the planning sink: a toolpath by the one traversal,
/// a series point by point.
fn push_whole(input: &Input, sink: &mut PlanningSink<'_>) {
    match input {
        Input::Toolpath(toolpath) => pvt_core::traverse::replay(toolpath, sink),
        Input::Series(series) => sink.stage.timed_points(&series.points),
    }
}

/// The notes on a program read whole: what planning changed, the path planner's
/// summary and, for PMAC without a quantum, the piece times that are not whole ms.
fn whole_notes(
    report: &PlanReport,
    totals: &Totals,
    units: Units,
    options: &CompileOptions,
) -> Vec<Report> {
    let mut notes = plan_notes(report, options);
    notes.extend(summary_note(report, totals, units));
    if options.format == Format::Pmac && options.quantize.is_none() {
        notes.extend(fractional_ms_report(totals.fractional_ms, totals.segments));
    }
    notes
}

/// A back end's refusal as a failure; `source` (when known) labels the line at fault.
fn emit_failure(e: StreamError, options: &CompileOptions, source: Option<&Source>) -> Failure {
    match e {
        StreamError::Invalid(invalid) => {
            let report = match source {
                Some(source) => at_line(
                    invalid.code,
                    &invalid.to_string(),
                    invalid.line,
                    source,
                )
                .with_source_code(source.named_text()),
                None => miette::miette!(code = invalid.code, "{invalid}"),
            };
            Failure::Input(vec![report])
        }
        StreamError::Io(error) => Failure::Io {
            path: PathBuf::from("<output>"),
            action: "write",
            error,
        },
        StreamError::NoTriggers(..) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::no_triggers",
            help = "leave out --trigger-every, or write pmac, powerpmac, zaber, json or csv",
            "{e}"
        )]),
        StreamError::MissingScale(..) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::no_scale",
            help = "give --counts-per-unit AXIS=N for each moved axis, or counts_per_unit in the machine file's [axes.AXIS]",
            "{e}"
        )]),
        StreamError::Unsupported(interpolation) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::unsupported_interpolation",
            help =
                "PMAC PVT mode needs velocities: choose a PVT planner, or --format movepvt (MovePT arrays) or json",
            "the {} format cannot express {interpolation:?} motion",
            options.format.name()
        )]),
    }
}

/// The warning for `fractional` of `segments` piece times that are not whole ms.
fn fractional_ms_report(fractional: usize, segments: usize) -> Option<Report> {
    (fractional > 0).then(|| {
        miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::emit::fractional_ms",
            help = "pass --quantize 1ms to make every piece time whole while keeping the path",
            "{fractional} of {segments} piece times are not whole milliseconds; PMAC rounds TA to whole ms, which changes speeds and times"
        )
    })
}

/// Notes on what planning changed (quantization, lengthened blends, ignored velocities).
fn plan_notes(report: &PlanReport, options: &CompileOptions) -> Vec<Report> {
    let mut notes = Vec::new();
    if let Some(q) = options.quantize {
        notes.push(miette::miette!(
            severity = Severity::Advice,
            code = "pvtc::plan::quantized",
            "piece times made whole multiples of {} ms (rounded {}); largest change of mid-segment speed: {:.4} %",
            q * 1000.0,
            crate::settings::rounding_words(options.quantize_rounding),
            report.quantize_speed_change * 100.0
        ));
    }
    if report.lengthened_segments > 0 {
        notes.push(miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::plan::lengthened",
            "{} segments were too short for their blends at --accel; their times were raised",
            report.lengthened_segments
        ));
    }
    if report.velocities_ignored {
        notes.push(miette::miette!(
            severity = Severity::Warning,
            code = "pvtc::plan::velocities_ignored",
            help = "--velocities plan ignores the velocity columns without a warning",
            "the input gives velocities, which the {} planner does not use",
            options.planner.name()
        ));
    }
    notes
}

/// What makes a planned program's calls again into a checked writer.
pub(crate) type Replay<'a> =
    dyn for<'w> FnMut(&mut Checked<Box<dyn ProgramWriter + 'w>>) -> Result<(), StreamError> + 'a;

/// The bytes `pvtc compile` writes in `options.format` for a program planned already
/// under the same options (its pieces kept as arrays, [`crate::embed`]): the header of
/// the source named `name`, then the calls `replay` makes into the checked writer, as
/// the planner made them.
pub(crate) fn write_planned(
    name: &str,
    options: &CompileOptions,
    (axes, units, interpolation): (&[Axis], Units, pvt_core::Interpolation),
    replay: &mut Replay<'_>,
) -> Result<Vec<u8>, Failure> {
    check_pmac_axes(options, axes)?;
    let emit_options = emit_options(options, name, header_lines(options, units), units);
    let mut bytes = Vec::new();
    let written = {
        let mut writer = Checked::new(options.format.writer(&mut bytes));
        let header = pvt_emit::Header {
            axes,
            units,
            interpolation,
            options: &emit_options,
        };
        writer.begin(&header).and_then(|()| {
            replay(&mut writer)?;
            writer.finish().map(|_| ())
        })
    };
    written.map_err(|e| emit_failure(e, options, None))?;
    Ok(bytes)
}
