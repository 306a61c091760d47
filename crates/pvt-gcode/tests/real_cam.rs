//! Issue 24: real CAM output read as LinuxCNC's `rs274` reads it, through the library.
//!
//! The differential programs (`tests/dialect/`, compared with `rs274` by
//! `crates/pvtc/tests/dialect.rs`) pin the motion; these tests pin what the comparison
//! cannot see: diagnostics and their codes, options, events and memory bounds.

mod common;

use common::ok;
use pvt_core::{plan_toolpath_report, PlanOptions, Planner};

#[test]
fn g64_p0_is_plain_g64() {
    let c = ok("G21 G64 P0 F100\nG1 X1\nG3 X0 Y1 I-1 J0\nG64 P0.02\nM2\n");
    assert_eq!(c.path_tolerance, Some(0.02));
    let c = ok("G21 G64 P0 F100\nG1 X1\nG3 X0 Y1 I-1 J0\nM2\n");
    assert_eq!(c.path_tolerance, None, "G64 P0 sets no tolerance");
}

/// A zero path tolerance from a source (a front end that reads G64 P0 literally) is
/// no tolerance of its own: the arc is planned within the one in force (it overflowed a
/// capacity computing the arc's knots).
#[test]
fn a_zero_path_tolerance_plans_an_arc_within_the_tolerance_in_force() {
    let mut c = ok("G21 F600\nG1 X10\nG3 X0 Y10 I-10 J0\nM2\n");
    c.toolpath.path_tolerances = vec![(0, 0.0)];
    let options = PlanOptions {
        planner: Planner::Path,
        ..PlanOptions::default()
    };
    let planned = plan_toolpath_report(&c.toolpath, &options).expect("planned");
    let bound = planned.report.path_error.expect("a path error bound");
    assert!(
        bound > 0.0 && bound <= pvt_core::defaults::TOLERANCE_MM,
        "{bound}"
    );
}
