//! Planners: polylines with target speeds to PVT contours.
//!
//! Owns the choice of velocity and time at every point. Planners never parse or print;
//! each takes a [`Polyline`](crate::polyline::Polyline) (or a [`TimedPoints`] series) and
//! returns a [`PvtContour`](crate::program::PvtContour) or a [`PlanError`] naming the source
//! line at fault. One module per planner: `contour` (seed 000), `pt`, `chord`,
//! `const_accel` (seed 001/002), `spline`, `lspb` (seed 004); `driver` dispatches on
//! [`PlanOptions::planner`] and [`quantize`] puts piece times on a grid.

mod chord;
mod const_accel;
mod contour;
mod driver;
mod lspb;
mod options;
mod path;
mod pt;
pub mod quantize;
mod spline;
mod timed;

pub use chord::chord_velocities;
pub use const_accel::const_accel_velocities;
pub use contour::{plan_contour, segment_time, ContourStream, REVERSAL_TOLERANCE};
pub use driver::{check_options, PlanReport};
pub(crate) use driver::{plan_buffered, plan_run};
pub use lspb::{blend_corner_deviation, plan_lspb, LspbPlan};
pub use options::{Planner, Timing, UnknownPlanner};
pub use path::{plan_path, PathOptions, PathReport, PathStream, TANGENT_ANGLE, WINDOW_ELEMENTS};
pub use pt::plan_pt;
pub use quantize::{Quantum, Rounding};
pub use spline::spline_velocities;
pub use timed::TimedPoints;

/// The shortest piece the LSPB planner writes, seconds: 0.1 µs, the finest time an output
/// prints (PMAC: 4 decimals of milliseconds). Shorter pieces print as `TA0.0000`, and the
/// rounding of their end positions swamps their acceleration.
pub const MIN_PIECE_SECONDS: f64 = 1e-7;

use crate::discretize::ChordTolerance;

/// Why a contour could not be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A segment's target speed is zero, negative or not finite.
    #[error(
        "segment from line {line} has feed {feed} units/s; a feed must be finite and positive"
    )]
    BadFeed {
        /// Source line of the segment.
        line: u32,
        /// The offending feed, units/s.
        feed: f64,
    },
    /// A coordinate is NaN or infinite.
    #[error("a point programmed on line {line} has a coordinate that is not finite")]
    NonFinitePoint {
        /// Source line of the point.
        line: u32,
    },
    /// The LSPB planner was chosen without an acceleration.
    #[error("the lspb planner needs an acceleration limit")]
    MissingAccel,
    /// The acceleration limit is zero, negative or not finite.
    #[error("acceleration {accel} units/s² must be finite and positive")]
    BadAccel {
        /// The offending acceleration.
        accel: f64,
    },
    /// The time slice is zero, negative or not finite.
    #[error("time slice {seconds} s must be finite and positive")]
    BadTimeSlice {
        /// The offending time slice, seconds.
        seconds: f64,
    },
    /// The quantization step is zero, negative or not finite.
    #[error("time quantum {seconds} s must be finite and positive")]
    BadQuantum {
        /// The offending quantum, seconds.
        seconds: f64,
    },
    /// A given segment time is zero, negative or not finite.
    #[error(
        "segment ending on line {line} takes {duration} s; a time must be finite and positive"
    )]
    BadDuration {
        /// Source line of the segment.
        line: u32,
        /// The offending time, seconds.
        duration: f64,
    },
    /// Given velocities do not start or end at rest.
    #[error("the point on line {line} has a velocity; a program starts and ends at rest")]
    NotAtRest {
        /// Source line of the point.
        line: u32,
    },
    /// A point-time series whose lengths disagree (a caller's bug, not the user's).
    #[error("point-time series lengths disagree with its number of axes and points")]
    BadShape,
    /// The path planner could not meet its tolerance and limits on a contour.
    #[error(
        "the contour from line {line} could not be planned within the path tolerance and limits"
    )]
    PathNotMet {
        /// Source line of the contour's first element.
        line: u32,
    },
    /// An option the chosen planner cannot honour.
    #[error("the {planner} planner cannot take {option}")]
    UnsupportedOption {
        /// The planner's name.
        planner: &'static str,
        /// The option, in words.
        option: &'static str,
    },
}

impl PlanError {
    /// Stable code of the error.
    pub fn code(&self) -> &'static str {
        match self {
            PlanError::BadFeed { .. } => "pvtc::plan::bad_feed",
            PlanError::NonFinitePoint { .. } => "pvtc::plan::non_finite_point",
            PlanError::MissingAccel => "pvtc::plan::missing_accel",
            PlanError::BadAccel { .. } => "pvtc::plan::bad_accel",
            PlanError::BadTimeSlice { .. } => "pvtc::plan::bad_time_slice",
            PlanError::BadQuantum { .. } => "pvtc::plan::bad_quantum",
            PlanError::BadDuration { .. } => "pvtc::plan::bad_duration",
            PlanError::NotAtRest { .. } => "pvtc::plan::not_at_rest",
            PlanError::BadShape => "pvtc::plan::bad_shape",
            PlanError::PathNotMet { .. } => "pvtc::plan::path_not_met",
            PlanError::UnsupportedOption { .. } => "pvtc::plan::unsupported_option",
        }
    }

    /// Source line the error names; 0 for an error about the options.
    pub fn line(&self) -> u32 {
        match self {
            PlanError::BadFeed { line, .. }
            | PlanError::NonFinitePoint { line }
            | PlanError::BadDuration { line, .. }
            | PlanError::NotAtRest { line }
            | PlanError::PathNotMet { line } => *line,
            _ => 0,
        }
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
    pub limits: std::collections::BTreeMap<crate::axis::Axis, crate::check::AxisLimits>,
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
