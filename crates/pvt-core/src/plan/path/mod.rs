//! The path planner: motion that follows the programmed geometry within a tolerance.
//!
//! Owns the choice of knots (points on the true elements), the speed at each knot, and
//! the piece between two knots, for one rest-to-rest contour. It must not parse, print or
//! flatten through chords: it reads the elements themselves ([`curve`]).
//!
//! # The guarantee
//! Each piece runs from knot `a` to knot `b` on one element `c(φ)`. The planner defines a
//! reference motion `φ(t)`, quadratic in time (constant parameter acceleration, so
//! constant tangential acceleration on a line or circle), and gives the piece the exact
//! position and velocity of `c(φ(t))` at both ends. Cubic Hermite interpolation of a
//! smooth function then errs by at most `max|d⁴c(φ(t))/dt⁴|·T⁴/384`, and with
//! `|dⁿc/dφⁿ| ≤ Dₙ` and `φ''' = 0`:
//!
//! ```text
//! |H(t) − c(φ(t))| ≤ T⁴/384 · (D₄·ω⁴ + 6·D₃·ω²·|ω'| + 3·D₂·ω'²)  +  4/27 · T · (|Δv_a| + |Δv_b|)
//! ```
//!
//! where `ω` is the largest parameter rate of the piece, `ω'` its parameter acceleration,
//! and `Δv` the difference between a knot's velocity and the element's own velocity there
//! (non-zero only at a junction passed at speed, where the velocity points along the
//! bisector of the two tangents; the Hermite basis functions of the end velocities peak
//! at 4/27). Every piece is split until this bound is within the path tolerance, so the
//! motion at every instant is within the tolerance of the programmed point `c(φ(t))`:
//! it stays near the geometry and it covers all of it. A line has `Dₙ = 0`: a piece whose
//! velocities lie along the line stays on it exactly.
//!
//! # Speeds
//! Each knot's speed is capped by the feed, by each axis' velocity and (with limits) by
//! each axis' share of the centripetal acceleration; a junction is passed at speed when
//! its tangents meet within [`TANGENT_ANGLE`] (without limits) or at the speed its
//! adjacent pieces' lateral acceleration allows (with limits), and otherwise is a stop.
//! A backward and a forward pass bound the change of speed between knots by the
//! tangential acceleration that is left. Lines get trapezoid knots (accelerate, cruise,
//! decelerate). Finally every piece's per-axis velocity and acceleration peaks are
//! computed in closed form; where one exceeds a limit the speeds of its knots are lowered
//! and the passes run again.

mod curve;
mod knots;
mod pieces;

use super::PlanError;
use crate::axis::Axis;
use crate::check::AxisLimits;
use crate::program::PvtContour;
use crate::toolpath::Contour;
use std::collections::BTreeMap;

use curve::Curve;
use knots::Knots;

/// Largest angle between two elements' tangents that is passed at the feed when no
/// acceleration limits are given (2°); a sharper corner is an exact stop.
pub const TANGENT_ANGLE: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Share of an axis' acceleration a piece's speed cap leaves to the centripetal part; the
/// rest is for speeding up and slowing down along the path.
const NORMAL_SHARE: f64 = 0.75;

/// Most rounds of splitting pieces and lowering speeds before the planner gives up.
const MAX_ROUNDS: usize = 400;

/// What the path planner must honour.
#[derive(Debug, Clone, PartialEq)]
pub struct PathOptions {
    /// Path tolerance: the farthest the motion may be from the programmed geometry.
    pub tolerance: f64,
    /// Per-axis limits; an axis not listed (or a limit left out) is not limited.
    pub limits: BTreeMap<Axis, AxisLimits>,
}

/// What the path planner achieved on a contour.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathReport {
    /// The largest per-piece error bound, program units.
    pub error_bound: f64,
}

/// Per projected axis: velocity and acceleration limits (infinite where none).
#[derive(Debug, Clone)]
pub(super) struct AxisBounds {
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
}

impl AxisBounds {
    fn new(axes: &[Axis], limits: &BTreeMap<Axis, AxisLimits>) -> AxisBounds {
        let get = |f: fn(&AxisLimits) -> Option<f64>| -> Vec<f64> {
            axes.iter()
                .map(|a| limits.get(a).and_then(f).unwrap_or(f64::INFINITY))
                .collect()
        };
        AxisBounds {
            velocity: get(|l| l.velocity),
            acceleration: get(|l| l.acceleration),
        }
    }

    fn accelerates(&self) -> bool {
        self.acceleration.iter().any(|a| a.is_finite())
    }
}

/// Plans one contour on `axes` so that its motion follows the elements within
/// `options.tolerance` and within every axis limit.
pub fn plan_path(
    contour: &Contour,
    axes: &[Axis],
    options: &PathOptions,
) -> Result<(PvtContour, PathReport), PlanError> {
    let curves = curves(contour, axes)?;
    let first = contour
        .elements
        .first()
        .map(|e| crate::discretize::project(&e.start, axes))
        .unwrap_or_else(|| vec![0.0; axes.len()]);
    let mut out = PvtContour::new(contour.motion, first);
    if curves.is_empty() {
        return Ok((out, PathReport::default()));
    }
    let bounds = AxisBounds::new(axes, &options.limits);
    let mut knots = Knots::new(&curves, &bounds, options.tolerance);
    let line = curves[0].line;
    // First without trapezoid knots, so that repairs do not multiply them; then with.
    settle(&mut knots, &curves, &bounds, options.tolerance)
        .ok_or(PlanError::PathNotMet { line })?;
    knots.add_trapezoids(&curves, &bounds);
    let pieces = settle(&mut knots, &curves, &bounds, options.tolerance)
        .ok_or(PlanError::PathNotMet { line })?;
    let error_bound = pieces.iter().map(|p| p.error).fold(0.0, f64::max);
    knots.emit(&curves, &pieces, &mut out);
    Ok((out, PathReport { error_bound }))
}

/// Plans speeds, splits pieces over the tolerance and slows pieces over a limit until
/// none is; the final pieces, or `None` after [`MAX_ROUNDS`].
fn settle(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
) -> Option<Vec<pieces::Piece>> {
    for _ in 0..MAX_ROUNDS {
        knots.plan_speeds(curves, bounds);
        let pieces = knots.pieces(curves, bounds);
        if knots.split_over(curves, &pieces, tolerance) {
            continue;
        }
        if knots.slow_over(&pieces, bounds) {
            continue;
        }
        return Some(pieces);
    }
    None
}

fn curves(contour: &Contour, axes: &[Axis]) -> Result<Vec<Curve>, PlanError> {
    let mut curves = Vec::with_capacity(contour.elements.len());
    for element in &contour.elements {
        let line = element.span.line;
        if !(element.feed.is_finite() && element.feed > 0.0) {
            return Err(PlanError::BadFeed {
                line,
                feed: element.feed,
            });
        }
        let finite = |p: &crate::axis::Position| p.iter().all(|x| x.is_finite());
        if !finite(&element.start) || !finite(&element.end) {
            return Err(PlanError::NonFinitePoint { line });
        }
        curves.extend(Curve::new(element, axes));
    }
    Ok(curves)
}
