//! The cubic a controller builds for one PVT piece of one axis.
//!
//! Owns the evaluation of a piece from its end conditions, in the kinematic form of seed
//! 001: `X(t) = X0 + V0·t + A·t²/2 + J·t³/6`, `V(t) = V0 + A·t + J·t²/2`, with the
//! acceleration `A` and jerk `J` chosen so the piece ends at `X1` with `V1` after `T`.
//! It must not decide positions, velocities or times.

/// Position, velocity, acceleration and jerk of one axis at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Position, units.
    pub position: f64,
    /// Velocity, units/s.
    pub velocity: f64,
    /// Acceleration, units/s².
    pub acceleration: f64,
    /// Jerk, units/s³ (constant over a piece).
    pub jerk: f64,
}

/// One axis of one PVT piece: start and end position and velocity, and the piece time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HermiteSegment {
    /// Start position.
    pub p0: f64,
    /// Start velocity.
    pub v0: f64,
    /// Start acceleration (`A` of seed 001).
    pub a0: f64,
    /// Jerk (`J` of seed 001).
    pub jerk: f64,
    /// Piece time, seconds.
    pub duration: f64,
}

impl HermiteSegment {
    /// The unique cubic from (`p0`, `v0`) to (`p1`, `v1`) in `duration` seconds.
    pub fn new(p0: f64, v0: f64, p1: f64, v1: f64, duration: f64) -> HermiteSegment {
        let t = duration;
        let d = p1 - p0;
        let a0 = 6.0 * d / (t * t) - (4.0 * v0 + 2.0 * v1) / t;
        let jerk = 6.0 * (v0 + v1) / (t * t) - 12.0 * d / (t * t * t);
        HermiteSegment {
            p0,
            v0,
            a0,
            jerk,
            duration,
        }
    }

    /// The axis state `t` seconds into the piece (any `t`, also outside `[0, T]`).
    pub fn at(&self, t: f64) -> State {
        let (a, j) = (self.a0, self.jerk);
        State {
            position: self.p0 + self.v0 * t + a * t * t / 2.0 + j * t * t * t / 6.0,
            velocity: self.v0 + a * t + j * t * t / 2.0,
            acceleration: a + j * t,
            jerk: j,
        }
    }

    /// The state at the end of the piece.
    pub fn end(&self) -> State {
        self.at(self.duration)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_where_it_was_told() {
        let s = HermiteSegment::new(1.0, 2.0, 5.0, -1.0, 0.7);
        let e = s.end();
        assert!((e.position - 5.0).abs() < 1e-12);
        assert!((e.velocity + 1.0).abs() < 1e-12);
        let b = s.at(0.0);
        assert_eq!((b.position, b.velocity), (1.0, 2.0));
    }

    #[test]
    fn rest_to_rest_is_the_smoothstep() {
        // x(t) = d(3τ² − 2τ³): peak speed 1.5·d/T at the middle, acceleration ±6d/T².
        let s = HermiteSegment::new(0.0, 0.0, 10.0, 0.0, 2.0);
        assert!((s.at(1.0).velocity - 7.5).abs() < 1e-12);
        assert!((s.at(0.0).acceleration - 15.0).abs() < 1e-12);
        assert!((s.jerk + 15.0).abs() < 1e-12);
        assert!((s.at(1.0).position - 5.0).abs() < 1e-12);
    }

    #[test]
    fn constant_velocity_has_no_acceleration() {
        let s = HermiteSegment::new(0.0, 3.0, 6.0, 3.0, 2.0);
        assert!(s.a0.abs() < 1e-12 && s.jerk.abs() < 1e-12);
    }
}
