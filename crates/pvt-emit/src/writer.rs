//! The piece writer every back end implements ([`ProgramWriter`]) and the check in
//! front of it ([`Checked`]).
//!
//! Owns the order in which a program reaches a back end: `begin`, then per contour
//! `contour` and its `segment`s, then `finish`. A back end may write as soon as it is
//! called, so a program of any length goes out in constant memory; it checks each value
//! before writing it ([`crate::validate`]). It must not plan or look ahead.

use crate::rules::{Caps, RuleCheck};
use crate::triggers::{TriggerClock, TriggerSupport};
use crate::validate::{check_piece_time, check_segment, check_start, InvalidProgram};
use crate::EmitOptions;
use pvt_core::{Axis, Interpolation, Motion, ProgramEvent, SegmentRef, Units};
use std::io;

/// What a back end needs to know before the first contour.
#[derive(Debug, Clone, Copy)]
pub struct Header<'a> {
    /// Axes of every position and velocity, in order.
    pub axes: &'a [Axis],
    /// Units of linear positions.
    pub units: Units,
    /// PVT or PT.
    pub interpolation: Interpolation,
    /// Source name and settings.
    pub options: &'a EmitOptions,
}

/// Running totals a back end may print at the end.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Totals {
    /// Contours written.
    pub contours: usize,
    /// Segments written.
    pub segments: usize,
    /// Segments written in the current contour.
    pub segments_in_contour: usize,
    /// Sum of piece times, seconds.
    pub time: f64,
    /// Piece times that PMAC text does not print as a whole number of milliseconds.
    pub fractional_ms: usize,
}

impl Totals {
    /// Counts one contour.
    pub fn add_contour(&mut self) {
        self.contours += 1;
        self.segments_in_contour = 0;
    }

    /// Counts one segment of `duration` seconds.
    pub fn add_segment(&mut self, duration: f64) {
        // As PMAC text prints it: 820.0000 ms is whole, whatever bits carried it.
        let whole =
            crate::number::prints_whole::<{ crate::pmac::TIME_DECIMALS }>(duration * 1000.0);
        self.add_printed_segment(duration, whole);
    }

    /// [`Totals::add_segment`] for a segment whose time PMAC text prints as a whole
    /// number of milliseconds or not (`whole_ms`), as the caller already knows.
    #[inline]
    pub fn add_printed_segment(&mut self, duration: f64, whole_ms: bool) {
        self.segments += 1;
        self.segments_in_contour += 1;
        self.time += duration;
        self.fractional_ms += usize::from(!whole_ms);
    }
}

/// A back end fed one piece at a time.
pub trait ProgramWriter {
    /// Starts the program.
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()>;
    /// Starts a contour at rest at `start`.
    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()>;
    /// Writes one segment of the current contour.
    fn segment(&mut self, segment: &SegmentRef<'_>) -> io::Result<()>;
    /// Writes an event that happens at rest before the next contour (or at the end).
    fn event(&mut self, event: &ProgramEvent) -> io::Result<()>;
    /// Ends the program.
    fn finish(&mut self) -> io::Result<()>;
    /// A trigger fires here: at the end of the last segment written (or at the start of
    /// the contour just begun). Called only where [`Caps::triggers`] says
    /// [`TriggerSupport::Written`].
    fn trigger(&mut self) -> io::Result<()> {
        Ok(())
    }
    /// Whether the back end can express `interpolation` (all take PVT).
    fn supports(&self, interpolation: Interpolation) -> bool {
        interpolation == Interpolation::Pvt
    }
    /// What the format's controller accepts ([`crate::Format::caps`]).
    fn caps(&self) -> Caps {
        Caps::FREE
    }
    /// How this back end's piece lines are written apart from it (on another thread,
    /// ahead of it), once begun: none where a piece's text depends on more than the
    /// piece (the default).
    fn piece_lines(&self) -> Option<PieceLines> {
        None
    }
    /// Writes one segment of the current contour whose line [`Self::piece_lines`] has
    /// written: the bytes, the totals and every state exactly as [`Self::segment`]
    /// leaves them (the default calls it).
    fn segment_with_line(
        &mut self,
        segment: &SegmentRef<'_>,
        line: PieceLine<'_>,
    ) -> io::Result<()> {
        let _ = line;
        self.segment(segment)
    }
}

/// A back end's piece lines written apart from its writer
/// ([`ProgramWriter::piece_lines`]): the text the writer's `segment` writes for a piece,
/// a pure function of the piece, made where there is time for it (the planner's
/// thread, while it waits for the front end) and handed to
/// [`ProgramWriter::segment_with_line`] with the piece.
#[derive(Debug, Clone)]
pub enum PieceLines {
    /// PMAC text: `TA<ms>` and each axis' `<letter><position>:<velocity>`
    /// ([`crate::pmac`]).
    Pmac(crate::pmac::PmacLines),
}

impl PieceLines {
    /// Writes `segment`'s line at the start of `room` (at least [`PieceLines::room`]
    /// long, the rest of it scratch): the line's length and note
    /// ([`PieceLine::whole_ms`]), or `None` where the writer writes this piece itself (a
    /// number beyond the usual ones), `room` then holding nothing of meaning.
    #[inline]
    pub fn write(&self, segment: &SegmentRef<'_>, room: &mut [u8]) -> Option<(usize, bool)> {
        match self {
            PieceLines::Pmac(lines) => lines.write(segment, room),
        }
    }

    /// Bytes [`PieceLines::write`] may take for one line.
    pub fn room(&self) -> usize {
        match self {
            PieceLines::Pmac(lines) => lines.room(),
        }
    }
}

/// A piece's line written by [`PieceLines::write`].
#[derive(Debug, Clone, Copy)]
pub struct PieceLine<'a> {
    /// The line, its newline included.
    pub text: &'a [u8],
    /// Its piece time prints as a whole number of milliseconds (what PMAC's totals
    /// count).
    pub whole_ms: bool,
}

/// A writer that validates every value before its back end sees it, checks every piece
/// against the format's controller rules ([`RuleCheck`]), and passes a contour on only
/// when its first segment arrives, so back ends never see an empty one. With
/// `--trigger-every` it cuts each piece at its triggers ([`TriggerClock`]), checks each
/// part, and calls [`ProgramWriter::trigger`] after the part that ends at one (once per
/// knot).
pub struct Checked<W> {
    inner: W,
    contour: usize,
    segment: usize,
    pending: Option<(Motion, Vec<f64>)>,
    rules: Option<RuleCheck>,
    /// The back end's longest piece time ([`Caps::max_piece_seconds`]), once begun.
    max_piece_seconds: Option<f64>,
    triggers: Option<TriggerClock>,
    /// Position and velocity of every axis after the last segment (for the cubic a
    /// trigger cuts).
    at: (Vec<f64>, Vec<f64>),
    /// A trigger fired at the end of the last segment written.
    triggered: bool,
    /// The back end took the header: nothing reaches it before, nor after a refusal.
    begun: bool,
}

/// A failure while streaming: a bad value or an I/O error.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// A value no controller may receive.
    #[error(transparent)]
    Invalid(#[from] InvalidProgram),
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] io::Error),
    /// The format cannot express the program's interpolation.
    #[error("this output format cannot express {0:?} interpolation")]
    Unsupported(Interpolation),
    /// The format writes counts and the axis has no counts per unit.
    #[error("the {0} writes positions in counts, and axis {1} has no counts per unit")]
    MissingScale(&'static str, Axis),
    /// Triggers were asked for and the format has no place for them.
    #[error("the {0} takes no triggers in its program: {1}")]
    NoTriggers(&'static str, &'static str),
}

impl<W: ProgramWriter> Checked<W> {
    /// Wraps a back end.
    pub fn new(inner: W) -> Checked<W> {
        Checked {
            inner,
            contour: 0,
            segment: 0,
            pending: None,
            rules: None,
            max_piece_seconds: None,
            triggers: None,
            at: (Vec::new(), Vec::new()),
            triggered: false,
            begun: false,
        }
    }

    /// Starts the program; refuses an interpolation the back end cannot express.
    pub fn begin(&mut self, header: &Header<'_>) -> Result<(), StreamError> {
        if !self.inner.supports(header.interpolation) {
            return Err(StreamError::Unsupported(header.interpolation));
        }
        let caps = self.inner.caps();
        let rules = RuleCheck::new(caps, header.axes, &header.options.axes);
        if let Some(axis) = rules.missing_scale() {
            return Err(StreamError::MissingScale(caps.controller, axis));
        }
        self.rules = Some(rules);
        self.max_piece_seconds = caps.max_piece_seconds;
        if let Some(triggers) = header.options.triggers {
            if let TriggerSupport::None(why) = caps.triggers {
                return Err(StreamError::NoTriggers(caps.controller, why));
            }
            let shortest = caps.min_piece_seconds;
            self.triggers = Some(TriggerClock::new(triggers, header.axes, shortest));
        }
        self.inner.begin(header)?;
        self.begun = true;
        Ok(())
    }

    /// An error unless [`Checked::begin`] succeeded: a refused header (its error already
    /// returned to the caller) stops everything after it.
    #[inline]
    fn ready(&self) -> Result<(), StreamError> {
        if self.begun {
            return Ok(());
        }
        Err(refused_header())
    }

    /// Starts a contour at rest at `start`, after checking it.
    pub fn contour(&mut self, motion: Motion, start: &[f64], line: u32) -> Result<(), StreamError> {
        check_start(start, self.contour + 1, line)?;
        self.pending = Some((motion, start.to_vec()));
        Ok(())
    }

    /// Writes a segment, after checking it.
    pub fn segment(&mut self, segment: &SegmentRef<'_>) -> Result<(), StreamError> {
        self.segment_as(segment, None)
    }

    /// Writes a segment whose line [`Checked::piece_lines`] wrote, after checking it, as
    /// [`Checked::segment`] writes it.
    pub fn segment_with_line(
        &mut self,
        segment: &SegmentRef<'_>,
        line: PieceLine<'_>,
    ) -> Result<(), StreamError> {
        self.segment_as(segment, Some(line))
    }

    /// The back end's piece lines written apart from it
    /// ([`ProgramWriter::piece_lines`]), once begun: none where triggers cut the pieces.
    pub fn piece_lines(&self) -> Option<PieceLines> {
        match self.begun && self.triggers.is_none() {
            true => self.inner.piece_lines(),
            false => None,
        }
    }

    /// [`Checked::segment`], with the line written ahead where there is one.
    #[inline]
    fn segment_as(
        &mut self,
        segment: &SegmentRef<'_>,
        line: Option<PieceLine<'_>>,
    ) -> Result<(), StreamError> {
        self.ready()?;
        if self.pending.is_some() {
            self.open_contour(segment.end.len())?;
        }
        self.segment += 1;
        check_segment(segment, self.contour, self.segment)?;
        if let Some(max) = self.max_piece_seconds {
            check_piece_time(segment, max, self.contour, self.segment)?;
        }
        if self.triggers.is_some() {
            return self.triggered(segment);
        }
        if let Some(rules) = self.rules.as_mut() {
            rules.piece(segment, self.contour, self.segment)?;
        }
        match line {
            Some(line) => self.inner.segment_with_line(segment, line)?,
            None => self.inner.segment(segment)?,
        }
        Ok(())
    }

    /// Passes the pending contour on, at its first segment (of `dim` axes).
    #[cold]
    fn open_contour(&mut self, dim: usize) -> Result<(), StreamError> {
        let Some((motion, start)) = self.pending.take() else {
            return Ok(());
        };
        self.contour += 1;
        self.segment = 0;
        if let Some(rules) = self.rules.as_mut() {
            rules.contour(&start, self.contour)?;
        }
        self.inner.contour(motion, &start)?;
        self.at = (start, vec![0.0; dim]);
        Ok(())
    }

    /// Writes a segment cut at the triggers inside it, each part checked.
    fn triggered(&mut self, segment: &SegmentRef<'_>) -> Result<(), StreamError> {
        let Some(clock) = self.triggers.as_mut() else {
            return Ok(());
        };
        let start = (self.at.0.as_slice(), self.at.1.as_slice());
        let cut = clock.cut(start, (segment.end, segment.velocity), segment.duration);
        self.at = (segment.end.to_vec(), segment.velocity.to_vec());
        // One trigger per knot: the end of the last piece is this one's start.
        if cut.at_start && !self.triggered {
            self.inner.trigger()?;
        }
        for (duration, end, velocity, trigger) in &cut.parts {
            let part = SegmentRef {
                end,
                velocity,
                duration: *duration,
                line: segment.line,
            };
            check_segment(&part, self.contour, self.segment)?;
            if let Some(rules) = self.rules.as_mut() {
                rules.piece(&part, self.contour, self.segment)?;
            }
            self.inner.segment(&part)?;
            self.triggered = *trigger;
            if *trigger {
                self.inner.trigger()?;
            }
        }
        Ok(())
    }

    /// Writes an event at rest between contours.
    pub fn event(&mut self, event: &ProgramEvent) -> Result<(), StreamError> {
        self.ready()?;
        Ok(self.inner.event(event)?)
    }

    /// Ends the program and returns the back end.
    pub fn finish(mut self) -> Result<W, StreamError> {
        self.ready()?;
        if let Some(rules) = self.rules.as_mut() {
            rules.finish(self.contour)?;
        }
        self.inner.finish()?;
        Ok(self.inner)
    }
}

/// A back end's caps and the interpolations it takes, without its text: behind
/// [`Checked`], which makes every refusal a program can meet (no back end refuses
/// anything but a failed write), a pass that checks a program as that back end would
/// and makes no text.
pub struct Unwritten<W>(pub W);

impl<W: ProgramWriter> ProgramWriter for Unwritten<W> {
    fn begin(&mut self, _: &Header<'_>) -> io::Result<()> {
        Ok(())
    }
    fn contour(&mut self, _: Motion, _: &[f64]) -> io::Result<()> {
        Ok(())
    }
    fn segment(&mut self, _: &SegmentRef<'_>) -> io::Result<()> {
        Ok(())
    }
    fn event(&mut self, _: &ProgramEvent) -> io::Result<()> {
        Ok(())
    }
    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
    fn supports(&self, interpolation: Interpolation) -> bool {
        self.0.supports(interpolation)
    }
    fn caps(&self) -> Caps {
        self.0.caps()
    }
}

/// A back end `K` of the caller's (one that keeps the pieces, not a format's text) that
/// answers for the caps and interpolations of the format whose writer is `W`: behind
/// [`Checked`], the pieces `K` receives are checked as that format's would be.
pub struct Collected<W, K> {
    /// The format's writer, asked only what it takes.
    pub format: W,
    /// Where the program goes.
    pub into: K,
}

impl<W: ProgramWriter, K: ProgramWriter> ProgramWriter for Collected<W, K> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.into.begin(header)
    }
    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        self.into.contour(motion, start)
    }
    fn segment(&mut self, segment: &SegmentRef<'_>) -> io::Result<()> {
        self.into.segment(segment)
    }
    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        self.into.event(event)
    }
    fn finish(&mut self) -> io::Result<()> {
        self.into.finish()
    }
    fn trigger(&mut self) -> io::Result<()> {
        self.into.trigger()
    }
    fn supports(&self, interpolation: Interpolation) -> bool {
        self.format.supports(interpolation)
    }
    fn caps(&self) -> Caps {
        self.format.caps()
    }
}

/// The error of every call after a refused header ([`Checked::begin`]).
#[cold]
fn refused_header() -> StreamError {
    StreamError::Io(io::Error::other(
        "the output's header was refused, so nothing more is written",
    ))
}

impl<T: ProgramWriter + ?Sized> ProgramWriter for Box<T> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        (**self).begin(header)
    }
    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        (**self).contour(motion, start)
    }
    fn segment(&mut self, segment: &SegmentRef<'_>) -> io::Result<()> {
        (**self).segment(segment)
    }
    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        (**self).event(event)
    }
    fn finish(&mut self) -> io::Result<()> {
        (**self).finish()
    }
    fn trigger(&mut self) -> io::Result<()> {
        (**self).trigger()
    }
    fn supports(&self, interpolation: Interpolation) -> bool {
        (**self).supports(interpolation)
    }
    fn caps(&self) -> Caps {
        (**self).caps()
    }
    fn piece_lines(&self) -> Option<PieceLines> {
        (**self).piece_lines()
    }
    fn segment_with_line(
        &mut self,
        segment: &SegmentRef<'_>,
        line: PieceLine<'_>,
    ) -> io::Result<()> {
        (**self).segment_with_line(segment, line)
    }
}
