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
//! (a piece of microseconds), the exact ones follow the spans. It must not know the page.

use pvt_core::{Axis, EventKind, HermiteSegment, Interpolation, PvtProgram};

/// Grid of piece times, seconds: 2⁻⁴⁰ s (under 10⁻¹² s).
pub const TIME_QUANTUM: f64 = 1.0 / 1_099_511_627_776.0;

/// Steps below the largest magnitude: positions 2⁻⁴⁰ of it, velocities 2⁻³⁰.
const POSITION_BITS: i32 = 40;
const VELOCITY_BITS: i32 = 30;

/// The grids of positions and velocities, powers of two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quanta {
    /// Position step, units.
    pub position: f64,
    /// Velocity step, units/s.
    pub velocity: f64,
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
    /// Grids fine enough for positions up to `largest_position` and velocities up to
    /// `largest_velocity` (absolute values).
    pub fn new(largest_position: f64, largest_velocity: f64) -> Quanta {
        Quanta {
            position: step(largest_position, POSITION_BITS),
            velocity: step(largest_velocity, VELOCITY_BITS),
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

/// Each axis' largest |a| and |j| over the pieces (exact, scaled): how far off the
/// page's own values may be.
fn scales(
    spans: &[Span<'_>],
    columns: &[Option<usize>],
    scale: &[f64],
    start: &[f64],
) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0f64, 0.0f64); columns.len()];
    let mut at: Vec<(f64, f64)> = start.iter().map(|p| (*p, 0.0)).collect();
    for span in spans {
        for (k, column) in columns.iter().enumerate() {
            let end = match (span.end, column) {
                (Some((e, v)), Some(i)) => (e[*i] * scale[k], v[*i] * scale[k]),
                (None, _) => (at[k].0, 0.0),
                (Some(_), None) => (0.0, 0.0),
            };
            if span.end.is_some() {
                let h = HermiteSegment::new(at[k].0, at[k].1, end.0, end.1, span.duration);
                let a1 = h.end().acceleration;
                out[k].0 = out[k].0.max(h.a0.abs()).max(a1.abs());
                out[k].1 = out[k].1.max(h.jerk.abs());
            }
            at[k] = end;
        }
    }
    out
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
        .map(|x| on_grid(*x, q.position))
        .collect();
    let spans = spans(program);
    let limits = scales(&spans, &columns, scale, &exact_start);
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
    let ratio = q.velocity / q.position;
    let pt = is_pt(program);
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
                Some(_) => (on_grid(exact.0, q.position), on_grid(exact.1, q.velocity)),
                None => (axle.p, 0),
            };
            // The velocity first: the position's prediction takes it.
            varint(&mut bytes, v1 - (2 * axle.v - axle.v_before));
            let mean = (d as f64 * TIME_QUANTUM * (axle.v + v1) as f64 * ratio / 2.0 + 0.5).floor();
            varint(&mut bytes, p1 - (axle.p + mean as i64));
            if span.end.is_some() && !pt {
                let page = page_cubic(
                    (axle.p as f64 * q.position, p1 as f64 * q.position),
                    (axle.v as f64 * q.velocity, v1 as f64 * q.velocity),
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
                let off = (page.0 - h.a0).abs() > 1e-7 * h.a0.abs() + 1e-9 * a_scale
                    || (page.1 - h.jerk).abs() > 1e-7 * h.jerk.abs() + 1e-9 * j_scale;
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
        let q = Quanta::new(1000.0, 100.0);
        assert_eq!(q.position, 1024.0 / (1u64 << 40) as f64);
        assert_eq!(q.velocity, 128.0 / (1u64 << 30) as f64);
        assert_eq!(Quanta::new(0.0, 0.0).position, 1.0 / (1u64 << 40) as f64);
    }
}
