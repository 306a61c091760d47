//! Why planning failed: [`PlanError`], with a stable code and the source line at fault.
//!
//! Owns the error type every planner returns. It must not plan.

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
    /// A tolerance below [`crate::ChordTolerance::SMALLEST`] or not finite.
    #[error("tolerance {tolerance} must be finite and at least 0.000001 (program units)")]
    BadTolerance {
        /// The offending tolerance, program units.
        tolerance: f64,
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
            PlanError::BadTolerance { .. } => "pvtc::plan::bad_tolerance",
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
