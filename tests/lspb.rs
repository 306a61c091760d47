//! The LSPB planner on every sample at `--accel 1e5`, with and without `--quantize 1ms`:
//! no piece shorter than the finest time an output prints (0.1 µs) or off the quantum
//! grid, and no axis of any emitted cubic above the acceleration limit (measured from
//! the program's own numbers, each piece on its own).

use pvt_core::{plan::MIN_PIECE_SECONDS, Planner, PvtProgram};
use pvt_emit::Format;
use pvtc::{CompileOptions, InputKind};
use pvtc_tests::{compile_file, samples};

const ACCEL: f64 = 1e5;

fn options(sample: &str, format: Format, quantize: Option<f64>) -> CompileOptions {
    let mut o = CompileOptions::new(format);
    o.input = InputKind::from_name(sample);
    if sample.ends_with(".dxf") {
        o.feed = Some(1200.0);
    }
    o.planner = Planner::Lspb;
    o.accel = Some(ACCEL);
    o.quantize = quantize;
    o
}

fn program(sample: &str, quantize: Option<f64>) -> PvtProgram {
    let json = compile_file(sample, &options(sample, Format::Json, quantize));
    pvt_emit::json::read(std::str::from_utf8(&json).unwrap()).unwrap()
}

/// The largest |acceleration| of each axis of each piece, at both ends of its cubic:
/// a(0) = 6(p1−p0)/T² − (4v0+2v1)/T, a(T) = −6(p1−p0)/T² + (2v0+4v1)/T; with what the
/// f64 rounding of the piece's own numbers can add to it.
fn piece_accels(program: &PvtProgram) -> Vec<(f64, f64, String)> {
    let mut out = Vec::new();
    for (c, contour) in program.contours.iter().enumerate() {
        let mut p0 = contour.start.clone();
        let mut v0 = vec![0.0; contour.dim];
        for (i, seg) in contour.segments().enumerate() {
            let t = seg.duration;
            for k in 0..contour.dim {
                let (p1, v1) = (seg.end[k], seg.velocity[k]);
                let d = p1 - p0[k];
                let a0 = 6.0 * d / (t * t) - (4.0 * v0[k] + 2.0 * v1) / t;
                let a1 = -6.0 * d / (t * t) + (2.0 * v0[k] + 4.0 * v1) / t;
                let p = p0[k].abs().max(p1.abs());
                let v = v0[k].abs().max(v1.abs());
                let rounding = 32.0 * f64::EPSILON * (6.0 * p / (t * t) + 6.0 * v / t);
                out.push((
                    a0.abs().max(a1.abs()),
                    rounding,
                    format!(
                        "contour {c} piece {i} axis {k} (T = {t} s, line {})",
                        seg.line
                    ),
                ));
            }
            p0 = seg.end.to_vec();
            v0 = seg.velocity.to_vec();
        }
    }
    out
}

fn all_samples() -> Vec<String> {
    let mut all = samples("gcode", ".ngc");
    all.extend(samples("dxf", ".dxf"));
    all.extend(samples("csv", ".csv"));
    all
}

#[test]
fn no_piece_is_shorter_than_the_output_resolution() {
    for sample in all_samples() {
        for quantize in [None, Some(0.001)] {
            let p = program(&sample, quantize);
            let least = quantize.unwrap_or(MIN_PIECE_SECONDS);
            for (c, contour) in p.contours.iter().enumerate() {
                for (i, &t) in contour.durations.iter().enumerate() {
                    assert!(
                        t >= least * (1.0 - 1e-9),
                        "{sample} {quantize:?}: contour {c} piece {i} lasts {t} s"
                    );
                    if let Some(q) = quantize {
                        let quanta = t / q;
                        assert!(
                            (quanta - quanta.round()).abs() < 1e-9,
                            "{sample}: contour {c} piece {i} lasts {t} s, off the grid"
                        );
                    }
                }
            }
            // Off the grid, a PMAC piece under 0.5 ms (which TA would round to no time)
            // is refused with its code; on it every piece prints a time.
            let o = options(&sample, Format::Pmac, quantize);
            let bytes = std::fs::read(pvtc_tests::root().join(&sample)).unwrap();
            let source = pvtc::Source {
                name: sample.clone(),
                bytes,
            };
            match pvtc::compile(&source, &o) {
                Ok(c) => {
                    let text = String::from_utf8(c.bytes).unwrap();
                    assert!(!text.contains("TA0.0000"), "{sample} {quantize:?}");
                }
                Err(f) => {
                    assert!(quantize.is_none(), "{sample}: {:?}", f.codes());
                    assert_eq!(f.codes(), ["pvtc::emit::piece_too_short"], "{sample}");
                }
            }
        }
    }
}

#[test]
fn no_axis_of_any_piece_exceeds_the_acceleration_limit() {
    for sample in all_samples() {
        for quantize in [None, Some(0.001)] {
            for (accel, rounding, at) in piece_accels(&program(&sample, quantize)) {
                assert!(
                    accel <= ACCEL * (1.0 + 1e-9) + rounding,
                    "{sample} {quantize:?}: {at}: |a| = {accel} (rounding {rounding})"
                );
            }
        }
    }
}

#[test]
fn quantizing_a_trapezoid_keeps_its_shape() {
    // 5000 mm in 0.25 s needs more than 1e5 mm/s²: the segment becomes a triangle of
    // 2·√(D/a) = 0.4472 s, two pieces; on the 1 ms grid, two pieces of 224 ms.
    let sample = "samples/gcode/an208_step.ngc";
    let exact = program(sample, None);
    let grid = program(sample, Some(0.001));
    assert_eq!(exact.contours[0].durations.len(), 2, "{exact:?}");
    assert_eq!(grid.contours[0].durations, [0.224, 0.224]);
    let peak = |p: &PvtProgram| p.contours[0].velocities[0].abs();
    assert!(
        peak(&grid) >= 0.99 * peak(&exact),
        "{} vs {}",
        peak(&grid),
        peak(&exact)
    );
}
