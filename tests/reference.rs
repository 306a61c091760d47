//! An independent reference for what the motion must do: every piece evaluated as the
//! Bézier its end states define, distances measured to the true programmed lines, arcs
//! and helices, per-axis peaks computed from the control points.
//!
//! Written from the definitions, not from pvt-core's planners or `check`: a piece from
//! p0 (velocity v0) to p1 (v1) in time T is the cubic Bézier p0, p0 + v0·T/3,
//! p1 − v1·T/3, p1; its velocity is the quadratic Bézier of 3·(P[j+1] − P[j])/T and its
//! acceleration the line between 6·(P[j] − 2P[j+1] + P[j+2])/T² at the two ends, its
//! jerk the constant 6·(P₃ − 3P₂ + 3P₁ − P₀)/T³. Arcs
//! are measured with std's trigonometry (not libm) from centre, direction and turns;
//! Bézier elements from their Bernstein form (not pvt-core's de Casteljau).
#![allow(clippy::disallowed_methods)]

use pvt_core::{
    Arc, ArcDirection, Axis, Bezier, Element, ElementKind, PvtContour, PvtProgram, Toolpath,
};
use std::f64::consts::PI;

/// Points sampled inside every piece, besides both ends.
pub const SAMPLES: usize = 48;

/// Bézier control points of piece `i` of `c`, one `[f64; 4]` per axis.
pub fn control_points(c: &PvtContour, i: usize) -> Vec<[f64; 4]> {
    let seg = c.segment(i);
    let (p0, v0): (Vec<f64>, Vec<f64>) = if i == 0 {
        (c.start.clone(), vec![0.0; c.dim])
    } else {
        let prev = c.segment(i - 1);
        (prev.end.to_vec(), prev.velocity.to_vec())
    };
    let t = seg.duration;
    (0..c.dim)
        .map(|k| {
            [
                p0[k],
                p0[k] + v0[k] * t / 3.0,
                seg.end[k] - seg.velocity[k] * t / 3.0,
                seg.end[k],
            ]
        })
        .collect()
}

/// The point of a piece at parameter `u` ∈ [0, 1].
pub fn bezier(cp: &[[f64; 4]], u: f64) -> Vec<f64> {
    let w = [
        (1.0 - u).powi(3),
        3.0 * u * (1.0 - u).powi(2),
        3.0 * u * u * (1.0 - u),
        u.powi(3),
    ];
    cp.iter()
        .map(|c| (0..4).map(|j| w[j] * c[j]).sum())
        .collect()
}

/// The sampled points of piece `i`, both ends included.
pub fn piece_samples(c: &PvtContour, i: usize) -> Vec<Vec<f64>> {
    let cp = control_points(c, i);
    (0..=SAMPLES)
        .map(|s| bezier(&cp, s as f64 / SAMPLES as f64))
        .collect()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Distance from `p` to the segment a–b.
pub fn to_segment(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = b.iter().zip(a).map(|(x, y)| x - y).collect();
    let dd: f64 = d.iter().map(|x| x * x).sum();
    let t = if dd == 0.0 {
        0.0
    } else {
        let pa: f64 = p.iter().zip(a).zip(&d).map(|((p, a), d)| (p - a) * d).sum();
        (pa / dd).clamp(0.0, 1.0)
    };
    let q: Vec<f64> = a.iter().zip(&d).map(|(a, d)| a + t * d).collect();
    dist(p, &q)
}

/// An element's start and end on `axes`.
fn ends(e: &Element, axes: &[Axis]) -> (Vec<f64>, Vec<f64>) {
    let project = |q: &pvt_core::Position| axes.iter().map(|a| q[a.index()]).collect();
    (project(&e.start), project(&e.end))
}

/// An arc's start angle, signed sweep and radius, from its centre, direction and turns.
fn arc_angles(a: &Arc, e: &Element) -> (f64, f64, f64, f64) {
    let (u, v, _) = a.plane.axes();
    let (su, sv) = (
        e.start[u.index()] - a.center[0],
        e.start[v.index()] - a.center[1],
    );
    let (eu, ev) = (
        e.end[u.index()] - a.center[0],
        e.end[v.index()] - a.center[1],
    );
    let a0 = sv.atan2(su);
    let a1 = ev.atan2(eu);
    let tau = 2.0 * PI;
    let mut sweep = match a.direction {
        ArcDirection::CounterClockwise => (a1 - a0).rem_euclid(tau),
        ArcDirection::Clockwise => (a0 - a1).rem_euclid(tau),
    };
    if sweep <= 1e-12 * tau {
        sweep = tau;
    }
    sweep += tau * f64::from(a.extra_turns);
    if a.direction == ArcDirection::Clockwise {
        sweep = -sweep;
    }
    (a0, sweep, su.hypot(sv), eu.hypot(ev))
}

/// The point of an arc element on `axes` at fraction `f` of its sweep (true geometry:
/// radius and the other axes change linearly with the angle).
fn arc_point(a: &Arc, e: &Element, axes: &[Axis], f: f64) -> Vec<f64> {
    let (a0, sweep, r0, r1) = arc_angles(a, e);
    let (u, v, _) = a.plane.axes();
    let ang = a0 + sweep * f;
    let rad = r0 + (r1 - r0) * f;
    axes.iter()
        .map(|&axis| {
            if axis == u {
                a.center[0] + rad * ang.cos()
            } else if axis == v {
                a.center[1] + rad * ang.sin()
            } else {
                let k = axis.index();
                e.start[k] + (e.end[k] - e.start[k]) * f
            }
        })
        .collect()
}

/// Distance from `p` to an arc element by search over its parameter: a grid of at most
/// 0.01 rad steps, then a golden-section search between the grid neighbours of the best.
fn to_arc_by_search(p: &[f64], a: &Arc, e: &Element, axes: &[Axis]) -> f64 {
    let (_, sweep, _, _) = arc_angles(a, e);
    let n = ((sweep.abs() / 0.01).ceil() as usize).max(64);
    let d = |f: f64| dist(p, &arc_point(a, e, axes, f));
    let best = (0..=n)
        .min_by(|&i, &j| d(i as f64 / n as f64).total_cmp(&d(j as f64 / n as f64)))
        .unwrap_or(0);
    let (mut lo, mut hi) = (
        best.saturating_sub(1) as f64 / n as f64,
        (best + 1).min(n) as f64 / n as f64,
    );
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..80 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if d(x1) < d(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    d(0.5 * (lo + hi)).min(d(best as f64 / n as f64))
}

/// The point of a Bézier element on `axes` at parameter `f`, from the Bernstein
/// polynomials; the other axes linear in `f`.
fn bezier_point(b: &Bezier, e: &Element, axes: &[Axis], f: f64) -> Vec<f64> {
    let (u, v, _) = b.plane.axes();
    let g = 1.0 - f;
    let w = [g.powi(3), 3.0 * g * g * f, 3.0 * g * f * f, f.powi(3)];
    let coordinate = |axis: Axis, j: usize| {
        let k = axis.index();
        w[0] * e.start[k] + w[1] * b.controls[0][j] + w[2] * b.controls[1][j] + w[3] * e.end[k]
    };
    axes.iter()
        .map(|&axis| {
            if axis == u {
                coordinate(u, 0)
            } else if axis == v {
                coordinate(v, 1)
            } else {
                let k = axis.index();
                e.start[k] + (e.end[k] - e.start[k]) * f
            }
        })
        .collect()
}

/// Distance from `p` to a Bézier element by search over its parameter: a grid of 512,
/// then a golden-section search between the grid neighbours of every grid point nearer
/// than both its neighbours (a loop passes near itself: the nearest grid point may lie
/// on the other branch).
fn to_bezier(p: &[f64], b: &Bezier, e: &Element, axes: &[Axis]) -> f64 {
    let n: usize = 512;
    let d = |f: f64| dist(p, &bezier_point(b, e, axes, f));
    let grid: Vec<f64> = (0..=n).map(|i| d(i as f64 / n as f64)).collect();
    let mut best = grid.iter().copied().fold(f64::INFINITY, f64::min);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for i in 0..=n {
        let left = if i == 0 { f64::INFINITY } else { grid[i - 1] };
        let right = if i == n { f64::INFINITY } else { grid[i + 1] };
        if grid[i] > left || grid[i] > right {
            continue;
        }
        let (mut lo, mut hi) = (
            i.saturating_sub(1) as f64 / n as f64,
            (i + 1).min(n) as f64 / n as f64,
        );
        for _ in 0..80 {
            let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if d(x1) < d(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        best = best.min(d(0.5 * (lo + hi)));
    }
    best
}

/// Distance from `p` (on `axes`) to element `e`: closed form for lines and flat circular
/// arcs, by search over the parameter for helices, spirals and Béziers.
pub fn to_element(p: &[f64], e: &Element, axes: &[Axis]) -> f64 {
    let (s, t) = ends(e, axes);
    if let ElementKind::Bezier(b) = e.kind {
        return to_bezier(p, &b, e, axes);
    }
    let ElementKind::Arc(a) = e.kind else {
        return to_segment(p, &s, &t);
    };
    let (u, v, _) = a.plane.axes();
    let (iu, iv) = (
        axes.iter().position(|&x| x == u),
        axes.iter().position(|&x| x == v),
    );
    let (a0, sweep, r0, r1) = arc_angles(&a, e);
    let flat = axes
        .iter()
        .all(|&x| x == u || x == v || e.start[x.index()] == e.end[x.index()]);
    if let (true, Some(iu), Some(iv)) = (flat && (r0 - r1).abs() < 1e-12, iu, iv) {
        let (du, dv) = (p[iu] - a.center[0], p[iv] - a.center[1]);
        let ang = dv.atan2(du);
        let within = if sweep.abs() >= 2.0 * PI {
            true
        } else if sweep > 0.0 {
            (ang - a0).rem_euclid(2.0 * PI) <= sweep
        } else {
            (a0 - ang).rem_euclid(2.0 * PI) <= -sweep
        };
        let off_plane: f64 = (0..axes.len())
            .filter(|&k| k != iu && k != iv)
            .map(|k| (p[k] - s[k]).powi(2))
            .sum();
        let ends = dist(p, &s).min(dist(p, &t));
        if !within {
            return ends;
        }
        let radial = du.hypot(dv) - r0;
        return (radial * radial + off_plane).sqrt().min(ends);
    }
    to_arc_by_search(p, &a, e, axes)
}

/// Points along an element on `axes`, `n` + 1 of them, for coverage.
pub fn element_points(e: &Element, axes: &[Axis], n: usize) -> Vec<Vec<f64>> {
    match e.kind {
        ElementKind::Line => {
            let (s, t) = ends(e, axes);
            (0..=n)
                .map(|i| {
                    let f = i as f64 / n as f64;
                    s.iter().zip(&t).map(|(a, b)| a + (b - a) * f).collect()
                })
                .collect()
        }
        ElementKind::Arc(a) => (0..=n)
            .map(|i| arc_point(&a, e, axes, i as f64 / n as f64))
            .collect(),
        ElementKind::Bezier(b) => (0..=n)
            .map(|i| bezier_point(&b, e, axes, i as f64 / n as f64))
            .collect(),
    }
}

/// How far the polyline through a piece's samples may be from the piece: a curve leaves
/// its chord over a time step Δt by at most |acceleration|·Δt²/8.
pub fn sample_sag(c: &PvtContour, i: usize) -> f64 {
    let cp = control_points(c, i);
    let t = c.durations[i];
    let accel = |j: usize| {
        cp.iter()
            .map(|q| (6.0 * (q[j] - 2.0 * q[j + 1] + q[j + 2]) / (t * t)).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let dt = t / SAMPLES as f64;
    accel(0).max(accel(1)) * dt * dt / 8.0
}

/// Per-axis (|velocity|, |acceleration|) peaks of a contour from its control points.
pub fn peaks(c: &PvtContour) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0f64, 0.0f64); c.dim];
    for i in 0..c.len() {
        let cp = control_points(c, i);
        let t = c.durations[i];
        for (k, q) in cp.iter().enumerate() {
            let d: Vec<f64> = (0..3).map(|j| 3.0 * (q[j + 1] - q[j]) / t).collect();
            let mut v = d[0].abs().max(d[2].abs());
            let den = d[0] - 2.0 * d[1] + d[2];
            if den != 0.0 {
                let u = (d[0] - d[1]) / den;
                if (0.0..=1.0).contains(&u) {
                    let val = (1.0 - u).powi(2) * d[0] + 2.0 * u * (1.0 - u) * d[1] + u * u * d[2];
                    v = v.max(val.abs());
                }
            }
            let a0 = 6.0 * (q[0] - 2.0 * q[1] + q[2]) / (t * t);
            let a1 = 6.0 * (q[1] - 2.0 * q[2] + q[3]) / (t * t);
            out[k].0 = out[k].0.max(v);
            out[k].1 = out[k].1.max(a0.abs().max(a1.abs()));
        }
    }
    out
}

/// How far a program's motion strays from its toolpath, and the largest gap between a
/// programmed point and the motion.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// Largest distance from a sampled motion point to the programmed elements.
    pub error: f64,
    /// Largest distance from a programmed point to the motion (less the sampling sag).
    pub gap: f64,
}

/// An axis-aligned box on the program's axes.
#[derive(Debug, Clone)]
struct Bounds {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Bounds {
    fn of_points<'a>(points: impl IntoIterator<Item = &'a [f64]>, dim: usize) -> Bounds {
        let mut b = Bounds {
            lo: vec![f64::INFINITY; dim],
            hi: vec![f64::NEG_INFINITY; dim],
        };
        for p in points {
            for ((lo, hi), x) in b.lo.iter_mut().zip(&mut b.hi).zip(p) {
                *lo = lo.min(*x);
                *hi = hi.max(*x);
            }
        }
        b
    }

    /// Whether the boxes come within `margin` of each other.
    fn near(&self, other: &Bounds, margin: f64) -> bool {
        (0..self.lo.len())
            .all(|k| self.lo[k] <= other.hi[k] + margin && other.lo[k] <= self.hi[k] + margin)
    }
}

/// A box holding element `e` on `axes`: its ends, for an arc its whole circle, for a
/// Bézier its control points.
fn element_bounds(e: &Element, axes: &[Axis]) -> Bounds {
    let (s, t) = ends(e, axes);
    let mut b = Bounds::of_points([s.as_slice(), t.as_slice()], axes.len());
    if let ElementKind::Arc(a) = e.kind {
        let (_, _, r0, r1) = arc_angles(&a, e);
        let r = r0.max(r1);
        let (u, v, _) = a.plane.axes();
        for (axis, c) in [(u, a.center[0]), (v, a.center[1])] {
            if let Some(k) = axes.iter().position(|&x| x == axis) {
                b.lo[k] = b.lo[k].min(c - r);
                b.hi[k] = b.hi[k].max(c + r);
            }
        }
    }
    if let ElementKind::Bezier(bz) = e.kind {
        let (u, v, _) = bz.plane.axes();
        for (j, axis) in [u, v].into_iter().enumerate() {
            if let Some(k) = axes.iter().position(|&x| x == axis) {
                for c in bz.controls {
                    b.lo[k] = b.lo[k].min(c[j]);
                    b.hi[k] = b.hi[k].max(c[j]);
                }
            }
        }
    }
    b
}

/// A box holding piece `i` of `c`: its control points (the curve lies in their hull).
fn piece_bounds(c: &PvtContour, i: usize) -> Bounds {
    let cp = control_points(c, i);
    let points: Vec<Vec<f64>> = (0..4).map(|j| cp.iter().map(|q| q[j]).collect()).collect();
    Bounds::of_points(points.iter().map(Vec::as_slice), c.dim)
}

/// The deviation of `program` from `toolpath` (contours matched in order, skipping
/// toolpath contours that planned to nothing). Only elements and pieces whose boxes come
/// within `reach` of each other are measured: a larger deviation shows as one at least
/// `reach` (or infinite).
pub fn deviation(program: &PvtProgram, toolpath: &Toolpath, reach: f64) -> Deviation {
    let axes = &program.axes;
    let moving: Vec<&pvt_core::Contour> = toolpath
        .contours
        .iter()
        .filter(|c| {
            c.elements.iter().any(|e| {
                matches!(e.kind, ElementKind::Arc(_) | ElementKind::Bezier(_))
                    || ends(e, axes).0 != ends(e, axes).1
            })
        })
        .collect();
    assert_eq!(moving.len(), program.contours.len(), "contours match");
    let mut out = Deviation::default();
    for (c, source) in program.contours.iter().zip(moving) {
        let elements = &source.elements;
        let element_boxes: Vec<Bounds> = elements.iter().map(|e| element_bounds(e, axes)).collect();
        let piece_boxes: Vec<Bounds> = (0..c.len()).map(|i| piece_bounds(c, i)).collect();
        let samples: Vec<Vec<Vec<f64>>> = (0..c.len()).map(|i| piece_samples(c, i)).collect();
        for i in 0..c.len() {
            let candidates: Vec<usize> = (0..elements.len())
                .filter(|&j| piece_boxes[i].near(&element_boxes[j], reach))
                .collect();
            for p in &samples[i] {
                let d = candidates
                    .iter()
                    .map(|&j| to_element(p, &elements[j], axes))
                    .fold(f64::INFINITY, f64::min);
                out.error = out.error.max(d);
            }
        }
        for (j, e) in elements.iter().enumerate() {
            let pieces: Vec<usize> = (0..c.len())
                .filter(|&i| piece_boxes[i].near(&element_boxes[j], reach))
                .collect();
            let sag = pieces.iter().map(|&i| sample_sag(c, i)).fold(0.0, f64::max);
            for p in element_points(e, axes, 64) {
                let d = pieces
                    .iter()
                    .flat_map(|&i| samples[i].windows(2))
                    .map(|w| to_segment(&p, &w[0], &w[1]))
                    .fold(f64::INFINITY, f64::min);
                out.gap = out.gap.max(d - sag);
            }
        }
    }
    out
}

/// Per-axis largest |jerk| of a contour: a cubic's jerk is constant, the third difference
/// of its control points, 6·(P₃ − 3P₂ + 3P₁ − P₀)/T³. The differences are taken from the
/// end states (P₁ − P₀ = v₀T/3, P₃ − P₂ = v₁T/3, P₂ − P₁ = p₁ − p₀ − (v₀ + v₁)T/3), not
/// from the control points themselves: on a piece of microseconds far from the origin,
/// the rounding of each control point alone is worth a jerk of 10⁴ and more.
pub fn jerks(c: &PvtContour) -> Vec<f64> {
    let mut out = vec![0.0f64; c.dim];
    for i in 0..c.len() {
        let seg = c.segment(i);
        let (p0, v0) = piece_start(c, i);
        let t = seg.duration;
        for k in 0..c.dim {
            let first = v0[k] * t / 3.0;
            let last = seg.velocity[k] * t / 3.0;
            let middle = (seg.end[k] - p0[k]) - first - last;
            let j = 6.0 * ((last - middle) - (middle - first)) / (t * t * t);
            out[k] = out[k].max(j.abs());
        }
    }
    out
}

/// Where piece `i` of a contour starts: position and velocity (the contour's start at
/// rest for the first).
fn piece_start(c: &PvtContour, i: usize) -> (Vec<f64>, Vec<f64>) {
    if i == 0 {
        (c.start.clone(), vec![0.0; c.dim])
    } else {
        let prev = c.segment(i - 1);
        (prev.end.to_vec(), prev.velocity.to_vec())
    }
}

/// Per-axis largest step of the acceleration at a knot of a contour: between the end of
/// each piece and the start of the next, and, counted twice, between rest and the first
/// piece's start and the last piece's end (another contour may follow straight on, and
/// the two steps then add up). Each cubic's end accelerations come from its written end
/// states, `a(0) = (6Δp − 4v₀T − 2v₁T)/T²` and `a(T) = (−6Δp + 2v₀T + 4v₁T)/T²`.
pub fn knot_steps(c: &PvtContour) -> Vec<f64> {
    let mut out = vec![0.0f64; c.dim];
    let mut before = vec![0.0f64; c.dim];
    for i in 0..c.len() {
        let seg = c.segment(i);
        let (p0, v0) = piece_start(c, i);
        let t = seg.duration;
        for k in 0..c.dim {
            let (dp, v1) = (seg.end[k] - p0[k], seg.velocity[k]);
            let a0 = (6.0 * dp - 4.0 * v0[k] * t - 2.0 * v1 * t) / (t * t);
            let a1 = (-6.0 * dp + 2.0 * v0[k] * t + 4.0 * v1 * t) / (t * t);
            let twice = if i == 0 { 2.0 } else { 1.0 };
            out[k] = out[k].max(twice * (a0 - before[k]).abs());
            before[k] = a1;
        }
    }
    for k in 0..c.dim {
        out[k] = out[k].max(2.0 * before[k].abs());
    }
    out
}

/// The contours of PMAC text as pvtc writes it, read back from the text alone: each
/// `; contour N (KIND) from X… Y…` comment starts one at those positions, and each
/// `TA<ms> X<p>:<v> …` line is a piece (velocities in units/s). Other lines are skipped.
/// The numbers are the written ones, rounded as a controller receives them.
pub fn pmac_contours(text: &str) -> Vec<PvtContour> {
    let mut contours: Vec<PvtContour> = Vec::new();
    for line in text.lines() {
        if let Some(from) = line
            .strip_prefix("; contour ")
            .and_then(|rest| rest.split_once(" from "))
            .map(|(_, from)| from)
        {
            let start: Vec<f64> = from
                .split_whitespace()
                .map(|w| w[1..].parse().expect("a start position"))
                .collect();
            contours.push(PvtContour::new(pvt_core::Motion::Feed, start));
        } else if let Some(rest) = line.strip_prefix("TA") {
            let mut words = rest.split_whitespace();
            let ms: f64 = words.next().unwrap().parse().expect("a piece time");
            let (mut p, mut v) = (Vec::new(), Vec::new());
            for w in words {
                let (pos, vel) = w[1..].split_once(':').expect("P:V");
                p.push(pos.parse::<f64>().unwrap());
                v.push(vel.parse::<f64>().unwrap());
            }
            let contour = contours
                .last_mut()
                .expect("a piece after a contour comment");
            contour.push(&p, &v, ms / 1000.0, 0);
        }
    }
    contours
}
