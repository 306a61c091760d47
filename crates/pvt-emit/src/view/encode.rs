//! The page's data as compact streams of integers, and base64.
//!
//! Owns the encoding the page's script decodes (`view.js`, `decodeMotion`): every value
//! on a grid of a power of two (positions, velocities, piece times), each written as the
//! zigzag varint of its difference from a prediction made from values already written
//! (a piece time from the last, a position from the last and the mean velocity, a
//! velocity from the last two), so a program of 10⁶ pieces on three axes takes about
//! 15 bytes a piece before deflate. The predictions use only integers and one rounded
//! product, which the script repeats bit for bit. Where the page's start acceleration or
//! jerk of a piece, computed from those values as the script computes it, would be off
//! (a piece of microseconds), the exact ones follow the spans; then each block of
//! [`BLOCK`] spans' exact ranges of position, velocity, acceleration and jerk per axis,
//! which the page's tree of extremes starts from. It must not know the page.

use pvt_core::{Axis, EventKind, HermiteSegment, Interpolation, PvtProgram};

/// Grid of piece times, seconds: 2⁻⁴⁰ s (under 10⁻¹² s).
pub const TIME_QUANTUM: f64 = 1.0 / 1_099_511_627_776.0;

/// Steps below an axis' largest magnitude: positions 2⁻⁴⁰ of it, velocities 2⁻³².
const POSITION_BITS: i32 = 40;
const VELOCITY_BITS: i32 = 32;

/// How far the page's own start acceleration and jerk of a piece may be off, as shares
/// of the axis' largest |a| and |j|, before the exact ones are written: the peaks the
/// page shows are then within these shares of the program's.
const FIX_SHARE: (f64, f64) = (1e-7, 1e-6);

/// Each axis' grids of positions and velocities, powers of two.
#[derive(Debug, Clone, PartialEq)]
pub struct Quanta {
    /// Position step per axis, units.
    pub position: Vec<f64>,
    /// Velocity step per axis, units/s.
    pub velocity: Vec<f64>,
}

/// The power of two at or above `x` (1 for 0), times 2^-`bits`.
fn step(x: f64, bits: i32) -> f64 {
    let mut p = 1.0;
    if x.is_finite() && x > 0.0 {
        while p < x {
            p *= 2.0;
        }
        while p / 2.0 >= x {
            p /= 2.0;
        }
    }
    (0..bits).fold(p, |q, _| q / 2.0)
}

impl Quanta {
    /// Grids fine enough for each axis' positions up to its `largest` position and
    /// velocities up to its largest velocity (absolute values).
    pub fn new(largest: &[(f64, f64)]) -> Quanta {
        Quanta {
            position: largest.iter().map(|l| step(l.0, POSITION_BITS)).collect(),
            velocity: largest.iter().map(|l| step(l.1, VELOCITY_BITS)).collect(),
        }
    }
}

/// Appends a zigzag varint of `x`.
pub fn varint(out: &mut Vec<u8>, x: i64) {
    let mut z = ((x << 1) ^ (x >> 63)) as u64;
    while z >= 0x80 {
        out.push((z as u8) | 0x80);
        z >>= 7;
    }
    out.push(z as u8);
}

/// `x` on a grid of `q`, as an integer.
pub fn on_grid(x: f64, q: f64) -> i64 {
    (x / q).round() as i64
}

/// What a span is, as the script draws it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Feed = 0,
    Rapid = 1,
    Rest = 2,
}

/// One span of a program: a piece or a dwell at rest.
struct Span<'a> {
    kind: Kind,
    duration: f64,
    line: u32,
    end: Option<(&'a [f64], &'a [f64])>,
}

/// Every span of `program` in time order, dwells as rests.
fn spans(program: &PvtProgram) -> Vec<Span<'_>> {
    let mut out = Vec::with_capacity(program.segment_count());
    let mut events = program.events.iter().peekable();
    for c in 0..=program.contours.len() {
        while let Some(e) = events.next_if(|e| e.before_contour <= c) {
            if let EventKind::Dwell { seconds } = e.kind {
                if seconds > 0.0 {
                    out.push(Span {
                        kind: Kind::Rest,
                        duration: seconds,
                        line: e.line,
                        end: None,
                    });
                }
            }
        }
        let Some(contour) = program.contours.get(c) else {
            continue;
        };
        let kind = match contour.motion {
            pvt_core::Motion::Rapid => Kind::Rapid,
            pvt_core::Motion::Feed => Kind::Feed,
        };
        out.extend(contour.segments().map(|s| Span {
            kind,
            duration: s.duration,
            line: s.line,
            end: Some((s.end, s.velocity)),
        }));
    }
    out
}

/// The streams of one program, and what the script needs to read them.
pub struct Encoded {
    /// The bytes.
    pub bytes: Vec<u8>,
    /// Spans (pieces and dwells) written.
    pub spans: usize,
    /// Where the axes start, on the position grid.
    pub start: Vec<i64>,
}

/// The start acceleration and jerk of a piece as the page computes them from its grid
/// values (`view.js`, `coeffs`: the same operations in the same order, so the same
/// numbers).
fn page_cubic(p: (f64, f64), v: (f64, f64), t: f64) -> (f64, f64) {
    let (v0, v1) = v;
    let d = p.1 - p.0;
    let a0 = (6.0 * d) / (t * t) - (4.0 * v0 + 2.0 * v1) / t;
    let jerk = (6.0 * (v0 + v1)) / (t * t) - (12.0 * d) / (t * t * t);
    (a0, jerk)
}

/// One axis as the page rebuilds it (grid values) and as it is (exact, scaled).
#[derive(Debug, Clone, Copy, Default)]
struct Axle {
    p: i64,
    v: i64,
    v_before: i64,
    exact: (f64, f64),
}

/// The exact start acceleration and jerk of each axis' cubic of a piece, where the page's
/// own from its grid values would be off (a piece of microseconds at speed: its jerk is
/// the small difference of two large terms): the span, the axis and both values, which
/// the page takes instead.
type Fix = (usize, usize, f64, f64);

/// Spans a block of the page's tree of extremes holds.
pub const BLOCK: usize = 64;

/// The range of position, velocity, acceleration and jerk of a cubic over a whole piece
/// of `t` seconds: `[min, max]` each.
fn ranges(h: &HermiteSegment, t: f64) -> [[f64; 2]; 4] {
    let end = h.at(t);
    let (mut p, mut v) = (
        [h.p0.min(end.position), h.p0.max(end.position)],
        [h.v0.min(end.velocity), h.v0.max(end.velocity)],
    );
    let take = |range: &mut [f64; 2], x: f64| {
        range[0] = range[0].min(x);
        range[1] = range[1].max(x);
    };
    let inside = |s: f64| s > 0.0 && s < t;
    // Velocity turns where the acceleration is zero; position where the velocity is.
    if h.jerk != 0.0 && inside(-h.a0 / h.jerk) {
        take(&mut v, h.at(-h.a0 / h.jerk).velocity);
    }
    let (a, b, c) = (h.jerk / 2.0, h.a0, h.v0);
    let roots = match (a == 0.0, b * b - 4.0 * a * c) {
        (true, _) if b != 0.0 => [-c / b, f64::NAN],
        (false, disc) if disc >= 0.0 => {
            let r = disc.sqrt();
            [(-b - r) / (2.0 * a), (-b + r) / (2.0 * a)]
        }
        _ => [f64::NAN; 2],
    };
    for s in roots.into_iter().filter(|s| inside(*s)) {
        take(&mut p, h.at(s).position);
    }
    let a = [h.a0.min(end.acceleration), h.a0.max(end.acceleration)];
    [p, v, a, [h.jerk, h.jerk]]
}

/// What the encoder learns of the exact motion before writing it: each axis' largest
/// |a| and |j| (how far off the page's own values may be), and each block's ranges.
struct Extremes {
    scales: Vec<(f64, f64)>,
    /// Per axis, per block, the ranges of the four quantities.
    blocks: Vec<Vec<[[f64; 2]; 4]>>,
}

/// The exact motion's [`Extremes`] (scaled): every piece's cubic, every dwell at rest.
fn extremes(
    spans: &[Span<'_>],
    columns: &[Option<usize>],
    scale: &[f64],
    start: &[f64],
    pt: bool,
) -> Extremes {
    let dim = columns.len();
    let empty = [[f64::INFINITY, f64::NEG_INFINITY]; 4];
    let mut out = Extremes {
        scales: vec![(0.0f64, 0.0f64); dim],
        blocks: vec![vec![empty; spans.len().div_ceil(BLOCK)]; dim],
    };
    let mut at: Vec<(f64, f64)> = start.iter().map(|p| (*p, 0.0)).collect();
    for (n, span) in spans.iter().enumerate() {
        for (k, column) in columns.iter().enumerate() {
            let end = match (span.end, column) {
                (Some((e, v)), Some(i)) => (e[*i] * scale[k], v[*i] * scale[k]),
                (None, _) => (at[k].0, 0.0),
                (Some(_), None) => (0.0, 0.0),
            };
            let h = match (span.end, pt) {
                (None, _) => HermiteSegment::new(end.0, 0.0, end.0, 0.0, span.duration),
                (Some(_), true) => HermiteSegment {
                    p0: at[k].0,
                    v0: end.1,
                    a0: 0.0,
                    jerk: 0.0,
                    duration: span.duration,
                },
                (Some(_), false) => {
                    HermiteSegment::new(at[k].0, at[k].1, end.0, end.1, span.duration)
                }
            };
            let r = ranges(&h, span.duration);
            let block = &mut out.blocks[k][n / BLOCK];
            for (b, x) in block.iter_mut().zip(r) {
                b[0] = b[0].min(x[0]);
                b[1] = b[1].max(x[1]);
            }
            let s = &mut out.scales[k];
            s.0 = s.0.max(r[2][0].abs()).max(r[2][1].abs());
            s.1 = s.1.max(h.jerk.abs());
            at[k] = end;
        }
    }
    out
}

/// Appends each block's ranges as single floats rounded outwards (a range never
/// narrower than the motion's): per axis, per quantity, per block, min then max.
fn write_blocks(out: &mut Vec<u8>, blocks: &[Vec<[[f64; 2]; 4]>]) {
    for axis in blocks {
        for q in 0..4 {
            for b in axis {
                let [lo, hi] = b[q];
                let (mut l, mut h) = (lo as f32, hi as f32);
                if f64::from(l) > lo {
                    l = l.next_down();
                }
                if f64::from(h) < hi {
                    h = h.next_up();
                }
                out.extend_from_slice(&l.to_le_bytes());
                out.extend_from_slice(&h.to_le_bytes());
            }
        }
    }
}

/// Writes `program`'s spans on `axes` (an axis it does not move is at 0), each axis'
/// values times its `scale` (the view's units), on the grids `q`; then the fixes.
pub fn motion(program: &PvtProgram, axes: &[Axis], scale: &[f64], q: &Quanta) -> Encoded {
    let columns: Vec<Option<usize>> = axes
        .iter()
        .map(|a| program.axes.iter().position(|b| b == a))
        .collect();
    let first = program.contours.first().map(|c| c.start.as_slice());
    let exact_start: Vec<f64> = columns
        .iter()
        .zip(scale)
        .map(|(c, s)| c.zip(first).map_or(0.0, |(i, p)| p[i] * s))
        .collect();
    let start: Vec<i64> = exact_start
        .iter()
        .zip(&q.position)
        .map(|(x, step)| on_grid(*x, *step))
        .collect();
    let spans = spans(program);
    let pt = is_pt(program);
    let found = extremes(&spans, &columns, scale, &exact_start, pt);
    let limits = &found.scales;
    let mut axles: Vec<Axle> = start
        .iter()
        .zip(&exact_start)
        .map(|(p, e)| Axle {
            p: *p,
            exact: (*e, 0.0),
            ..Axle::default()
        })
        .collect();
    let (mut d_before, mut line_before, mut clock) = (0i64, 0i64, 0.0f64);
    let mut fixes: Vec<Fix> = Vec::new();
    let mut bytes = Vec::with_capacity(spans.len() * (2 + 4 * axes.len()));
    for (n, span) in spans.iter().enumerate() {
        let d = on_grid(span.duration, TIME_QUANTUM).max(1);
        varint(&mut bytes, d - d_before);
        varint(
            &mut bytes,
            4 * (i64::from(span.line) - line_before) + span.kind as i64,
        );
        (d_before, line_before) = (d, i64::from(span.line));
        let before = clock;
        clock += d as f64 * TIME_QUANTUM;
        let t = clock - before;
        for (k, axle) in axles.iter_mut().enumerate() {
            let exact = match (span.end, columns[k]) {
                (Some((end, velocity)), Some(i)) => (end[i] * scale[k], velocity[i] * scale[k]),
                (None, _) => (axle.exact.0, 0.0),
                (Some(_), None) => (0.0, 0.0),
            };
            let (p1, v1) = match span.end {
                Some(_) => (
                    on_grid(exact.0, q.position[k]),
                    on_grid(exact.1, q.velocity[k]),
                ),
                None => (axle.p, 0),
            };
            // The velocity first: the position's prediction takes it.
            varint(&mut bytes, v1 - (2 * axle.v - axle.v_before));
            let ratio = q.velocity[k] / q.position[k];
            let mean = (d as f64 * TIME_QUANTUM * (axle.v + v1) as f64 * ratio / 2.0 + 0.5).floor();
            varint(&mut bytes, p1 - (axle.p + mean as i64));
            if span.end.is_some() && !pt {
                let page = page_cubic(
                    (axle.p as f64 * q.position[k], p1 as f64 * q.position[k]),
                    (axle.v as f64 * q.velocity[k], v1 as f64 * q.velocity[k]),
                    t,
                );
                let h = HermiteSegment::new(
                    axle.exact.0,
                    axle.exact.1,
                    exact.0,
                    exact.1,
                    span.duration,
                );
                let (a_scale, j_scale) = limits[k];
                let off = (page.0 - h.a0).abs() > FIX_SHARE.0 * a_scale
                    || (page.1 - h.jerk).abs() > FIX_SHARE.1 * j_scale;
                if off {
                    fixes.push((n, k, h.a0, h.jerk));
                }
            }
            *axle = Axle {
                p: p1,
                v: v1,
                v_before: axle.v,
                exact,
            };
        }
    }
    write_fixes(&mut bytes, &fixes);
    write_blocks(&mut bytes, &found.blocks);
    Encoded {
        bytes,
        spans: spans.len(),
        start,
    }
}

/// Appends the fixes: their count, then each one's span (from the last), axis, start
/// acceleration and jerk (little-endian doubles).
fn write_fixes(out: &mut Vec<u8>, fixes: &[Fix]) {
    varint(out, fixes.len() as i64);
    let mut last = 0;
    for &(n, k, a0, jerk) in fixes {
        varint(out, (n - last) as i64);
        varint(out, k as i64);
        out.extend_from_slice(&a0.to_le_bytes());
        out.extend_from_slice(&jerk.to_le_bytes());
        last = n;
    }
}

/// Whether a program's stored velocities are its pieces' own (PT).
pub fn is_pt(program: &PvtProgram) -> bool {
    program.interpolation == Interpolation::Pt
}

/// Appends polylines (each its point count, whether a rapid, then its points as grid
/// differences from the last point written) of `points` (flat, `dim` a point).
pub fn polyline(
    out: &mut Vec<u8>,
    points: &[f64],
    dim: usize,
    rapid: bool,
    q: f64,
    last: &mut [i64],
) {
    varint(out, (points.len() / dim.max(1)) as i64);
    varint(out, i64::from(rapid));
    for p in points.chunks(dim.max(1)) {
        for (k, x) in p.iter().enumerate() {
            let g = on_grid(*x, q);
            varint(out, g - last[k]);
            last[k] = g;
        }
    }
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_is_rfc_4648() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn varints_are_zigzag() {
        let mut out = Vec::new();
        for x in [0, -1, 1, -64, 64, 1 << 40] {
            varint(&mut out, x);
        }
        assert_eq!(out[..6], [0, 1, 2, 127, 128, 1]);
    }

    #[test]
    fn grids_are_powers_of_two() {
        let q = Quanta::new(&[(1000.0, 100.0), (0.0, 0.0)]);
        assert_eq!(q.position[0], 1024.0 / (1u64 << 40) as f64);
        assert_eq!(q.velocity[0], 128.0 / (1u64 << 32) as f64);
        assert_eq!(q.position[1], 1.0 / (1u64 << 40) as f64);
    }
}
