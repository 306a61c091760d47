//! One programmed element as a parametric curve on the program's axes.
//!
//! Owns the exact position, first derivative and derivative bounds of a line, arc, helix
//! or spiral arc, by a parameter `φ` (arc length on a line, swept angle on an arc). It
//! must not choose speeds or pieces: that is the planner's.

use super::Vector;
use crate::axis::Axis;
use crate::toolpath::{Element, ElementKind};
use crate::vector::{distance, norm};

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
    shape: Shape,
}

#[derive(Debug, Clone)]
enum Shape {
    /// φ is the distance from the start along `unit`.
    Line { unit: Vector },
    /// φ is the swept angle; see [`Curve::position`].
    Arc(ArcShape),
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
    /// The last angle interval [`ArcShape::largest_sin_cos`] was asked, and its answer.
    last_extremes: std::cell::Cell<[f64; 4]>,
}

impl Curve {
    /// The curve of `element` on `axes`; `None` when it does not move.
    pub fn new(element: &Element, axes: &[Axis]) -> Option<Curve> {
        let start = Vector::from_fn(axes.len(), |i| element.start[axes[i].index()]);
        let end = Vector::from_fn(axes.len(), |i| element.end[axes[i].index()]);
        let shape = match element.kind {
            ElementKind::Arc(arc) => arc_shape(element, &arc, axes),
            ElementKind::Line => None,
        };
        let (shape, span) = match shape {
            Some((arc, span)) => (Shape::Arc(arc), span),
            None => {
                let length = distance(&start, &end);
                let unit = Vector::from_fn(start.len(), |i| (end[i] - start[i]) / length);
                (Shape::Line { unit }, length)
            }
        };
        (span.is_finite() && span > 0.0).then_some(Curve {
            start,
            end,
            span,
            feed: element.feed,
            line: element.span.line,
            shape,
        })
    }

    /// True for a straight line.
    pub fn is_line(&self) -> bool {
        matches!(self.shape, Shape::Line { .. })
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
            Shape::Line { unit } => {
                for ((o, s), u) in out.iter_mut().zip(&self.start).zip(unit) {
                    *o = s + u * phi;
                }
            }
            Shape::Arc(a) => {
                for ((o, s), h) in out.iter_mut().zip(&self.start).zip(&a.linear_rate) {
                    *o = s + h * phi;
                }
                let (sin, cos) = libm::sincos(a.start_angle + a.turn * phi);
                let r = a.start_radius + a.radius_rate * phi;
                out[a.first] = a.center[0] + r * cos;
                out[a.second] = a.center[1] + r * sin;
            }
        }
    }

    /// dc/dφ at `φ`.
    pub fn derivative(&self, phi: f64, out: &mut [f64]) {
        match &self.shape {
            Shape::Line { unit } => out.copy_from_slice(unit),
            Shape::Arc(a) => {
                out.copy_from_slice(&a.linear_rate);
                let (sin, cos) = libm::sincos(a.start_angle + a.turn * phi);
                let r = a.start_radius + a.radius_rate * phi;
                out[a.first] = a.radius_rate * cos - a.turn * r * sin;
                out[a.second] = a.radius_rate * sin + a.turn * r * cos;
            }
        }
    }

    /// |dc/dφ| at `φ`: path length per unit of parameter.
    pub fn rate(&self, phi: f64) -> f64 {
        match &self.shape {
            Shape::Line { .. } => 1.0,
            Shape::Arc(a) => {
                let r = a.start_radius + a.radius_rate * phi;
                let h = norm(&a.linear_rate);
                (a.radius_rate * a.radius_rate + r * r + h * h).sqrt()
            }
        }
    }

    /// Bounds on |dⁿc/dφⁿ| for n = 2, 3, 4 over the whole element.
    ///
    /// In the plane, c = r(φ)·e^{i(a₀ ± φ)} with r linear, so |dⁿc/dφⁿ| ≤ r_max + n·|dr/dφ|;
    /// the other axes are linear in φ. A line has none.
    pub fn derivative_bounds(&self) -> [f64; 3] {
        match &self.shape {
            Shape::Line { .. } => [0.0; 3],
            Shape::Arc(a) => {
                let r = self.max_radius(a);
                let k = a.radius_rate.abs();
                [r + 2.0 * k, r + 3.0 * k, r + 4.0 * k]
            }
        }
    }

    /// Path length between two parameters (exact on lines and circles, the mean rate on
    /// a spiral).
    pub fn length(&self, from: f64, to: f64) -> f64 {
        let mid = 0.5 * (from + to);
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

    /// Per-axis bounds over `[from, to]` for axis `i`: (largest |dc_i/dφ|, largest
    /// |d²c_i/dφ²|), each divided by the smallest rate (resp. its square): the share of
    /// the path speed (resp. of speed²) that axis `i` sees.
    pub fn axis_factors(&self, from: f64, to: f64, i: usize) -> (f64, f64) {
        match &self.shape {
            Shape::Line { unit } => (unit[i].abs(), 0.0),
            Shape::Arc(a) => {
                let r = self.max_radius(a);
                let k = a.radius_rate.abs();
                let h = norm(&a.linear_rate);
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

    fn max_radius(&self, a: &ArcShape) -> f64 {
        a.start_radius
            .max(a.start_radius + a.radius_rate * self.span)
    }
}

impl ArcShape {
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
    let shape = ArcShape {
        first,
        second,
        center: arc.center,
        start_angle: sweep.start_angle,
        turn: sweep.sweep.signum(),
        start_radius: sweep.start_radius,
        radius_rate: (sweep.end_radius - sweep.start_radius) / span,
        linear_rate,
        last_extremes: std::cell::Cell::new([f64::NAN; 4]),
    };
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
