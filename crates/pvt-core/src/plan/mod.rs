//! Planners: polylines with target speeds to PVT contours.
//!
//! Owns the choice of velocity and time at every point. Planners never parse or print;
//! each takes a [`Polyline`](crate::polyline::Polyline) (or a [`TimedPoints`] series) and
//! returns a [`PvtContour`](crate::program::PvtContour) or a [`PlanError`] naming the source
//! line at fault. One module per planner: `contour` (seed 000), `pt`, `chord`,
//! `const_accel` (seed 001/002), `spline`, `lspb` (seed 004); `driver` dispatches on
//! [`PlanOptions::planner`] and [`quantize`] puts piece times on a grid; `options` holds
//! [`PlanOptions`], `error` [`PlanError`]. This file is the façade: `mod` lines and
//! re-exports only.

mod chord;
mod const_accel;
mod contour;
mod driver;
mod error;
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
pub use error::PlanError;
pub use lspb::{blend_corner_deviation, plan_lspb, LspbPlan};
pub use options::{PlanOptions, Planner, Timing, UnknownPlanner};
pub use path::{plan_path, PathOptions, PathReport, PathStream, TANGENT_ANGLE, WINDOW_ELEMENTS};
pub use pt::plan_pt;
pub use quantize::{Quantum, Rounding, MIN_PIECE_SECONDS};
pub use spline::spline_velocities;
pub use timed::TimedPoints;
