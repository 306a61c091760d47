//! Arc discretization: toolpath elements to polyline points by chord tolerance.
//!
//! Owns the rule that turns an arc into points. It must not choose velocities or times.
//!
//! # Chord tolerance
//! The chord tolerance is the largest *sagitta* allowed: the greatest distance, measured in
//! the arc's plane, between a chord and the circular arc it replaces. An arc of radius `r`
//! swept through `θ` is cut into the fewest equal-angle pieces `n` whose angle `θ/n` keeps
//! `r·(1 − cos(θ/2n)) ≤ tolerance`, and never pieces wider than 90°, so a full circle has at
//! least four. As in the quad-circle example (seed 002), each piece contributes one point,
//! its end; the last point is the programmed end point exactly, not a recomputed one.
//! Helical axes move linearly with angle; a spiral (start and end radius differ within the
//! front end's tolerance) changes radius linearly with angle.

use crate::axis::{Axis, Position};
use crate::polyline::Polyline;
use crate::toolpath::{Arc, Contour, ElementKind};

/// The largest sagitta allowed between a chord and its arc, in program units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChordTolerance(f64);

impl ChordTolerance {
    /// Default, millimetres: [`crate::defaults::TOLERANCE_MM`].
    pub const DEFAULT_MM: f64 = crate::defaults::TOLERANCE_MM;

    /// Smallest path, chord or corner tolerance pvtc plans to, in the program's units
    /// (1 nm in millimetres, 25.4 nm in inches): a finer one is refused where it is
    /// given (`--tolerance`, `--corner-tolerance`, G64 P, [`crate::plan::check_options`]),
    /// since the pieces of an arc grow without bound as the tolerance shrinks (G64
    /// P1e-201 exhausted memory) and no machine positions finer.
    pub const SMALLEST: f64 = 1e-6;

    /// A tolerance; `None` unless it is finite and positive.
    pub fn new(value: f64) -> Option<ChordTolerance> {
        (value.is_finite() && value > 0.0).then_some(ChordTolerance(value))
    }

    /// The tolerance in program units.
    pub fn get(self) -> f64 {
        self.0
    }
}

/// Widest piece any arc is cut into, radians (a quarter turn).
const MAX_PIECE_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

/// Fewest equal-angle pieces for an arc of `radius` sweeping `|sweep|` radians.
pub fn arc_piece_count(sweep: f64, radius: f64, tolerance: ChordTolerance) -> usize {
    let tol = tolerance.get();
    let widest = if tol < radius {
        2.0 * libm::acos(1.0 - tol / radius)
    } else {
        std::f64::consts::PI
    };
    let widest = widest.min(MAX_PIECE_ANGLE);
    // The small slack keeps an exact ratio (e.g. 90°/45°) from rounding up a piece.
    let n = (sweep.abs() / widest - 1e-9).ceil();
    if n.is_finite() && n >= 1.0 {
        n as usize
    } else {
        1
    }
}

/// The positions along an arc, excluding its start and ending exactly at `end`.
pub fn arc_positions(
    arc: &Arc,
    start: &Position,
    end: &Position,
    tolerance: ChordTolerance,
) -> Vec<Position> {
    let sweep = arc.sweep(start, end);
    let radius = sweep.start_radius.max(sweep.end_radius);
    let n = arc_piece_count(sweep.sweep, radius, tolerance);
    let (first, second, _) = arc.plane.axes();
    let mut out = Vec::with_capacity(n);
    for k in 1..n {
        let f = k as f64 / n as f64;
        let angle = sweep.start_angle + sweep.sweep * f;
        let r = sweep.start_radius + (sweep.end_radius - sweep.start_radius) * f;
        let mut p = *start;
        for axis in Axis::ALL {
            let i = axis.index();
            p[i] = start[i] + (end[i] - start[i]) * f;
        }
        let (s, c) = libm::sincos(angle);
        p[first.index()] = arc.center[0] + r * c;
        p[second.index()] = arc.center[1] + r * s;
        out.push(p);
    }
    out.push(*end);
    out
}

/// Projects a position onto the program's axes.
pub fn project(p: &Position, axes: &[Axis]) -> Vec<f64> {
    axes.iter().map(|a| p[a.index()]).collect()
}

/// The polyline of a contour on the given axes: lines as they are, arcs and Béziers by
/// chord tolerance.
///
/// # Panics
/// If the contour has no element.
pub fn flatten_contour(contour: &Contour, axes: &[Axis], tolerance: ChordTolerance) -> Polyline {
    let first = contour
        .elements
        .first()
        .expect("a contour has at least one element");
    let mut polyline = Polyline::start_at(&project(&first.start, axes));
    for element in &contour.elements {
        let line = element.span.line;
        match &element.kind {
            ElementKind::Line => polyline.push(&project(&element.end, axes), element.feed, line),
            ElementKind::Arc(arc) => {
                for p in arc_positions(arc, &element.start, &element.end, tolerance) {
                    polyline.push(&project(&p, axes), element.feed, line);
                }
            }
            ElementKind::Bezier(bezier) => {
                for p in bezier.flatten(&element.start, &element.end, tolerance.get()) {
                    polyline.push(&project(&p, axes), element.feed, line);
                }
            }
        }
    }
    polyline
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{ArcDirection, Plane};

    fn tol(t: f64) -> ChordTolerance {
        ChordTolerance::new(t).unwrap()
    }

    fn sagitta(r: f64, piece: f64) -> f64 {
        r * (1.0 - libm::cos(piece / 2.0))
    }

    #[test]
    fn piece_count_is_the_fewest_that_meets_the_tolerance() {
        for &(r, t) in &[(1000.0, 0.001), (10.0, 0.001), (5000.0, 0.01), (1.0, 1e-6)] {
            let sweep = std::f64::consts::FRAC_PI_2;
            let n = arc_piece_count(sweep, r, tol(t));
            assert!(
                sagitta(r, sweep / n as f64) <= t * (1.0 + 1e-12),
                "r={r} n={n}"
            );
            assert!(
                sagitta(r, sweep / (n - 1) as f64) > t,
                "r={r}: {n} is not the fewest"
            );
        }
        // Quad circle of seed 002, radius 1000, tolerance 0.001: 90° / 2·acos(1 − 1e-6).
        assert_eq!(
            arc_piece_count(std::f64::consts::FRAC_PI_2, 1000.0, tol(0.001)),
            556
        );
    }

    #[test]
    fn coarse_tolerance_still_cuts_quarter_turns() {
        let n = arc_piece_count(2.0 * std::f64::consts::PI, 1.0, tol(100.0));
        assert_eq!(n, 4);
        assert_eq!(arc_piece_count(1e-9, 1.0, tol(0.1)), 1);
    }

    #[test]
    fn arc_points_lie_on_the_circle_and_end_exactly() {
        let arc = Arc {
            plane: Plane::XY,
            center: [0.0, 0.0],
            direction: ArcDirection::CounterClockwise,
            extra_turns: 0,
        };
        let start = [1000.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let end = [0.0, 1000.0, 5.0, 0.0, 0.0, 0.0];
        let pts = arc_positions(&arc, &start, &end, tol(0.001));
        assert_eq!(pts.len(), 556);
        assert_eq!(*pts.last().unwrap(), end);
        for (k, p) in pts.iter().enumerate() {
            assert!((libm::hypot(p[0], p[1]) - 1000.0).abs() < 1e-9);
            // Helix: Z proportional to the swept angle.
            let expected_z = 5.0 * (k + 1) as f64 / 556.0;
            assert!((p[2] - expected_z).abs() < 1e-12);
        }
    }

    #[test]
    fn clockwise_full_circle_with_extra_turn_in_zx() {
        let arc = Arc {
            plane: Plane::ZX,
            center: [0.0, 0.0],
            direction: ArcDirection::Clockwise,
            extra_turns: 1,
        };
        // In ZX the first coordinate is Z: start at Z=2, X=0.
        let start = [0.0, 0.0, 2.0, 0.0, 0.0, 0.0];
        let sweep = arc.sweep(&start, &start);
        assert!((sweep.sweep + 4.0 * std::f64::consts::PI).abs() < 1e-12);
        let pts = arc_positions(&arc, &start, &start, tol(100.0));
        assert_eq!(pts.len(), 8);
        // Clockwise seen from +Y: Z towards -X first.
        assert!(pts[0][0] < 0.0 && pts[0][2].abs() < 1e-12);
    }
}
