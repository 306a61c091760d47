//! B-splines, rational ones included, as cubic Béziers within a tolerance.
//!
//! Owns the rule that turns a (rational) B-spline into cubics: a knot span whose Bézier
//! ([`crate::bezier::bezier_spans`], in homogeneous coordinates `(w·x, w·y, w·z, w)`) is
//! polynomial (every weight equal) and of degree 1 to 3 is raised to a cubic, exactly;
//! any other span (rational, or degree 4 and above) is cut into Hermite cubics: the span
//! is halved until the cubic through the exact end points and end derivatives (times
//! the interval) stays, at 31 equally spaced interior parameters, within 0.99 × the
//! tolerance of the curve at the same parameter. Between samples 1/32 apart the distance
//! of a smooth curve from its Hermite cubic is near its sampled largest (the error is a
//! smooth function that vanishes to second order at both ends), which the 1 % margin
//! covers. It must not know where the curve comes from (DXF, G-code) nor plan motion.

use crate::bezier::{bezier_spans, elevate_to_cubic, SplineError};

/// A point in X Y Z.
pub type Point3 = [f64; 3];
/// A cubic Bézier's four control points.
pub type Cubic3 = [Point3; 4];

/// Most cubics one curve may become.
pub const MAX_CUBICS: usize = 1_000_000;
/// Deepest halving of one span.
pub const MAX_DEPTH: u32 = 48;
/// Interior samples of each Hermite cubic against the curve.
pub const SAMPLES: usize = 31;
/// Share of the tolerance a sampled distance may reach.
pub const MARGIN: f64 = 0.99;

/// Why a B-spline cannot be given as cubics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The knots, degree or control points do not make a B-spline.
    #[error(transparent)]
    Spline(#[from] SplineError),
    /// A point of the curve is not finite (a zero weight sum).
    #[error("the curve evaluates to a non-finite point")]
    NotFinite,
    /// Halving reached [`MAX_DEPTH`] or the cubics [`MAX_CUBICS`].
    #[error("the tolerance cannot be met (the curve is too large or not smooth)")]
    Tolerance,
    /// More than [`MAX_CUBICS`] cubics.
    #[error("it needs more than a million cubics at this tolerance")]
    TooMany,
}

/// The cubics of the B-spline of `degree` with `knots` and homogeneous control points
/// `ctrl` (`(w·x, w·y, w·z, w)`), in order, within `tolerance` of it (see the module).
pub fn nurbs_cubics(
    degree: usize,
    knots: &[f64],
    ctrl: &[[f64; 4]],
    tolerance: f64,
) -> Result<Vec<Cubic3>, FitError> {
    let mut out = Vec::new();
    for span in bezier_spans(degree, knots, ctrl)? {
        let w = span[0][3];
        let cartesian: Vec<Point3> = span
            .iter()
            .map(|h| [h[0] / h[3], h[1] / h[3], h[2] / h[3]])
            .collect();
        let polynomial = span.iter().all(|h| h[3] == w);
        match elevate_to_cubic(&cartesian).filter(|_| polynomial) {
            Some(cubic) => out.push(cubic),
            None => fit_cubics(&RationalBezier(span), 0.0, 1.0, tolerance, 0, &mut out)?,
        }
        if out.len() > MAX_CUBICS {
            return Err(FitError::TooMany);
        }
    }
    Ok(out)
}

/// A rational Bézier in homogeneous coordinates `(w·x, w·y, w·z, w)`, on `[0, 1]`.
struct RationalBezier(Vec<[f64; 4]>);

impl RationalBezier {
    /// The point and the derivative at `t` (de Casteljau; the last level's difference
    /// times the degree is the homogeneous derivative).
    fn point_and_derivative(&self, t: f64) -> (Point3, Point3) {
        let mut d = self.0.clone();
        let p = d.len() - 1;
        for level in 1..p {
            for j in 0..=p - level {
                let next = d[j + 1];
                for (v, q) in d[j].iter_mut().zip(next) {
                    *v = (1.0 - t) * *v + t * q;
                }
            }
        }
        let (h0, h1) = (d[0], d[1]);
        let h: [f64; 4] = std::array::from_fn(|c| (1.0 - t) * h0[c] + t * h1[c]);
        let dh: [f64; 4] = std::array::from_fn(|c| p as f64 * (h1[c] - h0[c]));
        let point = [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
        let derivative = std::array::from_fn(|c| (dh[c] - point[c] * dh[3]) / h[3]);
        (point, derivative)
    }
}

/// Hermite cubics on `[a, b]` of `curve` within `tolerance`, halving where the sampled
/// error is over.
fn fit_cubics(
    curve: &RationalBezier,
    a: f64,
    b: f64,
    tolerance: f64,
    depth: u32,
    out: &mut Vec<Cubic3>,
) -> Result<(), FitError> {
    let ((p0, d0), (p3, d3)) = (curve.point_and_derivative(a), curve.point_and_derivative(b));
    let h = (b - a) / 3.0;
    let cubic: Cubic3 = [
        p0,
        std::array::from_fn(|k| p0[k] + d0[k] * h),
        std::array::from_fn(|k| p3[k] - d3[k] * h),
        p3,
    ];
    let worst = (1..=SAMPLES)
        .map(|s| {
            let f = s as f64 / (SAMPLES + 1) as f64;
            let (c, q) = (
                cubic_at(&cubic, f),
                curve.point_and_derivative(a + (b - a) * f).0,
            );
            let d: f64 = (0..3).map(|k| (c[k] - q[k]) * (c[k] - q[k])).sum();
            d.sqrt()
        })
        .fold(0.0, f64::max);
    if !worst.is_finite() {
        return Err(FitError::NotFinite);
    }
    if worst <= MARGIN * tolerance {
        out.push(cubic);
        return Ok(());
    }
    if depth >= MAX_DEPTH || out.len() > MAX_CUBICS {
        return Err(FitError::Tolerance);
    }
    let m = 0.5 * (a + b);
    fit_cubics(curve, a, m, tolerance, depth + 1, out)?;
    fit_cubics(curve, m, b, tolerance, depth + 1, out)
}

/// The point at `t` of a cubic Bézier.
pub fn cubic_at(c: &Cubic3, t: f64) -> Point3 {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    std::array::from_fn(|k| w[0] * c[0][k] + w[1] * c[1][k] + w[2] * c[2][k] + w[3] * c[3][k])
}
