//! One programmed element as a parametric curve on the program's axes.
//!
//! Owns the exact position, first derivative (and unit tangent: a line's is made once,
//! with its curve) and derivative bounds of a line, arc, helix,
//! spiral arc or cubic Bézier, by a parameter `φ` (arc length on a line, swept angle on an
//! arc, the Bézier parameter scaled by the part's length on a Bézier), and the split of a
//! Bézier into parts whose speed `|dc/dφ|` stays near 1 (see [`bezier_parts`]). It must
//! not choose speeds or pieces: that is the planner's.

use super::Vector;
use crate::axis::Axis;
use crate::bezier;
use crate::toolpath::{Bezier, Element, ElementKind};
use crate::vector::{distance, norm};

/// How far, relative to its radius, an arc may leave the circle of its start radius and
/// still count as one ([`Curve::circle`]).
pub(super) const CIRCLE_SLACK: f64 = 1e-9;

/// An element on the projected axes, parametrized by `φ ∈ [0, span]`.
#[derive(Debug, Clone)]
pub(super) struct Curve {
    /// Exact start, projected.
    pub start: Vector,
    /// Exact end, projected.
    pub end: Vector,
    /// Parameter range.
    pub span: f64,
    /// Programmed feed, units/s.
    pub feed: f64,
    /// Source line.
    pub line: u32,
    /// How far the programmed cubic may be from the curve it stands for (the Bézier's
    /// `fit`; 0 on lines, arcs and exact cubics): every piece's error bound adds it.
    pub fit: f64,
    shape: Shape,
}

#[derive(Debug, Clone)]
enum Shape {
    /// φ is the distance from the start along `unit`; `tangent` is `unit` divided by its
    /// own norm, the line's unit tangent as [`Curve::unit_tangent`] gives it (made once,
    /// with the curve: every junction asks for it).
    Line { unit: Vector, tangent: Vector },
    /// φ is the swept angle; see [`Curve::position`].
    Arc(ArcShape),
    /// φ = `scale`·u on a part of a Bézier; see [`BezierShape`].
    Bezier(BezierShape),
}

/// One part of a Bézier: `c(φ) = B(φ/scale)` in the plane, the other axes linear in φ.
/// With `D = 1/scale`, `|dⁿc/dφⁿ| = |Bⁿ(u)|·Dⁿ` in the plane, where by the convex hull
/// property `|B''| ≤ 6·max|ΔP²|`, `|B'''| = 6·|ΔP³|` and `B'''' = 0`.
#[derive(Debug, Clone)]
struct BezierShape {
    /// Indices of the plane's first and second axes among the projected axes.
    first: usize,
    second: usize,
    /// The part's control points in the plane.
    points: [[f64; 2]; 4],
    /// φ per unit of the part's parameter u: its length.
    scale: f64,
    /// d/dφ of every projected axis that moves linearly (zero on the plane's two axes).
    linear_rate: Vector,
    /// `[D₂, D₃, D₄]` of [`Curve::derivative_bounds`].
    bounds: [f64; 3],
}

#[derive(Debug, Clone)]
struct ArcShape {
    /// Indices of the plane's first and second axes among the projected axes.
    first: usize,
    second: usize,
    center: [f64; 2],
    start_angle: f64,
    /// +1 counter-clockwise, −1 clockwise.
    turn: f64,
    start_radius: f64,
    /// dr/dφ: the radius changes linearly with angle (a spiral posted with few decimals).
    radius_rate: f64,
    /// d/dφ of every projected axis that moves linearly (zero on the plane's two axes).
    linear_rate: Vector,
    /// `|linear_rate|`, the helix' lead per radian.
    lead: f64,
    /// [`ArcShape::normal_bound`] over the whole arc.
    normal_bound: f64,
    /// The last angle interval [`ArcShape::largest_sin_cos`] was asked, and its answer.
    last_extremes: std::cell::Cell<[f64; 4]>,
    /// The last two parameters [`ArcShape::sin_cos`] was asked, with their sines and
    /// cosines, the more recent first.
    last_sin_cos: std::cell::Cell<[[f64; 3]; 2]>,
}

impl Curve {
    /// Appends the curves of `element` on `axes` to `out`: none when it does not move, a
    /// Bézier's parts ([`bezier_parts`]), else one (written in place: a line or arc, the
    /// most common, costs no vector of its own).
    pub fn push_new(element: &Element, axes: &[Axis], out: &mut Vec<Curve>) {
        if let ElementKind::Bezier(bezier) = element.kind {
            if let Some(mut parts) = bezier_parts(element, &bezier, axes) {
                parts.iter_mut().for_each(|part| part.fit = bezier.fit);
                out.extend(parts);
                return;
            }
        }
        Curve::push_whole(element, axes, out);
    }

    /// Appends the curve of a line or arc (a Bézier off the projected axes: its chord)
    /// to `out`, none when it does not move: built where it lies (a curve is large).
    fn push_whole(element: &Element, axes: &[Axis], out: &mut Vec<Curve>) {
        let start = Vector::from_fn(axes.len(), |i| element.start[axes[i].index()]);
        let end = Vector::from_fn(axes.len(), |i| element.end[axes[i].index()]);
        let shape = match element.kind {
            ElementKind::Arc(arc) => arc_shape(element, &arc, axes),
            ElementKind::Line | ElementKind::Bezier(_) => None,
        };
        let (shape, span) = match shape {
            Some((arc, span)) => (Shape::Arc(arc), span),
            None => {
                let length = distance(&start, &end);
                let unit = Vector::from_fn(start.len(), |i| (end[i] - start[i]) / length);
                let n = norm(&unit);
                let tangent = Vector::from_fn(unit.len(), |i| unit[i] / n);
                (Shape::Line { unit, tangent }, length)
            }
        };
        if span.is_finite() && span > 0.0 {
            out.push(Curve {
                start,
                end,
                span,
                feed: element.feed,
                line: element.span.line,
                fit: 0.0,
                shape,
            });
        }
    }

    /// True for a straight line.
    pub fn is_line(&self) -> bool {
        matches!(self.shape, Shape::Line { .. })
    }

    /// A plane circle's two plane axes (indices among the projected axes), center and
    /// start radius: an arc whose radius changes and whose other axes move by at most
    /// [`CIRCLE_SLACK`] of its radius over the whole arc (the rounding of its end points).
    /// `None` for a line, a helix, a spiral and a Bézier part.
    pub fn circle(&self) -> Option<(usize, usize, [f64; 2], f64)> {
        match &self.shape {
            Shape::Arc(a) => {
                let r = a.start_radius;
                let slack = CIRCLE_SLACK * r;
                let round =
                    (a.radius_rate * self.span).abs() <= slack && a.lead * self.span <= slack;
                round.then_some((a.first, a.second, a.center, r))
            }
            _ => None,
        }
    }

    /// The position at `φ` (the exact programmed end at `φ = span`).
    pub fn position(&self, phi: f64, out: &mut [f64]) {
        if phi >= self.span {
            out.copy_from_slice(&self.end);
            return;
        }
        if phi <= 0.0 {
            out.copy_from_slice(&self.start);
            return;
        }
        match &self.shape {
            Shape::Line { unit, .. } => {
                for ((o, s), u) in out.iter_mut().zip(&self.start).zip(unit) {
                    *o = s + u * phi;
                }
            }
            Shape::Arc(a) => {
                for ((o, s), h) in out.iter_mut().zip(&self.start).zip(&a.linear_rate) {
                    *o = s + h * phi;
                }
                let (sin, cos) = a.sin_cos(phi);
                let r = a.start_radius + a.radius_rate * phi;
                out[a.first] = a.center[0] + r * cos;
                out[a.second] = a.center[1] + r * sin;
            }
            Shape::Bezier(b) => {
                for ((o, s), h) in out.iter_mut().zip(&self.start).zip(&b.linear_rate) {
                    *o = s + h * phi;
                }
                let p = bezier::eval(&b.points, phi / b.scale);
                out[b.first] = p[0];
                out[b.second] = p[1];
            }
        }
    }

    /// [`Curve::position`] as a vector: the ends are copied whole (no copy of a slice of
    /// unknown length, which is a call to `memcpy`).
    #[inline]
    pub fn point(&self, phi: f64) -> Vector {
        if phi >= self.span {
            return self.end;
        }
        if phi <= 0.0 {
            return self.start;
        }
        let mut p = Vector::zeros(self.start.len());
        self.position(phi, &mut p);
        p
    }

    /// dc/dφ at `φ`.
    pub fn derivative(&self, phi: f64, out: &mut [f64]) {
        let (base, plane) = self.derivative_parts(phi);
        out.copy_from_slice(&base);
        if let Some((first, second, x, y)) = plane {
            (out[first], out[second]) = (x, y);
        }
    }

    /// [`Curve::derivative`] as a vector (copied whole, not through a slice).
    #[inline]
    pub fn derivative_vector(&self, phi: f64) -> Vector {
        let (mut out, plane) = self.derivative_parts(phi);
        if let Some((first, second, x, y)) = plane {
            (out.values[first], out.values[second]) = (x, y);
        }
        out
    }

    /// dc/dφ at `φ` off the plane (or all of it on a line), and where there is one, the
    /// plane's two axes and their values.
    #[inline]
    fn derivative_parts(&self, phi: f64) -> (Vector, Option<(usize, usize, f64, f64)>) {
        match &self.shape {
            Shape::Line { unit, .. } => (*unit, None),
            Shape::Arc(a) => {
                let (sin, cos) = a.sin_cos(phi);
                let r = a.start_radius + a.radius_rate * phi;
                let x = a.radius_rate * cos - a.turn * r * sin;
                let y = a.radius_rate * sin + a.turn * r * cos;
                (a.linear_rate, Some((a.first, a.second, x, y)))
            }
            Shape::Bezier(b) => {
                let d = bezier::derivative(&b.points, phi / b.scale);
                let plane = (b.first, b.second, d[0] / b.scale, d[1] / b.scale);
                (b.linear_rate, Some(plane))
            }
        }
    }

    /// A line's unit tangent (the same at every `φ`), `None` on any other curve.
    #[inline]
    pub fn line_tangent(&self) -> Option<&Vector> {
        match &self.shape {
            Shape::Line { tangent, .. } => Some(tangent),
            _ => None,
        }
    }

    /// The unit tangent at `φ`: [`Curve::derivative`] divided by its norm (a line's is
    /// kept with it).
    pub fn unit_tangent(&self, phi: f64) -> Vector {
        if let Shape::Line { tangent, .. } = &self.shape {
            return *tangent;
        }
        let mut t = self.derivative_vector(phi);
        let n = norm(&t);
        t.iter_mut().for_each(|x| *x /= n);
        t
    }

    /// |dc/dφ| at `φ`: path length per unit of parameter.
    #[inline(always)]
    pub fn rate(&self, phi: f64) -> f64 {
        match &self.shape {
            Shape::Line { .. } => 1.0,
            Shape::Arc(a) => {
                let r = a.start_radius + a.radius_rate * phi;
                let h = a.lead;
                (a.radius_rate * a.radius_rate + r * r + h * h).sqrt()
            }
            Shape::Bezier(b) => {
                let d = bezier::derivative(&b.points, phi / b.scale);
                let (x, y) = (d[0] / b.scale, d[1] / b.scale);
                let h = norm(&b.linear_rate);
                (x * x + y * y + h * h).sqrt()
            }
        }
    }

    /// Bounds on |dⁿc/dφⁿ| for n = 2, 3, 4 over the whole element.
    ///
    /// In the plane, c = r(φ)·e^{i(a₀ ± φ)} with r linear, so |dⁿc/dφⁿ| ≤ r_max + n·|dr/dφ|;
    /// the other axes are linear in φ. A Bézier part's are those of [`BezierShape`]. A
    /// line has none.
    #[inline]
    pub fn derivative_bounds(&self) -> [f64; 3] {
        match &self.shape {
            Shape::Line { .. } => [0.0; 3],
            Shape::Bezier(b) => b.bounds,
            Shape::Arc(a) => {
                let r = self.max_radius(a);
                let k = a.radius_rate.abs();
                [r + 2.0 * k, r + 3.0 * k, r + 4.0 * k]
            }
        }
    }

    /// Path length between two parameters (exact on lines and circles, the mean rate on
    /// a spiral, Simpson's rule on a Bézier part).
    #[inline]
    pub fn length(&self, from: f64, to: f64) -> f64 {
        let mid = 0.5 * (from + to);
        if let Shape::Bezier(_) = &self.shape {
            let rates = self.rate(from) + 4.0 * self.rate(mid) + self.rate(to);
            return (to - from) * rates / 6.0;
        }
        (to - from) * self.rate(mid)
    }

    /// The widest angle an arc piece of constant speed may sweep so that its Hermite
    /// error `D₄·θ⁴/384` stays within `tolerance`, and never above a quarter turn.
    pub fn arc_piece_angle(&self, tolerance: f64) -> Option<f64> {
        let Shape::Arc(_) = &self.shape else {
            return None;
        };
        let d4 = self.derivative_bounds()[2];
        let theta = libm::pow(384.0 * tolerance / d4, 0.25);
        Some(theta.min(std::f64::consts::FRAC_PI_2))
    }

    /// A bound on every axis' second factor of [`Curve::axis_factors`] over the whole
    /// curve, without a sine (`None` on a Bézier part, whose factor may be infinite).
    #[inline]
    pub fn normal_bound(&self) -> Option<f64> {
        match &self.shape {
            Shape::Line { .. } => Some(0.0),
            Shape::Arc(a) => Some(a.normal_bound),
            Shape::Bezier(_) => None,
        }
    }

    /// Per-axis bounds over `[from, to]` for axis `i`: (largest |dc_i/dφ|, largest
    /// |d²c_i/dφ²|), each divided by the smallest rate (resp. its square): the share of
    /// the path speed (resp. of speed²) that axis `i` sees.
    #[inline]
    pub fn axis_factors(&self, from: f64, to: f64, i: usize) -> (f64, f64) {
        match &self.shape {
            Shape::Line { unit, .. } => (unit[i].abs(), 0.0),
            Shape::Bezier(b) => self.bezier_factors(b, from, to, i),
            Shape::Arc(a) => {
                let r = self.max_radius(a);
                let k = a.radius_rate.abs();
                let h = a.lead;
                let r_min = a
                    .start_radius
                    .min(a.start_radius + a.radius_rate * self.span);
                let rate_min = (r_min * r_min + h * h).sqrt();
                let (lo, hi) = {
                    let x = a.start_angle + a.turn * from;
                    let y = a.start_angle + a.turn * to;
                    (x.min(y), x.max(y))
                };
                let (d1, d2) = if i == a.first {
                    let (sin, cos) = a.largest_sin_cos(lo, hi);
                    (k + r * sin, 2.0 * k + r * cos)
                } else if i == a.second {
                    let (sin, cos) = a.largest_sin_cos(lo, hi);
                    (k + r * cos, 2.0 * k + r * sin)
                } else {
                    (a.linear_rate[i].abs(), 0.0)
                };
                (d1 / rate_min, d2 / (rate_min * rate_min))
            }
        }
    }

    /// [`Curve::axis_factors`] on a Bézier part: `dc_i/dφ` is a quadratic in φ (its
    /// largest magnitude at an end or its vertex) and `d²c_i/dφ²` linear (at an end); the
    /// rate is at least `(rate(from) + rate(to) − D₂·(to − from))/2` (it changes by at
    /// most `D₂` per unit of φ).
    fn bezier_factors(&self, b: &BezierShape, from: f64, to: f64, i: usize) -> (f64, f64) {
        let d2 = b.bounds[0];
        let rate_min = 0.5 * (self.rate(from) + self.rate(to) - d2 * (to - from));
        if rate_min <= 0.0 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let k = if i == b.first {
            0
        } else if i == b.second {
            1
        } else {
            return (b.linear_rate[i].abs() / rate_min, 0.0);
        };
        let (u0, u1) = (from / b.scale, to / b.scale);
        let first = |u: f64| bezier::derivative(&b.points, u)[k].abs();
        let mut d1 = first(u0).max(first(u1));
        // The quadratic's vertex, where its derivative (linear) vanishes.
        let (s0, s1) = (
            bezier::second_derivative(&b.points, 0.0)[k],
            bezier::second_derivative(&b.points, 1.0)[k],
        );
        if s0 != s1 {
            let vertex = s0 / (s0 - s1);
            if vertex > u0 && vertex < u1 {
                d1 = d1.max(first(vertex));
            }
        }
        let second = |u: f64| bezier::second_derivative(&b.points, u)[k].abs();
        let d2 = second(u0).max(second(u1));
        (
            d1 / b.scale / rate_min,
            d2 / (b.scale * b.scale) / (rate_min * rate_min),
        )
    }

    fn max_radius(&self, a: &ArcShape) -> f64 {
        a.start_radius
            .max(a.start_radius + a.radius_rate * self.span)
    }
}

impl ArcShape {
    /// The sine and cosine of the angle at `φ`, kept for the last two parameters: a
    /// piece asks for the position and the derivative at both its ends, and its start
    /// is the last piece's end, so each piece takes one `sincos`, with the same values.
    fn sin_cos(&self, phi: f64) -> (f64, f64) {
        let [last, before] = self.last_sin_cos.get();
        for [at, sin, cos] in [last, before] {
            if at == phi {
                return (sin, cos);
            }
        }
        let (sin, cos) = libm::sincos(self.start_angle + self.turn * phi);
        self.last_sin_cos.set([[phi, sin, cos], last]);
        (sin, cos)
    }

    /// A bound on `|d²c_i/dφ²|` over the arc divided by the square of its least rate:
    /// on every axis, at least [`Curve::axis_factors`]' second factor.
    fn find_normal_bound(&self, span: f64) -> f64 {
        let r = self
            .start_radius
            .max(self.start_radius + self.radius_rate * span);
        let r_min = self
            .start_radius
            .min(self.start_radius + self.radius_rate * span);
        let h = self.lead;
        // As `axis_factors` computes it: its numerator `2k + r·|cos|` is at most this
        // one's under rounding too.
        let rate_min = (r_min * r_min + h * h).sqrt();
        (2.0 * self.radius_rate.abs() + r) / (rate_min * rate_min)
    }

    /// The largest |sin| and |cos| of the angle over `[lo, hi]`, kept for the last
    /// interval asked: the planner asks for both plane axes of one piece in turn, so
    /// each piece takes its sines once, with the same values.
    fn largest_sin_cos(&self, lo: f64, hi: f64) -> (f64, f64) {
        let [last_lo, last_hi, sin, cos] = self.last_extremes.get();
        if (last_lo, last_hi) == (lo, hi) {
            return (sin, cos);
        }
        let (sin, cos) = (
            max_abs_sin(lo, hi),
            max_abs_sin(lo + FRAC_PI_2, hi + FRAC_PI_2),
        );
        self.last_extremes.set([lo, hi, sin, cos]);
        (sin, cos)
    }
}

use std::f64::consts::{FRAC_PI_2, PI};

/// Largest ratio of the fastest to the slowest rate `|dB/du|` (sampled) on one Bézier
/// part: a part over it is halved, so φ stays within about this factor of arc length and
/// the path speed at a constant parameter rate within it of the planned one.
const RATE_RATIO: f64 = 1.25;

/// Deepest halving of a Bézier into parts (near a cusp, where the rate falls to zero).
const MAX_DEPTH: u32 = 12;

/// The parts of a Bézier `element` on `axes`, halved until each one's sampled rate
/// varies by at most [`RATE_RATIO`] (or [`MAX_DEPTH`] is reached); a part whose rate
/// vanishes at an end (a cusp) or whose control points all coincide becomes its chord.
/// `None` when the plane's axes are not both projected.
fn bezier_parts(element: &Element, bezier: &Bezier, axes: &[Axis]) -> Option<Vec<Curve>> {
    let (a0, a1, _) = bezier.plane.axes();
    let first = axes.iter().position(|&a| a == a0)?;
    let second = axes.iter().position(|&a| a == a1)?;
    let mut out = Vec::new();
    let mut stack = vec![(0.0, 1.0, 0)];
    let whole = bezier.points(&element.start, &element.end);
    while let Some((u0, u1, depth)) = stack.pop() {
        let points = bezier::sub_curve(&whole, u0, u1);
        if depth < MAX_DEPTH && !even_rate(element, &points, u1 - u0) {
            let mid = 0.5 * (u0 + u1);
            stack.push((mid, u1, depth + 1));
            stack.push((u0, mid, depth + 1));
            continue;
        }
        let start = bezier.position(&element.start, &element.end, u0);
        let end = bezier.position(&element.start, &element.end, u1);
        let part = Element {
            kind: ElementKind::Line,
            start,
            end,
            ..*element
        };
        let scale = part_length(element, &points, u1 - u0);
        let cusp = rates(element, &points, u1 - u0)
            .iter()
            .any(|r| r.is_nan() || *r <= 1e-9 * scale);
        if cusp || !(scale > 0.0 && scale.is_finite()) {
            Curve::push_whole(&part, axes, &mut out);
            continue;
        }
        let mut linear_rate = Vector::from_fn(axes.len(), |i| {
            let a = axes[i].index();
            (end[a] - start[a]) / scale
        });
        linear_rate[first] = 0.0;
        linear_rate[second] = 0.0;
        let bounds = [
            bezier::second_derivative_bound(&points) / (scale * scale),
            bezier::third_derivative(&points) / (scale * scale * scale),
            0.0,
        ];
        let shape = BezierShape {
            first,
            second,
            points,
            scale,
            linear_rate,
            bounds,
        };
        out.push(Curve {
            start: Vector::from_fn(axes.len(), |i| start[axes[i].index()]),
            end: Vector::from_fn(axes.len(), |i| end[axes[i].index()]),
            span: scale,
            feed: element.feed,
            line: element.span.line,
            fit: 0.0,
            shape: Shape::Bezier(shape),
        });
    }
    Some(out)
}

/// `|dB/du|` of a part (control points `points`, the other axes moving `share` of the
/// element's travel) at 9 equally spaced parameters, every axis counted.
fn rates(element: &Element, points: &[[f64; 2]; 4], share: f64) -> [f64; 9] {
    let ElementKind::Bezier(bezier) = element.kind else {
        return [1.0; 9];
    };
    let (a0, a1, _) = bezier.plane.axes();
    let other: f64 = (0..crate::axis::AXIS_COUNT)
        .filter(|&i| i != a0.index() && i != a1.index())
        .map(|i| (share * (element.end[i] - element.start[i])).powi(2))
        .sum();
    std::array::from_fn(|k| {
        let d = bezier::derivative(points, k as f64 / 8.0);
        (d[0] * d[0] + d[1] * d[1] + other).sqrt()
    })
}

/// True when the sampled rates of a part differ by at most [`RATE_RATIO`].
fn even_rate(element: &Element, points: &[[f64; 2]; 4], share: f64) -> bool {
    let r = rates(element, points, share);
    let (lo, hi) = r.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    hi <= RATE_RATIO * lo
}

/// A part's length by Simpson's rule on its 9 sampled rates.
fn part_length(element: &Element, points: &[[f64; 2]; 4], share: f64) -> f64 {
    let r = rates(element, points, share);
    let weights = [1.0, 4.0, 2.0, 4.0, 2.0, 4.0, 2.0, 4.0, 1.0];
    r.iter().zip(weights).map(|(r, w)| r * w).sum::<f64>() / 24.0
}

/// The largest |sin x| for x in `[lo, hi]`.
fn max_abs_sin(lo: f64, hi: f64) -> f64 {
    // A peak of |sin| lies at π/2 + nπ.
    let n = ((lo - FRAC_PI_2) / PI).ceil();
    if FRAC_PI_2 + n * PI <= hi {
        return 1.0;
    }
    libm::sin(lo).abs().max(libm::sin(hi).abs())
}

fn arc_shape(
    element: &Element,
    arc: &crate::toolpath::Arc,
    axes: &[Axis],
) -> Option<(ArcShape, f64)> {
    let (first, second, _) = arc.plane.axes();
    let first = axes.iter().position(|&a| a == first)?;
    let second = axes.iter().position(|&a| a == second)?;
    let sweep = arc.sweep(&element.start, &element.end);
    let span = sweep.sweep.abs();
    let mut linear_rate = Vector::from_fn(axes.len(), |i| {
        let a = axes[i].index();
        (element.end[a] - element.start[a]) / span
    });
    linear_rate[first] = 0.0;
    linear_rate[second] = 0.0;
    let mut shape = ArcShape {
        first,
        second,
        center: arc.center,
        start_angle: sweep.start_angle,
        turn: sweep.sweep.signum(),
        start_radius: sweep.start_radius,
        radius_rate: (sweep.end_radius - sweep.start_radius) / span,
        lead: norm(&linear_rate),
        normal_bound: f64::NAN,
        linear_rate,
        last_extremes: std::cell::Cell::new([f64::NAN; 4]),
        last_sin_cos: std::cell::Cell::new([[f64::NAN; 3]; 2]),
    };
    shape.normal_bound = shape.find_normal_bound(span);
    Some((shape, span))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_abs_sin_finds_inner_peaks() {
        assert_eq!(max_abs_sin(0.0, 2.0), 1.0);
        assert!((max_abs_sin(0.0, 1.0) - libm::sin(1.0)).abs() < 1e-15);
        assert_eq!(max_abs_sin(-2.0, -1.0), 1.0);
        assert!((max_abs_sin(2.0, 3.0) - libm::sin(2.0)).abs() < 1e-15);
    }
}
