//! Curvature transitions under a jerk limit: where a line meets a plane circle at a
//! tangent, the motion leaves the exact geometry for a short stretch so that its
//! acceleration ramps from the line's (zero) to the circle's (`v²/R`, normal) instead of
//! stepping by `v²/R` at the junction.
//!
//! Owns the transition's shape at unit speed (where it leaves the first element and joins
//! the second, its middle state, its two times), its deviation bound and the per-axis
//! acceleration, jerk and velocity it takes per unit of speed. It must not choose speeds
//! or knots (that is [`super::knots`]) nor build pieces (that is [`super::pieces`]).
//!
//! # The shape
//! In the junction's frame (origin at the junction, `x` along the line towards the
//! circle, `y` towards the circle's center), the motion at unit speed runs from `L_a`
//! before the junction on the line, at velocity `(1, 0)` and acceleration 0, to the
//! point `φ = L_b/R` along the circle, at its tangent `(cos φ, sin φ)` and its
//! acceleration `A₁ = (−sin φ, cos φ)/R`. Its acceleration is linear in time on two parts:
//! from 0 to a middle value `M` over `θ·τ`, then from `M` to `A₁` over `(1 − θ)·τ`. The
//! velocity change fixes `M = 2·Δv/τ − (1 − θ)·A₁`, and the position change
//! `p_b − p_a = τ·(t_a + (2 − θ)/3·Δv) − τ²·(1 − θ)/6·A₁` is two equations in `τ` and `θ`,
//! solved by a fixed number of Newton steps. Each part is a cubic, so the two pieces are
//! the motion itself, exactly; the acceleration is continuous at the middle and matches
//! the line's and the circle's at the ends. At speed `v` the path is the same (times
//! `τ/v`), the acceleration scales with `v²` and the jerk with `v³`: both speeds of the
//! transition are equal (the passes keep them so). An arc into a line is the same shape
//! run backward.
//!
//! # The bound
//! The deviation is measured on the path (speed-independent) by [`deviation`]: each
//! part sampled at [`SAMPLES`] intervals, the distance to the line (`|y|` where `x ≤ 0`)
//! or to the circle (`|‖p − C‖ − R|` where `x ≥ 0`) at the samples, plus the largest
//! second derivative of that distance over the interval times `h²/8` (a function whose
//! second derivative is within `G` exceeds the larger of its end values by at most
//! `G·h²/8` in between). An interval that crosses `x = 0` takes the circle's distance
//! plus `(s·h)²/R`, the gap between the circle continued back and the line there.
//! `L_a + L_b` is sized so that the bound is within [`TOLERANCE_SHARE`] of the path
//! tolerance, at most [`MOST_SPAN`] of either element.

use super::curve::{Curve, CIRCLE_SLACK};
use super::{AxisBounds, Vector};

/// Share of the path tolerance a transition's deviation takes.
const TOLERANCE_SHARE: f64 = 0.9;

/// The share of the transition's length on the circle: `L_b = ARC_SIDE·(L_a + L_b)`
/// (0.3 puts the middle at about a sixth of the time; it gives the least jerk for a
/// given deviation among the shares with both parts' times positive, which need it
/// under a third).
const ARC_SIDE: f64 = 0.3;

/// Largest share of either element a transition takes.
const MOST_SPAN: f64 = 0.45;

/// Share of each axis' jerk and acceleration limit a transition's cap takes: both of its
/// speeds are equal, so nothing is left for a change of speed; the rest is margin for
/// the closed-form check of its pieces from their rounded end states.
const LIMIT_SHARE: f64 = 0.95;

/// Samples per part of [`deviation`].
const SAMPLES: usize = 64;

/// Newton steps of the shape's two equations: a fixed count, so the result is the same on
/// every run.
const NEWTON_STEPS: usize = 40;

/// A transition between a line and a tangent circle at unit speed (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Transition {
    /// Where it leaves the first element and joins the second (their parameters).
    pub params: [f64; 2],
    /// The path length it replaces (both sides).
    pub length: f64,
    /// Its middle point.
    pub middle: Vector,
    /// Its velocity at the middle point at unit speed.
    pub middle_velocity: Vector,
    /// The times of its two parts at unit speed.
    pub times: [f64; 2],
    /// Bound on its distance from the two elements.
    pub error: f64,
    /// Bound on the distance of the chord from its start to its end from the elements
    /// (the piece at rest there).
    pub chord_error: f64,
    /// Per axis, per unit of speed: the largest |acceleration| (per speed²), |jerk| (per
    /// speed³) and |velocity| (per speed).
    accel: Vector,
    jerk: Vector,
    velocity: Vector,
}

impl Transition {
    /// The highest speed at which every axis' velocity, acceleration and jerk stay
    /// within [`LIMIT_SHARE`] of its limits.
    pub fn cap(&self, bounds: &AxisBounds) -> f64 {
        let mut cap = f64::INFINITY;
        for i in 0..self.accel.len() {
            if self.velocity[i] > 0.0 {
                cap = cap.min(bounds.velocity[i] / self.velocity[i]);
            }
            if self.accel[i] > 0.0 {
                cap = cap.min((LIMIT_SHARE * bounds.acceleration[i] / self.accel[i]).sqrt());
            }
            if self.jerk[i] > 0.0 {
                cap = cap.min(libm::cbrt(LIMIT_SHARE * bounds.jerk[i] / self.jerk[i]));
            }
        }
        cap
    }
}

/// One part of the shape in the junction's frame at unit speed: start position,
/// velocity, acceleration, the constant jerk and the time.
#[derive(Debug, Clone, Copy)]
struct Part {
    p: [f64; 2],
    v: [f64; 2],
    a: [f64; 2],
    j: [f64; 2],
    t: f64,
}

impl Part {
    fn at(&self, s: f64) -> ([f64; 2], [f64; 2]) {
        let pos = |i: usize| {
            self.p[i] + self.v[i] * s + 0.5 * self.a[i] * s * s + self.j[i] * s * s * s / 6.0
        };
        let vel = |i: usize| self.v[i] + self.a[i] * s + 0.5 * self.j[i] * s * s;
        ([pos(0), pos(1)], [vel(0), vel(1)])
    }
}

/// The transition from `a` into `b` when one is a line and the other a plane circle
/// that meet at a tangent, within `tolerance`; `None` otherwise.
pub(super) fn transition(a: &Curve, b: &Curve, tolerance: f64) -> Option<Transition> {
    let (entry, line, arc) = match (a.is_line(), b.is_line()) {
        (true, false) => (true, a, b),
        (false, true) => (false, b, a),
        _ => return None,
    };
    let (first, second, center, r) = arc.circle()?;
    let dim = line.start.len();
    let mut unit = Vector::zeros(dim);
    line.derivative(0.0, &mut unit);
    let off_plane = (0..dim).any(|i| i != first && i != second && unit[i] != 0.0);
    if off_plane || !(r > 0.0 && tolerance > 0.0) {
        return None;
    }
    let junction = if entry { &line.end } else { &line.start };
    let origin = [junction[first], junction[second]];
    let dir = if entry { 1.0 } else { -1.0 };
    let x_axis = [dir * unit[first], dir * unit[second]];
    let to_center = [center[0] - origin[0], center[1] - origin[1]];
    let distance = libm::hypot(to_center[0], to_center[1]);
    let n = [to_center[0] / distance, to_center[1] / distance];
    // The line must meet the circle at a tangent, moving the way the arc does.
    let mut arc_tangent = Vector::zeros(dim);
    arc.derivative(if entry { 0.0 } else { arc.span }, &mut arc_tangent);
    let along = (arc_tangent[first] * unit[first] + arc_tangent[second] * unit[second]) / r;
    let tangent = (x_axis[0] * n[0] + x_axis[1] * n[1]).abs() <= 1e-9;
    if (distance - r).abs() > 1e-9 * r || !tangent || along < 1.0 - 1e-9 {
        return None;
    }
    let most = (MOST_SPAN * line.span / (1.0 - ARC_SIDE)).min(MOST_SPAN * arc.span * r / ARC_SIDE);
    let budget = TOLERANCE_SHARE * tolerance;
    // The deviation grows about as D²/R: sized from a first guess, then shrunk until
    // its bound is within the budget.
    let mut d = (budget * r / 0.011).sqrt().min(most);
    let mut found = None;
    for round in 0..24 {
        let Some((parts, error)) = shape(d, r) else {
            d *= 0.8;
            continue;
        };
        if error <= budget {
            found = Some((parts, error, d));
            break;
        }
        d *= if round < 2 {
            (budget / error).sqrt() * 0.98
        } else {
            0.9
        };
    }
    let (parts, error, d) = found?;
    // The arc may leave its circle by its slack (see `Curve::circle`).
    let error = error + CIRCLE_SLACK * r;
    let (la, lb) = ((1.0 - ARC_SIDE) * d, ARC_SIDE * d);
    let phi = lb / r;
    let chord = chord_error(la, r, phi);
    // From the junction's frame to the program's axes.
    let to_axes = |local: [f64; 2]| {
        let mut out = Vector::zeros(dim);
        out[first] = local[0] * x_axis[0] + local[1] * n[0];
        out[second] = local[0] * x_axis[1] + local[1] * n[1];
        out
    };
    let (mp, mv) = parts[0].at(parts[0].t);
    let mut middle = to_axes(mp);
    for i in 0..dim {
        middle[i] += junction[i];
    }
    let mut middle_velocity = to_axes(mv);
    if !entry {
        middle_velocity.iter_mut().for_each(|x| *x = -*x);
    }
    let mut accel = Vector::zeros(dim);
    let mut jerk = Vector::zeros(dim);
    let mut velocity = Vector::zeros(dim);
    // Raises each axis' largest magnitude in `most` to the local vector's on that axis.
    let raise = |most: &mut Vector, local: [f64; 2]| {
        let v = to_axes(local);
        most.iter_mut()
            .zip(&v)
            .for_each(|(m, x)| *m = m.max(x.abs()));
    };
    for part in &parts {
        let end = [0, 1].map(|i| part.a[i] + part.j[i] * part.t);
        raise(&mut accel, part.a);
        raise(&mut accel, end);
        raise(&mut jerk, part.j);
        // Each velocity component is a quadratic: its ends and its vertex.
        for s in [0.0, part.t, vertex(part)] {
            raise(&mut velocity, part.at(s.clamp(0.0, part.t)).1);
        }
    }
    let times = [parts[0].t, parts[1].t];
    let (params, times) = if entry {
        ([line.span - la, phi], times)
    } else {
        ([arc.span - phi, la], [times[1], times[0]])
    };
    Some(Transition {
        params,
        length: la + lb,
        middle,
        middle_velocity,
        times,
        error,
        chord_error: chord,
        accel,
        jerk,
        velocity,
    })
}

/// Where a velocity component of `part` may peak inside it (the larger of the two axes'
/// vertices is enough for the bound: both are checked by the caller's clamp).
fn vertex(part: &Part) -> f64 {
    (0..2)
        .filter(|&i| part.j[i] != 0.0)
        .map(|i| -part.a[i] / part.j[i])
        .filter(|s| *s > 0.0 && *s < part.t)
        .fold(0.0, f64::max)
}

/// The two parts of the shape of length `d` (`L_a = (1 − ARC_SIDE)·d` on the line) into
/// a circle of radius `r`, with their deviation bound; `None` when the equations have no
/// solution with both parts' times positive.
fn shape(d: f64, r: f64) -> Option<([Part; 2], f64)> {
    let (la, lb) = ((1.0 - ARC_SIDE) * d, ARC_SIDE * d);
    let phi = lb / r;
    let (s, c) = (libm::sin(phi), libm::cos(phi));
    let x = ARC_SIDE;
    let (mut tau, mut theta) = (d, (3.0 * x - 1.0) * (x - 1.0) / (1.0 - 2.0 * x));
    for _ in 0..NEWTON_STEPS {
        let f1 = tau * (1.0 + (2.0 - theta) * (c - 1.0) / 3.0)
            + tau * tau * (1.0 - theta) * s / (6.0 * r)
            - (la + r * s);
        let f2 = tau * (2.0 - theta) * s / 3.0
            - tau * tau * (1.0 - theta) * c / (6.0 * r)
            - r * (1.0 - c);
        let j11 = 1.0 + (2.0 - theta) * (c - 1.0) / 3.0 + tau * (1.0 - theta) * s / (3.0 * r);
        let j12 = -tau * (c - 1.0) / 3.0 - tau * tau * s / (6.0 * r);
        let j21 = (2.0 - theta) * s / 3.0 - tau * (1.0 - theta) * c / (3.0 * r);
        let j22 = -tau * s / 3.0 + tau * tau * c / (6.0 * r);
        let det = j11 * j22 - j12 * j21;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        tau -= (f1 * j22 - j12 * f2) / det;
        theta -= (j11 * f2 - j21 * f1) / det;
    }
    if !(tau > 0.0 && theta > 0.02 && theta < 0.98) {
        return None;
    }
    let end_accel = [-s / r, c / r];
    let dv = [c - 1.0, s];
    let m = [0, 1].map(|i| 2.0 * dv[i] / tau - (1.0 - theta) * end_accel[i]);
    let (t1, t2) = (theta * tau, (1.0 - theta) * tau);
    let first = Part {
        p: [-la, 0.0],
        v: [1.0, 0.0],
        a: [0.0, 0.0],
        j: [m[0] / t1, m[1] / t1],
        t: t1,
    };
    let (mp, mv) = first.at(t1);
    let second = Part {
        p: mp,
        v: mv,
        a: m,
        j: [0, 1].map(|i| (end_accel[i] - m[i]) / t2),
        t: t2,
    };
    // The end must be the circle's point (the equations' residual).
    let (end, _) = second.at(t2);
    let gap = libm::hypot(end[0] - r * s, end[1] - r * (1.0 - c));
    if gap.is_nan() || gap > 1e-9 * d {
        return None;
    }
    let error = deviation(&[first, second], r, phi) + gap;
    Some(([first, second], error))
}

/// The deviation bound of the straight chord from `L_a` before the junction on the line
/// to the point `φ` along the circle of radius `r`.
fn chord_error(la: f64, r: f64, phi: f64) -> f64 {
    let end = [r * libm::sin(phi), r * (1.0 - libm::cos(phi))];
    let (dx, dy) = (end[0] + la, end[1]);
    let length = libm::hypot(dx, dy);
    let chord = Part {
        p: [-la, 0.0],
        v: [dx / length, dy / length],
        a: [0.0, 0.0],
        j: [0.0, 0.0],
        t: length,
    };
    deviation(&[chord], r, phi)
}

/// A bound on the distance of `parts` (in the junction's frame) from the line `y = 0,
/// x ≤ 0` and the circle of radius `r` around `(0, r)` up to angle `phi_end`: see "The
/// bound" in the module documentation. Infinite where a sample lies past the circle's
/// part (`phi_end` and a little more, as the sampled point may lie there only by the
/// rounding of the end).
fn deviation(parts: &[Part], r: f64, phi_end: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for part in parts {
        let h = part.t / SAMPLES as f64;
        let accel = [0, 1].map(|i| part.a[i] + part.j[i] * part.t);
        let a_max = libm::hypot(part.a[0], part.a[1]).max(libm::hypot(accel[0], accel[1]));
        let speed = libm::hypot(part.v[0], part.v[1])
            + libm::hypot(part.a[0], part.a[1]) * part.t
            + 0.5 * libm::hypot(part.j[0], part.j[1]) * part.t * part.t;
        let mut previous: Option<([f64; 2], f64, f64)> = None;
        for k in 0..=SAMPLES {
            let (p, _) = part.at(h * k as f64);
            let rho = libm::hypot(p[0], r - p[1]);
            let circle = (rho - r).abs();
            let line = p[1].abs();
            if p[0] > 0.0 && libm::atan2(p[0], r - p[1]) > phi_end * (1.0 + 1e-6) + 1e-12 {
                return f64::INFINITY;
            }
            if let Some((q, q_circle, q_line)) = previous {
                let value = if p[0] <= 0.0 && q[0] <= 0.0 {
                    q_line.max(line) + a_max * h * h / 8.0
                } else {
                    // |g''| of g = ‖p − C‖ − R: (|p'|² + ρ·|p''|)/ρ + |p'|²/ρ.
                    let rho_min = (rho.min(libm::hypot(q[0], r - q[1])) - speed * h).max(0.5 * r);
                    let rho_max = rho.max(libm::hypot(q[0], r - q[1])) + speed * h;
                    let g = (2.0 * speed * speed + rho_max * a_max) / rho_min;
                    let mut v = q_circle.max(circle) + g * h * h / 8.0;
                    if p[0] <= 0.0 || q[0] <= 0.0 {
                        v += (speed * h) * (speed * h) / r;
                    }
                    v
                };
                worst = worst.max(value);
            }
            previous = Some((p, circle, line));
        }
    }
    worst
}

#[cfg(test)]
// std's trigonometry on purpose: the check is independent of the planner's libm.
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::shape;

    /// The shape of the module documentation ends on the circle with its tangent and its
    /// acceleration, and its acceleration is continuous at the middle.
    #[test]
    fn the_shape_meets_the_circle_with_its_acceleration() {
        for (d, r) in [(0.6, 5.0), (0.2, 1.0), (3.0, 50.0)] {
            let (parts, error) = shape(d, r).expect("a shape");
            let phi = super::ARC_SIDE * d / r;
            let (end, velocity) = parts[1].at(parts[1].t);
            let accel = [0, 1].map(|i| parts[1].a[i] + parts[1].j[i] * parts[1].t);
            assert!((end[0] - r * phi.sin()).abs() < 1e-9 * d, "{end:?}");
            assert!((end[1] - r * (1.0 - phi.cos())).abs() < 1e-9 * d, "{end:?}");
            assert!((velocity[0] - phi.cos()).abs() < 1e-9, "{velocity:?}");
            assert!((velocity[1] - phi.sin()).abs() < 1e-9, "{velocity:?}");
            assert!((accel[0] + phi.sin() / r).abs() < 1e-9 / r, "{accel:?}");
            assert!((accel[1] - phi.cos() / r).abs() < 1e-9 / r, "{accel:?}");
            let (_, mv) = parts[0].at(parts[0].t);
            assert_eq!(mv, parts[1].v);
            let middle = [0, 1].map(|i| parts[0].j[i] * parts[0].t);
            assert!(
                (middle[0] - parts[1].a[0]).abs() < 1e-12
                    && (middle[1] - parts[1].a[1]).abs() < 1e-12
            );
            assert!(error > 0.0 && error < 0.05 * d * d / r, "{error}");
        }
    }
}
