//! Cutter-radius compensation: the path of a tool's centre that cuts a programmed path
//! with the tool on its left or right, as LinuxCNC's interpreter builds it (G41/G42).
//!
//! Owns the offset geometry in the compensation plane (XY, or ZX for lathes): the entry
//! move, lines and arcs moved one tool radius aside, an arc about the programmed corner
//! at every outside corner, the previous move cut back to the intersection at every
//! inside corner, and the gouge checks. The corner depends on the next move, so the last
//! move (and any event after it) is held until the next one arrives: one move of
//! look-ahead, released in order through [`Released`]. It must not parse, and it knows
//! no G-code words: a front end hands it programmed elements (machine coordinates, arc
//! centres already found) and reports its [`Gouge`]s.
//!
//! In the plane, a point is `[first, second]` of [`Plane::axes`]; the plane's normal axis
//! and the rotary axes move with each programmed move, and an outside-corner arc stays
//! at the normal axis' level before the move while taking its rotary motion (as rs274
//! does).

use crate::axis::Position;
use crate::toolpath::{Arc, ArcDirection, Element, ElementKind, EventKind, Motion, Plane, Span};

/// Below this corner angle (radians) a corner is a straight continuation: no arc, no cut
/// back (LinuxCNC's `TOLERANCE_CONCAVE_CORNER`).
const CORNER_ANGLE: f64 = 0.05;

/// Which side of the programmed path, looking along the motion, the tool runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// G41.
    Left,
    /// G42.
    Right,
}

impl Side {
    /// The other side (a negative radius swaps sides).
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// Whether a tool on this side of an arc turning `turn` (positive counter-clockwise)
    /// runs inside it.
    fn inside(self, turn: i32) -> bool {
        matches!((self, turn > 0), (Side::Left, true) | (Side::Right, false))
    }
}

/// Why the compensated path cannot be made: the tool would cut into the part, or the
/// geometry leaves no place for it. Each is one of LinuxCNC's refusals.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum Gouge {
    /// The first move after G41/G42 ends within one tool radius of where it starts.
    #[error("the entry move is not longer than the tool radius {radius}")]
    EntryTooShort {
        /// The tool radius.
        radius: f64,
    },
    /// An arc on the tool's side is no larger than the tool.
    #[error("the tool radius {radius} is not less than the arc radius")]
    ToolLargerThanArc {
        /// The tool radius.
        radius: f64,
    },
    /// An inside corner too tight for the tool: cutting the previous move back to the
    /// intersection would reverse it, or the two offset paths never meet.
    #[error("the inside corner is too tight for the tool: {0}")]
    ConcaveCorner(&'static str),
    /// Two arcs about the same centre meet at a corner.
    #[error("arc to arc motion about the same centre")]
    SameCentre,
    /// A Bézier (a spline) under compensation, which LinuxCNC refuses too ("Cannot
    /// convert spline with cutter radius compensation").
    #[error("a spline cannot be cut with cutter radius compensation")]
    Spline,
}

/// What the compensation lets go of, in program order.
#[derive(Debug, Clone, PartialEq)]
pub enum Released {
    /// A move of the tool's centre.
    Element(Motion, Element),
    /// An event that came after the move before it.
    Event(EventKind, u32),
}

/// A move of the tool's centre held for the next corner.
#[derive(Debug, Clone, PartialEq)]
struct HeldMove {
    motion: Motion,
    /// The end, in full (the plane's two axes may still move).
    end: Position,
    feed: f64,
    span: Span,
    shape: Shape,
}

/// The shape of a held move, with what the gouge check of a moved end needs.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    /// A straight move and the direction it was programmed in.
    Line { direction: [f64; 2] },
    /// An arc: centre, turns (±n, positive counter-clockwise, n − 1 extra), and the
    /// sweep it had when made (0: never checked).
    Arc {
        center: [f64; 2],
        turn: i32,
        sweep: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
enum Held {
    Move(HeldMove),
    Event(EventKind, u32),
}

/// The corner before a move, as the tool meets it.
#[derive(Debug, Clone, Copy)]
struct LineCorner {
    /// How far the path turns at the corner, towards the tool's side (radians, −π/2…3π/2
    /// on arcs): below 0 an inside corner, above it an outside one.
    turn: f64,
    /// Lines: the direction back along the last move from the tool; arcs: the direction
    /// square to the last move, away from the tool.
    back: f64,
    /// The direction from the programmed path to the tool at the corner, for the move.
    aside: f64,
    /// The tool's centre at the corner.
    c: [f64; 2],
}

/// How the tool passes a programmed corner.
#[derive(Debug, Clone, Copy)]
enum Join {
    /// An outside corner: an arc about it.
    Round,
    /// An inside corner: the held moves end at this point.
    Cut([f64; 2]),
    /// Straight on (within the corner angle).
    Straight,
}

/// A programmed move handed to [`Compensation::feed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Programmed {
    /// Rapid or feed.
    pub motion: Motion,
    /// Line, or arc in the compensation plane (its centre from the programmed start).
    pub kind: ElementKind,
    /// The programmed end, machine coordinates.
    pub end: Position,
    /// Units per second.
    pub feed: f64,
    /// The block.
    pub span: Span,
}

/// Compensation in effect from G41/G42 until G40.
#[derive(Debug, Clone)]
pub struct Compensation {
    side: Side,
    radius: f64,
    plane: Plane,
    /// No move made yet: the next one is the entry move.
    first_move: bool,
    /// The programmed point the tool stands for.
    programmed: Position,
    /// The tool's centre after the last move made.
    tool: Position,
    /// Where the released elements end (the next released one starts there).
    released_at: Position,
    held: Vec<Held>,
    /// The start of the last held move, in the plane, while known.
    endpoint: Option<[f64; 2]>,
    /// How far (radians) a held arc may sweep beyond its programmed sweep when its end
    /// moves into a corner.
    sweep_slack: f64,
    /// A lathe tool's orientation (1…8; 0: none): the point the machine moves lies off
    /// the nose radius' centre by this, in the plane, added to every released position.
    nose_offset: [f64; 2],
}

/// The sweep slack LinuxCNC 2.9's `rs274` allows a held arc in a millimetre program
/// (radians; it scales its inch value as a length).
pub const SWEEP_SLACK_MM: f64 = 0.0254;

/// The sweep slack in an inch program (radians).
pub const SWEEP_SLACK_INCH: f64 = 0.001;

impl Compensation {
    /// Compensation on `side` by a tool of `radius` (> 0) in `plane` (XY or ZX), the tool
    /// standing at `at` (the programmed point too).
    pub fn new(side: Side, radius: f64, plane: Plane, at: Position) -> Compensation {
        Compensation {
            side,
            radius,
            plane,
            first_move: true,
            programmed: at,
            tool: at,
            released_at: at,
            held: Vec::new(),
            endpoint: None,
            sweep_slack: SWEEP_SLACK_INCH,
            nose_offset: [0.0; 2],
        }
    }

    /// The same compensation for a lathe tool of `orientation` (1…8, LinuxCNC's tool
    /// table Q) in the ZX plane: compensation places the centre of the tool's nose
    /// radius, the machine moves the tool's point, one radius off in Z and X (or in one
    /// of them) as the orientation says. 0, 9 or another plane: no offset.
    pub fn with_tool_orientation(mut self, orientation: u32) -> Compensation {
        if self.plane != Plane::ZX {
            return self;
        }
        let r = self.radius;
        let x = match orientation {
            1 | 2 | 6 => -r,
            3 | 4 | 8 => r,
            _ => 0.0,
        };
        let z = match orientation {
            2 | 3 | 7 => -r,
            1 | 4 | 5 => r,
            _ => 0.0,
        };
        self.nose_offset = [z, x];
        self
    }

    /// Whether the tool is a lathe tool whose point is off its nose radius' centre.
    fn has_nose_offset(&self) -> bool {
        self.nose_offset != [0.0; 2]
    }

    /// The same compensation allowing a held arc `slack` radians beyond its programmed
    /// sweep ([`SWEEP_SLACK_MM`], [`SWEEP_SLACK_INCH`]).
    pub fn with_sweep_slack(mut self, slack: f64) -> Compensation {
        self.sweep_slack = slack;
        self
    }

    /// The same compensation with its first released move starting at `tool` (after an
    /// exit move that G41 interrupted, the tool stands off the programmed point).
    pub fn released_from(mut self, tool: Position) -> Compensation {
        self.released_at = tool;
        self
    }

    /// The plane compensation works in.
    pub fn plane(&self) -> Plane {
        self.plane
    }

    /// The programmed point the tool stands for (machine coordinates).
    pub fn programmed(&self) -> Position {
        self.programmed
    }

    /// An event after the moves so far: released at once when nothing is held.
    pub fn event(&mut self, kind: EventKind, line: u32, out: &mut Vec<Released>) {
        if self.held.is_empty() {
            out.push(Released::Event(kind, line));
        } else {
            self.held.push(Held::Event(kind, line));
        }
    }

    /// One programmed move; what it settles is pushed onto `out`.
    pub fn feed(&mut self, step: Programmed, out: &mut Vec<Released>) -> Result<(), Gouge> {
        match (step.kind, self.first_move) {
            (ElementKind::Bezier(_), _) => Err(Gouge::Spline),
            (ElementKind::Arc(arc), true) => self.entry_arc(arc, step),
            (ElementKind::Arc(arc), false) => self.arc(arc, step, out),
            (_, true) => self.entry_line(step),
            (_, false) => self.line(step, out),
        }
    }

    /// G40: the held moves end where the tool is and are released; the tool's position,
    /// where the exit move starts (`None` when no move was made under compensation).
    pub fn finish(mut self, out: &mut Vec<Released>) -> Result<Option<Position>, Gouge> {
        if self.first_move {
            self.release(out);
            return Ok(None);
        }
        let at = self.point(&self.tool);
        self.move_end_and_release(at, out)?;
        Ok(Some(self.released_at))
    }

    fn point(&self, p: &Position) -> [f64; 2] {
        self.plane.project(p)
    }

    /// `p` with the plane's two axes set to `at`.
    fn placed(&self, mut p: Position, at: [f64; 2]) -> Position {
        let (a, b, _) = self.plane.axes();
        p[a.index()] = at[0];
        p[b.index()] = at[1];
        p
    }

    /// The end of a corner arc: `at` in the plane, the normal axis where the tool is,
    /// every other axis at the move's end.
    fn corner_end(&self, end: &Position, at: [f64; 2]) -> Position {
        let (_, _, n) = self.plane.axes();
        let mut p = self.placed(*end, at);
        p[n.index()] = self.tool[n.index()];
        p
    }

    /// The offset direction angle: a quarter turn from `angle` towards the tool's side.
    fn toward_side(&self, angle: f64) -> f64 {
        match self.side {
            Side::Left => angle + FRAC_PI_2,
            Side::Right => angle - FRAC_PI_2,
        }
    }

    /// The first move after G41/G42, straight: it ends one radius aside of the programmed
    /// end, square to the move.
    fn entry_line(&mut self, step: Programmed) -> Result<(), Gouge> {
        let c = self.point(&self.tool);
        let p = self.point(&step.end);
        if libm::hypot(p[0] - c[0], p[1] - c[1]) <= self.radius {
            return Err(Gouge::EntryTooShort {
                radius: self.radius,
            });
        }
        let alpha = self.toward_side(angle(c, p));
        let (sin, cos) = libm::sincos(alpha);
        let end = [p[0] + self.radius * cos, p[1] + self.radius * sin];
        self.endpoint = Some(c);
        let shape = Shape::Line {
            direction: [cos, sin],
        };
        self.hold(step, self.placed(step.end, end), shape);
        Ok(())
    }

    /// The first move after G41/G42, an arc: an arc about a new centre from the tool to
    /// one radius aside of the programmed end, tangent there to the programmed arc's
    /// offset.
    fn entry_arc(&mut self, arc: Arc, step: Programmed) -> Result<(), Gouge> {
        let c = self.point(&self.tool);
        let p = self.point(&step.end);
        let turn = turns(&arc);
        if libm::hypot(p[0] - c[0], p[1] - c[1]) <= self.radius {
            return Err(Gouge::EntryTooShort {
                radius: self.radius,
            });
        }
        let (end, center) = self.entry_arc_geometry(c, p, arc.center, turn)?;
        if self.has_nose_offset() {
            // The tool's point moves to where the nose radius' centre stands first.
            let straight = Programmed {
                kind: ElementKind::Line,
                motion: Motion::Feed,
                ..step
            };
            let direction = [0.0; 2];
            self.hold(straight, self.tool, Shape::Line { direction });
            self.endpoint = Some(c);
        }
        let shape = Shape::Arc {
            center,
            turn,
            sweep: find_sweep(c, center, turn, end),
        };
        let kind = ElementKind::Arc(Arc { center, ..arc });
        self.hold(
            Programmed { kind, ..step },
            self.placed(step.end, end),
            shape,
        );
        Ok(())
    }

    /// The end and centre of the entry arc from the tool at `c` towards the arc about
    /// `center` ending at `p`: it ends one radius aside of `p`, its centre on the line from
    /// there towards `center`, as far from the tool as from the end.
    fn entry_arc_geometry(
        &self,
        c: [f64; 2],
        p: [f64; 2],
        center: [f64; 2],
        turn: i32,
    ) -> Result<([f64; 2], [f64; 2]), Gouge> {
        let too_large = Gouge::ToolLargerThanArc {
            radius: self.radius,
        };
        let inside = self.side.inside(turn);
        if inside && distance(center, c) <= self.radius {
            return Err(too_large);
        }
        let gamma = match inside {
            true => angle(p, center),
            false => angle(center, p),
        };
        let end = along(p, gamma, self.radius);
        let half_chord = distance(c, end) / 2.0;
        let towards_center = angle(end, center);
        let cos = libm::cos(angle(end, c) - towards_center);
        if cos.abs() < 1e-4 {
            return Err(too_large);
        }
        Ok((end, along(end, towards_center, half_chord / cos)))
    }

    /// A straight move after the first: one radius aside of the programmed line, joined to
    /// the previous move by an arc about the programmed corner (outside) or at their
    /// intersection (inside).
    fn line(&mut self, step: Programmed, out: &mut Vec<Released>) -> Result<(), Gouge> {
        let c = self.point(&self.tool);
        let op = self.point(&self.programmed);
        let p = self.point(&step.end);
        let direction = [p[0] - op[0], p[1] - op[1]];
        if p == op {
            // No motion in the plane: the tool moves along the normal axis where it is.
            self.hold(step, self.placed(step.end, c), Shape::Line { direction });
            return Ok(());
        }
        let corner = self.line_corner(c, op, p);
        let aside = corner.aside;
        match self.line_join(corner, op, p)? {
            Join::Round => {
                self.move_end_and_release(c, out)?;
                self.round_corner(&step, op, along(op, aside, self.radius), out);
            }
            Join::Cut(at) => self.move_end_and_release(at, out)?,
            Join::Straight => {
                self.release(out);
                self.endpoint = Some(c);
            }
        }
        let end = self.placed(step.end, along(p, aside, self.radius));
        let step = Programmed {
            kind: ElementKind::Line,
            ..step
        };
        self.hold(step, end, Shape::Line { direction });
        Ok(())
    }

    /// The corner between the tool's last move (ending at `c`, about the programmed point
    /// `op`) and a line from `op` to `p`.
    fn line_corner(&self, c: [f64; 2], op: [f64; 2], p: [f64; 2]) -> LineCorner {
        let mut theta = angle(op, c);
        let mut alpha = angle(op, p);
        let (turn, gamma) = match self.side {
            Side::Left => {
                if theta < alpha {
                    theta += TAU;
                }
                (theta - alpha - FRAC_PI_2, FRAC_PI_2)
            }
            Side::Right => {
                if alpha < theta {
                    alpha += TAU;
                }
                (alpha - theta - FRAC_PI_2, -FRAC_PI_2)
            }
        };
        LineCorner {
            turn,
            back: theta + gamma,
            aside: alpha + gamma,
            c,
        }
    }

    /// How a line joins the held move: round an outside corner, cut an inside one, or
    /// run straight on.
    fn line_join(&self, corner: LineCorner, op: [f64; 2], p: [f64; 2]) -> Result<Join, Gouge> {
        let beta = corner.turn;
        let front_arc = self.front_arc();
        let over_round = front_arc.is_some_and(|(_, turn, _)| !self.side.inside(turn));
        let concave = !(-CORNER_ANGLE..=PI + CORNER_ANGLE).contains(&beta)
            || (beta > PI - CORNER_ANGLE && over_round);
        if !concave {
            return Ok(if beta > CORNER_ANGLE {
                Join::Round
            } else {
                Join::Straight
            });
        }
        let cut = match front_arc {
            None => {
                let half_corner = (beta + PI) / 2.0;
                if half_corner == 0.0 {
                    return Err(Gouge::ConcaveCorner("a zero degree inside corner"));
                }
                along(corner.c, corner.back, self.radius / libm::tan(half_corner))
            }
            Some((center, turn, end)) => self.arc_to_line_corner(op, p, center, turn, end)?,
        };
        Ok(Join::Cut(cut))
    }

    /// Takes the tool around the outside corner at `op` to `mid`: an arc about the
    /// corner, or a straight rapid (there is no rapid arc); nothing else is held.
    fn round_corner(
        &mut self,
        step: &Programmed,
        op: [f64; 2],
        mid: [f64; 2],
        out: &mut Vec<Released>,
    ) {
        let end = self.corner_end(&step.end, mid);
        let (kind, shape) = match step.motion {
            Motion::Rapid => (
                ElementKind::Line,
                Shape::Line {
                    direction: [0.0; 2],
                },
            ),
            Motion::Feed => {
                let arc = self.corner_arc(op);
                let turn = turns(&arc);
                let shape = Shape::Arc {
                    center: op,
                    turn,
                    sweep: 0.0,
                };
                (ElementKind::Arc(arc), shape)
            }
        };
        self.hold(Programmed { kind, ..*step }, end, shape);
        self.release(out);
        self.endpoint = Some(mid);
    }

    /// The arc about the programmed corner `op` that takes the tool around an outside
    /// corner: clockwise for a tool on the left.
    fn corner_arc(&self, op: [f64; 2]) -> Arc {
        Arc {
            plane: self.plane,
            center: op,
            direction: match self.side {
                Side::Left => ArcDirection::Clockwise,
                Side::Right => ArcDirection::CounterClockwise,
            },
            extra_turns: 0,
        }
    }

    /// Where the held arc (about `center`, ending at `end`) meets the offset of the line
    /// from `op` to `p` at an inside corner.
    fn arc_to_line_corner(
        &self,
        op: [f64; 2],
        p: [f64; 2],
        center: [f64; 2],
        turn: i32,
        end: [f64; 2],
    ) -> Result<[f64; 2], Gouge> {
        let r = self.radius;
        let old_radius = distance(center, end);
        let base = angle(op, p);
        let theta = if turn > 0 {
            base + FRAC_PI_2
        } else {
            base - FRAC_PI_2
        };
        let phi = angle(op, center);
        let inside = self.side.inside(turn);
        let programmed_radius = if inside {
            old_radius + r
        } else {
            old_radius - r
        };
        // Distance from the old centre to the programmed line, square to it.
        let d = programmed_radius * libm::cos(theta - phi);
        let l = if inside { d - r } else { d + r } / old_radius;
        if !(-1.0..=1.0).contains(&l) {
            return Err(Gouge::ConcaveCorner(
                "arc to straight motion makes a corner the tool cannot fit in",
            ));
        }
        let swing = if inside == (turn > 0) {
            -libm::acos(l)
        } else {
            libm::acos(l)
        };
        Ok(along(center, swing + theta + PI, old_radius))
    }

    /// An arc after the first move: about the programmed centre, one radius larger or
    /// smaller, joined to the previous move as [`Self::line`] joins.
    fn arc(&mut self, arc: Arc, step: Programmed, out: &mut Vec<Released>) -> Result<(), Gouge> {
        let c = self.point(&self.tool);
        let op = self.point(&self.programmed);
        let p = self.point(&step.end);
        let (center, turn) = (arc.center, turns(&arc));
        let arc_radius = distance(center, p);
        let inside = self.side.inside(turn);
        if inside && arc_radius <= self.radius {
            return Err(Gouge::ToolLargerThanArc {
                radius: self.radius,
            });
        }
        let corner = self.arc_corner(c, op, center, turn);
        match self.arc_join(&corner, center, turn, arc_radius)? {
            Join::Round => {
                self.release(out);
                self.round_corner(&step, op, along(op, corner.aside, self.radius), out);
            }
            Join::Cut(at) => self.move_end_and_release(at, out)?,
            Join::Straight => {
                self.release(out);
                self.endpoint = Some(c);
            }
        }
        let gamma = if inside {
            angle(p, center)
        } else {
            angle(center, p)
        };
        let new_end = along(p, gamma, self.radius);
        let shape = Shape::Arc {
            center,
            turn,
            sweep: find_sweep(op, center, turn, p),
        };
        self.hold(step, self.placed(step.end, new_end), shape);
        Ok(())
    }

    /// The corner between the tool's last move (ending at `c`, about the programmed point
    /// `op`) and an arc about `center` turning `turn`.
    fn arc_corner(&self, c: [f64; 2], op: [f64; 2], center: [f64; 2], turn: i32) -> LineCorner {
        let theta = angle(op, c)
            + match self.side {
                Side::Left => -FRAC_PI_2,
                Side::Right => FRAC_PI_2,
            };
        let delta = angle(op, center);
        let alpha = if turn > 0 {
            delta - FRAC_PI_2
        } else {
            delta + FRAC_PI_2
        };
        let mut beta = match self.side {
            Side::Left => theta - alpha,
            Side::Right => alpha - theta,
        };
        if beta > 1.5 * PI {
            beta -= TAU;
        } else if beta < -FRAC_PI_2 {
            beta += TAU;
        }
        // The tool stands towards the centre when inside the arc, away from it outside.
        let aside = if self.side.inside(turn) {
            delta
        } else {
            delta + PI
        };
        LineCorner {
            turn: beta,
            back: theta,
            aside,
            c,
        }
    }

    /// How an arc joins the held move (see [`Self::line_join`]).
    fn arc_join(
        &self,
        corner: &LineCorner,
        center: [f64; 2],
        turn: i32,
        arc_radius: f64,
    ) -> Result<Join, Gouge> {
        let beta = corner.turn;
        let concave = !(-CORNER_ANGLE..=PI + CORNER_ANGLE).contains(&beta)
            || ((beta - PI).abs() < CORNER_ANGLE && !self.side.inside(turn));
        if !concave {
            return Ok(if beta > CORNER_ANGLE {
                Join::Round
            } else {
                Join::Straight
            });
        }
        let cut = match self.front_arc() {
            None => self.line_to_arc_corner(beta, corner.back, center, turn, arc_radius)?,
            Some((old_center, old_turn, old_end)) => {
                self.arc_to_arc_corner(center, turn, arc_radius, old_center, old_turn, old_end)?
            }
        };
        Ok(Join::Cut(cut))
    }

    /// Where the held line meets the offset arc at an inside corner.
    fn line_to_arc_corner(
        &self,
        beta: f64,
        theta: f64,
        center: [f64; 2],
        turn: i32,
        arc_radius: f64,
    ) -> Result<[f64; 2], Gouge> {
        let r = self.radius;
        let across = arc_radius * libm::sin(beta - FRAC_PI_2);
        let (from_center, toward) = match self.side.inside(turn) {
            true => (arc_radius - r, across + r),
            false => (arc_radius + r, across - r),
        };
        let l = toward / from_center;
        if !(-1.0..=1.0).contains(&l) {
            return Err(Gouge::ConcaveCorner(
                "the arc in the corner cannot be reached without gouging",
            ));
        }
        let swing = libm::asin(l);
        let direction = match (self.side.inside(turn), turn > 0) {
            (true, true) => theta + swing,
            (true, false) => theta - swing,
            (false, true) => theta + PI - swing,
            (false, false) => theta + PI + swing,
        };
        Ok(along(center, direction, from_center))
    }

    /// Where the held arc meets the offset of the next arc at an inside corner.
    fn arc_to_arc_corner(
        &self,
        center: [f64; 2],
        turn: i32,
        arc_radius: f64,
        old_center: [f64; 2],
        old_turn: i32,
        old_end: [f64; 2],
    ) -> Result<[f64; 2], Gouge> {
        let old_radius = distance(old_center, old_end);
        let new_radius = match self.side.inside(turn) {
            true => arc_radius - self.radius,
            false => arc_radius + self.radius,
        };
        let between = distance(old_center, center);
        if old_radius == 0.0 || between == 0.0 {
            return Err(Gouge::SameCentre);
        }
        let cos = (old_radius * old_radius + between * between - new_radius * new_radius)
            / (2.0 * old_radius * between);
        if !(-1.0..=1.0).contains(&cos) {
            return Err(Gouge::ConcaveCorner(
                "arc to arc motion makes a corner the tool cannot fit in",
            ));
        }
        let pullback = libm::acos(cos);
        let toward = angle(old_center, center);
        let direction = if self.side.inside(old_turn) == (turn > 0) {
            toward + pullback
        } else {
            toward - pullback
        };
        Ok(along(old_center, direction, old_radius))
    }

    /// The first held move if it is an arc: centre, turns and end in the plane.
    fn front_arc(&self) -> Option<([f64; 2], i32, [f64; 2])> {
        match self.held.first() {
            Some(Held::Move(HeldMove {
                shape: Shape::Arc { center, turn, .. },
                end,
                ..
            })) => Some((*center, *turn, self.point(end))),
            _ => None,
        }
    }

    /// Holds a move of the tool to `end`; the tool and the programmed point move on.
    fn hold(&mut self, step: Programmed, end: Position, shape: Shape) {
        self.held.push(Held::Move(HeldMove {
            motion: step.motion,
            end,
            feed: step.feed,
            span: step.span,
            shape,
        }));
        self.tool = end;
        self.programmed = step.end;
        self.first_move = false;
    }

    /// Every held move ends at `to` (the last one's end moved into a corner) and all is
    /// released; a move turned back or an arc swept further than it was is a gouge.
    fn move_end_and_release(&mut self, to: [f64; 2], out: &mut Vec<Released>) -> Result<(), Gouge> {
        if self.held.is_empty() {
            return Ok(());
        }
        let endpoint = self.endpoint;
        let slack = self.sweep_slack;
        let (a, b, _) = self.plane.axes();
        for held in &mut self.held {
            let Held::Move(m) = held else { continue };
            match m.shape {
                Shape::Arc {
                    center,
                    turn,
                    sweep,
                } => {
                    if let Some(start) = endpoint {
                        let new_sweep = find_sweep(start, center, turn, to);
                        if sweep != 0.0 && new_sweep.abs() > sweep.abs() + slack {
                            return Err(Gouge::ConcaveCorner(
                                "the arc in the corner cannot be reached without gouging",
                            ));
                        }
                    }
                }
                Shape::Line { direction } => {
                    if let Some(start) = endpoint {
                        let dot =
                            direction[0] * (to[0] - start[0]) + direction[1] * (to[1] - start[1]);
                        if dot < 0.0 {
                            return Err(Gouge::ConcaveCorner(
                                "the straight move into the corner would run backwards",
                            ));
                        }
                    }
                }
            }
            m.end[a.index()] = to[0];
            m.end[b.index()] = to[1];
        }
        self.release(out);
        self.endpoint = Some(to);
        Ok(())
    }

    /// A point of the nose radius' centre as the machine's tool point.
    fn nosed(&self, p: [f64; 2]) -> [f64; 2] {
        [p[0] + self.nose_offset[0], p[1] + self.nose_offset[1]]
    }

    /// Releases everything held, in order; the start of every move is the end of the one
    /// before.
    fn release(&mut self, out: &mut Vec<Released>) {
        self.endpoint = None;
        for held in std::mem::take(&mut self.held) {
            match held {
                Held::Event(kind, line) => out.push(Released::Event(kind, line)),
                Held::Move(m) => {
                    let end = self.placed(m.end, self.nosed(self.point(&m.end)));
                    let start = std::mem::replace(&mut self.released_at, end);
                    let kind = match m.shape {
                        Shape::Line { .. } => ElementKind::Line,
                        Shape::Arc { center, turn, .. } => ElementKind::Arc(Arc {
                            plane: self.plane,
                            center: self.nosed(center),
                            direction: if turn > 0 {
                                ArcDirection::CounterClockwise
                            } else {
                                ArcDirection::Clockwise
                            },
                            extra_turns: turn.unsigned_abs().saturating_sub(1),
                        }),
                    };
                    if start == end && kind == ElementKind::Line {
                        continue;
                    }
                    let element = Element {
                        kind,
                        start,
                        end,
                        feed: m.feed,
                        span: m.span,
                    };
                    out.push(Released::Element(m.motion, element));
                }
            }
        }
    }
}

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The turns of an arc as rs274 counts them: ±(1 + extra turns), positive
/// counter-clockwise.
fn turns(arc: &Arc) -> i32 {
    let n = i32::try_from(arc.extra_turns).unwrap_or(i32::MAX - 1) + 1;
    match arc.direction {
        ArcDirection::CounterClockwise => n,
        ArcDirection::Clockwise => -n,
    }
}

/// The direction from `from` to `to`, radians.
fn angle(from: [f64; 2], to: [f64; 2]) -> f64 {
    libm::atan2(to[1] - from[1], to[0] - from[0])
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    libm::hypot(b[0] - a[0], b[1] - a[1])
}

/// The point `length` from `from` in direction `angle`.
fn along(from: [f64; 2], angle: f64, length: f64) -> [f64; 2] {
    let (sin, cos) = libm::sincos(angle);
    [from[0] + length * cos, from[1] + length * sin]
}

/// The signed angle an arc about `center` sweeps from `start` to `end` in `turn` turns
/// (positive counter-clockwise; a coincident start and end sweeps a whole turn).
fn find_sweep(start: [f64; 2], center: [f64; 2], turn: i32, end: [f64; 2]) -> f64 {
    if turn == 0 {
        return 0.0;
    }
    let mut a = angle(center, start);
    let mut b = angle(center, end);
    if turn > 0 {
        if b <= a {
            b += TAU;
        }
        b - a + f64::from(turn - 1) * TAU
    } else {
        if a <= b {
            a += TAU;
        }
        b - a + f64::from(turn + 1) * TAU
    }
}
