//! Cubic Bézier curves in a plane and B-spline curves broken into them.
//!
//! Owns the [`Bezier`] element kind's geometry (position, derivative, length, subdivision,
//! flattening within a chord tolerance and distance to a point), the exact conversion of
//! a quadratic Bézier into a cubic one (degree elevation), and the exact decomposition of
//! a non-rational B-spline into Béziers ([`bezier_spans`], by blossoming: de Boor's
//! algorithm with a parameter per level). It must not choose speeds or pieces: the path
//! planner does, from the bounds this geometry gives.
//!
//! # The curve
//! `B(u) = (1−u)³P₀ + 3(1−u)²u·P₁ + 3(1−u)u²·P₂ + u³P₃`, `u ∈ [0, 1]`, in the plane's
//! (first, second) coordinates, with `P₀` and `P₃` the element's start and end; every
//! other axis moves linearly in `u`. Its derivatives are Béziers of the control point
//! differences, so by the convex hull property `|B''(u)| ≤ 6·max(|P₀−2P₁+P₂|,
//! |P₁−2P₂+P₃|)`, `B'''` is the constant `6·(P₃−3P₂+3P₁−P₀)` and `B'''' = 0`.

use crate::axis::{Plane, Position, AXIS_COUNT};

/// A cubic Bézier in a plane; start and end are those of its
/// [`Element`](crate::toolpath::Element).
///
/// Axes other than the plane's two move linearly with the Bézier parameter `u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bezier {
    /// Plane of the curve.
    pub plane: Plane,
    /// The inner control points `P₁`, `P₂` in the plane's (first, second) coordinates.
    pub controls: [[f64; 2]; 2],
}

/// The 8-point Gauss–Legendre rule on `[−1, 1]`: its positive abscissas with their
/// weights (the negative ones mirror them).
const GAUSS: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_2, 0.101_228_536_290_376_3),
];

impl Bezier {
    /// The cubic through the quadratic Bézier with inner control point `q` (degree
    /// elevation, exact): `P₁ = P₀ + ⅔(q − P₀)`, `P₂ = P₃ + ⅔(q − P₃)`.
    pub fn from_quadratic(plane: Plane, start: [f64; 2], q: [f64; 2], end: [f64; 2]) -> Bezier {
        let lerp = |a: [f64; 2], b: [f64; 2]| {
            [
                a[0] + 2.0 / 3.0 * (b[0] - a[0]),
                a[1] + 2.0 / 3.0 * (b[1] - a[1]),
            ]
        };
        Bezier {
            plane,
            controls: [lerp(start, q), lerp(end, q)],
        }
    }

    /// The four control points in the plane.
    pub fn points(&self, start: &Position, end: &Position) -> [[f64; 2]; 4] {
        [
            self.plane.project(start),
            self.controls[0],
            self.controls[1],
            self.plane.project(end),
        ]
    }

    /// The same curve traversed the other way.
    pub fn reversed(&self) -> Bezier {
        Bezier {
            plane: self.plane,
            controls: [self.controls[1], self.controls[0]],
        }
    }

    /// The position at parameter `u ∈ [0, 1]` (exactly `start` and `end` at the ends).
    pub fn position(&self, start: &Position, end: &Position, u: f64) -> Position {
        if u <= 0.0 {
            return *start;
        }
        if u >= 1.0 {
            return *end;
        }
        let mut p = *start;
        for ((q, s), e) in p.iter_mut().zip(start).zip(end) {
            *q = s + (e - s) * u;
        }
        let b = eval(&self.points(start, end), u);
        let (a0, a1, _) = self.plane.axes();
        p[a0.index()] = b[0];
        p[a1.index()] = b[1];
        p
    }

    /// dB/du at `u`, every axis.
    pub fn derivative(&self, start: &Position, end: &Position, u: f64) -> Position {
        let mut d = [0.0; AXIS_COUNT];
        for ((q, s), e) in d.iter_mut().zip(start).zip(end) {
            *q = e - s;
        }
        let b = derivative(&self.points(start, end), u);
        let (a0, a1, _) = self.plane.axes();
        d[a0.index()] = b[0];
        d[a1.index()] = b[1];
        d
    }

    /// Arc length (8-point Gauss–Legendre on each of 16 equal parameter intervals).
    pub fn length(&self, start: &Position, end: &Position) -> f64 {
        const PARTS: usize = 16;
        let speed = |u: f64| crate::vector::norm(&self.derivative(start, end, u));
        let h = 1.0 / PARTS as f64;
        (0..PARTS)
            .map(|k| {
                let mid = (k as f64 + 0.5) * h;
                GAUSS
                    .iter()
                    .map(|&(x, w)| w * (speed(mid - 0.5 * h * x) + speed(mid + 0.5 * h * x)))
                    .sum::<f64>()
                    * 0.5
                    * h
            })
            .sum()
    }

    /// The least number of equal parameter intervals whose chords stay within
    /// `tolerance` of the curve: linear interpolation over `h` errs by at most
    /// `h²/8·max|B''|`, and the other axes are linear (at most 1,000,000).
    pub fn chord_count(&self, start: &Position, end: &Position, tolerance: f64) -> usize {
        let m2 = second_derivative_bound(&self.points(start, end));
        let n = (m2 / (8.0 * tolerance)).sqrt().ceil();
        if n.is_finite() {
            n.clamp(1.0, 1e6) as usize
        } else {
            1_000_000
        }
    }

    /// The curve as chords within `tolerance`: the points after `start`, ending at `end`.
    pub fn flatten(&self, start: &Position, end: &Position, tolerance: f64) -> Vec<Position> {
        let n = self.chord_count(start, end, tolerance);
        (1..=n)
            .map(|k| self.position(start, end, k as f64 / n as f64))
            .collect()
    }

    /// The Bézier's two halves split at `u` and the position there.
    pub fn split(&self, start: &Position, end: &Position, u: f64) -> (Bezier, Position, Bezier) {
        let (left, right) = subdivide(&self.points(start, end), u);
        let mid = self.position(start, end, u);
        let part = |p: [[f64; 2]; 4]| Bezier {
            plane: self.plane,
            controls: [p[1], p[2]],
        };
        (part(left), mid, part(right))
    }

    /// Distance from `point` (the values of the axes `columns`) to the curve: 64 equally
    /// spaced parameters, each one nearer than both its neighbours refined by
    /// golden-section search over the intervals beside it (a loop passes near itself, so
    /// the nearest sample may lie on the other branch).
    pub fn distance(
        &self,
        start: &Position,
        end: &Position,
        columns: &[usize],
        point: &[f64],
    ) -> f64 {
        let at = |u: f64| {
            let p = self.position(start, end, u);
            columns
                .iter()
                .zip(point)
                .map(|(&c, x)| (p[c] - x) * (p[c] - x))
                .sum::<f64>()
                .sqrt()
        };
        const SAMPLES: usize = 64;
        let h = 1.0 / SAMPLES as f64;
        let grid: Vec<f64> = (0..=SAMPLES).map(|k| at(k as f64 * h)).collect();
        let mut best = grid.iter().copied().fold(f64::INFINITY, f64::min);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for k in 0..=SAMPLES {
            let left = if k == 0 { f64::INFINITY } else { grid[k - 1] };
            let right = grid.get(k + 1).copied().unwrap_or(f64::INFINITY);
            if grid[k] > left || grid[k] > right {
                continue;
            }
            let u = k as f64 * h;
            let (mut lo, mut hi) = ((u - h).max(0.0), (u + h).min(1.0));
            for _ in 0..60 {
                let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if at(x1) < at(x2) {
                    hi = x2;
                } else {
                    lo = x1;
                }
            }
            best = best.min(at(0.5 * (lo + hi)));
        }
        best
    }
}

/// The point at `u` of the planar cubic with control points `p` (de Casteljau).
pub fn eval(p: &[[f64; 2]; 4], u: f64) -> [f64; 2] {
    let v = 1.0 - u;
    let (b0, b1, b2, b3) = (v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u);
    [
        b0 * p[0][0] + b1 * p[1][0] + b2 * p[2][0] + b3 * p[3][0],
        b0 * p[0][1] + b1 * p[1][1] + b2 * p[2][1] + b3 * p[3][1],
    ]
}

/// dB/du at `u` of the planar cubic with control points `p`.
pub fn derivative(p: &[[f64; 2]; 4], u: f64) -> [f64; 2] {
    let v = 1.0 - u;
    let (b0, b1, b2) = (3.0 * v * v, 6.0 * v * u, 3.0 * u * u);
    let d = |i: usize, c: usize| p[i + 1][c] - p[i][c];
    [
        b0 * d(0, 0) + b1 * d(1, 0) + b2 * d(2, 0),
        b0 * d(0, 1) + b1 * d(1, 1) + b2 * d(2, 1),
    ]
}

/// d²B/du² at `u` of the planar cubic with control points `p`.
pub fn second_derivative(p: &[[f64; 2]; 4], u: f64) -> [f64; 2] {
    let d2 = |i: usize, c: usize| p[i + 2][c] - 2.0 * p[i + 1][c] + p[i][c];
    [
        6.0 * ((1.0 - u) * d2(0, 0) + u * d2(1, 0)),
        6.0 * ((1.0 - u) * d2(0, 1) + u * d2(1, 1)),
    ]
}

/// `max|B''|` over `[0, 1]`: `B''` is linear in `u`, so the larger of its end values.
pub fn second_derivative_bound(p: &[[f64; 2]; 4]) -> f64 {
    let n = |v: [f64; 2]| libm::hypot(v[0], v[1]);
    n(second_derivative(p, 0.0)).max(n(second_derivative(p, 1.0)))
}

/// `|B'''|`, constant: `6·|P₃ − 3P₂ + 3P₁ − P₀|`.
pub fn third_derivative(p: &[[f64; 2]; 4]) -> f64 {
    let c = |k: usize| p[3][k] - 3.0 * p[2][k] + 3.0 * p[1][k] - p[0][k];
    6.0 * libm::hypot(c(0), c(1))
}

/// The control points of the two halves of `p` split at `u` (de Casteljau).
pub fn subdivide(p: &[[f64; 2]; 4], u: f64) -> ([[f64; 2]; 4], [[f64; 2]; 4]) {
    let lerp = |a: [f64; 2], b: [f64; 2]| [a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u];
    let (a, b, c) = (lerp(p[0], p[1]), lerp(p[1], p[2]), lerp(p[2], p[3]));
    let (d, e) = (lerp(a, b), lerp(b, c));
    let m = lerp(d, e);
    ([p[0], a, d, m], [m, e, c, p[3]])
}

/// The control points of `p` on `[u0, u1]` (an interval inside `[0, 1]`).
pub fn sub_curve(p: &[[f64; 2]; 4], u0: f64, u1: f64) -> [[f64; 2]; 4] {
    if u1 <= u0 {
        let q = eval(p, u0);
        return [q; 4];
    }
    let (_, right) = subdivide(p, u0);
    let (left, _) = subdivide(&right, ((u1 - u0) / (1.0 - u0)).min(1.0));
    let mut out = left;
    out[3] = eval(p, u1);
    out
}

/// Why a B-spline cannot be broken into Béziers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    /// The degree is 0.
    #[error("degree 0 has no curve")]
    Degree,
    /// Too few control points for the degree.
    #[error("{points} control points are too few for degree {degree}")]
    TooFewPoints {
        /// Control points given.
        points: usize,
        /// Degree asked.
        degree: usize,
    },
    /// The knot vector's length is not points + degree + 1.
    #[error("{knots} knots, but {points} control points of degree {degree} need {needed}")]
    KnotCount {
        /// Knots given.
        knots: usize,
        /// Control points given.
        points: usize,
        /// Degree asked.
        degree: usize,
        /// Knots needed.
        needed: usize,
    },
    /// Knots not finite or decreasing, or an empty domain.
    #[error("the knots are not finite and non-decreasing over a non-empty domain")]
    Knots,
}

/// The Bézier control points (degree `degree`, `degree + 1` each) of every non-empty knot
/// span of the B-spline with `knots` and control points `ctrl` (of any dimension `D`,
/// homogeneous ones included), in order. Point `i` of the span `[t_k, t_{k+1}]` is the
/// blossom at `(t_k, …, t_k, t_{k+1}, …, t_{k+1})`, `degree − i` times `t_k`: exact.
pub fn bezier_spans<const D: usize>(
    degree: usize,
    knots: &[f64],
    ctrl: &[[f64; D]],
) -> Result<Vec<Vec<[f64; D]>>, SplineError> {
    let n = ctrl.len();
    if degree == 0 {
        return Err(SplineError::Degree);
    }
    if n < degree + 1 {
        return Err(SplineError::TooFewPoints { points: n, degree });
    }
    if knots.len() != n + degree + 1 {
        return Err(SplineError::KnotCount {
            knots: knots.len(),
            points: n,
            degree,
            needed: n + degree + 1,
        });
    }
    let ordered = knots.iter().all(|k| k.is_finite()) && knots.windows(2).all(|w| w[0] <= w[1]);
    if !ordered || knots[degree] >= knots[n] {
        return Err(SplineError::Knots);
    }
    let mut out = Vec::new();
    for k in degree..n {
        let (a, b) = (knots[k], knots[k + 1]);
        if a >= b {
            continue;
        }
        let span = (0..=degree)
            .map(|i| {
                let params: Vec<f64> = (0..degree)
                    .map(|j| if j < degree - i { a } else { b })
                    .collect();
                blossom(degree, knots, ctrl, k, &params)
            })
            .collect();
        out.push(span);
    }
    Ok(out)
}

/// The blossom (polar form) of the B-spline's polynomial piece on span `k` at `params`
/// (`degree` of them): de Boor's algorithm with `params[r − 1]` at level `r`.
pub fn blossom<const D: usize>(
    degree: usize,
    knots: &[f64],
    ctrl: &[[f64; D]],
    k: usize,
    params: &[f64],
) -> [f64; D] {
    let p = degree;
    let mut d: Vec<[f64; D]> = (0..=p).map(|j| ctrl[j + k - p]).collect();
    for r in 1..=p {
        let t = params[r - 1];
        for j in (r..=p).rev() {
            let lo = knots[j + k - p];
            let hi = knots[j + 1 + k - r];
            let alpha = (t - lo) / (hi - lo);
            let prev = d[j - 1];
            for (v, q) in d[j].iter_mut().zip(prev) {
                *v = (1.0 - alpha) * q + alpha * *v;
            }
        }
    }
    d[p]
}

/// A Bézier of degree 1, 2 or 3 as a cubic (degree elevation, exact); `None` above 3.
pub fn elevate_to_cubic<const D: usize>(points: &[[f64; D]]) -> Option<[[f64; D]; 4]> {
    let mix = |a: [f64; D], b: [f64; D], f: f64| std::array::from_fn(|c| a[c] + (b[c] - a[c]) * f);
    match points {
        [a, b] => Some([*a, mix(*a, *b, 1.0 / 3.0), mix(*a, *b, 2.0 / 3.0), *b]),
        [a, q, b] => Some([*a, mix(*a, *q, 2.0 / 3.0), mix(*b, *q, 2.0 / 3.0), *b]),
        [a, b, c, d] => Some([*a, *b, *c, *d]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(x: f64, y: f64, z: f64) -> Position {
        [x, y, z, 0.0, 0.0, 0.0]
    }

    /// The Bernstein form evaluated independently of de Casteljau.
    #[test]
    fn subdivision_reproduces_the_curve() {
        let p = [[0.0, 0.0], [1.0, 3.0], [4.0, -1.0], [5.0, 2.0]];
        let (l, r) = subdivide(&p, 0.3);
        for k in 0..=10 {
            let u = k as f64 / 10.0;
            let a = eval(&l, u);
            let b = eval(&p, 0.3 * u);
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
            let a = eval(&r, u);
            let b = eval(&p, 0.3 + 0.7 * u);
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
        }
        let s = sub_curve(&p, 0.2, 0.6);
        let (a, b) = (eval(&s, 0.5), eval(&p, 0.4));
        assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
    }

    #[test]
    fn length_of_a_straight_cubic_is_its_chord() {
        let b = Bezier {
            plane: Plane::XY,
            controls: [[1.0, 1.0], [2.0, 2.0]],
        };
        let l = b.length(&pos(0.0, 0.0, 0.0), &pos(3.0, 3.0, 4.0));
        assert!((l - (18.0f64 + 16.0).sqrt()).abs() < 1e-12, "{l}");
    }

    #[test]
    fn flattening_stays_within_tolerance() {
        let b = Bezier {
            plane: Plane::XY,
            controls: [[0.0, 10.0], [10.0, -10.0]],
        };
        let (s, e) = (pos(0.0, 0.0, 0.0), pos(10.0, 0.0, 0.0));
        let tol = 1e-3;
        let mut points = vec![s];
        points.extend(b.flatten(&s, &e, tol));
        for k in 0..=2000 {
            let p = b.position(&s, &e, k as f64 / 2000.0);
            let d = points
                .windows(2)
                .map(|w| segment_distance(&w[0], &w[1], &p))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tol, "{d}");
        }
    }

    fn segment_distance(a: &Position, b: &Position, p: &Position) -> f64 {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let f = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        libm::hypot(p[0] - a[0] - f * dx, p[1] - a[1] - f * dy)
    }

    /// A uniform cubic B-spline's spans against the basis functions evaluated directly.
    #[test]
    fn bezier_spans_match_the_basis() {
        let ctrl = [[0.0, 0.0], [1.0, 2.0], [3.0, 3.0], [4.0, 0.0], [6.0, 1.0]];
        let knots = [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
        let spans = bezier_spans(3, &knots, &ctrl).unwrap();
        assert_eq!(spans.len(), 2);
        for (s, (a, b)) in spans.iter().zip([(0.0, 0.5), (0.5, 1.0)]) {
            let p: [[f64; 2]; 4] = [s[0], s[1], s[2], s[3]];
            for k in 0..=8 {
                let u = k as f64 / 8.0;
                let t = a + (b - a) * u;
                let want = cox_de_boor(3, &knots, &ctrl, t);
                let got = eval(&p, u);
                assert!((want[0] - got[0]).abs() < 1e-12, "{t}");
                assert!((want[1] - got[1]).abs() < 1e-12, "{t}");
            }
        }
    }

    /// Σ N_{i,p}(t)·P_i by the Cox–de Boor recursion (right-open spans, the end closed).
    fn cox_de_boor(p: usize, knots: &[f64], ctrl: &[[f64; 2]], t: f64) -> [f64; 2] {
        fn basis(i: usize, p: usize, knots: &[f64], t: f64, last: bool) -> f64 {
            if p == 0 {
                let inside = knots[i] <= t && t < knots[i + 1];
                let end = last && t == knots[i + 1] && knots[i] < knots[i + 1];
                return if inside || end { 1.0 } else { 0.0 };
            }
            let mut v = 0.0;
            if knots[i + p] > knots[i] {
                v += (t - knots[i]) / (knots[i + p] - knots[i]) * basis(i, p - 1, knots, t, last);
            }
            if knots[i + p + 1] > knots[i + 1] {
                v += (knots[i + p + 1] - t) / (knots[i + p + 1] - knots[i + 1])
                    * basis(i + 1, p - 1, knots, t, last);
            }
            v
        }
        let last = t >= knots[knots.len() - 1];
        let mut out = [0.0; 2];
        for (i, c) in ctrl.iter().enumerate() {
            let n = basis(i, p, knots, t, last);
            out[0] += n * c[0];
            out[1] += n * c[1];
        }
        out
    }

    #[test]
    fn quadratics_elevate_exactly() {
        let q = [[0.0, 0.0], [1.0, 2.0], [3.0, 0.0]];
        let c = elevate_to_cubic(&q).unwrap();
        for k in 0..=8 {
            let u = k as f64 / 8.0;
            let v = 1.0 - u;
            let want = [
                v * v * q[0][0] + 2.0 * u * v * q[1][0] + u * u * q[2][0],
                v * v * q[0][1] + 2.0 * u * v * q[1][1] + u * u * q[2][1],
            ];
            let got = eval(&c, u);
            assert!((want[0] - got[0]).abs() < 1e-12 && (want[1] - got[1]).abs() < 1e-12);
        }
    }
}
