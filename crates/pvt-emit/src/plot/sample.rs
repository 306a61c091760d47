//! Sampling a program's motion into series for plotting.
//!
//! Owns which instants are evaluated and the cap on how many: dense sampling of every
//! piece (both ends included) while the cap allows, otherwise the piece ends decimated
//! evenly. It must not draw, and it never changes a value of the program.

use pvt_core::{HermiteSegment, Interpolation, Motion, PvtContour, PvtProgram};

/// How densely [`sample_program`] samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleOptions {
    /// Samples per piece, both ends included (2 at least).
    pub per_piece: usize,
    /// Most samples in all; beyond it the piece ends are decimated evenly.
    pub max_samples: usize,
}

impl Default for SampleOptions {
    fn default() -> SampleOptions {
        SampleOptions {
            per_piece: 24,
            max_samples: 20_000,
        }
    }
}

/// Where a sample comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleAt {
    /// Rapid or feed, as the contour is.
    pub motion: Motion,
    /// Index of the contour in the program.
    pub contour: usize,
    /// Index of the segment in the contour; `None` for the rest a PT contour starts and
    /// ends with (its velocity steps from and to zero there).
    pub segment: Option<usize>,
}

/// The motion at a sequence of instants, in time order; vectors are flat, `dim` a sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Samples {
    /// Axes a sample.
    pub dim: usize,
    /// Program time of each sample, seconds from the start of the program.
    pub time: Vec<f64>,
    /// Axis positions.
    pub position: Vec<f64>,
    /// Axis velocities, units/s.
    pub velocity: Vec<f64>,
    /// Axis accelerations, units/s² (zero inside PT pieces).
    pub acceleration: Vec<f64>,
    /// Vector speed over the linear axes (over all axes when none is linear).
    pub speed: Vec<f64>,
    /// Where each sample comes from.
    pub at: Vec<SampleAt>,
    /// True when the cap made the sampling keep only some piece ends.
    pub decimated: bool,
}

impl Samples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Positions of sample `i`.
    pub fn position(&self, i: usize) -> &[f64] {
        &self.position[i * self.dim..(i + 1) * self.dim]
    }

    /// Velocities of sample `i`.
    pub fn velocity(&self, i: usize) -> &[f64] {
        &self.velocity[i * self.dim..(i + 1) * self.dim]
    }

    /// Accelerations of sample `i`.
    pub fn acceleration(&self, i: usize) -> &[f64] {
        &self.acceleration[i * self.dim..(i + 1) * self.dim]
    }
}

/// Samples the motion of `program` as the controller interpolates it.
///
/// Dense mode (when every piece can have 2 samples within the cap): each piece is
/// evaluated at evenly spaced instants from its start to its end, both included, so
/// the first sample of a piece is its start point and the last its end point. Beyond
/// the cap only piece ends are evaluated and every n-th is kept (and the very last).
pub fn sample_program(program: &PvtProgram, options: &SampleOptions) -> Samples {
    let mut sampler = Sampler::new(program);
    let pieces = program.segment_count();
    if pieces == 0 {
        return sampler.out;
    }
    let max = options.max_samples.max(2);
    let pt = program.interpolation == Interpolation::Pt;
    let rests = if pt { 2 * program.contours.len() } else { 0 };
    if pieces * 2 + rests <= max {
        let k = ((max - rests) / pieces).clamp(2, options.per_piece.max(2));
        sampler.dense(program, k, pt);
    } else {
        let raw = pieces + program.contours.len();
        sampler.sparse(program, raw.div_ceil(max - 1), raw);
    }
    sampler.out
}

/// Samples the motion of `program` every `period` seconds (finite, positive) from its
/// start to its end, as a servo loop reads it: instant `k · period` (computed so, not
/// summed, so that no error accumulates) is evaluated in the piece running then, the
/// last one starting at or before it, from the cubic the controller builds (PT: the
/// straight piece). Dwells add no time, as in `pvtc check`.
pub fn sample_every(program: &PvtProgram, period: f64) -> Samples {
    let mut sampler = Sampler::new(program);
    let total: f64 = program.contours.iter().map(PvtContour::total_time).sum();
    let mut k = 0u64;
    let pieces = program.segment_count();
    let mut seen = 0;
    for (c, contour) in program.contours.iter().enumerate() {
        for i in 0..contour.len() {
            seen += 1;
            let piece = Piece::new(contour, i, sampler.interpolation);
            let at = SampleAt {
                motion: contour.motion,
                contour: c,
                segment: Some(i),
            };
            let end = sampler.clock + piece.duration;
            loop {
                let t = k as f64 * period;
                let inside = t < end || (seen == pieces && t <= total);
                if !inside {
                    break;
                }
                let into = (t - sampler.clock).clamp(0.0, piece.duration);
                sampler.push(at, &piece, into, into >= piece.duration);
                if let Some(time) = sampler.out.time.last_mut() {
                    *time = t;
                }
                k += 1;
            }
            sampler.clock = end;
        }
    }
    sampler.out
}

/// Accumulates samples; owns the speed axes and the running program time.
struct Sampler {
    out: Samples,
    speed_axes: Vec<usize>,
    interpolation: Interpolation,
    clock: f64,
}

impl Sampler {
    fn new(program: &PvtProgram) -> Sampler {
        let linear: Vec<usize> = (0..program.axes.len())
            .filter(|&i| !program.axes[i].is_rotary())
            .collect();
        let speed_axes = if linear.is_empty() {
            (0..program.axes.len()).collect()
        } else {
            linear
        };
        Sampler {
            out: Samples {
                dim: program.axes.len(),
                ..Samples::default()
            },
            speed_axes,
            interpolation: program.interpolation,
            clock: 0.0,
        }
    }

    /// Every piece at `k` instants; PT contours also get their rest at both ends.
    fn dense(&mut self, program: &PvtProgram, k: usize, pt: bool) {
        for (c, contour) in program.contours.iter().enumerate() {
            let rest = SampleAt {
                motion: contour.motion,
                contour: c,
                segment: None,
            };
            if pt && !contour.is_empty() {
                self.push_rest(rest, &contour.start);
            }
            for i in 0..contour.len() {
                let piece = Piece::new(contour, i, self.interpolation);
                let at = SampleAt {
                    segment: Some(i),
                    ..rest
                };
                for j in 0..k {
                    let t = piece.duration * j as f64 / (k - 1) as f64;
                    self.push(at, &piece, t, j == k - 1);
                }
                self.clock += piece.duration;
            }
            if pt && !contour.is_empty() {
                self.push_rest(rest, contour.segment(contour.len() - 1).end);
            }
        }
    }

    /// Contour starts and piece ends, keeping every `stride`-th of `raw` and the last.
    fn sparse(&mut self, program: &PvtProgram, stride: usize, raw: usize) {
        self.out.decimated = true;
        let mut r = 0;
        for (c, contour) in program.contours.iter().enumerate() {
            for i in 0..contour.len() {
                let piece = Piece::new(contour, i, self.interpolation);
                let at = SampleAt {
                    motion: contour.motion,
                    contour: c,
                    segment: Some(i),
                };
                if i == 0 && r % stride == 0 {
                    self.push(at, &piece, 0.0, false);
                }
                r += usize::from(i == 0);
                if r % stride == 0 || r + 1 == raw {
                    self.push(at, &piece, piece.duration, true);
                }
                self.clock += piece.duration;
                r += 1;
            }
        }
    }

    /// The state `t` into `piece` (`end`: the piece's end, taken as stored for PT).
    fn push(&mut self, at: SampleAt, piece: &Piece, t: f64, end: bool) {
        let base = self.clock;
        self.out.time.push(base + t);
        for axis in 0..self.out.dim {
            let (p, v, a) = piece.eval(axis, t, end);
            self.out.position.push(p);
            self.out.velocity.push(v);
            self.out.acceleration.push(a);
        }
        self.finish(at);
    }

    /// A PT contour at rest at `position`.
    fn push_rest(&mut self, at: SampleAt, position: &[f64]) {
        self.out.time.push(self.clock);
        self.out.position.extend_from_slice(position);
        let zeros = std::iter::repeat_n(0.0, self.out.dim);
        self.out.velocity.extend(zeros.clone());
        self.out.acceleration.extend(zeros);
        self.finish(at);
    }

    /// Records where the last sample comes from and its vector speed.
    fn finish(&mut self, at: SampleAt) {
        let i = self.out.len() - 1;
        let v = self.out.velocity(i);
        let sq: f64 = self.speed_axes.iter().map(|&a| v[a] * v[a]).sum();
        self.out.speed.push(sq.sqrt());
        self.out.at.push(at);
    }
}

/// One segment of a contour, every axis, ready to evaluate.
struct Piece<'a> {
    hermites: Vec<HermiteSegment>,
    start: &'a [f64],
    end: &'a [f64],
    velocity: &'a [f64],
    duration: f64,
}

impl<'a> Piece<'a> {
    fn new(contour: &'a PvtContour, i: usize, interpolation: Interpolation) -> Piece<'a> {
        let seg = contour.segment(i);
        let start = if i == 0 {
            &contour.start[..]
        } else {
            contour.segment(i - 1).end
        };
        let hermites = match interpolation {
            Interpolation::Pvt => (0..contour.dim).map(|a| contour.hermite(i, a)).collect(),
            Interpolation::Pt => Vec::new(),
        };
        Piece {
            hermites,
            start,
            end: seg.end,
            velocity: seg.velocity,
            duration: seg.duration,
        }
    }

    /// Position, velocity and acceleration of `axis` at `t` into the piece.
    fn eval(&self, axis: usize, t: f64, end: bool) -> (f64, f64, f64) {
        if let Some(h) = self.hermites.get(axis) {
            let s = h.at(t);
            return (s.position, s.velocity, s.acceleration);
        }
        let (p0, p1) = (self.start[axis], self.end[axis]);
        let p = if end {
            p1
        } else {
            p0 + (p1 - p0) * (t / self.duration)
        };
        (p, self.velocity[axis], 0.0)
    }
}
