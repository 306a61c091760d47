//! The program laid out on one time axis, as the controller will run it.
//!
//! Owns the absolute start time of every piece and the evaluation of any axis at any
//! instant, for PVT (cubic Hermite pieces) and PT (straight pieces, velocity steps at the
//! points) alike, and [`Walk`]: the same evaluation at non-decreasing instants, in
//! constant memory, walking the pieces in order with each piece's cubics built once. It
//! must not judge the motion: the other check modules do.

use crate::hermite::HermiteSegment;
use crate::program::{Interpolation, PvtContour, PvtProgram};
use crate::toolpath::Motion;

/// One piece of the program with its place in time.
#[derive(Debug, Clone, Copy)]
pub(super) struct Piece {
    /// Index of its contour in the program.
    pub contour: usize,
    /// Index of the piece in its contour.
    pub index: usize,
    /// Absolute start time, seconds.
    pub start: f64,
    /// Piece time, seconds.
    pub duration: f64,
    /// Source line.
    pub line: u32,
    /// Rapid or feed.
    pub motion: Motion,
}

/// Every piece of a program in execution order.
pub(super) struct Timeline<'a> {
    pub program: &'a PvtProgram,
    pub pieces: Vec<Piece>,
    pub total: f64,
}

impl<'a> Timeline<'a> {
    /// Lays the contours of a program end to end in time.
    pub fn new(program: &'a PvtProgram) -> Timeline<'a> {
        let mut pieces = Vec::with_capacity(program.segment_count());
        let mut clock = 0.0;
        for (c, contour) in program.contours.iter().enumerate() {
            for (index, seg) in contour.segments().enumerate() {
                let (line, motion) = (seg.line, contour.motion);
                pieces.push(Piece {
                    contour: c,
                    index,
                    start: clock,
                    duration: seg.duration,
                    line,
                    motion,
                });
                clock += seg.duration;
            }
        }
        Timeline {
            program,
            pieces,
            total: clock,
        }
    }

    /// True when the machine rests before contour `c` starts: it is the first or past the
    /// last, or a dwell, a pause or a tool change comes between it and the contour
    /// before. Otherwise (spindle, coolant, messages, nothing) the contour follows the
    /// previous one straight on, and a servo loop sees one acceleration step between them.
    pub fn rests_before(&self, c: usize) -> bool {
        use crate::toolpath::EventKind;
        c == 0
            || c >= self.program.contours.len()
            || self.program.events.iter().any(|e| {
                e.before_contour == c
                    && matches!(
                        e.kind,
                        EventKind::Dwell { .. } | EventKind::Pause { .. } | EventKind::ToolChange
                    )
            })
    }

    /// True when the program is PT (straight pieces).
    pub fn is_pt(&self) -> bool {
        self.program.interpolation == Interpolation::Pt
    }

    fn contour(&self, p: &Piece) -> &'a PvtContour {
        &self.program.contours[p.contour]
    }

    /// Start position of a piece on axis column `k`.
    pub fn start_position(&self, p: &Piece, k: usize) -> f64 {
        let c = self.contour(p);
        if p.index == 0 {
            c.start[k]
        } else {
            c.segment(p.index - 1).end[k]
        }
    }

    /// End velocity of a PVT piece on axis column `k` (PT: the piece's own velocity).
    pub fn end_velocity(&self, p: &Piece, k: usize) -> f64 {
        self.contour(p).segment(p.index).velocity[k]
    }

    /// The cubic of a PVT piece (for PT, the straight line as a zero-acceleration cubic).
    pub fn cubic(&self, p: &Piece, k: usize) -> HermiteSegment {
        let c = self.contour(p);
        if self.is_pt() {
            let (p0, p1) = (self.start_position(p, k), c.segment(p.index).end[k]);
            let v = (p1 - p0) / p.duration;
            HermiteSegment {
                p0,
                v0: v,
                a0: 0.0,
                jerk: 0.0,
                duration: p.duration,
            }
        } else {
            c.hermite(p.index, k)
        }
    }

    /// Position of axis column `k` at `t` seconds into piece `p` (exact at both ends).
    pub fn position(&self, p: &Piece, k: usize, t: f64) -> f64 {
        if t >= p.duration {
            return self.contour(p).segment(p.index).end[k];
        }
        self.cubic(p, k).at(t.max(0.0)).position
    }

    /// Index of the piece running at absolute time `t` (the last one at or after the end),
    /// by binary search: what [`Walk::seek`] must agree with.
    #[cfg(test)]
    pub fn piece_at(&self, t: f64) -> Option<usize> {
        if self.pieces.is_empty() {
            return None;
        }
        let i = self.pieces.partition_point(|p| p.start <= t);
        Some(i.saturating_sub(1))
    }
}

/// Reads a program at non-decreasing instants (servo samples), in order: the piece running
/// at each instant is found by stepping forward from the last one, not by searching, and
/// its cubics are built once. The piece is the one a binary search over the starts finds
/// (the last one starting at or before the instant; piece times are not negative, so the
/// starts are in order) and a position is [`Timeline::position`]'s; its memory does not
/// grow with the number of instants read.
pub(super) struct Walk<'t, 'a> {
    tl: &'t Timeline<'a>,
    /// The piece running at the last instant sought.
    at: usize,
    /// The piece whose cubics and end positions are held, if any.
    loaded: Option<usize>,
    cubics: Vec<HermiteSegment>,
    ends: Vec<f64>,
}

impl<'t, 'a> Walk<'t, 'a> {
    /// A walk from the start of the program.
    pub fn new(tl: &'t Timeline<'a>) -> Walk<'t, 'a> {
        let dim = tl.program.axes.len();
        Walk {
            tl,
            at: 0,
            loaded: None,
            cubics: Vec::with_capacity(dim),
            ends: Vec::with_capacity(dim),
        }
    }

    /// Index of the piece running at `t` (not earlier than any instant sought before): the
    /// last one starting at or before `t`, the first before the start.
    pub fn seek(&mut self, t: f64) -> Option<usize> {
        let pieces = &self.tl.pieces;
        if pieces.is_empty() {
            return None;
        }
        while self.at + 1 < pieces.len() && pieces[self.at + 1].start <= t {
            self.at += 1;
        }
        Some(self.at)
    }

    /// Holds the cubics and end positions of piece `i`.
    fn load(&mut self, i: usize) -> &Piece {
        let p = &self.tl.pieces[i];
        if self.loaded != Some(i) {
            let dim = self.tl.program.axes.len();
            let end = self.tl.contour(p).segment(p.index).end;
            self.cubics.clear();
            self.cubics.extend((0..dim).map(|k| self.tl.cubic(p, k)));
            self.ends.clear();
            self.ends.extend_from_slice(&end[..dim]);
            self.loaded = Some(i);
        }
        p
    }

    /// Positions of every axis at absolute time `t` (held at rest before and after), as
    /// [`Timeline::position`] gives them in the piece running then.
    pub fn positions_at(&mut self, t: f64, out: &mut [f64]) {
        let Some(i) = self.seek(t) else { return };
        let p = *self.load(i);
        let t = t - p.start;
        for (k, o) in out.iter_mut().enumerate() {
            *o = if t >= p.duration {
                self.ends[k]
            } else {
                self.cubics[k].at(t.max(0.0)).position
            };
        }
    }

    /// Velocities of every axis `t` seconds into piece `i`.
    pub fn velocities(&mut self, i: usize, t: f64, out: &mut [f64]) {
        self.load(i);
        for (o, h) in out.iter_mut().zip(&self.cubics) {
            *o = h.at(t).velocity;
        }
    }
}
