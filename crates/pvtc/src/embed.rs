//! The entry points of a program that embeds pvtc (the Python package,
//! `crates/pvtc-py`): a compile whose pieces are kept as flat arrays ([`Pieces`]) instead
//! of written as text, streamed in chunks, and written later in any format exactly as
//! `pvtc compile` writes it.
//!
//! Owns the collector of pieces ([`Collector`], a back end behind pvt-emit's checks, as
//! the format's text would be) and the replay of kept pieces into a format's writer. It
//! must not parse options, plan, check or format: the route ([`crate::route`]), the
//! settings and the back ends do all of that, as they do for the command line.

use crate::front::{self, Input};
use crate::options::{CompileOptions, Failure, InputKind, Source};
use crate::route::{self, Layout, MovedAxes, Out};
use crate::settings::{header_lines, plan_options, split_grid};
use miette::Report;
use pvt_core::{Axis, Interpolation, Motion, ProgramEvent, PvtContour, PvtProgram, SegmentRef};
use pvt_core::{Toolpath, Units};
use pvt_emit::{Checked, Header, ProgramWriter, StreamError};
use std::io;

/// Where a contour of kept pieces starts.
#[derive(Debug, Clone, PartialEq)]
pub struct ContourStart {
    /// Rapid or feed.
    pub motion: Motion,
    /// Where the axes are before its first piece kept.
    pub start: Vec<f64>,
    /// Index of its first piece among the pieces kept.
    pub first: usize,
}

/// What kept pieces hold besides the per-piece arrays: their axes, contours and events.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Outline {
    /// Axes of every position and velocity, in X Y Z A B C order.
    pub axes: Vec<Axis>,
    /// Units of the linear positions.
    pub units: Units,
    /// PVT or PT.
    pub interpolation: Interpolation,
    /// The contours the pieces belong to, in order.
    pub contours: Vec<ContourStart>,
    /// Index of the first of `contours` in the whole program (0 but for a chunk).
    pub first_contour: usize,
    /// Velocities before the first piece: zero, but for a chunk cut inside a contour.
    pub start_velocity: Vec<f64>,
    /// Events, each with the number of pieces before it, in order.
    pub events: Vec<(usize, ProgramEvent)>,
}

impl Outline {
    /// True when the pieces start in motion (a chunk cut inside a contour): they are not
    /// a program of their own.
    pub fn starts_in_motion(&self) -> bool {
        self.start_velocity.iter().any(|v| *v != 0.0)
    }
}

/// A planned program as flat arrays: piece `i`'s end position is
/// `ends[i * dim..(i + 1) * dim]`, likewise its end velocity.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Pieces {
    /// Piece times, seconds.
    pub durations: Vec<f64>,
    /// End positions, flat.
    pub ends: Vec<f64>,
    /// End velocities, flat.
    pub velocities: Vec<f64>,
    /// Source line of each piece.
    pub lines: Vec<u32>,
    /// Index of each piece's contour in the whole program.
    pub contour_of: Vec<u32>,
    /// Axes, contours and events.
    pub outline: Outline,
}

/// Kept pieces borrowed from wherever they are held (a [`Pieces`], or arrays handed
/// back by the embedding program).
#[derive(Debug, Clone, Copy)]
pub struct PiecesView<'a> {
    /// Piece times, seconds.
    pub durations: &'a [f64],
    /// End positions, flat.
    pub ends: &'a [f64],
    /// End velocities, flat.
    pub velocities: &'a [f64],
    /// Source line of each piece.
    pub lines: &'a [u32],
    /// Axes, contours and events.
    pub outline: &'a Outline,
}

impl Pieces {
    /// The pieces, borrowed.
    pub fn view(&self) -> PiecesView<'_> {
        PiecesView {
            durations: &self.durations,
            ends: &self.ends,
            velocities: &self.velocities,
            lines: &self.lines,
            outline: &self.outline,
        }
    }

    /// The pieces of `program`, as its writer receives them (contours without pieces
    /// left out, as [`Checked`] leaves them out).
    pub fn of_program(program: &PvtProgram) -> Pieces {
        let mut collector = Collector::whole();
        let mut into = &mut collector;
        let emit = pvt_emit::EmitOptions::default();
        let header = Header {
            axes: &program.axes,
            units: program.units,
            interpolation: program.interpolation,
            options: &emit,
        };
        // The collector refuses nothing.
        let _ = into.begin(&header);
        for step in pvt_core::traverse::program(program) {
            let _ = match step {
                pvt_core::traverse::Step::Event(event) => into.event(event),
                pvt_core::traverse::Step::PathTolerance(_) => Ok(()),
                pvt_core::traverse::Step::Contour(contour) if contour.is_empty() => Ok(()),
                pvt_core::traverse::Step::Contour(contour) => {
                    let _ = into.contour(contour.motion, &contour.start);
                    contour
                        .segments()
                        .try_for_each(|piece| into.segment(&piece))
                }
            };
        }
        collector.pieces
    }
}

impl PiecesView<'_> {
    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.durations.len()
    }

    /// True when there is no piece.
    pub fn is_empty(&self) -> bool {
        self.durations.is_empty()
    }

    /// Piece `i`.
    pub fn piece(&self, i: usize) -> SegmentRef<'_> {
        let dim = self.outline.axes.len();
        SegmentRef {
            end: &self.ends[i * dim..(i + 1) * dim],
            velocity: &self.velocities[i * dim..(i + 1) * dim],
            duration: self.durations[i],
            line: self.lines[i],
        }
    }

    /// Where contour `k` of the outline ends (the first piece of the next).
    fn contour_end(&self, k: usize) -> usize {
        self.outline
            .contours
            .get(k + 1)
            .map_or(self.len(), |c| c.first)
    }

    /// The pieces as a program (events before the contour they precede); `None` for
    /// pieces that start in motion, which no program holds.
    pub fn program(&self) -> Option<PvtProgram> {
        if self.outline.starts_in_motion() {
            return None;
        }
        let o = self.outline;
        let dim = o.axes.len();
        let contours = o.contours.iter().enumerate().map(|(k, c)| {
            let range = c.first..self.contour_end(k);
            PvtContour {
                motion: c.motion,
                dim,
                start: c.start.clone(),
                ends: self.ends[range.start * dim..range.end * dim].to_vec(),
                velocities: self.velocities[range.start * dim..range.end * dim].to_vec(),
                durations: self.durations[range.clone()].to_vec(),
                lines: self.lines[range].to_vec(),
            }
        });
        let events = o.events.iter().map(|(at, e)| ProgramEvent {
            before_contour: o.contours.iter().filter(|c| c.first < *at).count(),
            ..e.clone()
        });
        Some(PvtProgram {
            axes: o.axes.clone(),
            units: o.units,
            interpolation: o.interpolation,
            contours: contours.collect(),
            events: events.collect(),
        })
    }

    /// Makes the calls a writer received for these pieces again, in the same order.
    fn replay<W: ProgramWriter>(&self, writer: &mut Checked<W>) -> Result<(), StreamError> {
        let mut events = self.outline.events.iter().peekable();
        for (k, contour) in self.outline.contours.iter().enumerate() {
            while let Some((_, event)) = events.next_if(|(at, _)| *at <= contour.first) {
                writer.event(event)?;
            }
            let line = self.lines.get(contour.first).copied().unwrap_or(0);
            writer.contour(contour.motion, &contour.start, line)?;
            for i in contour.first..self.contour_end(k) {
                writer.segment(&self.piece(i))?;
            }
        }
        for (_, event) in events {
            writer.event(event)?;
        }
        Ok(())
    }

    /// Makes the same calls into a collector, which refuses nothing; stops when it
    /// does (a closed stream).
    fn replay_into(&self, into: &mut &mut Collector<'_>) -> io::Result<()> {
        let mut events = self.outline.events.iter().peekable();
        for (k, contour) in self.outline.contours.iter().enumerate() {
            while let Some((_, event)) = events.next_if(|(at, _)| *at <= contour.first) {
                into.event(event)?;
            }
            into.contour(contour.motion, &contour.start)?;
            for i in contour.first..self.contour_end(k) {
                into.segment(&self.piece(i))?;
            }
        }
        events.try_for_each(|(_, event)| into.event(event))
    }
}

/// Where chunks go; `false` when nobody takes them any more.
pub type ChunkSink<'a> = dyn FnMut(Pieces) -> bool + 'a;

/// A back end that keeps the pieces it is given (behind the format's checks, through
/// the route's [`Out::Into`]), whole or handed on in chunks.
pub struct Collector<'a> {
    pieces: Pieces,
    /// Contours begun, in the whole program.
    contours: usize,
    /// Where the axes are and how fast they move, after the last piece.
    at: (Vec<f64>, Vec<f64>),
    motion: Motion,
    chunks: Option<(usize, Box<ChunkSink<'a>>)>,
}

impl<'a> Collector<'a> {
    /// A collector of the whole program.
    pub fn whole() -> Collector<'a> {
        Collector {
            pieces: Pieces::default(),
            contours: 0,
            at: (Vec::new(), Vec::new()),
            motion: Motion::Feed,
            chunks: None,
        }
    }

    /// A collector that hands every `chunk` pieces (the rest at the end) to `sink`.
    pub fn chunked(chunk: usize, sink: Box<ChunkSink<'a>>) -> Collector<'a> {
        Collector {
            chunks: Some((chunk.max(1), sink)),
            ..Collector::whole()
        }
    }

    /// The pieces kept (none once handed on in chunks).
    pub fn into_pieces(self) -> Pieces {
        self.pieces
    }

    /// The pieces since the last chunk, the next chunk's outline begun where they end.
    fn take(&mut self) -> Pieces {
        let outline = Outline {
            axes: self.pieces.outline.axes.clone(),
            units: self.pieces.outline.units,
            interpolation: self.pieces.outline.interpolation,
            contours: Vec::new(),
            first_contour: self.contours.saturating_sub(1),
            start_velocity: self.at.1.clone(),
            events: Vec::new(),
        };
        std::mem::replace(
            &mut self.pieces,
            Pieces {
                outline,
                ..Pieces::default()
            },
        )
    }

    /// Hands the pieces on when a chunk is full (`end`: whatever is left).
    fn hand_on(&mut self, end: bool) -> io::Result<()> {
        let kept = &self.pieces;
        let due = match &self.chunks {
            Some(_) if end => !kept.durations.is_empty() || !kept.outline.events.is_empty(),
            Some((n, _)) => kept.durations.len() >= *n,
            None => false,
        };
        if !due {
            return Ok(());
        }
        let chunk = self.take();
        match self.chunks.as_mut().map(|(_, sink)| sink(chunk)) {
            Some(false) => Err(io::Error::other("the stream of chunks was closed")),
            _ => Ok(()),
        }
    }
}

impl ProgramWriter for &mut Collector<'_> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        let dim = header.axes.len();
        self.pieces = Pieces::default();
        self.pieces.outline = Outline {
            axes: header.axes.to_vec(),
            units: header.units,
            interpolation: header.interpolation,
            start_velocity: vec![0.0; dim],
            ..Outline::default()
        };
        self.contours = 0;
        self.at = (vec![0.0; dim], vec![0.0; dim]);
        Ok(())
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        let first = self.pieces.durations.len();
        if self.pieces.outline.contours.is_empty() {
            self.pieces.outline.first_contour = self.contours;
            self.pieces.outline.start_velocity = vec![0.0; start.len()];
        }
        self.pieces.outline.contours.push(ContourStart {
            motion,
            start: start.to_vec(),
            first,
        });
        self.contours += 1;
        self.motion = motion;
        self.at.0.copy_from_slice(start);
        self.at.1.fill(0.0);
        Ok(())
    }

    fn segment(&mut self, piece: &SegmentRef<'_>) -> io::Result<()> {
        let kept = &mut self.pieces;
        if kept.outline.contours.is_empty() {
            // A chunk that begins inside the contour the last one ended in.
            kept.outline.contours.push(ContourStart {
                motion: self.motion,
                start: self.at.0.clone(),
                first: 0,
            });
        }
        kept.durations.push(piece.duration);
        kept.ends.extend_from_slice(piece.end);
        kept.velocities.extend_from_slice(piece.velocity);
        kept.lines.push(piece.line);
        let contour = self.contours.saturating_sub(1);
        kept.contour_of
            .push(u32::try_from(contour).unwrap_or(u32::MAX));
        self.at.0.copy_from_slice(piece.end);
        self.at.1.copy_from_slice(piece.velocity);
        self.hand_on(false)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        let at = self.pieces.durations.len();
        self.pieces.outline.events.push((at, event.clone()));
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.hand_on(true)
    }
}

/// Plans the G-code file at `path` (named `name` in diagnostics and headers) as
/// `pvtc compile` streams it into a file, its pieces kept instead of written: the
/// format's checks made, memory the arrays and the streaming bound. Returns the pieces
/// and the warnings and notes.
pub fn plan_file(
    path: &std::path::Path,
    name: &str,
    options: &CompileOptions,
) -> Result<(Pieces, Vec<Report>), Failure> {
    let gcode = front::gcode_options(options);
    let prescan =
        pvt_gcode::prescan(&mut route::open(path)?).map_err(|e| route::read_failure(path, e))?;
    let layout = Layout::guess(&prescan, &gcode);
    let mut collector = Collector::whole();
    let into = Out::Into(Box::new(&mut collector));
    let mut pass = route::write_pass(path, name, options, &gcode, &layout, into)?;
    if pass.layout != layout {
        // As into a file: the guess was wrong, so the pass is made again (its begin
        // clears what the first kept).
        let found = pass.layout.clone();
        let into = Out::Into(Box::new(&mut collector));
        pass = route::write_pass(path, name, options, &gcode, &found, into)?;
    }
    let warnings = route::outcome_warnings(path, name, options, pass)?;
    Ok((collector.into_pieces(), warnings))
}

/// Plans the G-code file at `path` into chunks of at most `chunk` pieces, each handed to
/// `sink` as it fills, while planning goes on. A pass of the front end alone first finds
/// the axes and units (a chunk handed on cannot be taken back, as a pipe's text cannot),
/// then one pass plans. Returns the warnings and notes, or the first failure (after the
/// chunks before it).
pub fn stream_file(
    path: &std::path::Path,
    name: &str,
    options: &CompileOptions,
    chunk: usize,
    sink: Box<ChunkSink<'_>>,
) -> Result<Vec<Report>, Failure> {
    let gcode = front::gcode_options(options);
    let mut moved = MovedAxes::default();
    let summary = route::compile_read(path, name, &gcode, &mut moved)?;
    let layout = Layout {
        axes: moved.axes(),
        units: summary.units,
    };
    let mut collector = Collector::chunked(chunk, sink);
    let into = Out::Into(Box::new(&mut collector));
    let pass = route::write_pass(path, name, options, &gcode, &layout, into)?;
    route::outcome_warnings(path, name, options, pass)
}

/// Compiles `source`, held in memory, as [`crate::compile`] does, and keeps its pieces as
/// the writer received them; the warnings and notes.
pub fn plan_source(
    source: &Source,
    options: &CompileOptions,
) -> Result<(Pieces, Vec<Report>), Failure> {
    let compiled = crate::route::compile(source, options)?;
    Ok((Pieces::of_program(&compiled.program), compiled.warnings))
}

/// Hands `pieces` on in chunks of at most `chunk`, as [`stream_file`] hands on a
/// streamed program's; stops when `sink` takes no more.
pub fn chunk_pieces(pieces: PiecesView<'_>, chunk: usize, sink: Box<ChunkSink<'_>>) {
    let mut collector = Collector::chunked(chunk, sink);
    let mut into = &mut collector;
    let emit = pvt_emit::EmitOptions::default();
    let header = Header {
        axes: &pieces.outline.axes,
        units: pieces.outline.units,
        interpolation: pieces.outline.interpolation,
        options: &emit,
    };
    // A closed sink stops the replay; there is nothing more to do then.
    let _ = into
        .begin(&header)
        .and_then(|()| pieces.replay_into(&mut into))
        .and_then(|()| into.finish());
}

/// True when `a` and `b` plan a program in `units` moving `axes` the same: the same
/// planner options, the same longest piece and grid, the same header settings. A
/// program planned under one is then written under the other from its pieces.
pub fn same_plan(
    a: &CompileOptions,
    b: &CompileOptions,
    units: Units,
    axes: &[Axis],
) -> Result<bool, Failure> {
    Ok(
        plan_options(a, units, axes)? == plan_options(b, units, axes)?
            && a.format.max_piece_seconds() == b.format.max_piece_seconds()
            && split_grid(a) == split_grid(b)
            && header_lines(a, units) == header_lines(b, units),
    )
}

/// The bytes `pvtc compile` writes for kept `pieces` of the source named `name`, in
/// `options.format` (with its PMAC settings and triggers), when the pieces were planned
/// under options that [`same_plan`] finds the same as `options`.
pub fn write_pieces(
    pieces: PiecesView<'_>,
    name: &str,
    options: &CompileOptions,
) -> Result<Vec<u8>, Failure> {
    let o = pieces.outline;
    let layout = (o.axes.as_slice(), o.units, o.interpolation);
    route::write_planned(name, options, layout, &mut |writer| pieces.replay(writer))
}

/// The geometry `source` was planned from, read again by its front end (for the path
/// error of `check`).
pub fn toolpath(source: &Source, options: &CompileOptions) -> Result<Toolpath, Failure> {
    let (input, _) = front::read(source, options)?;
    Ok(match input {
        Input::Toolpath(toolpath) => toolpath,
        Input::Series(series) => series.toolpath(),
    })
}

/// True when `options` read G-code, which [`plan_file`] and [`stream_file`] stream.
pub fn streams(options: &CompileOptions) -> bool {
    options.input == InputKind::Gcode
}

/// The diagnostics of `reports` as `--diagnostics json` prints them, repeats grouped.
pub fn diagnostics(reports: &[Report]) -> Vec<serde_json::Value> {
    crate::report::json_items(reports)
}
