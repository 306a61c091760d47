//! Every default value of a compile, defined once.
//!
//! Owns the numbers used when neither the command line, a machine file nor the program
//! gives a value: the rapid rate, the tolerances, the DXF join tolerance and point limit,
//! the servo period `check` samples at. Front ends, the planners and the CLI refer to
//! these constants and never write the numbers again (`tests/tidy.rs` checks the rapid
//! rate). It must hold only constants: resolving an option against its default (and
//! converting it into a program's units) is the caller's job, done once per compile.

/// Rapid (G0) rate, millimetres per minute, converted into the program's units.
pub const RAPID_MM_PER_MIN: f64 = 5000.0;

/// Tolerance, millimetres: the path tolerance of the path planner and the chord
/// tolerance (largest sagitta) of the others.
pub const TOLERANCE_MM: f64 = 0.001;

/// G-code arc centre check: absolute radius tolerance, millimetres.
pub const ARC_ABS_TOLERANCE_MM: f64 = 0.002;

/// G-code arc centre check: radius tolerance relative to the start radius (0.1 %).
pub const ARC_REL_TOLERANCE: f64 = 0.001;

/// DXF: end points closer than this many millimetres are joined (raised to the
/// tolerance when that is larger).
pub const JOIN_TOLERANCE_MM: f64 = 0.01;

/// DXF: most points a drawing may hold. A drawing is read in memory, at roughly 400
/// bytes per point from file to output (10 million points took 4.2 GB), so this bounds
/// the memory of a compile near 1 GB.
pub const DXF_MAX_POINTS: usize = 2_000_000;

/// Servo period `check` samples at, seconds (seed 001's XMP: 500 µs).
pub const SERVO_PERIOD_S: f64 = 0.0005;
