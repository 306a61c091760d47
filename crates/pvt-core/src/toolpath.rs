//! The toolpath: what a part program or drawing asks the machine to do, as geometry.
//!
//! Owns lines, arcs (with plane, centre and direction), cubic Béziers (their geometry is
//! [`crate::bezier`]'s), per-element feed and source span,
//! and the grouping of elements into contours. It must not know any source syntax, and
//! it holds no planned motion: that is [`crate::program`].

pub use crate::axis::Plane;
use crate::axis::{Axis, Position, Units, AXIS_COUNT};
pub use crate::bezier::Bezier;

/// Where in the source an element came from: byte range and 1-based line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    /// Byte offset of the first byte.
    pub start: usize,
    /// Byte offset one past the last byte.
    pub end: usize,
    /// 1-based line number of `start`.
    pub line: u32,
}

/// Whether a contour is cut at the programmed feed or traversed at the rapid rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// G0: positioning at the rapid rate; each rapid move is its own rest-to-rest contour.
    Rapid,
    /// G1/G2/G3: cutting at the programmed feed.
    Feed,
}

impl Motion {
    /// The word used in every output: `rapid` or `feed`.
    pub fn name(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Feed => "feed",
        }
    }
}

/// Sense of rotation seen from the positive end of the plane's normal axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArcDirection {
    /// G2.
    Clockwise,
    /// G3.
    CounterClockwise,
}

/// A circular (or helical) arc; start and end are those of its [`Element`].
///
/// Axes other than the plane's two move linearly with the swept angle (a helix when the
/// normal axis moves). When the start and end radii differ (a program posted with few
/// decimals), the radius changes linearly with angle so both end points stay exact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Plane of the circle.
    pub plane: Plane,
    /// Centre in the plane's (first, second) coordinates.
    pub center: [f64; 2],
    /// Sense of rotation.
    pub direction: ArcDirection,
    /// Extra full turns beyond the first sweep (G-code P word minus one).
    pub extra_turns: u32,
}

impl Arc {
    /// Start angle, signed sweep (positive counter-clockwise) and start/end radii.
    pub fn sweep(&self, start: &Position, end: &Position) -> ArcSweep {
        let s = self.plane.project(start);
        let e = self.plane.project(end);
        let (c0, c1) = (self.center[0], self.center[1]);
        let a0 = libm::atan2(s[1] - c1, s[0] - c0);
        let a1 = libm::atan2(e[1] - c1, e[0] - c0);
        let tau = 2.0 * std::f64::consts::PI;
        let mut sweep = match self.direction {
            ArcDirection::CounterClockwise => a1 - a0,
            ArcDirection::Clockwise => a0 - a1,
        };
        sweep = sweep.rem_euclid(tau);
        // Same start and end angle: a full circle, not an empty arc.
        if sweep <= 1e-12 * tau {
            sweep = tau;
        }
        sweep += tau * f64::from(self.extra_turns);
        let signed = match self.direction {
            ArcDirection::CounterClockwise => sweep,
            ArcDirection::Clockwise => -sweep,
        };
        ArcSweep {
            start_angle: a0,
            sweep: signed,
            start_radius: libm::hypot(s[0] - c0, s[1] - c1),
            end_radius: libm::hypot(e[0] - c0, e[1] - c1),
        }
    }
}

/// The angles and radii of an arc between two positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcSweep {
    /// Angle of the start point about the centre, radians.
    pub start_angle: f64,
    /// Signed swept angle, radians, positive counter-clockwise, never zero.
    pub sweep: f64,
    /// Distance from centre to start point.
    pub start_radius: f64,
    /// Distance from centre to end point.
    pub end_radius: f64,
}

/// What kind of geometry an element is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ElementKind {
    /// A straight move in all axes at once.
    Line,
    /// A circular or helical arc.
    Arc(Arc),
    /// A cubic Bézier in a plane (G5, G5.1, a B-spline's span, a drawing's spline or
    /// ellipse); the other axes move linearly with its parameter.
    Bezier(Bezier),
}

/// One programmed move: geometry, feed and origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    /// Line, arc or Bézier.
    pub kind: ElementKind,
    /// Position before the move.
    pub start: Position,
    /// Position after the move.
    pub end: Position,
    /// Target path speed in units per second (the programmed feed, or the rapid rate).
    pub feed: f64,
    /// Where the move was programmed.
    pub span: Span,
}

impl Element {
    /// Path length: the straight distance of a line; for an arc, its swept length in
    /// the plane (mean radius) combined with the other axes' travel (a helix); for a
    /// Bézier, its arc length on every axis.
    pub fn length(&self) -> f64 {
        let squared = |skip: &[usize]| -> f64 {
            (0..AXIS_COUNT)
                .filter(|i| !skip.contains(i))
                .map(|i| (self.end[i] - self.start[i]) * (self.end[i] - self.start[i]))
                .sum()
        };
        match self.kind {
            ElementKind::Line => squared(&[]).sqrt(),
            ElementKind::Arc(arc) => {
                let sweep = arc.sweep(&self.start, &self.end);
                let (a, b, _) = arc.plane.axes();
                let planar = 0.5 * (sweep.start_radius + sweep.end_radius) * sweep.sweep.abs();
                (planar * planar + squared(&[a.index(), b.index()])).sqrt()
            }
            ElementKind::Bezier(bezier) => bezier.length(&self.start, &self.end),
        }
    }

    /// Sets `moved[axis]` for every axis this element moves (an arc or a Bézier always
    /// moves the two axes of its plane).
    pub fn mark_moved_axes(&self, moved: &mut [bool; AXIS_COUNT]) {
        for (i, flag) in moved.iter_mut().enumerate() {
            if self.start[i] != self.end[i] {
                *flag = true;
            }
        }
        let plane = match self.kind {
            ElementKind::Line => None,
            ElementKind::Arc(arc) => Some(arc.plane),
            ElementKind::Bezier(bezier) => Some(bezier.plane),
        };
        if let Some(plane) = plane {
            let (a, b, _) = plane.axes();
            moved[a.index()] = true;
            moved[b.index()] = true;
        }
    }
}

/// A run of elements the machine moves through without stopping, rest to rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// Rapid or feed.
    pub motion: Motion,
    /// The moves, each starting where the previous one ended.
    pub elements: Vec<Element>,
}

/// Spindle state set by M3, M4 and M5.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpindleState {
    /// M3.
    Clockwise,
    /// M4.
    CounterClockwise,
    /// M5.
    Off,
}

/// Coolant state set by M7, M8 and M9.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoolantState {
    /// M7.
    Mist,
    /// M8.
    Flood,
    /// M9.
    Off,
}

/// How the machine follows the path from a program's G61, G61.1 or G64 on (LinuxCNC's
/// motion control mode): a front end hands it on with
/// [`crate::stream::ToolpathSink::path_control`] for the record (the `toolpath` format,
/// the differential tests); the planners follow G61/G61.1 through contour ends and G64
/// P through [`crate::stream::ToolpathSink::path_tolerance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathControl {
    /// G61: exact path (every programmed point is reached).
    ExactPath,
    /// G61.1: exact stop (the machine comes to rest at the end of every move).
    ExactStop,
    /// G64: continuous, with P (the path tolerance) and Q (LinuxCNC's naive-CAM
    /// tolerance), in the toolpath's units; 0 where not given.
    Continuous {
        /// P.
        tolerance: f64,
        /// Q (P where Q is not given, as LinuxCNC sets it).
        naive_cam_tolerance: f64,
    },
}

impl PathControl {
    /// The name used in every output (`exact_path`, `exact_stop`, `continuous`).
    pub fn name(&self) -> &'static str {
        match self {
            PathControl::ExactPath => "exact_path",
            PathControl::ExactStop => "exact_stop",
            PathControl::Continuous { .. } => "continuous",
        }
    }
}

/// What a program asks the machine to do that is not motion.
#[derive(Debug, Clone, PartialEq)]
pub enum EventKind {
    /// G4: wait this many seconds at rest.
    Dwell {
        /// Seconds.
        seconds: f64,
    },
    /// M0 (or M1 when `optional`): stop until the operator resumes.
    Pause {
        /// M1, optional stop.
        optional: bool,
    },
    /// M3/M4/M5.
    Spindle {
        /// New state.
        state: SpindleState,
    },
    /// S word.
    SpindleSpeed {
        /// Revolutions per minute.
        rpm: f64,
    },
    /// M7/M8/M9.
    Coolant {
        /// New state.
        state: CoolantState,
    },
    /// T word: select a tool.
    ToolSelect {
        /// Tool number.
        tool: u32,
    },
    /// M6: change to the selected tool.
    ToolChange,
    /// `(MSG, …)`: show a message to the operator.
    Message {
        /// The text.
        text: String,
    },
    /// An M code the machine's integrator implements: digital and analog I/O (M62–M68)
    /// or a user-defined code (M100–M199), with the words given with it.
    MachineCode {
        /// The code number: 62…68 or 100…199 ([`EventKind::machine_code`]).
        code: u16,
        /// Its P, Q, E and L words.
        words: CodeWords,
    },
}

/// The words of a [`EventKind::MachineCode`], where given: P (an output or input
/// number, or a user code's first value), Q (an analog value, a timeout, or a user
/// code's second value), E (an analog channel), L (M66's wait mode).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CodeWords {
    /// P.
    pub p: Option<f64>,
    /// Q.
    pub q: Option<f64>,
    /// E.
    pub e: Option<f64>,
    /// L.
    pub l: Option<f64>,
}

impl CodeWords {
    /// The words as LinuxCNC's programs write them, in P E L Q order: `M67 E0 Q2.5`.
    pub fn written(&self) -> String {
        let words = [('P', self.p), ('E', self.e), ('L', self.l), ('Q', self.q)];
        let written: Vec<String> = words
            .iter()
            .filter_map(|(letter, value)| value.map(|v| format!("{letter}{v}")))
            .collect();
        written.join(" ")
    }
}

impl EventKind {
    /// The event of a kind that carries no value (the pauses, the spindle's and the
    /// coolant's states, the tool change) by its [`EventKind::name`]; `None` for any other
    /// name.
    pub fn without_value(name: &str) -> Option<EventKind> {
        use CoolantState::{Flood, Mist};
        use SpindleState::{Clockwise, CounterClockwise};
        [
            EventKind::Pause { optional: false },
            EventKind::Pause { optional: true },
            EventKind::Spindle { state: Clockwise },
            EventKind::Spindle {
                state: CounterClockwise,
            },
            EventKind::Spindle {
                state: SpindleState::Off,
            },
            EventKind::Coolant { state: Mist },
            EventKind::Coolant { state: Flood },
            EventKind::Coolant {
                state: CoolantState::Off,
            },
            EventKind::ToolChange,
        ]
        .into_iter()
        .find(|k| k.name() == name)
    }

    /// The name used in every output (`dwell`, `spindle_cw`, `coolant_off`, …).
    pub fn name(&self) -> &'static str {
        match self {
            EventKind::Dwell { .. } => "dwell",
            EventKind::Pause { optional: false } => "pause",
            EventKind::Pause { optional: true } => "optional_pause",
            EventKind::Spindle {
                state: SpindleState::Clockwise,
            } => "spindle_cw",
            EventKind::Spindle {
                state: SpindleState::CounterClockwise,
            } => "spindle_ccw",
            EventKind::Spindle {
                state: SpindleState::Off,
            } => "spindle_off",
            EventKind::SpindleSpeed { .. } => "spindle_speed",
            EventKind::Coolant {
                state: CoolantState::Mist,
            } => "coolant_mist",
            EventKind::Coolant {
                state: CoolantState::Flood,
            } => "coolant_flood",
            EventKind::Coolant {
                state: CoolantState::Off,
            } => "coolant_off",
            EventKind::ToolSelect { .. } => "tool_select",
            EventKind::ToolChange => "tool_change",
            EventKind::Message { .. } => "message",
            EventKind::MachineCode { code, .. } => match code {
                62 => "digital_output_on_synced",
                63 => "digital_output_off_synced",
                64 => "digital_output_on",
                65 => "digital_output_off",
                66 => "wait_input",
                67 => "analog_output_synced",
                68 => "analog_output",
                _ => "user_m_code",
            },
        }
    }

    /// The event of M code `code` with its words, if it is one an integrator implements
    /// (M62–M68, M100–M199).
    pub fn machine_code(code: u16, words: CodeWords) -> Option<EventKind> {
        matches!(code, 62..=68 | 100..=199).then_some(EventKind::MachineCode { code, words })
    }

    /// The event as a program line writes it, for one that has a code and words
    /// (`M62 P1`); `None` for the others.
    pub fn code_written(&self) -> Option<String> {
        let EventKind::MachineCode { code, words } = self else {
            return None;
        };
        let words = words.written();
        Some(match words.is_empty() {
            true => format!("M{code}"),
            false => format!("M{code} {words}"),
        })
    }
}

/// An event and where it happens: at rest, before contour `before_contour` (a value equal
/// to the number of contours means after the last one).
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramEvent {
    /// Index of the contour the event precedes.
    pub before_contour: usize,
    /// What happens.
    pub kind: EventKind,
    /// Source line.
    pub line: u32,
}

/// Everything a source asks for, in order, in one set of units.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Toolpath {
    /// Units of every linear coordinate and feed.
    pub units: Units,
    /// Contours in execution order.
    pub contours: Vec<Contour>,
    /// Events between contours, in order; each happens with the machine at rest.
    pub events: Vec<ProgramEvent>,
    /// Path tolerances the source sets (G-code's G64 P), program units, each with the
    /// index of the first contour it applies to, in order.
    pub path_tolerances: Vec<(usize, f64)>,
}

impl Toolpath {
    /// The time the programmed path takes at its feeds with no acceleration at all:
    /// the sum of every element's length over its feed, seconds.
    pub fn feed_time(&self) -> f64 {
        self.contours
            .iter()
            .flat_map(|c| &c.elements)
            .map(|e| e.length() / e.feed)
            .sum()
    }

    /// The axes whose position changes anywhere in the toolpath, in X Y Z A B C order.
    pub fn moved_axes(&self) -> Vec<Axis> {
        let mut moved = [false; AXIS_COUNT];
        for element in self.contours.iter().flat_map(|c| &c.elements) {
            element.mark_moved_axes(&mut moved);
        }
        Axis::ALL.into_iter().filter(|a| moved[a.index()]).collect()
    }
}
