//! pvt-core: the data that flows through pvtc and every computation on it.
//!
//! Owns the intermediate representation ([`Toolpath`] → [`Polyline`] → [`PvtProgram`]),
//! the geometry of its cubic Bézier elements and B-splines broken into them ([`bezier`]),
//! arc discretization by chord tolerance ([`discretize`]), the planners ([`plan`]) and the
//! cubic Hermite evaluation a controller performs ([`hermite`]), long pieces cut along
//! their own cubic for controllers with a largest piece time ([`split`]) and the check of
//! a planned program against limits and its source ([`check`]), the comparison of two
//! programs as motion ([`compare`]), the machine model
//! both use ([`limits`]), line/column
//! positions in source text ([`text`]), the one walk of a toolpath or program
//! ([`traverse`]) and every default value ([`defaults`]).
//!
//! Architecture invariants:
//! - this crate does no I/O and knows no file format: front ends produce a [`Toolpath`],
//!   back ends consume a [`PvtProgram`], and neither is visible from here;
//! - every transcendental float function goes through `libm`, so the same input gives
//!   bit-identical numbers on every machine;
//! - data flows one way: nothing here calls back into a front end.

pub mod axis;
pub mod bezier;
pub mod check;
pub mod compare;
pub mod compensate;
pub mod defaults;
pub mod discretize;
pub mod hermite;
pub mod limits;
pub mod plan;
pub mod polyline;
pub mod program;
pub mod rational;
pub mod split;
pub mod stream;
pub mod text;
pub mod toolpath;
pub mod traverse;
pub mod vector;

pub use axis::{Axis, Position, Units, AXIS_COUNT};
pub use check::{
    check_program, AxisReport, CheckOptions, CheckReport, Peak, Quantity, SpeedReport, Violation,
};
pub use discretize::{flatten_contour, ChordTolerance};
pub use hermite::{HermiteSegment, State};
pub use limits::{AxisLimits, MachineLimits};
pub use plan::{
    plan_contour, plan_path, PathOptions, PathReport, PathStream, PlanOptions, PlanReport, Planner,
    Quantum, Rounding, TimedPoints, Timing,
};
pub use polyline::Polyline;
pub use program::{Interpolation, PvtContour, PvtProgram, SegmentRef};
pub use split::{split_long_pieces, PieceSplitter};
pub use stream::{
    plan_timed, plan_toolpath, plan_toolpath_report, PieceSink, PlanStage, Planned, ToolpathSink,
};
pub use toolpath::{
    Arc, ArcDirection, Bezier, CodeWords, Contour, CoolantState, Element, ElementKind, EventKind,
    Motion, PathControl, Plane, ProgramEvent, Span, SpindleState, Toolpath,
};
