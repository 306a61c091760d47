//! Long pieces cut along their own cubic, for controllers with a largest piece time.
//!
//! Owns cutting a PVT piece longer than a given time (Turbo PMAC: 4095 ms) into sub-pieces
//! that move exactly as the piece did. Each boundary is the state (position and velocity
//! of every axis) of the piece's own cubic at that time, and the cubic restricted to a
//! sub-interval is the unique cubic through the states at its ends, so a controller builds
//! the same motion from the sub-pieces as from the piece. The last sub-piece ends on the
//! piece's own end state, bit for bit. It must not re-plan, and it must not touch a piece
//! that is short enough: such pieces pass through unchanged.
//!
//! Sub-piece times:
//! - without a quantum, a piece of time `T` becomes `n = ⌈T / max⌉` pieces of `T / n`
//!   (one more where rounding puts `T / n` above `max`);
//! - with a quantum `q` (a `--quantize` grid, or the time a controller rounds to: PMAC's
//!   whole ms), a piece of `m` quanta becomes `n = ⌈m / k⌉` pieces of whole quanta,
//!   `k = ⌊max / q⌋`, as equal as whole quanta allow (the first `m mod n` one quantum
//!   longer), so a time on the grid stays on it; a piece whose time is not on the grid is
//!   cut as without a quantum.
//!
//! A piece that would need more than [`MAX_SUB_PIECES`] sub-pieces (or whose time is not a
//! finite number) is left whole: a back end with a largest piece time refuses it.
//!
//! For PVT contours only: a PT piece is not a cubic.

use crate::axis::AXIS_COUNT;
use crate::hermite::HermiteSegment;
use crate::plan::quantize::quanta_time;
use crate::program::{PvtContour, SegmentRef};

/// Most sub-pieces one piece is cut into (over 49 days at 4095 ms each).
pub const MAX_SUB_PIECES: usize = 1 << 20;

/// How one piece is cut.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cuts {
    /// `n` pieces of equal time.
    Equal { n: usize },
    /// `m` quanta of `q` seconds in `n` pieces of whole quanta.
    Quanta { q: f64, m: u64, n: u64 },
}

impl Cuts {
    fn count(self) -> usize {
        match self {
            Cuts::Equal { n } => n,
            Cuts::Quanta { n, .. } => n as usize,
        }
    }

    /// The end time of sub-piece `k` (1-based) and its duration, for a piece of time `t`.
    fn sub_piece(self, k: usize, t: f64) -> (f64, f64) {
        match self {
            Cuts::Equal { n } => {
                let h = t / n as f64;
                (k as f64 * h, h)
            }
            Cuts::Quanta { q, m, n } => {
                let (base, longer) = (m / n, m % n);
                let k = k as u64;
                let before = k * base + k.min(longer);
                let own = base + u64::from(k <= longer);
                (quanta_time(before as f64, q), quanta_time(own as f64, q))
            }
        }
    }
}

/// Cuts the pieces of a stream as they come; [`split_long_pieces`] for a whole contour.
#[derive(Debug, Clone)]
pub struct PieceSplitter {
    max_seconds: f64,
    quantum: Option<f64>,
    /// Where the last piece ended, and its end velocity.
    position: AxisValues,
    velocity: AxisValues,
    /// One sub-piece's end state, reused.
    end: Vec<f64>,
    end_velocity: Vec<f64>,
}

/// A value per axis, kept in place for up to [`AXIS_COUNT`] axes (copied without a call
/// into `memcpy`, which a piece's few values do not pay for), in a vector for more.
#[derive(Debug, Clone)]
struct AxisValues {
    len: usize,
    inline: [f64; AXIS_COUNT],
    spilled: Vec<f64>,
}

impl AxisValues {
    fn new() -> AxisValues {
        AxisValues {
            len: 0,
            inline: [0.0; AXIS_COUNT],
            spilled: Vec::new(),
        }
    }

    /// Keeps `values`.
    #[inline]
    fn set(&mut self, values: &[f64]) {
        self.len = values.len();
        let inline = &mut self.inline;
        // Each length its own fixed-size copy.
        match values.len() {
            1 => inline[..1].copy_from_slice(values),
            2 => inline[..2].copy_from_slice(values),
            3 => inline[..3].copy_from_slice(values),
            4 => inline[..4].copy_from_slice(values),
            5 => inline[..5].copy_from_slice(values),
            6 => inline[..6].copy_from_slice(values),
            _ => {
                self.spilled.clear();
                self.spilled.extend_from_slice(values);
            }
        }
    }

    /// `len` zeros.
    fn set_zeros(&mut self, len: usize) {
        self.len = len;
        self.inline = [0.0; AXIS_COUNT];
        self.spilled.clear();
        if len > AXIS_COUNT {
            self.spilled.resize(len, 0.0);
        }
    }

    /// The values kept.
    fn get(&self) -> &[f64] {
        match self.inline.get(..self.len) {
            Some(values) => values,
            None => &self.spilled,
        }
    }
}

impl PieceSplitter {
    /// A splitter into pieces of at most `max_seconds` (on the `quantum` grid if given).
    pub fn new(max_seconds: f64, quantum: Option<f64>) -> PieceSplitter {
        PieceSplitter {
            max_seconds,
            quantum,
            position: AxisValues::new(),
            velocity: AxisValues::new(),
            end: Vec::new(),
            end_velocity: Vec::new(),
        }
    }

    /// Starts a contour at rest at `start`.
    pub fn start(&mut self, start: &[f64]) {
        self.position.set(start);
        self.velocity.set_zeros(start.len());
    }

    /// Whether [`PieceSplitter::push`] passes `seg` on whole, uncut.
    #[inline]
    pub fn passes_whole(&self, seg: &SegmentRef<'_>) -> bool {
        self.cuts(seg.duration).is_none() || self.position.len != seg.end.len()
    }

    /// Passes `seg` (the next piece of the contour) to `emit`, cut where it is too long.
    #[inline]
    pub fn push<F: FnMut(&SegmentRef<'_>)>(&mut self, seg: &SegmentRef<'_>, emit: &mut F) {
        match self.cuts(seg.duration) {
            Some(cuts) if self.position.len == seg.end.len() => self.cut(seg, cuts, emit),
            _ => emit(seg),
        }
        self.position.set(seg.end);
        self.velocity.set(seg.velocity);
    }

    /// Passes `seg` to `emit` as the sub-pieces `cuts` says.
    #[cold]
    fn cut<F: FnMut(&SegmentRef<'_>)>(&mut self, seg: &SegmentRef<'_>, cuts: Cuts, emit: &mut F) {
        let dim = seg.end.len();
        let n = cuts.count();
        let (position, velocity) = (self.position.get(), self.velocity.get());
        let cubics: Vec<HermiteSegment> = (0..dim)
            .map(|k| {
                HermiteSegment::new(
                    position[k],
                    velocity[k],
                    seg.end[k],
                    seg.velocity[k],
                    seg.duration,
                )
            })
            .collect();
        self.end.resize(dim, 0.0);
        self.end_velocity.resize(dim, 0.0);
        for k in 1..=n {
            let (at, duration) = cuts.sub_piece(k, seg.duration);
            if k == n {
                self.end.copy_from_slice(seg.end);
                self.end_velocity.copy_from_slice(seg.velocity);
            } else {
                for (axis, cubic) in cubics.iter().enumerate() {
                    let state = cubic.at(at);
                    self.end[axis] = state.position;
                    self.end_velocity[axis] = state.velocity;
                }
            }
            emit(&SegmentRef {
                end: &self.end,
                velocity: &self.end_velocity,
                duration,
                line: seg.line,
            });
        }
    }

    /// How a piece of `t` seconds is cut; `None` to leave it whole.
    #[inline]
    fn cuts(&self, t: f64) -> Option<Cuts> {
        // A piece no longer than the longest (the usual case) is answered first.
        if t > self.max_seconds {
            self.long_cuts(t)
        } else {
            None
        }
    }

    /// [`PieceSplitter::cuts`] for a piece longer than the longest.
    #[cold]
    fn long_cuts(&self, t: f64) -> Option<Cuts> {
        let max = self.max_seconds;
        if !(t > max && t.is_finite() && max.is_finite() && max > 0.0) {
            return None;
        }
        if let Some(q) = self.quantum.filter(|q| q.is_finite() && *q > 0.0) {
            let quanta = t / q;
            let m = quanta.round();
            let per_piece = (max / q + 1e-9).floor();
            if (quanta - m).abs() <= 1e-6 && per_piece >= 1.0 && m < 1e15 {
                let (m, per_piece) = (m as u64, per_piece as u64);
                let n = m.div_ceil(per_piece);
                return (n > 1 && n as usize <= MAX_SUB_PIECES).then_some(Cuts::Quanta { q, m, n });
            }
        }
        let mut n = (t / max).ceil();
        if n > MAX_SUB_PIECES as f64 {
            return None;
        }
        while t / n > max {
            n += 1.0;
        }
        let n = n as usize;
        (n > 1 && n <= MAX_SUB_PIECES).then_some(Cuts::Equal { n })
    }
}

/// `contour` with every piece longer than `max_seconds` cut along its own cubic (see the
/// module documentation); `quantum` keeps times that are on its grid on it.
pub fn split_long_pieces(
    contour: &PvtContour,
    max_seconds: f64,
    quantum: Option<f64>,
) -> PvtContour {
    let mut splitter = PieceSplitter::new(max_seconds, quantum);
    splitter.start(&contour.start);
    let mut out = PvtContour::new(contour.motion, contour.start.clone());
    for seg in contour.segments() {
        splitter.push(&seg, &mut |sub| {
            out.push(sub.end, sub.velocity, sub.duration, sub.line);
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::Motion;

    /// Position and velocity of every axis at time `t` from the contour's start.
    fn state_at(c: &PvtContour, t: f64) -> Vec<(f64, f64)> {
        let mut begin = 0.0;
        for i in 0..c.len() {
            let end = begin + c.durations[i];
            if t <= end || i + 1 == c.len() {
                return (0..c.dim)
                    .map(|k| {
                        let s = c.hermite(i, k).at(t - begin);
                        (s.position, s.velocity)
                    })
                    .collect();
            }
            begin = end;
        }
        unreachable!("a contour with pieces")
    }

    fn sample() -> PvtContour {
        let mut c = PvtContour::new(Motion::Feed, vec![0.0, 5.0]);
        c.push(&[100.0, -3.0], &[0.7, -0.2], 900.0, 1);
        c.push(&[101.0, -3.5], &[0.0, 0.0], 2.0, 2);
        c.push(&[40.0, 20.0], &[0.0, 0.0], 12.3456789, 3);
        c
    }

    fn same_motion(a: &PvtContour, b: &PvtContour) {
        let total = a.total_time();
        assert!((b.total_time() - total).abs() <= 1e-9 * total);
        for s in 0..=20_000 {
            let t = total * f64::from(s) / 20_000.0;
            for ((pa, va), (pb, vb)) in state_at(a, t).into_iter().zip(state_at(b, t)) {
                assert!(
                    (pa - pb).abs() <= 1e-9 * pa.abs().max(1.0),
                    "t={t}: {pa} vs {pb}"
                );
                assert!(
                    (va - vb).abs() <= 1e-9 * va.abs().max(1.0),
                    "t={t}: {va} vs {vb}"
                );
            }
        }
    }

    #[test]
    fn long_pieces_become_equal_sub_pieces_with_the_same_motion() {
        let c = sample();
        let s = split_long_pieces(&c, 4.095, None);
        assert!(s.durations.iter().all(|&t| t <= 4.095), "{:?}", s.durations);
        // 900 s: 220 pieces of 4.0909 s; 2 s stays; 12.35 s: 4 pieces of 3.086 s.
        assert_eq!(s.len(), 220 + 1 + 4);
        assert!(s.durations[..220].iter().all(|&t| t == 900.0 / 220.0));
        assert_eq!(s.segment(219).end, c.segment(0).end);
        assert_eq!(s.segment(219).velocity, c.segment(0).velocity);
        assert_eq!(s.segment(220), c.segment(1));
        assert!(s.lines[..220].iter().all(|&l| l == 1));
        same_motion(&c, &s);
    }

    /// The last piece's state is kept in place up to six axes and in a vector beyond:
    /// contours of one to eight axes are cut along their own cubics alike.
    #[test]
    fn every_axis_count_is_cut_along_its_cubic() {
        for dim in 1..=8 {
            let at = |k: usize, x: f64| (0..dim).map(|a| x + (a + k) as f64).collect::<Vec<_>>();
            let mut c = PvtContour::new(Motion::Feed, at(0, 0.0));
            c.push(&at(1, 10.0), &at(1, 0.5), 9.5, 1);
            c.push(&at(2, 12.0), &at(2, -0.25), 2.0, 2);
            c.push(&at(3, -4.0), &vec![0.0; dim], 13.0, 3);
            let s = split_long_pieces(&c, 4.095, None);
            assert_eq!(s.len(), 3 + 1 + 4, "{dim} axes");
            assert_eq!(s.segment(2).end, c.segment(0).end);
            same_motion(&c, &s);
        }
    }

    #[test]
    fn quantized_pieces_stay_on_the_grid() {
        let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
        c.push(&[10.0], &[0.5], 9.001, 1);
        c.push(&[12.0], &[0.0], 4.095, 2);
        let s = split_long_pieces(&c, 4.095, Some(0.001));
        // 9001 quanta in 3 pieces: 3001 + 3000 + 3000; 4095 quanta stay whole.
        let ms: Vec<f64> = s.durations.iter().map(|t| t * 1000.0).collect();
        let whole: Vec<i64> = ms.iter().map(|m| m.round() as i64).collect();
        assert_eq!(whole, [3001, 3000, 3000, 4095]);
        for (m, w) in ms.iter().zip(&whole) {
            assert!((m - *w as f64).abs() < 1e-9, "{m}");
        }
        same_motion(&c, &s);
    }

    #[test]
    fn short_pieces_and_hopeless_ones_pass_through() {
        let mut c = PvtContour::new(Motion::Rapid, vec![1.0]);
        c.push(&[2.0], &[0.0], 4.095, 7);
        assert_eq!(split_long_pieces(&c, 4.095, None), c);
        for t in [f64::NAN, f64::INFINITY, 1e300] {
            let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
            c.push(&[1.0], &[0.0], t, 1);
            let s = split_long_pieces(&c, 4.095, Some(0.001));
            assert_eq!(s.len(), 1, "{t}");
        }
    }
}
