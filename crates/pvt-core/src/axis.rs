//! Axis names, machine positions, planes and length units.
//!
//! Owns the fixed set of axes a part program can address, the three planes an arc or
//! curve lies in (each a triple of axes) and the unit conversions; it must not know how a
//! front end spells an axis word.

use std::fmt;

/// Number of axes a [`Position`] holds.
pub const AXIS_COUNT: usize = 6;

/// A position of all six axes, indexed by [`Axis::index`]: X Y Z A B C.
pub type Position = [f64; AXIS_COUNT];

/// One machine axis. Linear axes are in program units, rotary axes in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Axis {
    /// Linear X.
    X,
    /// Linear Y.
    Y,
    /// Linear Z.
    Z,
    /// Rotary about X, degrees.
    A,
    /// Rotary about Y, degrees.
    B,
    /// Rotary about Z, degrees.
    C,
}

impl Axis {
    /// All axes in output order.
    pub const ALL: [Axis; AXIS_COUNT] = [Axis::X, Axis::Y, Axis::Z, Axis::A, Axis::B, Axis::C];

    /// Index of this axis in a [`Position`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The axis letter, upper case.
    pub fn letter(self) -> char {
        ['X', 'Y', 'Z', 'A', 'B', 'C'][self.index()]
    }

    /// The axis for a letter (either case), if it names one.
    pub fn from_letter(c: char) -> Option<Axis> {
        match c.to_ascii_uppercase() {
            'X' => Some(Axis::X),
            'Y' => Some(Axis::Y),
            'Z' => Some(Axis::Z),
            'A' => Some(Axis::A),
            'B' => Some(Axis::B),
            'C' => Some(Axis::C),
            _ => None,
        }
    }

    /// True for the rotary axes A, B and C.
    pub fn is_rotary(self) -> bool {
        matches!(self, Axis::A | Axis::B | Axis::C)
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.letter())
    }
}

/// The plane an arc lies in, named as G17/G18/G19 name them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// G17: first axis X, second Y, normal Z.
    #[default]
    XY,
    /// G18: first axis Z, second X, normal Y.
    ZX,
    /// G19: first axis Y, second Z, normal X.
    YZ,
}

impl Plane {
    /// The (first, second, normal) axes; counter-clockwise turns first towards second.
    pub fn axes(self) -> (Axis, Axis, Axis) {
        match self {
            Plane::XY => (Axis::X, Axis::Y, Axis::Z),
            Plane::ZX => (Axis::Z, Axis::X, Axis::Y),
            Plane::YZ => (Axis::Y, Axis::Z, Axis::X),
        }
    }

    /// The in-plane coordinates (first, second) of a position.
    pub fn project(self, p: &Position) -> [f64; 2] {
        let (a, b, _) = self.axes();
        [p[a.index()], p[b.index()]]
    }
}

/// Length unit of a program's linear axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    /// Millimetres (G21).
    #[default]
    Millimetre,
    /// Inches (G20).
    Inch,
}

impl Units {
    /// Millimetres per one of this unit.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::Millimetre => 1.0,
            Units::Inch => 25.4,
        }
    }

    /// Converts a length given in millimetres into this unit.
    pub fn from_mm(self, mm: f64) -> f64 {
        mm / self.mm_per_unit()
    }

    /// Short name used in every output: `mm` or `in`.
    pub fn name(self) -> &'static str {
        match self {
            Units::Millimetre => "mm",
            Units::Inch => "in",
        }
    }
}
