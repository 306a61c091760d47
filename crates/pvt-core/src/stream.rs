//! The one planning path: a toolpath in program order in, planned pieces out.
//!
//! Owns the [`ToolpathSink`] a front end pushes elements, contour ends and events into,
//! the [`PieceSink`] a back end (or a collector) receives pieces from, and the
//! [`PlanStage`] between them, which holds only what its planner must look ahead over:
//! - `path`: a [`PathStream`] window of at most [`crate::plan::WINDOW_ELEMENTS`] elements
//!   (with quantization too: it puts each window's pieces on the grid itself);
//! - `contour`: seed 000's three-point [`ContourStream`] over the flattened points;
//! - the other planners, and contour with quantization (which re-times a whole
//!   contour): the open contour's elements, planned when it ends;
//! - a timed run (a point-time series pushed with [`PlanStage::timed_point`]): the whole
//!   run, planned with its own times when it ends, since the timed planners solve over
//!   every point (the C2 spline, LSPB's blends).
//!
//! [`plan_toolpath_report`], [`plan_toolpath`] and [`plan_timed`] are this stage with a
//! collecting sink; there is no second pipeline. The stage sits above the planners'
//! dispatch (`crate::plan`'s driver), which never names it. It must not parse or print.

use crate::axis::{Axis, Units};
use crate::discretize::{arc_positions, project};
use crate::plan::{
    plan_buffered, plan_run, ContourStream, PathStream, PlanError, PlanOptions, PlanReport,
    Planner, TimedPoints, Timing,
};
use crate::program::{PvtContour, PvtProgram, SegmentRef};
use crate::toolpath::{Contour, Element, ElementKind, EventKind, Motion, ProgramEvent, Toolpath};

/// Receives a toolpath in program order, one element at a time.
///
/// Elements between two [`ToolpathSink::end_contour`] calls form one rest-to-rest contour
/// and share one [`Motion`]; a rapid move is always followed by `end_contour`. An event
/// comes only with no contour open (the machine at rest).
pub trait ToolpathSink {
    /// The next move of the open contour (or the first of a new one).
    fn element(&mut self, motion: Motion, element: &Element);
    /// The open contour ends: the machine comes to rest.
    fn end_contour(&mut self);
    /// Something happens at rest, from source line `line`.
    fn event(&mut self, event: &EventKind, line: u32);
    /// The path tolerance (G-code's G64 P), program units, from the next contour on.
    fn path_tolerance(&mut self, _tolerance: f64) {}
    /// The path control mode (G-code's G61, G61.1, G64 P Q) from the next move on, for
    /// the record: planning follows it through contour ends and
    /// [`ToolpathSink::path_tolerance`].
    fn path_control(&mut self, _control: &crate::toolpath::PathControl) {}
}

/// Receives planned motion: contours of pieces, and events between them.
pub trait PieceSink {
    /// A contour starts at rest at `start` (its first element is on `line`).
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32);
    /// The next piece of the open contour.
    fn piece(&mut self, piece: &SegmentRef<'_>);
    /// An event at rest, before the next contour.
    fn event(&mut self, event: &ProgramEvent);
}

/// The open contour and what its planner holds of it.
enum Open {
    Path(Box<PathStream>),
    Points(Box<ContourStream>),
    Buffered(Contour),
    Timed(TimedPoints),
}

/// The planning stage: a [`ToolpathSink`] that plans as elements arrive and hands pieces
/// to a [`PieceSink`]. The first planning error stops it; later input is ignored.
pub struct PlanStage<S: PieceSink> {
    axes: Vec<Axis>,
    options: PlanOptions,
    sink: S,
    open: Option<(Open, Pending)>,
    contours: usize,
    report: PlanReport,
    error: Option<PlanError>,
    point: Vec<f64>,
}

/// A contour whose start is not yet handed on: a contour with no piece is left out.
struct Pending {
    motion: Motion,
    start: Vec<f64>,
    line: u32,
    started: bool,
}

impl<S: PieceSink> PlanStage<S> {
    /// A stage planning on `axes` with `options` into `sink`.
    pub fn new(axes: Vec<Axis>, options: PlanOptions, sink: S) -> Result<PlanStage<S>, PlanError> {
        crate::plan::check_options(&options)?;
        Ok(PlanStage {
            point: vec![0.0; axes.len()],
            axes,
            options,
            sink,
            open: None,
            contours: 0,
            report: PlanReport::default(),
            error: None,
        })
    }

    /// Ends the program: finishes any open contour; the sink and the report, or the
    /// first planning error.
    pub fn finish(mut self) -> Result<(S, PlanReport), PlanError> {
        self.close();
        match self.error {
            Some(e) => Err(e),
            None => Ok((self.sink, self.report)),
        }
    }

    fn begin(&mut self, motion: Motion, element: &Element) {
        let start = project(&element.start, &self.axes);
        let streams = self.options.quantize.is_none();
        let open = match self.options.planner {
            Planner::Path => Open::Path(Box::new(PathStream::new(
                &self.axes,
                &self.options.path_options(),
            ))),
            Planner::Contour if streams => Open::Points(Box::new(ContourStream::new(&start))),
            _ => Open::Buffered(Contour {
                motion,
                elements: Vec::new(),
            }),
        };
        let pending = Pending {
            motion,
            start,
            line: element.span.line,
            started: false,
        };
        self.open = Some((open, pending));
    }

    /// Pushes every point of a series ([`PlanStage::timed_point`]), each with the time of
    /// the piece that reaches it, its source line and any given velocity.
    pub fn timed_points(&mut self, points: &TimedPoints) {
        let dim = points.dim;
        for i in 0..points.len() {
            let (duration, line) = match i.checked_sub(1) {
                Some(k) => (points.durations[k], points.lines[k]),
                None => (0.0, points.line_of_point(0)),
            };
            let velocity = points
                .velocities
                .as_ref()
                .map(|v| &v[i * dim..(i + 1) * dim]);
            self.timed_point(points.point(i), duration, velocity, line);
        }
    }

    /// The next point of a timed run (a point-time series, e.g. a CSV row): reached
    /// `duration` seconds after the run's previous point (ignored for its first point),
    /// from source `line`, with the velocity the series gives there, if any (given at
    /// every point of a run or at none).
    ///
    /// A run is one rest-to-rest feed contour on the stage's axes. It ends like a contour
    /// ([`ToolpathSink::end_contour`], an event, an element or [`PlanStage::finish`]) and
    /// is then planned whole with its own times (see [`plan_timed`]), so the
    /// stage holds every point of it.
    pub fn timed_point(
        &mut self,
        position: &[f64],
        duration: f64,
        velocity: Option<&[f64]>,
        line: u32,
    ) {
        if self.error.is_some() {
            return;
        }
        if !matches!(self.open, Some((Open::Timed(_), _)) | None) {
            self.close();
        }
        let Some((Open::Timed(run), _)) = self.open.as_mut() else {
            let mut run = TimedPoints::start_at(position);
            run.velocities = velocity.map(<[f64]>::to_vec);
            let pending = Pending {
                motion: Motion::Feed,
                start: position.to_vec(),
                line,
                started: false,
            };
            self.open = Some((Open::Timed(run), pending));
            return;
        };
        if position.len() != run.dim {
            self.error = Some(PlanError::BadShape);
            return;
        }
        match (run.velocities.as_mut(), velocity) {
            (Some(given), Some(v)) if v.len() == run.dim => given.extend_from_slice(v),
            (None, None) => {}
            _ => {
                self.error = Some(PlanError::BadShape);
                return;
            }
        }
        run.push(position, duration, line);
    }

    /// Plans a whole timed run with its own times.
    fn plan_timed_run(&mut self, run: &TimedPoints) -> Result<PvtContour, PlanError> {
        run.validate()?;
        if run.dim != self.axes.len() {
            return Err(PlanError::BadShape);
        }
        plan_run(run, &self.options, Motion::Feed, &mut self.report)
    }

    /// Pushes one element into the open contour's planner.
    fn push(&mut self, element: &Element) -> Result<(), PlanError> {
        let Some((open, pending)) = self.open.as_mut() else {
            return Ok(());
        };
        let (sink, contours) = (&mut self.sink, &mut self.contours);
        let mut emit = |seg: &SegmentRef<'_>| hand_on(sink, contours, pending, seg);
        match open {
            Open::Path(stream) => stream.push(element, &mut emit),
            Open::Buffered(contour) => {
                contour.elements.push(*element);
                Ok(())
            }
            // Never open here: an element ends a timed run first.
            Open::Timed(_) => Ok(()),
            Open::Points(stream) => {
                let line = element.span.line;
                let ends = match &element.kind {
                    ElementKind::Line => vec![element.end],
                    ElementKind::Arc(arc) => {
                        arc_positions(arc, &element.start, &element.end, self.options.tolerance)
                    }
                    ElementKind::Bezier(bezier) => {
                        bezier.flatten(&element.start, &element.end, self.options.tolerance.get())
                    }
                };
                for p in ends {
                    for (slot, axis) in self.point.iter_mut().zip(&self.axes) {
                        *slot = p[axis.index()];
                    }
                    stream.push(&self.point, element.feed, line, &mut |seg| emit(&seg))?;
                }
                Ok(())
            }
        }
    }

    /// Ends the open contour: its planner emits what it still holds.
    fn close(&mut self) {
        let Some((open, mut pending)) = self.open.take() else {
            return;
        };
        if self.error.is_some() {
            return;
        }
        let open = match open {
            Open::Timed(run) => {
                match self.plan_timed_run(&run) {
                    Ok(planned) => {
                        pending.start.clone_from(&planned.start);
                        for seg in planned.segments() {
                            hand_on(&mut self.sink, &mut self.contours, &mut pending, &seg);
                        }
                    }
                    Err(e) => self.error = Some(e),
                }
                return;
            }
            open => open,
        };
        let (sink, contours) = (&mut self.sink, &mut self.contours);
        let mut emit = |seg: &SegmentRef<'_>| hand_on(sink, contours, &mut pending, seg);
        let result = match open {
            Open::Path(stream) => stream.finish(&mut emit).map(|r| {
                let worst = self.report.path_error.unwrap_or(0.0).max(r.error_bound);
                self.report.path_error = Some(worst);
                let change = self.report.quantize_speed_change.max(r.speed_change);
                self.report.quantize_speed_change = change;
            }),
            Open::Points(mut stream) => {
                stream.finish(&mut |seg| emit(&seg));
                Ok(())
            }
            Open::Timed(_) => Ok(()),
            Open::Buffered(contour) => {
                plan_buffered(&contour, &self.axes, &self.options, &mut self.report).map(
                    |planned| {
                        for seg in planned.segments() {
                            emit(&seg);
                        }
                    },
                )
            }
        };
        if let Err(e) = result {
            self.error = Some(e);
        }
    }
}

/// Hands a piece on, starting its contour first if this is the contour's first piece.
fn hand_on<S: PieceSink>(
    sink: &mut S,
    contours: &mut usize,
    pending: &mut Pending,
    seg: &SegmentRef<'_>,
) {
    if !pending.started {
        pending.started = true;
        *contours += 1;
        sink.contour(pending.motion, &pending.start, pending.line);
    }
    sink.piece(seg);
}

impl<S: PieceSink> ToolpathSink for PlanStage<S> {
    fn element(&mut self, motion: Motion, element: &Element) {
        if self.error.is_some() {
            return;
        }
        if matches!(self.open, Some((Open::Timed(_), _))) {
            self.close();
        }
        if self.open.is_none() {
            self.begin(motion, element);
        }
        self.report.feed_time += element.length() / element.feed;
        if let Err(e) = self.push(element) {
            self.error = Some(e);
        }
    }

    fn end_contour(&mut self) {
        self.close();
    }

    /// A tolerance that is not positive (G64 P0) leaves the one in force: no motion is
    /// within zero of an arc.
    fn path_tolerance(&mut self, tolerance: f64) {
        if tolerance > 0.0 && tolerance.is_finite() {
            self.options.path_tolerance = Some(tolerance);
        }
    }

    fn event(&mut self, event: &EventKind, line: u32) {
        self.close();
        if self.error.is_some() {
            return;
        }
        self.sink.event(&ProgramEvent {
            before_contour: self.contours,
            kind: event.clone(),
            line,
        });
    }
}

/// A planned program together with its report.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// The program.
    pub program: PvtProgram,
    /// What planning changed.
    pub report: PlanReport,
}

/// Plans every contour of a toolpath with the chosen planner, timing and quantization:
/// the toolpath fed through the one planning path ([`PlanStage`]) into a collector.
///
/// Contours that do not move are left out. See [`plan_toolpath`] for the program only.
pub fn plan_toolpath_report(
    toolpath: &Toolpath,
    options: &PlanOptions,
) -> Result<Planned, PlanError> {
    let axes: Vec<Axis> = toolpath.moved_axes();
    let collector = Collector {
        program: PvtProgram {
            axes: axes.clone(),
            units: toolpath.units,
            interpolation: options.interpolation(),
            contours: Vec::new(),
            events: Vec::new(),
        },
    };
    let mut stage = PlanStage::new(axes, options.clone(), collector)?;
    let mut events = toolpath.events.iter().peekable();
    let mut tolerances = toolpath.path_tolerances.iter().peekable();
    for (index, contour) in toolpath.contours.iter().enumerate() {
        while let Some(e) = events.next_if(|e| e.before_contour <= index) {
            stage.event(&e.kind, e.line);
        }
        while let Some(&(_, t)) = tolerances.next_if(|(from, _)| *from <= index) {
            stage.path_tolerance(t);
        }
        for element in &contour.elements {
            stage.element(contour.motion, element);
        }
        stage.end_contour();
    }
    for e in events {
        stage.event(&e.kind, e.line);
    }
    let (collector, report) = stage.finish()?;
    Ok(Planned {
        program: collector.program,
        report,
    })
}

/// A [`PieceSink`] that keeps the whole program.
struct Collector {
    program: PvtProgram,
}

impl PieceSink for Collector {
    fn contour(&mut self, motion: Motion, start: &[f64], _line: u32) {
        self.program
            .contours
            .push(PvtContour::new(motion, start.to_vec()));
    }

    fn piece(&mut self, piece: &SegmentRef<'_>) {
        if let Some(c) = self.program.contours.last_mut() {
            c.push(piece.end, piece.velocity, piece.duration, piece.line);
        }
    }

    fn event(&mut self, event: &ProgramEvent) {
        self.program.events.push(event.clone());
    }
}

/// Plans every contour of a toolpath on the axes it moves with the chosen planner.
/// Contours that do not move (every point the same) are left out.
pub fn plan_toolpath(toolpath: &Toolpath, options: &PlanOptions) -> Result<PvtProgram, PlanError> {
    plan_toolpath_report(toolpath, options).map(|planned| planned.program)
}

/// Plans a point-time series (e.g. from CSV) on `axes` as one feed contour: the series
/// pushed point by point through the one planning path ([`PlanStage::timed_point`]) into
/// a collector.
///
/// The series' own times are used ([`PlanOptions::timing`] applies to toolpaths only);
/// given velocities are used as given by chord, const-accel and spline. The contour
/// planner takes each segment's mean speed (chord / time) as its feed, drops zero-length
/// segments (dwells) and chooses its own times (seed 000).
pub fn plan_timed(
    points: &TimedPoints,
    axes: Vec<Axis>,
    units: Units,
    options: &PlanOptions,
) -> Result<Planned, PlanError> {
    points.validate()?;
    if axes.len() != points.dim {
        return Err(PlanError::BadShape);
    }
    let options = PlanOptions {
        timing: Timing::FromFeed,
        ..options.clone()
    };
    let collector = Collector {
        program: PvtProgram {
            axes: axes.clone(),
            units,
            interpolation: options.interpolation(),
            contours: Vec::new(),
            events: Vec::new(),
        },
    };
    let mut stage = PlanStage::new(axes, options, collector)?;
    stage.timed_points(points);
    let (collector, report) = stage.finish()?;
    Ok(Planned {
        program: collector.program,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every contour, piece and event as text, in the order the stage hands them on.
    #[derive(Default)]
    struct Log(Vec<String>);

    impl PieceSink for Log {
        fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
            self.0
                .push(format!("contour {motion:?} {start:?} line {line}"));
        }
        fn piece(&mut self, p: &SegmentRef<'_>) {
            let (end, v, t, line) = (p.end, p.velocity, p.duration, p.line);
            self.0.push(format!("piece {end:?} {v:?} {t} line {line}"));
        }
        fn event(&mut self, e: &ProgramEvent) {
            let (before, line) = (e.before_contour, e.line);
            self.0.push(format!("event before {before} line {line}"));
        }
    }

    fn chord_stage() -> PlanStage<Log> {
        let options = PlanOptions {
            planner: Planner::Chord,
            ..PlanOptions::default()
        };
        PlanStage::new(vec![Axis::X], options, Log::default()).unwrap()
    }

    #[test]
    fn timed_runs_are_planned_with_their_own_times_between_events() {
        let mut stage = chord_stage();
        // x = 0, 1, 3, 6 at 1 s, 1 s, 0.5 s: chord-forward's velocity at a point is the
        // outgoing chord over its time, 0 at both ends.
        for (x, dt, line) in [(0.0, 0.0, 2), (1.0, 1.0, 3), (3.0, 1.0, 4), (6.0, 0.5, 5)] {
            stage.timed_point(&[x], dt, None, line);
        }
        stage.event(&EventKind::Dwell { seconds: 1.0 }, 6);
        stage.timed_point(&[6.0], 0.0, None, 7);
        stage.timed_point(&[4.0], 2.0, None, 8);
        let (log, report) = stage.finish().unwrap();
        let expected = [
            "contour Feed [0.0] line 2",
            "piece [1.0] [2.0] 1 line 3",
            "piece [3.0] [6.0] 1 line 4",
            "piece [6.0] [0.0] 0.5 line 5",
            "event before 1 line 6",
            "contour Feed [6.0] line 7",
            "piece [4.0] [0.0] 2 line 8",
        ];
        assert_eq!(log.0, expected);
        assert!(!report.velocities_ignored);
    }

    #[test]
    fn a_timed_run_keeps_given_velocities_and_refuses_a_missing_one() {
        let mut stage = chord_stage();
        stage.timed_point(&[0.0], 0.0, Some(&[0.0]), 1);
        stage.timed_point(&[1.0], 1.0, Some(&[0.25]), 2);
        stage.timed_point(&[2.0], 1.0, Some(&[0.0]), 3);
        let (log, _) = stage.finish().unwrap();
        assert_eq!(log.0[1], "piece [1.0] [0.25] 1 line 2");

        let mut stage = chord_stage();
        stage.timed_point(&[0.0], 0.0, Some(&[0.0]), 1);
        stage.timed_point(&[1.0], 1.0, None, 2);
        assert!(matches!(stage.finish(), Err(PlanError::BadShape)));
    }

    #[test]
    fn a_bad_time_in_a_timed_run_is_an_error_at_its_line() {
        let mut stage = chord_stage();
        stage.timed_point(&[0.0], 0.0, None, 1);
        stage.timed_point(&[1.0], -1.0, None, 2);
        assert!(matches!(
            stage.finish(),
            Err(PlanError::BadDuration { line: 2, .. })
        ));
    }
}
