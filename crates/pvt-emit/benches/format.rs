//! Cost of the back ends per piece: realistic three-axis pieces (positions like
//! 123.456789012, velocities of either sign, times like 0.0080117 s or whole
//! milliseconds) formatted by each writer into memory, alone and behind [`Checked`] (the
//! value checks, the controller rules and the totals the compile runs on every piece).
//!
//! ```sh
//! cargo bench -p pvt-emit --bench format
//! ```
//!
//! Criterion reports time per batch of [`PIECES`] pieces; divide by it for a piece, and
//! by seven more for a number of PMAC text (a time, three positions, three velocities).

use criterion::{criterion_main, Criterion, Throughput};
use pvt_core::{Axis, Interpolation, Motion, SegmentRef, Units};
use pvt_emit::{Checked, EmitOptions, Format, Header, ProgramWriter};
use std::hint::black_box;

/// Pieces per measured batch.
const PIECES: usize = 10_000;

/// Deterministic pieces: (end positions, end velocities, time, line).
type Piece = ([f64; 3], [f64; 3], f64, u32);

/// The states of a xorshift generator from `seed`.
fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state as f64 / u64::MAX as f64
    }
}

/// Pieces of a three-axis program: positions within ±500 units, velocities within
/// ±100 units/s (one axis in four at rest), times of 1–20 ms, off the grid or on it.
fn pieces(on_grid: bool) -> Vec<Piece> {
    let mut random = xorshift(0x9e37_79b9_7f4a_7c15);
    (0..PIECES)
        .map(|i| {
            let mut p = [0.0; 3];
            let mut v = [0.0; 3];
            for k in 0..3 {
                p[k] = (random() - 0.5) * 1000.0;
                v[k] = if random() < 0.25 {
                    0.0
                } else {
                    (random() - 0.5) * 200.0
                };
            }
            let t = 0.001 + random() * 0.019;
            let t = if on_grid {
                (t * 1000.0).round() / 1000.0
            } else {
                t
            };
            (p, v, t, i as u32 + 1)
        })
        .collect()
}

const AXES: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

fn header(options: &EmitOptions) -> Header<'_> {
    Header {
        axes: &AXES,
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        options,
    }
}

fn segment(piece: &Piece) -> SegmentRef<'_> {
    SegmentRef {
        end: &piece.0,
        velocity: &piece.1,
        duration: piece.2,
        line: piece.3,
    }
}

/// Bytes written by `format`'s writer for `pieces`, with or without [`Checked`].
fn write(format: Format, pieces: &[Piece], checked: bool, out: &mut Vec<u8>) -> usize {
    out.clear();
    let options = EmitOptions::default();
    let header = header(&options);
    let start = [0.0; 3];
    if checked {
        let mut writer = Checked::new(format.writer(&mut *out));
        writer.begin(&header).expect("begins");
        writer.contour(Motion::Feed, &start, 1).expect("starts");
        for piece in pieces {
            writer.segment(&segment(piece)).expect("writes");
        }
        writer.finish().expect("finishes");
    } else {
        let mut writer = format.writer(&mut *out);
        writer.begin(&header).expect("begins");
        writer.contour(Motion::Feed, &start).expect("starts");
        for piece in pieces {
            writer.segment(&segment(piece)).expect("writes");
        }
        writer.finish().expect("finishes");
    }
    out.len()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("format");
    group.sample_size(20);
    group.throughput(Throughput::Elements(PIECES as u64));
    let (off_grid, on_grid) = (pieces(false), pieces(true));
    let mut out = Vec::with_capacity(PIECES * 256);
    let cases = [
        ("pmac", Format::Pmac, false),
        ("pmac-checked", Format::Pmac, true),
        ("powerpmac", Format::PowerPmac, false),
        ("json", Format::Json, false),
        ("json-checked", Format::Json, true),
        ("movepvt", Format::MovePvt, false),
        ("movepvt-checked", Format::MovePvt, true),
    ];
    for (name, format, checked) in cases {
        for (grid, pieces) in [("off-grid", &off_grid), ("1ms", &on_grid)] {
            group.bench_function(format!("{name}/{grid}"), |b| {
                b.iter(|| write(format, black_box(pieces), checked, &mut out))
            });
        }
    }
    group.finish();
}

// criterion's macros define undocumented items.
#[allow(missing_docs)]
mod harness {
    criterion::criterion_group!(benches, super::bench);
}
criterion_main!(harness::benches);
