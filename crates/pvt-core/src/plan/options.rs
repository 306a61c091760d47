//! The planner and timing choices a user makes, by name.
//!
//! Owns the [`Planner`] and [`Timing`] enums and their spellings on a command line, and
//! [`PlanOptions`], everything a planning run is told. It must not plan: the planners
//! themselves live in their own modules.

use super::path::PathOptions;
use super::quantize::{self, Rounding};
use crate::discretize::ChordTolerance;
use std::fmt;
use std::str::FromStr;

/// Which method chooses the velocities (and, for some, the times) at the points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Planner {
    /// Seed 000: velocity along the corner bisector at the feed, time from a quadratic.
    #[default]
    Contour,
    /// Motion within the path tolerance of the true elements, within machine limits.
    Path,
    /// Seed 001 PT: constant velocity between points.
    Pt,
    /// Forward difference (the quad-circle MovePVT example): the velocity at a point is
    /// its outgoing chord over that chord's time. Named `chord-forward`; `chord` is an
    /// alias.
    Chord,
    /// Backward difference (application note AN208): the velocity at a point is its
    /// incoming chord over that chord's time. Named `chord-back`.
    ChordBack,
    /// Seed 001 method 2: constant-acceleration fit from rest.
    ConstAccel,
    /// C2 cubic spline through the points with zero end velocities.
    Spline,
    /// Seed 004: linear segments with parabolic blends under an acceleration limit.
    Lspb,
}

impl Planner {
    /// Every planner, in the order the documentation lists them.
    pub const ALL: [Planner; 8] = [
        Planner::Contour,
        Planner::Path,
        Planner::Pt,
        Planner::Chord,
        Planner::ChordBack,
        Planner::ConstAccel,
        Planner::Spline,
        Planner::Lspb,
    ];

    /// The name used on the command line and in every output.
    pub fn name(self) -> &'static str {
        match self {
            Planner::Contour => "contour",
            Planner::Path => "path",
            Planner::Pt => "pt",
            Planner::Chord => "chord-forward",
            Planner::ChordBack => "chord-back",
            Planner::ConstAccel => "const-accel",
            Planner::Spline => "spline",
            Planner::Lspb => "lspb",
        }
    }

    /// True for the planners that take given times and choose only velocities.
    pub fn is_velocity_method(self) -> bool {
        matches!(
            self,
            Planner::Chord | Planner::ChordBack | Planner::ConstAccel | Planner::Spline
        )
    }
}

impl fmt::Display for Planner {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The name `chord`, kept as an alias of `chord-forward` (what it named before the
/// backward difference had its own name).
pub const CHORD_ALIAS: &str = "chord";

/// A planner name that names no planner.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown planner `{0}`; expected one of contour, path, pt, chord-forward (or chord), chord-back, const-accel, spline, lspb"
)]
pub struct UnknownPlanner(pub String);

impl FromStr for Planner {
    type Err = UnknownPlanner;

    fn from_str(s: &str) -> Result<Planner, UnknownPlanner> {
        if s.trim().eq_ignore_ascii_case(CHORD_ALIAS) {
            return Ok(Planner::Chord);
        }
        Planner::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownPlanner(s.to_owned()))
    }
}

/// Where the time of each segment comes from, for the planners that take given times.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Timing {
    /// Segment time = chord length / segment feed (seed 004).
    #[default]
    FromFeed,
    /// Every segment takes this many seconds (seed 002's `TIME_SLICE`).
    TimeSlice(f64),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for p in Planner::ALL {
            assert_eq!(p.name().parse::<Planner>(), Ok(p));
        }
        assert_eq!("CONST-ACCEL".parse::<Planner>(), Ok(Planner::ConstAccel));
        assert_eq!("chord".parse::<Planner>(), Ok(Planner::Chord));
        assert_eq!("chord-back".parse::<Planner>(), Ok(Planner::ChordBack));
        assert!("cubic".parse::<Planner>().is_err());
    }
}

/// How to turn a toolpath into a program.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Chord tolerance for arcs, program units.
    pub tolerance: ChordTolerance,
    /// Path tolerance of the path planner, program units; `None` is the chord tolerance.
    pub path_tolerance: Option<f64>,
    /// Corner tolerance of the path planner's blends, program units (`None`: the path
    /// tolerance, and no blend without limits).
    pub corner_tolerance: Option<f64>,
    /// Per-axis machine limits the path planner honours (and `check` verifies).
    pub limits: std::collections::BTreeMap<crate::axis::Axis, crate::limits::AxisLimits>,
    /// Which planner chooses velocities and times.
    pub planner: Planner,
    /// Where segment times come from, for every planner but contour.
    pub timing: Timing,
    /// Acceleration limit, units/s², per axis (required by lspb).
    pub accel: Option<f64>,
    /// Make every piece time a whole multiple of this many seconds (e.g. 0.001).
    pub quantize: Option<f64>,
    /// Which way piece times go onto the `quantize` grid.
    pub quantize_rounding: Rounding,
    /// Servo period, seconds, over which the path planner bounds the acceleration step
    /// at a knot under a jerk limit (`None`: [`crate::defaults::SERVO_PERIOD_S`]).
    pub servo_period: Option<f64>,
    /// The resolution positions are written with, program units (PMAC text: 10⁻⁶; 0 when
    /// they are written exactly): under a jerk limit the path planner keeps room in each
    /// knot's step for the rounding (see [`PathOptions::position_resolution`]).
    pub position_resolution: f64,
}

impl PlanOptions {
    /// What the path planner runs with: the path tolerance (the chord tolerance unless
    /// set), the corner tolerance and the limits.
    pub fn path_options(&self) -> PathOptions {
        PathOptions {
            tolerance: self.path_tolerance.unwrap_or(self.tolerance.get()),
            corner_tolerance: self.corner_tolerance,
            limits: self.limits.clone(),
            quantum: self.quantize.map(|seconds| quantize::Quantum {
                seconds,
                rounding: self.quantize_rounding,
            }),
            servo_period: self.servo_period.unwrap_or(crate::defaults::SERVO_PERIOD_S),
            position_resolution: self.position_resolution,
        }
    }

    /// How the controller moves between points under the chosen planner.
    pub fn interpolation(&self) -> crate::program::Interpolation {
        match self.planner {
            Planner::Pt => crate::program::Interpolation::Pt,
            _ => crate::program::Interpolation::Pvt,
        }
    }
}

impl Default for PlanOptions {
    fn default() -> PlanOptions {
        PlanOptions {
            tolerance: ChordTolerance::new(ChordTolerance::DEFAULT_MM).expect("positive"),
            path_tolerance: None,
            corner_tolerance: None,
            limits: std::collections::BTreeMap::new(),
            planner: Planner::default(),
            timing: Timing::default(),
            accel: None,
            quantize: None,
            quantize_rounding: Rounding::Up,
            servo_period: None,
            position_resolution: 0.0,
        }
    }
}
