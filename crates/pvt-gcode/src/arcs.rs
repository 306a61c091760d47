//! Arc centres: from I/J/K offsets or an R radius, checked the way controllers check them.
//!
//! Owns the geometry of one arc in its plane's (first, second) coordinates; it must not
//! know words, spans or modal state. Lengths are in output units throughout.

use pvt_core::ArcDirection;

/// How far an end point may miss the circle, as LinuxCNC's `interp_arc.cc` allows it: a
/// centre-form arc is refused when its start and end radii differ by more than 100 times
/// `absolute`, or by more than `absolute` and by more than `relative` of the larger radius;
/// within that it runs as a spiral (the radius changing linearly with the angle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ArcTolerance {
    /// Absolute, output units.
    pub absolute: f64,
    /// Relative to the larger radius.
    pub relative: f64,
    /// How far R may fall short of half the chord, and the smallest centre-form radius,
    /// output units.
    pub radius: f64,
}

impl ArcTolerance {
    /// True when radii `a` and `b` differ by more than the rule allows.
    fn exceeded(self, a: f64, b: f64) -> bool {
        let difference = (a - b).abs();
        difference > 100.0 * self.absolute
            || (difference > self.absolute && difference > self.relative * a.max(b))
    }
}

/// Why no arc could be made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ArcProblem {
    /// The centre is the start point.
    ZeroRadius,
    /// The end point is off the circle through the start point.
    RadiusMismatch { start_radius: f64, end_radius: f64 },
    /// R form with the end point at the start point.
    FullCircleR,
    /// R shorter than half the chord.
    RadiusTooSmall { radius: f64, half_chord: f64 },
}

/// The centre of an arc given as offsets from its start point.
pub(crate) fn center_from_offsets(
    start: [f64; 2],
    end: [f64; 2],
    offsets: [f64; 2],
    tolerance: ArcTolerance,
) -> Result<[f64; 2], ArcProblem> {
    let center = [start[0] + offsets[0], start[1] + offsets[1]];
    let start_radius = distance(start, center);
    let end_radius = distance(end, center);
    if start_radius == 0.0 || start_radius.min(end_radius) < tolerance.radius {
        return Err(ArcProblem::ZeroRadius);
    }
    if tolerance.exceeded(start_radius, end_radius) {
        return Err(ArcProblem::RadiusMismatch {
            start_radius,
            end_radius,
        });
    }
    Ok(center)
}

/// The centre of an arc given by its radius: `radius > 0` the short way (≤ 180°),
/// `radius < 0` the long way. A radius short of half the chord by no more than the
/// tolerance's `radius` gives a half circle.
pub(crate) fn center_from_radius(
    start: [f64; 2],
    end: [f64; 2],
    radius: f64,
    direction: ArcDirection,
    tolerance: ArcTolerance,
) -> Result<[f64; 2], ArcProblem> {
    let chord = [end[0] - start[0], end[1] - start[1]];
    let length = libm::hypot(chord[0], chord[1]);
    if length == 0.0 {
        return Err(ArcProblem::FullCircleR);
    }
    let half_chord = length / 2.0;
    let r = radius.abs();
    if half_chord - r > tolerance.radius {
        return Err(ArcProblem::RadiusTooSmall {
            radius: r,
            half_chord,
        });
    }
    // Distance from the chord's midpoint to the centre.
    let rise = ((r - half_chord) * (r + half_chord)).max(0.0).sqrt();
    // Counter-clockwise the short way, the centre lies left of the chord.
    let mut side = match direction {
        ArcDirection::CounterClockwise => 1.0,
        ArcDirection::Clockwise => -1.0,
    };
    if radius < 0.0 {
        side = -side;
    }
    let left = [-chord[1] / length, chord[0] / length];
    let mid = [(start[0] + end[0]) / 2.0, (start[1] + end[1]) / 2.0];
    Ok([
        mid[0] + side * rise * left[0],
        mid[1] + side * rise * left[1],
    ])
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    libm::hypot(a[0] - b[0], a[1] - b[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LinuxCNC's in a millimetre program.
    const TOL: ArcTolerance = ArcTolerance {
        absolute: 0.028284271247461905,
        relative: 0.001,
        radius: 0.00127,
    };

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        distance(a, b) < 1e-12
    }

    #[test]
    fn short_and_long_way_centres() {
        let (s, e) = ([0.0, 0.0], [2.0, 0.0]);
        let r = std::f64::consts::SQRT_2;
        let ccw = ArcDirection::CounterClockwise;
        let cw = ArcDirection::Clockwise;
        assert!(close(
            center_from_radius(s, e, r, ccw, TOL).unwrap(),
            [1.0, 1.0]
        ));
        assert!(close(
            center_from_radius(s, e, -r, ccw, TOL).unwrap(),
            [1.0, -1.0]
        ));
        assert!(close(
            center_from_radius(s, e, r, cw, TOL).unwrap(),
            [1.0, -1.0]
        ));
        assert!(close(
            center_from_radius(s, e, -r, cw, TOL).unwrap(),
            [1.0, 1.0]
        ));
    }

    #[test]
    fn radius_just_short_of_half_chord_is_a_half_circle() {
        let c = center_from_radius([0.0, 0.0], [2.0, 0.0], 0.9990, ArcDirection::Clockwise, TOL);
        assert!(close(c.unwrap(), [1.0, 0.0]));
        let err = center_from_radius([0.0, 0.0], [2.0, 0.0], 0.9985, ArcDirection::Clockwise, TOL);
        assert_eq!(
            err,
            Err(ArcProblem::RadiusTooSmall {
                radius: 0.9985,
                half_chord: 1.0
            })
        );
    }

    /// LinuxCNC's rule: refused beyond 100 times the absolute tolerance, or beyond it
    /// and beyond 0.1 % of the larger radius; a spiral within.
    #[test]
    fn offsets_follow_linuxcnc_rule() {
        let arc = |r: f64, end: f64| center_from_offsets([r, 0.0], [0.0, end], [-r, 0.0], TOL);
        // Radius 7: 0.028 (under the absolute tolerance) runs, 0.03 (0.43 %) does not.
        assert!(arc(7.0, 7.028).is_ok());
        assert!(arc(7.0, 7.03).is_err());
        // Radius 100: 0.1 % is 0.1, so 0.09 runs though beyond the absolute tolerance.
        assert!(arc(100.0, 100.09).is_ok());
        assert!(arc(100.0, 100.11).is_err());
        // Radius 10000: 0.1 % is 10, but 100 × 0.0283 = 2.83 is the most.
        assert!(arc(10_000.0, 10_002.8).is_ok());
        assert!(arc(10_000.0, 10_002.9).is_err());
        assert_eq!(
            center_from_offsets([1.0, 1.0], [2.0, 2.0], [0.0, 0.0], TOL),
            Err(ArcProblem::ZeroRadius)
        );
        // A radius under the radius tolerance is a zero radius, as LinuxCNC has it.
        assert_eq!(
            center_from_offsets([0.0, 0.0], [0.001, 0.0], [0.0005, 0.0], TOL),
            Err(ArcProblem::ZeroRadius)
        );
    }
}
