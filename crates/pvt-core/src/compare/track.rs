//! One program on the comparison's time axis.
//!
//! Owns the spans of a program in the order it runs them, each with its start time: the
//! pieces, and a rest for every dwell event (a format that writes a dwell as a piece at
//! rest, as XPS, Galil, Zaber and the CSV table do, holds it as a piece), so both
//! programs' times are the time the machine takes; each span's cubic on the compared
//! axes, in the compared scale (each axis' factor: the other program's units, or counts);
//! the span running at an instant and the position there. A program is held at its last
//! position after its end. It must not compare: `aligned` and `along` do.

use super::cubic::Local;
use crate::axis::{Axis, AXIS_COUNT};
use crate::program::{Interpolation, PvtProgram};
use crate::toolpath::EventKind;

/// What runs during a span: a piece (contour, index) or a rest at a position.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Runs {
    Piece { contour: usize, index: usize },
    Rest { at: usize },
}

/// One span of the time line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Span {
    /// Start, seconds from the program's start.
    pub start: f64,
    /// Length, seconds.
    pub duration: f64,
    /// The line it came from.
    pub line: u32,
    runs: Runs,
}

impl Span {
    /// End, seconds from the program's start.
    pub fn end(&self) -> f64 {
        self.start + self.duration
    }
}

/// A program laid out in time on the compared axes.
pub(super) struct Track<'a> {
    program: &'a PvtProgram,
    /// Per compared axis, the program's column of it (none: held at 0).
    columns: Vec<Option<usize>>,
    /// Per compared axis, the factor to the compared scale.
    factors: Vec<f64>,
    /// Rest positions (compared axes, scaled), flat.
    rests: Vec<f64>,
    /// The spans in time order.
    pub spans: Vec<Span>,
    /// When each contour starts (after the dwells before it), and the end.
    pub contour_starts: Vec<f64>,
    /// Total time, seconds.
    pub total: f64,
}

impl<'a> Track<'a> {
    /// Lays out `program` on `axes`, each scaled by its factor.
    pub fn new(program: &'a PvtProgram, axes: &[Axis], factors: &[f64]) -> Track<'a> {
        let columns = axes
            .iter()
            .map(|a| program.axes.iter().position(|b| b == a))
            .collect();
        let mut track = Track {
            program,
            columns,
            factors: factors.to_vec(),
            rests: Vec::new(),
            spans: Vec::with_capacity(program.segment_count()),
            contour_starts: Vec::with_capacity(program.contours.len() + 1),
            total: 0.0,
        };
        let mut events = program.events.iter().peekable();
        for c in 0..=program.contours.len() {
            while let Some(e) = events.next_if(|e| e.before_contour <= c) {
                if let EventKind::Dwell { seconds } = e.kind {
                    track.rest(c, seconds, e.line);
                }
            }
            track.contour_starts.push(track.total);
            if let Some(contour) = program.contours.get(c) {
                for index in 0..contour.len() {
                    let runs = Runs::Piece { contour: c, index };
                    track.push(contour.durations[index], contour.lines[index], runs);
                }
            }
        }
        track
    }

    fn push(&mut self, duration: f64, line: u32, runs: Runs) {
        let start = self.total;
        self.spans.push(Span {
            start,
            duration,
            line,
            runs,
        });
        self.total += duration;
    }

    /// A dwell of `seconds` before contour `c`, where the axes are then.
    fn rest(&mut self, c: usize, seconds: f64, line: u32) {
        if seconds.is_nan() || seconds <= 0.0 {
            return;
        }
        let here = self.place(c);
        let at = self.rests.len();
        self.rests.extend_from_slice(&here[..self.dim()]);
        self.push(seconds, line, Runs::Rest { at });
    }

    /// Where the axes rest before contour `c` (after the last: where it ends), on the
    /// compared axes and scale.
    pub fn place(&self, c: usize) -> [f64; AXIS_COUNT] {
        let contours = &self.program.contours;
        let here: Vec<f64> = match (
            contours.get(c),
            c.checked_sub(1).and_then(|p| contours.get(p)),
        ) {
            (Some(next), _) => next.start.clone(),
            (None, Some(last)) if !last.is_empty() => last.segment(last.len() - 1).end.to_vec(),
            (None, Some(last)) => last.start.clone(),
            (None, None) => vec![0.0; self.program.axes.len()],
        };
        let mut out = [0.0; AXIS_COUNT];
        for (k, column) in self.columns.iter().enumerate() {
            out[k] = column.map_or(0.0, |i| here[i]) * self.factors[k];
        }
        out
    }

    /// The instants at which the `counts[i]`-th piece ends (pieces, not rests; 0: the
    /// start), for counts in increasing order.
    pub fn after_pieces(&self, counts: &[usize]) -> Vec<f64> {
        let mut out = Vec::with_capacity(counts.len());
        let mut wanted = counts.iter().peekable();
        let mut pieces = 0;
        while let Some(&&n) = wanted.peek() {
            if n > pieces {
                break;
            }
            out.push(0.0);
            wanted.next();
        }
        for s in &self.spans {
            if let Runs::Piece { .. } = s.runs {
                pieces += 1;
            }
            while let Some(&&n) = wanted.peek() {
                if n > pieces {
                    break;
                }
                out.push(s.end());
                wanted.next();
            }
        }
        out.extend(wanted.map(|_| self.total));
        out
    }

    /// Number of compared axes.
    pub fn dim(&self) -> usize {
        self.columns.len()
    }

    /// The cubic of span `i` in its own local time (0 at its start).
    pub fn cubic(&self, i: usize) -> Local {
        let dim = self.dim();
        let mut out = Local::zero(dim);
        match self.spans[i].runs {
            Runs::Rest { at } => {
                for k in 0..dim {
                    out.c[k][0] = self.rests[at + k];
                }
            }
            Runs::Piece { contour, index } => {
                let c = &self.program.contours[contour];
                for (k, column) in self.columns.iter().enumerate() {
                    let Some(col) = *column else { continue };
                    let f = self.factors[k];
                    out.c[k] = match self.program.interpolation {
                        Interpolation::Pvt => {
                            let h = c.hermite(index, col);
                            [h.p0, h.v0, h.a0 / 2.0, h.jerk / 6.0]
                        }
                        Interpolation::Pt => {
                            let p0 = match index {
                                0 => c.start[col],
                                i => c.segment(i - 1).end[col],
                            };
                            let p1 = c.segment(index).end[col];
                            [p0, (p1 - p0) / c.durations[index], 0.0, 0.0]
                        }
                    }
                    .map(|x| x * f);
                }
            }
        }
        out
    }

    /// Where the program rests after its end (before its start: where it starts).
    pub fn final_rest(&self) -> Local {
        let mut out = Local::zero(self.dim());
        if let Some(last) = self.spans.len().checked_sub(1) {
            let s = &self.spans[last];
            let end = self.cubic(last).at(s.duration);
            for (c, x) in out.c.iter_mut().zip(end).take(self.dim()) {
                c[0] = x;
            }
        }
        out
    }

    /// Index of the span running at `t` (the last starting at or before it; the first
    /// before the start, the last after the end); `None` for a program without spans.
    pub fn span_at(&self, t: f64) -> Option<usize> {
        if self.spans.is_empty() {
            return None;
        }
        let i = self.spans.partition_point(|s| s.start <= t);
        Some(i.saturating_sub(1))
    }

    /// The cubic running from `t` on, in local time from `t`, and the line then.
    pub fn running_at(&self, t: f64) -> (Local, u32) {
        match self.span_at(t) {
            Some(i) if t < self.spans[i].end() => {
                let s = &self.spans[i];
                (self.cubic(i).shifted(t - s.start), s.line)
            }
            Some(i) => (self.final_rest(), self.spans[i].line),
            None => (Local::zero(self.dim()), 0),
        }
    }

    /// The position at `t`.
    pub fn position(&self, t: f64) -> [f64; AXIS_COUNT] {
        self.running_at(t).0.at(0.0)
    }

    /// The line of the span running up to `t`: at a knot, the piece that ends there,
    /// whose line writes the knot (the first span's at the start).
    pub fn line_to(&self, t: f64) -> u32 {
        let i = self.spans.partition_point(|s| s.start < t);
        self.spans.get(i.saturating_sub(1)).map_or(0, |s| s.line)
    }
}
