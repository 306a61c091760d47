//! Exact curves, as cubic Béziers or as chords: NURBS (de Boor), fit-point splines,
//! ellipses.
//!
//! Owns the evaluation of every curve pvt-core cannot discretize itself, its conversion
//! into cubic Béziers ([`CubicCurve`], see "Cubic Béziers" below) and the rule that turns
//! it into chords where it cannot be one (a curve off a plane parallel to XY). It must
//! not know DXF records, layers or options.
//!
//! # Cubic Béziers
//! - A non-rational B-spline of degree 1 to 3 (every weight equal) is its knot spans'
//!   Béziers ([`pvt_core::bezier::bezier_spans`], by blossoming), raised to degree 3:
//!   exact.
//! - A fit-point spline is a cubic polynomial between fit points: exact.
//! - An ellipse `c + u·cos t + v·sin t` is the image of the unit circle under the linear
//!   map `[u v]`; each of `n` equal parts of its sweep `θ` is the image of the standard
//!   circular-arc cubic (handles `4/3·tan(θ/4)` along the tangents), whose radial
//!   distance from the circle is at most `e(θ) = 2·sin⁶(θ/4)/(27·cos²(θ/4))` (Goldapp).
//!   Each point of that cubic is `e(θ)` or less from the circle point in its direction,
//!   and the map stretches that difference by at most its largest singular value, at
//!   most `√(|u|² + |v|²)`: `n` is the least with `√(|u|² + |v|²)·e(θ/n) ≤` the
//!   tolerance, and at least one part per quarter turn.
//! - Any other curve (a rational or degree-4+ NURBS) is cut into Hermite cubics by
//!   [`pvt_core::rational::nurbs_cubics`]: each knot span is halved until the cubic
//!   through the exact end points and end derivatives (times the interval) stays, at 31
//!   equally spaced interior parameters, within 0.99 × the tolerance of the curve at the
//!   same parameter, the rule of "Flattening rule" below with the cubic in place of the
//!   chord.
//!
//! The tolerance given is the share of the path tolerance a drawing's curves take
//! (`pvt_dxf::DxfOptions::curve_share`).
//!
//! # Flattening rule
//! A curve is a sequence of smooth pieces (knot spans of a NURBS, intervals between fit
//! points, quarter turns of an ellipse). Each piece is first cut into 4 equal parameter
//! intervals (so a closed or looping piece never collapses into one chord), then every
//! interval `[t0, t1]` is accepted as one chord from `C(t0)` to `C(t1)` only when the true
//! curve, evaluated at 31 equally spaced interior parameters, stays within 0.99 × the
//! chord tolerance of that chord; otherwise it is halved and both halves are tried. Every
//! emitted point is an exact evaluation `C(t)`. For a smooth piece the deviation between
//! samples 1/32 apart is within 0.2 % of the largest sampled one (near-parabolic
//! deviation), which the 1 % margin covers, so the sagitta against the true curve stays
//! within the tolerance. A piece that needs more than [`MAX_DEPTH`] halvings or a curve
//! that needs more than [`MAX_POINTS`] points is refused rather than emitted coarser.

use crate::geom::{add, dist_to_segment, norm, scale, sub, P3};

/// A cubic Bézier's four control points.
pub type Cubic = [P3; 4];

/// A curve that can be given as cubic Béziers within a tolerance (see the module's
/// "Cubic Béziers").
pub trait CubicCurve {
    /// The cubics, in order, each starting where the previous one ends.
    fn cubics(&self, tolerance: f64) -> Result<Vec<Cubic>, String>;
}

/// Most cubics one curve may become.
pub const MAX_CUBICS: usize = pvt_core::rational::MAX_CUBICS;

/// Deepest halving of one interval.
pub const MAX_DEPTH: u32 = 48;
/// Most chords one curve may become.
pub const MAX_POINTS: usize = 2_000_000;
const SAMPLES: usize = 31;
const MARGIN: f64 = 0.99;

/// A parametric curve made of smooth pieces.
pub trait PieceCurve {
    /// Parameter intervals of the smooth pieces, in order, each with `t0 < t1` or `t0 > t1`.
    fn pieces(&self) -> Vec<(f64, f64)>;
    /// The point at parameter `t` of piece `piece`.
    fn eval(&self, piece: usize, t: f64) -> P3;
}

/// The points of a curve flattened to `tolerance`: first point first, exact at both ends.
pub fn flatten(curve: &dyn PieceCurve, tolerance: f64) -> Result<Vec<P3>, String> {
    let pieces = curve.pieces();
    let Some(&(first_t, _)) = pieces.first() else {
        return Err("the curve has no extent".to_string());
    };
    let mut out = vec![curve.eval(0, first_t)];
    for (k, &(a, b)) in pieces.iter().enumerate() {
        let mut p0 = curve.eval(k, a);
        for q in 1..=4 {
            let t0 = a + (b - a) * f64::from(q - 1) / 4.0;
            let t1 = if q == 4 {
                b
            } else {
                a + (b - a) * f64::from(q) / 4.0
            };
            let p1 = curve.eval(k, t1);
            refine(curve, k, (t0, p0), (t1, p1), tolerance, 0, &mut out)?;
            p0 = p1;
        }
    }
    if out.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
        return Err("the curve evaluates to a non-finite point".to_string());
    }
    Ok(out)
}

fn refine(
    curve: &dyn PieceCurve,
    piece: usize,
    (t0, p0): (f64, P3),
    (t1, p1): (f64, P3),
    tolerance: f64,
    depth: u32,
    out: &mut Vec<P3>,
) -> Result<(), String> {
    let mut worst: f64 = 0.0;
    for s in 1..=SAMPLES {
        let t = t0 + (t1 - t0) * (s as f64 / (SAMPLES + 1) as f64);
        let d = dist_to_segment(curve.eval(piece, t), p0, p1);
        if d.is_nan() {
            return Err("the curve evaluates to a non-finite point".to_string());
        }
        worst = worst.max(d);
    }
    if worst <= MARGIN * tolerance {
        if out.len() >= MAX_POINTS {
            return Err(format!(
                "it needs more than {MAX_POINTS} chords at this tolerance"
            ));
        }
        out.push(p1);
        return Ok(());
    }
    if depth >= MAX_DEPTH {
        return Err(
            "the tolerance cannot be met (the curve is too large or not smooth)".to_string(),
        );
    }
    let tm = 0.5 * (t0 + t1);
    let pm = curve.eval(piece, tm);
    refine(curve, piece, (t0, p0), (tm, pm), tolerance, depth + 1, out)?;
    refine(curve, piece, (tm, pm), (t1, p1), tolerance, depth + 1, out)
}

/// An elliptical (or circular) arc `c + u·cos t + v·sin t`, `t` from `t0` to `t1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipseArc {
    /// Centre.
    pub c: P3,
    /// Point at t = 0, relative to the centre.
    pub u: P3,
    /// Point at t = π/2, relative to the centre.
    pub v: P3,
    /// Start parameter, radians.
    pub t0: f64,
    /// End parameter, radians (below `t0` for a backward arc).
    pub t1: f64,
}

impl EllipseArc {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> P3 {
        let (s, c) = libm::sincos(t);
        add(self.c, add(scale(self.u, c), scale(self.v, s)))
    }
}

impl PieceCurve for EllipseArc {
    fn pieces(&self) -> Vec<(f64, f64)> {
        let quarter = std::f64::consts::FRAC_PI_2;
        let n = ((self.t1 - self.t0).abs() / quarter).ceil().clamp(1.0, 8.0) as usize;
        (0..n)
            .map(|k| {
                let a = self.t0 + (self.t1 - self.t0) * k as f64 / n as f64;
                let b = if k + 1 == n {
                    self.t1
                } else {
                    self.t0 + (self.t1 - self.t0) * (k + 1) as f64 / n as f64
                };
                (a, b)
            })
            .collect()
    }

    fn eval(&self, _piece: usize, t: f64) -> P3 {
        self.at(t)
    }
}

/// A NURBS curve of any degree, evaluated exactly by de Boor's algorithm.
#[derive(Debug, Clone, PartialEq)]
pub struct Nurbs {
    degree: usize,
    knots: Vec<f64>,
    /// Control points in homogeneous form (w·x, w·y, w·z, w).
    ctrl: Vec<[f64; 4]>,
}

impl Nurbs {
    /// Checks and builds a NURBS; `weights` may be empty (all 1).
    pub fn new(
        degree: usize,
        knots: &[f64],
        points: &[P3],
        weights: &[f64],
    ) -> Result<Nurbs, String> {
        let n = points.len();
        if degree < 1 {
            return Err(format!("degree {degree} is below 1"));
        }
        if n < degree + 1 {
            return Err(format!(
                "{n} control points are too few for degree {degree}"
            ));
        }
        if knots.len() != n + degree + 1 {
            return Err(format!(
                "{} knots, but {n} control points of degree {degree} need {}",
                knots.len(),
                n + degree + 1
            ));
        }
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err("the knots are not finite and non-decreasing".to_string());
        }
        if knots[degree] >= knots[n] {
            return Err("the knot vector has an empty domain".to_string());
        }
        if !weights.is_empty() && weights.len() != n {
            return Err(format!("{} weights for {n} control points", weights.len()));
        }
        if weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err("a weight is not a positive number".to_string());
        }
        if points.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
            return Err("a control point is not finite".to_string());
        }
        let ctrl = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let w = weights.get(i).copied().unwrap_or(1.0);
                [p[0] * w, p[1] * w, p[2] * w, w]
            })
            .collect();
        Ok(Nurbs {
            degree,
            knots: knots.to_vec(),
            ctrl,
        })
    }

    /// The knot span indices `k` (with `knots[k] < knots[k + 1]`) inside the domain.
    fn spans(&self) -> Vec<usize> {
        (self.degree..self.ctrl.len())
            .filter(|&k| self.knots[k] < self.knots[k + 1])
            .collect()
    }

    /// The point at `t` on the polynomial piece of knot span `k` (de Boor).
    fn eval_span(&self, k: usize, t: f64) -> P3 {
        let p = self.degree;
        let u = &self.knots;
        let mut d: Vec<[f64; 4]> = (0..=p).map(|j| self.ctrl[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let lo = u[j + k - p];
                let hi = u[j + 1 + k - r];
                let alpha = (t - lo) / (hi - lo);
                let prev = d[j - 1];
                for (v, q) in d[j].iter_mut().zip(prev) {
                    *v = (1.0 - alpha) * q + alpha * *v;
                }
            }
        }
        let h = d[p];
        [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
    }
}

/// A NURBS with its spans cached, ready to flatten.
pub struct NurbsCurve {
    nurbs: Nurbs,
    spans: Vec<usize>,
}

impl NurbsCurve {
    /// Wraps a NURBS.
    pub fn new(nurbs: Nurbs) -> NurbsCurve {
        let spans = nurbs.spans();
        NurbsCurve { nurbs, spans }
    }
}

impl PieceCurve for NurbsCurve {
    fn pieces(&self) -> Vec<(f64, f64)> {
        self.spans
            .iter()
            .map(|&k| (self.nurbs.knots[k], self.nurbs.knots[k + 1]))
            .collect()
    }

    fn eval(&self, piece: usize, t: f64) -> P3 {
        self.nurbs.eval_span(self.spans[piece], t)
    }
}

/// An interpolating cubic spline through fit points, chord-length parametrised.
///
/// Each coordinate is the C² cubic spline through the points at parameters equal to the
/// cumulative chord lengths. At an end with a tangent, the derivative there is the unit
/// tangent (clamped end: with chord-length parameters the curve's speed is about 1); at an
/// end without one, the second derivative is zero (natural end). Consecutive duplicate
/// points are dropped first.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSpline {
    t: Vec<f64>,
    y: Vec<P3>,
    m: Vec<P3>,
}

impl FitSpline {
    /// Builds the spline; tangents of zero length count as absent.
    pub fn new(
        points: &[P3],
        start_tangent: Option<P3>,
        end_tangent: Option<P3>,
    ) -> Result<FitSpline, String> {
        if points.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
            return Err("a fit point is not finite".to_string());
        }
        let mut y: Vec<P3> = Vec::with_capacity(points.len());
        for &p in points {
            if y.last().is_none_or(|&q| norm(sub(p, q)) > 0.0) {
                y.push(p);
            }
        }
        if y.len() < 2 {
            return Err("fewer than two distinct fit points".to_string());
        }
        let mut t = vec![0.0];
        for w in y.windows(2) {
            let last = t[t.len() - 1];
            t.push(last + norm(sub(w[1], w[0])));
        }
        let unit = |v: Option<P3>| {
            v.and_then(|v| {
                let l = norm(v);
                (l.is_finite() && l > 0.0).then(|| scale(v, 1.0 / l))
            })
        };
        let (d0, d1) = (unit(start_tangent), unit(end_tangent));
        let mut m = vec![[0.0; 3]; y.len()];
        for c in 0..3 {
            let ys: Vec<f64> = y.iter().map(|p| p[c]).collect();
            let ms = second_derivatives(&t, &ys, d0.map(|d| d[c]), d1.map(|d| d[c]));
            for (i, v) in ms.into_iter().enumerate() {
                m[i][c] = v;
            }
        }
        Ok(FitSpline { t, y, m })
    }
}

/// Second derivatives of the cubic spline through `(t[i], y[i])` (Thomas algorithm).
fn second_derivatives(t: &[f64], y: &[f64], d0: Option<f64>, d1: Option<f64>) -> Vec<f64> {
    let n = t.len();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let (mut a, mut b, mut c, mut r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let slope = |i: usize| (y[i + 1] - y[i]) / h[i];
    match d0 {
        Some(d) => {
            b[0] = 2.0 * h[0];
            c[0] = h[0];
            r[0] = 6.0 * (slope(0) - d);
        }
        None => b[0] = 1.0,
    }
    for i in 1..n - 1 {
        a[i] = h[i - 1];
        b[i] = 2.0 * (h[i - 1] + h[i]);
        c[i] = h[i];
        r[i] = 6.0 * (slope(i) - slope(i - 1));
    }
    match d1 {
        Some(d) => {
            a[n - 1] = h[n - 2];
            b[n - 1] = 2.0 * h[n - 2];
            r[n - 1] = 6.0 * (d - slope(n - 2));
        }
        None => b[n - 1] = 1.0,
    }
    for i in 1..n {
        let w = a[i] / b[i - 1];
        b[i] -= w * c[i - 1];
        r[i] -= w * r[i - 1];
    }
    let mut m = vec![0.0; n];
    m[n - 1] = r[n - 1] / b[n - 1];
    for i in (0..n - 1).rev() {
        m[i] = (r[i] - c[i] * m[i + 1]) / b[i];
    }
    m
}

impl PieceCurve for FitSpline {
    fn pieces(&self) -> Vec<(f64, f64)> {
        self.t.windows(2).map(|w| (w[0], w[1])).collect()
    }

    fn eval(&self, i: usize, t: f64) -> P3 {
        let h = self.t[i + 1] - self.t[i];
        let a = (self.t[i + 1] - t) / h;
        let b = (t - self.t[i]) / h;
        let k = h * h / 6.0;
        let mut p = [0.0; 3];
        for (c, v) in p.iter_mut().enumerate() {
            *v = a * self.y[i][c]
                + b * self.y[i + 1][c]
                + ((a * a * a - a) * self.m[i][c] + (b * b * b - b) * self.m[i + 1][c]) * k;
        }
        p
    }
}

impl CubicCurve for EllipseArc {
    fn cubics(&self, tolerance: f64) -> Result<Vec<Cubic>, String> {
        let sweep = self.t1 - self.t0;
        let stretch = (norm(self.u).powi(2) + norm(self.v).powi(2)).sqrt();
        let quarters = (sweep.abs() / std::f64::consts::FRAC_PI_2 - 1e-9)
            .ceil()
            .max(1.0);
        let mut n = quarters as usize;
        while stretch * circle_cubic_error(sweep.abs() / n as f64) > tolerance {
            n = n
                .checked_mul(2)
                .filter(|&n| n <= MAX_CUBICS)
                .ok_or_else(|| {
                    "it needs more than a million cubics at this tolerance".to_string()
                })?;
        }
        let part = sweep / n as f64;
        let k = 4.0 / 3.0 * libm::tan(part / 4.0);
        let tangent = |t: f64| {
            let (s, c) = libm::sincos(t);
            add(scale(self.u, -s), scale(self.v, c))
        };
        Ok((0..n)
            .map(|i| {
                let a = self.t0 + part * i as f64;
                let b = if i + 1 == n { self.t1 } else { a + part };
                let (p0, p3) = (self.at(a), self.at(b));
                [
                    p0,
                    add(p0, scale(tangent(a), k)),
                    sub(p3, scale(tangent(b), k)),
                    p3,
                ]
            })
            .collect())
    }
}

/// The largest radial distance from the unit circle of the standard cubic for an arc of
/// `theta` radians (handles `4/3·tan(θ/4)`): `2·sin⁶(θ/4)/(27·cos²(θ/4))`.
pub fn circle_cubic_error(theta: f64) -> f64 {
    let (s, c) = libm::sincos(theta / 4.0);
    2.0 * s.powi(6) / (27.0 * c * c)
}

impl CubicCurve for Nurbs {
    fn cubics(&self, tolerance: f64) -> Result<Vec<Cubic>, String> {
        pvt_core::rational::nurbs_cubics(self.degree, &self.knots, &self.ctrl, tolerance)
            .map_err(|e| e.to_string())
    }
}

pub use pvt_core::rational::cubic_at;

impl CubicCurve for FitSpline {
    fn cubics(&self, _tolerance: f64) -> Result<Vec<Cubic>, String> {
        Ok((0..self.t.len() - 1)
            .map(|i| {
                let h = self.t[i + 1] - self.t[i];
                let (y0, y1, m0, m1) = (self.y[i], self.y[i + 1], self.m[i], self.m[i + 1]);
                // Derivatives at the span's ends of the spline's cubic (see `eval`).
                let d0: P3 =
                    std::array::from_fn(|c| (y1[c] - y0[c]) / h - h * (2.0 * m0[c] + m1[c]) / 6.0);
                let d1: P3 =
                    std::array::from_fn(|c| (y1[c] - y0[c]) / h + h * (m0[c] + 2.0 * m1[c]) / 6.0);
                [
                    y0,
                    add(y0, scale(d0, h / 3.0)),
                    sub(y1, scale(d1, h / 3.0)),
                    y1,
                ]
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::dist;

    #[test]
    fn rational_quadratic_is_an_exact_quarter_circle() {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let nurbs = Nurbs::new(
            2,
            &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            &[1.0, w, 1.0],
        )
        .unwrap();
        let curve = NurbsCurve::new(nurbs);
        for i in 0..=100 {
            let p = curve.eval(0, f64::from(i) / 100.0);
            assert!((norm(p) - 1.0).abs() < 1e-14);
        }
        let pts = flatten(&curve, 1e-4).unwrap();
        assert_eq!(pts[0], [1.0, 0.0, 0.0]);
        assert!(dist(*pts.last().unwrap(), [0.0, 1.0, 0.0]) < 1e-15);
        // Chords of a unit circle within 1e-4: each spans at most 2·acos(1 − 1e-4).
        let widest = 2.0 * libm::acos(1.0 - 1e-4);
        assert!(pts.len() > (std::f64::consts::FRAC_PI_2 / widest).ceil() as usize);
        for w in pts.windows(2) {
            let mid = scale(add(w[0], w[1]), 0.5);
            assert!(1.0 - norm(mid) <= 1e-4, "sagitta {}", 1.0 - norm(mid));
        }
    }

    #[test]
    fn invalid_nurbs_are_refused() {
        let p = [[0.0; 3], [1.0, 0.0, 0.0]];
        assert!(Nurbs::new(1, &[0.0, 0.0, 1.0], &p, &[]).is_err());
        assert!(Nurbs::new(1, &[0.0, 0.0, 0.0, 0.0], &p, &[]).is_err());
        assert!(Nurbs::new(1, &[0.0, 0.0, 1.0, 1.0], &p, &[1.0, -1.0]).is_err());
        assert!(Nurbs::new(1, &[0.0, 1.0, 0.5, 1.0], &p, &[]).is_err());
        assert!(Nurbs::new(0, &[0.0, 1.0], &p[..1], &[]).is_err());
        assert!(Nurbs::new(1, &[0.0, 0.0, 1.0, 1.0], &p, &[]).is_ok());
    }

    #[test]
    fn fit_spline_passes_through_points_with_given_tangent() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
        ];
        let s = FitSpline::new(&pts, Some([1.0, 0.0, 0.0]), None).unwrap();
        for (i, p) in pts.iter().enumerate().take(3) {
            assert!(dist(s.eval(i, s.t[i]), *p) < 1e-12);
        }
        assert!(dist(s.eval(2, s.t[3]), pts[3]) < 1e-12);
        // Start derivative is the unit tangent (finite difference).
        let e = 1e-6;
        let d = scale(sub(s.eval(0, e), s.eval(0, 0.0)), 1.0 / e);
        assert!((d[0] - 1.0).abs() < 1e-5 && d[1].abs() < 1e-5);
        // Natural end: second derivative zero at the last point.
        let last = s.m.last().unwrap();
        assert!(last.iter().all(|v| v.abs() < 1e-12));
        // Two points and natural ends: the straight line.
        let line = FitSpline::new(&[[0.0; 3], [0.0; 3], [2.0, 2.0, 0.0]], None, None).unwrap();
        assert!(dist(line.eval(0, 1.0), [libm::sqrt(0.5), libm::sqrt(0.5), 0.0]) < 1e-12);
    }

    /// The ellipse's cubics, evaluated densely, against the ellipse itself: the distance
    /// from each cubic point to the ellipse (by a fine search over its parameter) stays
    /// within the tolerance; and the circle bound holds where the module says it does.
    #[test]
    fn ellipse_cubics_stay_within_tolerance() {
        for theta in [0.1, 0.5, 1.0, std::f64::consts::FRAC_PI_2] {
            let k = 4.0 / 3.0 * libm::tan(theta / 4.0);
            let c = [
                [1.0, 0.0, 0.0],
                [1.0, k, 0.0],
                [
                    libm::cos(theta) + k * libm::sin(theta),
                    libm::sin(theta) - k * libm::cos(theta),
                    0.0,
                ],
                [libm::cos(theta), libm::sin(theta), 0.0],
            ];
            let worst = (0..=1000)
                .map(|i| {
                    let p = cubic_at(&c, f64::from(i) / 1000.0);
                    (libm::hypot(p[0], p[1]) - 1.0).abs()
                })
                .fold(0.0, f64::max);
            let bound = circle_cubic_error(theta);
            assert!(
                worst <= bound * (1.0 + 1e-6) + 1e-14 && worst >= 0.9 * bound,
                "{theta}: {worst} vs {bound}"
            );
        }
        let e = EllipseArc {
            c: [3.0, -1.0, 2.0],
            u: [40.0, 10.0, 0.0],
            v: [-2.0, 8.0, 0.0],
            t0: 0.3,
            t1: 0.3 + 5.0,
        };
        // Chords of 1/20,000 of the sweep lie within 1e-5 of this ellipse.
        let fine: Vec<P3> = (0..=20_000)
            .map(|i| e.at(0.3 + 5.0 * f64::from(i) / 20_000.0))
            .collect();
        for tol in [1e-2, 1e-3] {
            let cubics = e.cubics(tol).unwrap();
            for c in &cubics {
                for i in 0..=64 {
                    let p = cubic_at(c, f64::from(i) / 64.0);
                    let d = fine
                        .windows(2)
                        .map(|w| dist_to_segment(p, w[0], w[1]))
                        .fold(f64::INFINITY, f64::min);
                    assert!(d <= tol + 1e-5, "{tol}: {d}");
                }
            }
        }
    }

    #[test]
    fn ellipse_flattening_keeps_sagitta() {
        let e = EllipseArc {
            c: [1.0, 2.0, 0.0],
            u: [10.0, 0.0, 0.0],
            v: [0.0, 3.0, 0.0],
            t0: 0.5,
            t1: -4.0,
        };
        let pts = flatten(&e, 1e-3).unwrap();
        assert_eq!(pts[0], e.at(0.5));
        assert_eq!(*pts.last().unwrap(), e.at(-4.0));
        for i in 0..=20_000 {
            let t = 0.5 - 4.5 * f64::from(i) / 20_000.0;
            let p = e.at(t);
            let d = pts
                .windows(2)
                .map(|w| dist_to_segment(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 1e-3, "t={t}: {d}");
        }
    }
}
