//! Arc centres: from I/J/K offsets or an R radius, checked the way controllers check them.
//!
//! Owns the geometry of one arc in its plane's (first, second) coordinates; it must not
//! know words, spans or modal state. Lengths are in output units throughout.

use pvt_core::ArcDirection;

/// How far an end point may miss the circle: a centre arc is rejected only when the radii
/// differ by more than both tolerances (as LinuxCNC does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ArcTolerance {
    /// Absolute, output units.
    pub absolute: f64,
    /// Relative to the start radius.
    pub relative: f64,
}

impl ArcTolerance {
    /// True when `difference` between two radii near `radius` exceeds both tolerances.
    fn exceeded(self, difference: f64, radius: f64) -> bool {
        difference > self.absolute && difference > self.relative * radius
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
    if start_radius == 0.0 {
        return Err(ArcProblem::ZeroRadius);
    }
    if tolerance.exceeded((start_radius - end_radius).abs(), start_radius) {
        return Err(ArcProblem::RadiusMismatch {
            start_radius,
            end_radius,
        });
    }
    Ok(center)
}

/// The centre of an arc given by its radius: `radius > 0` the short way (≤ 180°),
/// `radius < 0` the long way. A radius short of half the chord within the tolerance
/// gives a half circle.
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
    if half_chord > r && tolerance.exceeded(half_chord - r, r) {
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

    const TOL: ArcTolerance = ArcTolerance {
        absolute: 0.002,
        relative: 0.001,
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
        let c = center_from_radius([0.0, 0.0], [2.0, 0.0], 0.9995, ArcDirection::Clockwise, TOL)
            .unwrap();
        assert!(close(c, [1.0, 0.0]));
        let err = center_from_radius([0.0, 0.0], [2.0, 0.0], 0.99, ArcDirection::Clockwise, TOL);
        assert_eq!(
            err,
            Err(ArcProblem::RadiusTooSmall {
                radius: 0.99,
                half_chord: 1.0
            })
        );
    }

    #[test]
    fn offsets_check_both_tolerances() {
        // Radius 7: relative tolerance 0.007 beats absolute 0.002.
        assert!(center_from_offsets([7.0, 0.0], [0.0, 7.005], [-7.0, 0.0], TOL).is_ok());
        assert!(center_from_offsets([7.0, 0.0], [0.0, 7.01], [-7.0, 0.0], TOL).is_err());
        assert_eq!(
            center_from_offsets([1.0, 1.0], [2.0, 2.0], [0.0, 0.0], TOL),
            Err(ArcProblem::ZeroRadius)
        );
    }
}
