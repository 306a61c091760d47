//! Every default value of a compile, defined once.
//!
//! Owns the numbers used when neither the command line, a machine file nor the program
//! gives a value: the rapid rate, the tolerances, the DXF join tolerance and point limit,
//! the servo period `check` samples at, the tolerances `diff` compares within. Front ends, the planners and the CLI refer to
//! these constants and never write the numbers again (`tests/tidy.rs` checks the rapid
//! rate). Beside the constants it holds the resolutions that depend on a program's units
//! ([`rapid_per_minute`], [`tolerance`]), one function each, which the front ends and
//! pvtc's settings all call. It must hold nothing else.

/// Rapid (G0) rate, millimetres per minute, converted into the program's units.
pub const RAPID_MM_PER_MIN: f64 = 5000.0;

/// Tolerance, millimetres: the path tolerance of the path planner and the chord
/// tolerance (largest sagitta) of the others.
pub const TOLERANCE_MM: f64 = 0.001;

/// G-code arc centre check: absolute radius tolerance of a program in millimetres,
/// LinuxCNC's `CENTER_ARC_RADIUS_TOLERANCE_MM` (2 · 0.01 · √2 mm). An arc whose start and
/// end radii differ by more than 100 times it, or by more than it and by more than
/// [`ARC_REL_TOLERANCE`], is refused; one within runs as a spiral.
pub const ARC_ABS_TOLERANCE_MM: f64 = 2.0 * 0.01 * std::f64::consts::SQRT_2;

/// The same for a program in inches, inches: LinuxCNC's
/// `CENTER_ARC_RADIUS_TOLERANCE_INCH` (2 · 0.001 · √2 in).
pub const ARC_ABS_TOLERANCE_IN: f64 = 2.0 * 0.001 * std::f64::consts::SQRT_2;

/// G-code arc centre check: radius difference relative to the larger radius (0.1 %),
/// LinuxCNC's `SPIRAL_RELATIVE_TOLERANCE`.
pub const ARC_REL_TOLERANCE: f64 = 0.001;

/// G-code arcs, inches: how far R may fall short of half the chord (a half circle), and
/// the smallest radius of a centre-form arc, LinuxCNC's `RADIUS_TOLERANCE_INCH`
/// (millimetre programs: the same length, 0.00127 mm).
pub const ARC_RADIUS_TOLERANCE_IN: f64 = 0.00005;

/// DXF: end points closer than this many millimetres are joined (raised to the
/// tolerance when that is larger).
pub const JOIN_TOLERANCE_MM: f64 = 0.01;

/// DXF: most points a drawing may hold. A drawing is read in memory, at roughly 400
/// bytes per point from file to output (10 million points took 4.2 GB), so this bounds
/// the memory of a compile near 1 GB.
pub const DXF_MAX_POINTS: usize = 2_000_000;

/// Servo period `check` samples at, seconds (seed 001's XMP: 500 µs).
pub const SERVO_PERIOD_S: f64 = 0.0005;

/// `diff`: farthest apart two motions' positions may be, millimetres (1 µm).
pub const DIFF_TOLERANCE_MM: f64 = 0.001;

/// `diff`: largest time shift and difference of total times, seconds (1 ms).
pub const DIFF_TIME_TOLERANCE_S: f64 = 0.001;

/// `diff`: largest relative difference of an axis' peak (1 %).
pub const DIFF_PEAK_TOLERANCE: f64 = 0.01;

/// The rapid rate of a program in `units`, per minute: `given` when it is a positive,
/// finite rate, else [`RAPID_MM_PER_MIN`] converted. The front ends plan rapids with it
/// and pvtc's header prints it.
pub fn rapid_per_minute(given: Option<f64>, units: crate::axis::Units) -> f64 {
    match given {
        Some(rate) if rate > 0.0 && rate.is_finite() => rate,
        _ => units.from_mm(RAPID_MM_PER_MIN),
    }
}

/// The tolerance of a program in `units`: `given`, else [`TOLERANCE_MM`] converted. pvtc
/// plans with it and pvt-dxf flattens curves with it.
pub fn tolerance(given: Option<f64>, units: crate::axis::Units) -> f64 {
    given.unwrap_or_else(|| units.from_mm(TOLERANCE_MM))
}

/// The absolute arc radius tolerance of a program in `units`, in those units: `given_mm`
/// (`--arc-abs-tolerance`, millimetres) converted, else LinuxCNC's for those units
/// ([`ARC_ABS_TOLERANCE_MM`], [`ARC_ABS_TOLERANCE_IN`]).
pub fn arc_abs_tolerance(given_mm: Option<f64>, units: crate::axis::Units) -> f64 {
    match (given_mm, units) {
        (Some(mm), units) => units.from_mm(mm),
        (None, crate::axis::Units::Millimetre) => ARC_ABS_TOLERANCE_MM,
        (None, crate::axis::Units::Inch) => ARC_ABS_TOLERANCE_IN,
    }
}

/// How far R may fall short of half the chord, and the smallest centre-form radius, of a
/// program in `units`, in those units: [`ARC_RADIUS_TOLERANCE_IN`], the same length in
/// millimetres.
pub fn arc_radius_tolerance(units: crate::axis::Units) -> f64 {
    units.from_mm(ARC_RADIUS_TOLERANCE_IN * crate::axis::Units::Inch.mm_per_unit())
}
