//! The PVT program: planned motion, ready for a back end.
//!
//! Owns contours of PVT segments (end position, end velocity, duration) on named axes.
//! It must not know how a controller spells them; that is the back ends' job.

use crate::axis::{Axis, Units};
use crate::hermite::HermiteSegment;
use crate::toolpath::{Motion, ProgramEvent};

/// A whole planned program.
#[derive(Debug, Clone, PartialEq)]
pub struct PvtProgram {
    /// The axes every position and velocity lists, in X Y Z A B C order.
    pub axes: Vec<Axis>,
    /// Units of every linear position (velocities are units per second).
    pub units: Units,
    /// How the controller moves between points.
    pub interpolation: Interpolation,
    /// Rest-to-rest contours in execution order.
    pub contours: Vec<PvtContour>,
    /// Events between contours (indices into `contours`), in order.
    pub events: Vec<ProgramEvent>,
}

impl PvtProgram {
    /// Total motion time in seconds.
    pub fn total_time(&self) -> f64 {
        self.contours.iter().map(PvtContour::total_time).sum()
    }

    /// Total number of segments.
    pub fn segment_count(&self) -> usize {
        self.contours.iter().map(PvtContour::len).sum()
    }
}

/// How a controller interpolates between the points of a program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Cubic Hermite pieces through position and velocity at both ends (PVT).
    #[default]
    Pvt,
    /// Constant velocity between points (PT); the velocities stored are each piece's.
    ///
    /// Segment `i`'s stored velocity is its own constant `(X(i+1) − X(i)) / T(i)`, not a
    /// velocity at its end point: the velocity steps at every point (from 0 at the start,
    /// to 0 after the last piece) and [`PvtContour::hermite`] does not apply.
    Pt,
}

/// One rest-to-rest run of segments, stored flat: segment `i`'s end position is
/// `ends[i * dim..(i + 1) * dim]`, likewise its end velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct PvtContour {
    /// Rapid or feed.
    pub motion: Motion,
    /// Axes per point.
    pub dim: usize,
    /// Where the axes are, at rest, before the first segment.
    pub start: Vec<f64>,
    /// End positions, flat.
    pub ends: Vec<f64>,
    /// End velocities (units/s), flat.
    pub velocities: Vec<f64>,
    /// Segment durations, seconds.
    pub durations: Vec<f64>,
    /// Source line of each segment.
    pub lines: Vec<u32>,
}

/// A borrowed view of one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentRef<'a> {
    /// End position of every axis.
    pub end: &'a [f64],
    /// End velocity of every axis, units/s.
    pub velocity: &'a [f64],
    /// Piece time, seconds.
    pub duration: f64,
    /// Source line.
    pub line: u32,
}

impl PvtContour {
    /// An empty contour starting at rest at `start`.
    pub fn new(motion: Motion, start: Vec<f64>) -> PvtContour {
        PvtContour {
            motion,
            dim: start.len(),
            start,
            ends: Vec::new(),
            velocities: Vec::new(),
            durations: Vec::new(),
            lines: Vec::new(),
        }
    }

    /// Appends a segment.
    pub fn push(&mut self, end: &[f64], velocity: &[f64], duration: f64, line: u32) {
        self.ends.extend_from_slice(end);
        self.velocities.extend_from_slice(velocity);
        self.durations.push(duration);
        self.lines.push(line);
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.durations.len()
    }

    /// True when the contour has no segment.
    pub fn is_empty(&self) -> bool {
        self.durations.is_empty()
    }

    /// Segment `i`.
    pub fn segment(&self, i: usize) -> SegmentRef<'_> {
        let r = i * self.dim..(i + 1) * self.dim;
        SegmentRef {
            end: &self.ends[r.clone()],
            velocity: &self.velocities[r],
            duration: self.durations[i],
            line: self.lines[i],
        }
    }

    /// All segments in order.
    pub fn segments(&self) -> impl Iterator<Item = SegmentRef<'_>> + '_ {
        (0..self.len()).map(|i| self.segment(i))
    }

    /// The cubic the controller builds for segment `i` on axis column `axis`.
    pub fn hermite(&self, i: usize, axis: usize) -> HermiteSegment {
        let seg = self.segment(i);
        let (p0, v0) = if i == 0 {
            (self.start[axis], 0.0)
        } else {
            let prev = self.segment(i - 1);
            (prev.end[axis], prev.velocity[axis])
        };
        HermiteSegment::new(p0, v0, seg.end[axis], seg.velocity[axis], seg.duration)
    }

    /// Sum of the segment durations, seconds.
    pub fn total_time(&self) -> f64 {
        self.durations.iter().sum()
    }
}
