//! Golden tests of every planner on seed 001's series and seed 002's quad circle.

use super::*;
use crate::axis::Units;
use crate::discretize::ChordTolerance;
use crate::stream::{plan_timed, plan_toolpath, plan_toolpath_report, Planned};
use crate::toolpath::{Arc, ArcDirection, Contour, Element, ElementKind, Plane, Span, Toolpath};

const XY: [Axis; 2] = [Axis::X, Axis::Y];

fn series(dim: usize, points: &[f64], dt: f64) -> TimedPoints {
    let mut r = TimedPoints::start_at(&points[..dim]);
    for (i, p) in points.chunks(dim).skip(1).enumerate() {
        r.push(p, dt, i as u32 + 2);
    }
    r
}

fn options(planner: Planner) -> PlanOptions {
    PlanOptions {
        planner,
        accel: Some(1e6),
        ..PlanOptions::default()
    }
}

fn plan(points: &TimedPoints, axes: &[Axis], opts: &PlanOptions) -> Planned {
    plan_timed(points, axes.to_vec(), Units::Millimetre, opts).unwrap()
}

/// Seed 002's arrays, computed the way its C code computes them.
fn quad_circle(points: usize, slice: f64) -> (Vec<f64>, Vec<f64>) {
    // The C code's 3.14159265358979323 rounds to the same double as PI.
    let (radius, pi) = (1000.0_f64, std::f64::consts::PI);
    let degrees = 90.0 / points as f64;
    let mut position = vec![0.0; points * 2];
    for i in 0..points {
        position[2 * i] = radius * libm::cos((i + 1) as f64 * degrees * pi / 180.0);
        position[2 * i + 1] = radius * libm::sin((i + 1) as f64 * degrees * pi / 180.0);
    }
    let mut vel = vec![0.0; points * 2];
    for x in 0..(points - 1) * 2 {
        vel[x] = (position[x + 2] - position[x]) / slice;
    }
    (position, vel)
}

#[test]
fn chord_reproduces_the_quad_circle_arrays() {
    let (position, vel) = quad_circle(3000, 0.005);
    let mut input = TimedPoints::start_at(&[1000.0, 0.0]);
    for (i, p) in position.chunks(2).enumerate() {
        input.push(p, 0.005, i as u32 + 1);
    }
    let planned = plan(&input, &XY, &options(Planner::Chord));
    let c = &planned.program.contours[0];
    assert_eq!(c.ends, position);
    assert_eq!(c.velocities, vel);
    assert!(c.durations.iter().all(|&t| t == 0.005));
    assert_eq!(&vel[vel.len() - 2..], &[0.0, 0.0]);
}

/// AN208's method 1 as its text states it, computed here from the formula:
/// `V(n+1) = (X(n+1) − X(n)) / T(n)`, `V(0) = 0`, and the last velocity set to zero.
fn an208_backward(dim: usize, points: &[f64], dt: f64) -> Vec<f64> {
    let n = points.len() / dim;
    let mut v = vec![0.0; points.len()];
    for p in 0..n - 1 {
        for k in 0..dim {
            v[(p + 1) * dim + k] = (points[(p + 1) * dim + k] - points[p * dim + k]) / dt;
        }
    }
    v[(n - 1) * dim..].iter_mut().for_each(|x| *x = 0.0);
    v[dim..].to_vec()
}

#[test]
fn chord_back_is_an208_backward_difference_on_its_step_table() {
    // AN208 table 1: the step, points every 500 samples of 500 µs = 0.25 s.
    let step = [0.0, 0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0, 5000.0];
    let back = plan(
        &series(1, &step, 0.25),
        &[Axis::X],
        &options(Planner::ChordBack),
    );
    let c = &back.program.contours[0];
    assert_eq!(c.velocities, an208_backward(1, &step, 0.25));
    // The chord behind the point at 2000 samples (5000 counts in 0.25 s): 20000 counts/s
    // there, where the forward difference puts it on the point before.
    assert_eq!(c.velocities, vec![0.0, 0.0, 0.0, 20000.0, 0.0, 0.0, 0.0]);
    let forward = plan(
        &series(1, &step, 0.25),
        &[Axis::X],
        &options(Planner::Chord),
    );
    assert_eq!(
        forward.program.contours[0].velocities,
        vec![0.0, 0.0, 20000.0, 0.0, 0.0, 0.0, 0.0]
    );
}

#[test]
fn chord_back_gives_an208_zigzag_velocity_at_its_second_point() {
    // AN208's zigzag table: 5000,0 at 500 samples has Vx, Vy = 20000, 0: the chord behind
    // it (5000 counts in 0.25 s). The forward difference gives the chord ahead instead.
    let zigzag = [0.0, 0.0, 5000.0, 0.0, 0.0, 10000.0, 5000.0, 1000.0];
    let back = plan(&series(2, &zigzag, 0.25), &XY, &options(Planner::ChordBack));
    let c = &back.program.contours[0];
    assert_eq!(c.velocities, an208_backward(2, &zigzag, 0.25));
    assert_eq!(&c.velocities[..2], &[20000.0, 0.0]);
    let forward = plan(&series(2, &zigzag, 0.25), &XY, &options(Planner::Chord));
    assert_eq!(
        &forward.program.contours[0].velocities[..2],
        &[-20000.0, 40000.0]
    );
}

#[test]
fn chord_on_an_arc_with_a_time_slice_matches_seed_002() {
    let arc = Arc {
        plane: Plane::XY,
        center: [0.0, 0.0],
        direction: ArcDirection::CounterClockwise,
        extra_turns: 0,
    };
    let start = [1000.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let end = [0.0, 1000.0, 0.0, 0.0, 0.0, 0.0];
    let element = Element {
        kind: ElementKind::Arc(arc),
        start,
        end,
        feed: 100.0,
        span: Span::default(),
    };
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements: vec![element],
        }],
        ..Toolpath::default()
    };
    let opts = PlanOptions {
        planner: Planner::Chord,
        timing: Timing::TimeSlice(0.005),
        tolerance: ChordTolerance::new(0.001).unwrap(),
        ..PlanOptions::default()
    };
    let c = &plan_toolpath(&toolpath, &opts).unwrap().contours[0];
    let (position, vel) = quad_circle(556, 0.005);
    assert_eq!(c.len(), 556);
    for (a, b) in c.ends.iter().zip(&position) {
        assert!((a - b).abs() < 1e-9);
    }
    for (a, b) in c.velocities.iter().zip(&vel) {
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn pt_on_the_step_series_is_linear() {
    let step = [0.0, 0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0, 5000.0];
    let planned = plan(&series(1, &step, 0.25), &[Axis::X], &options(Planner::Pt));
    assert_eq!(planned.program.interpolation, Interpolation::Pt);
    let c = &planned.program.contours[0];
    assert_eq!(c.velocities, vec![0.0, 0.0, 0.0, 20000.0, 0.0, 0.0, 0.0]);
}

#[test]
fn const_accel_is_seed_001_method_2_and_ends_at_rest() {
    let pts = [0.0, 1.0, 3.0, 6.0, 7.0];
    let c = plan(
        &series(1, &pts, 0.5),
        &[Axis::X],
        &options(Planner::ConstAccel),
    )
    .program
    .contours
    .remove(0);
    // V1 = 2·1/0.5 − 0 = 4, V2 = 2·2/0.5 − 4 = 4, V3 = 2·3/0.5 − 4 = 8, last forced to 0.
    assert_eq!(c.velocities, vec![4.0, 4.0, 8.0, 0.0]);
    for i in 0..c.len() - 1 {
        assert!(
            c.hermite(i, 0).jerk.abs() < 1e-9,
            "piece {i} is not constant acceleration"
        );
    }
    assert!(c.hermite(c.len() - 1, 0).jerk.abs() > 1.0);
}

#[test]
fn spline_is_c2_and_through_the_points() {
    let pts = [0.0, 0.0, 3.0, 1.0, 5.0, -2.0, 9.0, 0.5, 12.0, 7.0];
    let mut input = series(2, &pts, 0.3);
    input.durations = vec![0.3, 0.7, 0.2, 0.5];
    let c = plan(&input, &XY, &options(Planner::Spline))
        .program
        .contours
        .remove(0);
    assert_eq!(c.ends, pts[2..].to_vec());
    assert_eq!(c.segment(c.len() - 1).velocity, &[0.0, 0.0]);
    for i in 1..c.len() {
        for k in 0..2 {
            let before = c.hermite(i - 1, k).end().acceleration;
            let after = c.hermite(i, k).at(0.0).acceleration;
            assert!(
                (before - after).abs() < 1e-9 * before.abs().max(1.0),
                "point {i} axis {k}"
            );
            let e = c.hermite(i - 1, k).end();
            assert!((e.position - c.segment(i - 1).end[k]).abs() < 1e-12);
        }
    }
    // Three points, equal times h: V1 = 3·(d0 + d1)/(4h).
    let three = plan(
        &series(1, &[0.0, 2.0, 6.0], 0.5),
        &[Axis::X],
        &options(Planner::Spline),
    );
    assert!((three.program.contours[0].velocities[0] - 3.0 * 6.0 / 2.0).abs() < 1e-12);
}

#[test]
fn given_velocities_are_used_as_given() {
    // Seed 001's zigzag with its table velocities.
    let pts = [0.0, 0.0, 5000.0, 0.0, 0.0, 10000.0, 5000.0, 1000.0];
    let mut input = series(2, &pts, 0.25);
    input.velocities = Some(vec![0.0, 0.0, 20000.0, 0.0, 20000.0, 0.0, 0.0, 0.0]);
    let planned = plan(&input, &XY, &options(Planner::Spline));
    assert_eq!(
        planned.program.contours[0].velocities,
        vec![20000.0, 0.0, 20000.0, 0.0, 0.0, 0.0]
    );
    assert!(!planned.report.velocities_ignored);
    assert!(
        plan(&input, &XY, &options(Planner::Lspb))
            .report
            .velocities_ignored
    );
}

#[test]
fn contour_takes_timed_points_as_feeds() {
    let step = [0.0, 0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0, 5000.0];
    let c = plan(
        &series(1, &step, 0.25),
        &[Axis::X],
        &options(Planner::Contour),
    )
    .program
    .contours
    .remove(0);
    // Dwells dropped: one rest-to-rest segment at 20000 counts/s peak.
    assert_eq!(c.len(), 1);
    assert!((c.durations[0] - 1.5 * 5000.0 / 20000.0).abs() < 1e-12);
}

/// Distance from `p` to the segment from `a` to `b` (two axes).
fn to_segment(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let u = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    let (x, y) = (a[0] + u * dx - p[0], a[1] + u * dy - p[1]);
    (x * x + y * y).sqrt()
}

#[test]
fn quantization_puts_every_piece_on_the_grid() {
    let pts = [0.0, 0.0, 3.0, 1.0, 5.0, -2.0, 9.0, 0.5, 12.0, 7.0];
    for planner in Planner::ALL {
        let mut input = series(2, &pts, 0.0);
        input.durations = vec![0.0304, 0.0517, 0.0222, 0.0405];
        let opts = PlanOptions {
            quantize: Some(0.001),
            accel: Some(5e4),
            ..options(planner)
        };
        let planned = plan(&input, &XY, &opts);
        let tol = opts.path_options().tolerance;
        let plain = plan(
            &input,
            &XY,
            &PlanOptions {
                quantize: None,
                ..opts
            },
        );
        let (q, p) = (&planned.program.contours[0], &plain.program.contours[0]);
        for &t in &q.durations {
            let k = t / 0.001;
            assert!(
                (k - k.round()).abs() < 1e-9 && t >= 0.001 - 1e-15,
                "{planner}: {t}"
            );
        }
        if planner == Planner::Lspb {
            // LSPB plans again on the grid: its blends start and end elsewhere along the
            // same lines, the run's end stays.
            assert_eq!(q.ends[q.ends.len() - 2..], p.ends[p.ends.len() - 2..]);
        } else if planner == Planner::Path {
            // The path planner may resample its motion in time onto the grid: its knots
            // are points of the planned motion, within the path tolerance of the
            // polyline, and the run's end stays.
            assert_eq!(q.ends[q.ends.len() - 2..], p.ends[p.ends.len() - 2..]);
            for end in q.ends.chunks(2) {
                let d = pts
                    .chunks(2)
                    .zip(pts.chunks(2).skip(1))
                    .map(|(a, b)| to_segment(end, a, b))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= tol, "{planner}: {end:?} is {d} from the polyline");
            }
        } else {
            assert_eq!(q.ends, p.ends, "{planner}: positions must not move");
        }
        assert!(planned.report.quantize_speed_change > 0.0, "{planner}");
        // LSPB's change is of its line speeds, which its short blends move most.
        let bound = if planner == Planner::Lspb { 0.5 } else { 0.2 };
        assert!(
            planned.report.quantize_speed_change < bound,
            "{planner}: {:?}",
            planned.report
        );
    }
}

#[test]
fn quantized_chord_is_chord_on_the_new_times() {
    let input = series(1, &[0.0, 1.0, 3.0, 4.0], 0.0104);
    let opts = PlanOptions {
        quantize: Some(0.001),
        ..options(Planner::Chord)
    };
    let c = plan(&input, &[Axis::X], &opts).program.contours.remove(0);
    assert!(c.durations.iter().all(|&t| (t - 0.011).abs() < 1e-15));
    assert!((c.velocities[0] - 2.0 / 0.011).abs() < 1e-9);
}

#[test]
fn options_are_checked() {
    let input = series(1, &[0.0, 1.0], 0.1);
    let err =
        |o: PlanOptions| plan_timed(&input, vec![Axis::X], Units::Millimetre, &o).unwrap_err();
    assert_eq!(
        err(PlanOptions {
            planner: Planner::Lspb,
            ..PlanOptions::default()
        }),
        PlanError::MissingAccel
    );
    assert_eq!(
        err(PlanOptions {
            quantize: Some(0.0),
            ..PlanOptions::default()
        })
        .code(),
        "pvtc::plan::bad_quantum"
    );
    assert_eq!(
        err(PlanOptions {
            accel: Some(-1.0),
            ..PlanOptions::default()
        })
        .code(),
        "pvtc::plan::bad_accel"
    );
    let sliced = PlanOptions {
        timing: Timing::TimeSlice(0.01),
        ..PlanOptions::default()
    };
    assert_eq!(
        check_options(&sliced).unwrap_err().code(),
        "pvtc::plan::unsupported_option"
    );
}

#[test]
fn every_planner_plans_a_toolpath_to_rest_at_its_end() {
    let line = |s: [f64; 2], e: [f64; 2], n: u32| Element {
        kind: ElementKind::Line,
        start: [s[0], s[1], 0.0, 0.0, 0.0, 0.0],
        end: [e[0], e[1], 0.0, 0.0, 0.0, 0.0],
        feed: 50.0,
        span: Span {
            start: 0,
            end: 0,
            line: n,
        },
    };
    let elements = vec![
        line([0.0, 0.0], [10.0, 0.0], 1),
        line([10.0, 0.0], [10.0, 5.0], 2),
        line([10.0, 5.0], [0.0, 5.0], 3),
    ];
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements,
        }],
        ..Toolpath::default()
    };
    for planner in Planner::ALL {
        let planned = plan_toolpath_report(&toolpath, &options(planner)).unwrap();
        let c = &planned.program.contours[0];
        assert_eq!(c.segment(c.len() - 1).end, &[0.0, 5.0], "{planner}");
        if planner != Planner::Pt {
            assert_eq!(c.segment(c.len() - 1).velocity, &[0.0, 0.0], "{planner}");
        }
        if matches!(planner, Planner::Pt | Planner::Chord | Planner::Spline) {
            // Times from the feed: chord / feed.
            assert!((c.total_time() - 25.0 / 50.0).abs() < 1e-12, "{planner}");
        }
    }
}
