//! Properties of the LSPB planner over random runs: collinear points at one speed (empty
//! blends), points close together (tiny segments), short times (raised segments), any
//! acceleration, with and without a 1 ms quantum (rounding up or to the nearest). Every piece lasts at least 0.1 µs (or a
//! whole, positive number of quanta), no axis of any piece's cubic exceeds the limit, and
//! the run ends at rest on its last point.

use proptest::prelude::*;
use pvt_core::plan::quantize::Quantum;
use pvt_core::plan::{plan_lspb, Rounding, TimedPoints, MIN_PIECE_SECONDS};
use pvt_core::{Motion, PvtContour};

/// Largest |a| at either end of each axis of each piece, with the f64 rounding bound.
fn accels(c: &PvtContour) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let (mut p0, mut v0) = (c.start.clone(), vec![0.0; c.dim]);
    for seg in c.segments() {
        let t = seg.duration;
        for k in 0..c.dim {
            let d = seg.end[k] - p0[k];
            let a0 = 6.0 * d / (t * t) - (4.0 * v0[k] + 2.0 * seg.velocity[k]) / t;
            let a1 = -6.0 * d / (t * t) + (2.0 * v0[k] + 4.0 * seg.velocity[k]) / t;
            let p = p0[k].abs().max(seg.end[k].abs());
            let v = v0[k].abs().max(seg.velocity[k].abs());
            let rounding = 32.0 * f64::EPSILON * (6.0 * p / (t * t) + 6.0 * v / t);
            out.push((a0.abs().max(a1.abs()), rounding));
        }
        p0 = seg.end.to_vec();
        v0 = seg.velocity.to_vec();
    }
    out
}

/// How the next point is made: a random step, the last step again (collinear, same speed
/// when its time is the same), or a tiny step.
#[derive(Debug, Clone, Copy)]
enum Step {
    Random(f64, f64),
    Again,
    Tiny(f64, f64),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        3 => (-1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y)| Step::Random(x, y)),
        1 => Just(Step::Again),
        1 => (-1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y)| Step::Tiny(x, y)),
    ]
}

fn run(scale: f64, steps: &[(Step, f64)]) -> TimedPoints {
    let mut r = TimedPoints::start_at(&[0.0, 0.0]);
    let (mut p, mut d) = ([0.0, 0.0], [scale, 0.0]);
    for (i, &(s, t)) in steps.iter().enumerate() {
        d = match s {
            Step::Random(x, y) => [x * scale, y * scale],
            Step::Again => d,
            Step::Tiny(x, y) => [x * scale * 1e-9, y * scale * 1e-9],
        };
        p = [p[0] + d[0], p[1] + d[1]];
        r.push(&p, t, i as u32 + 1);
    }
    r
}

proptest! {
    #[test]
    fn pieces_are_long_enough_and_within_the_limit(
        scale in prop_oneof![Just(1e-3), Just(1.0), Just(1e3)],
        steps in prop::collection::vec(
            (step(), prop_oneof![Just(1e-6), Just(1e-3), 1e-3..1.0f64, Just(0.5)]),
            1..12,
        ),
        accel in prop_oneof![Just(1.0), Just(1e3), Just(1e5), Just(1e7)],
        quantum in prop_oneof![
            Just(None),
            Just(Some(Quantum { seconds: 0.001, rounding: Rounding::Up })),
            Just(Some(Quantum { seconds: 0.001, rounding: Rounding::Nearest })),
        ],
    ) {
        let points = run(scale, &steps);
        let plan = plan_lspb(&points, accel, quantum, Motion::Feed);
        let c = &plan.contour;
        prop_assert!(!c.is_empty());
        for &t in &c.durations {
            match quantum {
                None => prop_assert!(t >= MIN_PIECE_SECONDS, "{t}"),
                Some(q) => {
                    let n = t / q.seconds;
                    prop_assert!(n >= 1.0 - 1e-9 && (n - n.round()).abs() <= 1e-9 * n, "{t}");
                }
            }
        }
        for (a, rounding) in accels(c) {
            prop_assert!(a <= accel * (1.0 + 1e-9) + rounding, "|a| {a} > {accel} (+{rounding})");
        }
        let last = c.len() - 1;
        prop_assert_eq!(c.segment(last).end, points.point(points.len() - 1));
        prop_assert_eq!(c.segment(last).velocity, &[0.0, 0.0][..]);
    }
}
