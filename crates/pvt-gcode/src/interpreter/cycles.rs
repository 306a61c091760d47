//! Canned cycles: G73 and G81…G89 expanded into rapids, feeds, dwells and spindle events
//! exactly as LinuxCNC's interpreter (`rs274`) expands them.
//!
//! Owns the cycle levels (R, the bottom, the initial level that G98 returns to, G91's
//! increments and L repeats), what a continuation block (only X/Y) reuses, and each
//! cycle's sequence of moves. The levels are computed in program units along the plane's
//! normal axis (Z in G17, Y in G18, X in G19), as LinuxCNC does, so peck depths step
//! identically. It must not read words (that is [`crate::request`]) nor change modes.

use pvt_core::{Motion, PathControl, Plane, SpindleState, Units};

use super::motion::polar_point;
use super::Interpreter;
use crate::block::{cover, Block};
use crate::codes::{Cycle, Distance, FeedMode, NonModal};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;
use pvt_core::EventKind;

/// The most pecks (holes, for cycles without Q) one block may make: a smaller Q or a
/// larger L is refused, never a hang.
const MAX_PECKS: f64 = 100_000.0;

/// What LinuxCNC keeps between cycle blocks, program units.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CycleMemory {
    /// The cycle of the last cycle block; `None` after any other motion mode.
    pub code: Option<Cycle>,
    /// R and the bottom (the normal axis word) as written, reused by continuation blocks.
    pub r: f64,
    pub bottom: f64,
    pub p: Option<f64>,
    pub q: Option<f64>,
    /// The level of the normal axis when the cycles began (any motion code other than a
    /// cycle ends them): G98 returns to it, and G91's R counts from it.
    pub initial_level: Option<f64>,
}

/// Program coordinates of one cycle point: in-plane first, second, normal.
type Point = [f64; 3];

impl Interpreter<'_> {
    /// Runs a cycle block: the cycle at each position of the block, L times.
    pub(super) fn cycle_move(&mut self, cycle: Cycle, request: &Request, block: &Block) {
        match self.cycle_plan(cycle, request) {
            Ok(plan) => self.run_cycle(cycle, &plan, request, block),
            Err(detail) => {
                let words = request
                    .motion
                    .iter()
                    .map(|(_, w)| w)
                    .chain(request.axis_words())
                    .chain(&request.radius);
                let at = cover(words).unwrap_or_else(|| block.span());
                self.push(GcodeDiagnostic::Cycle {
                    code: cycle.name(),
                    detail,
                    span: span(at),
                });
                self.cycle.code = None;
            }
        }
    }

    /// The block's levels and positions, checked as LinuxCNC checks them.
    fn cycle_plan(&mut self, cycle: Cycle, request: &Request) -> Result<Plan, String> {
        if self.modal.feed_mode == FeedMode::InverseTime {
            return Err("cannot run in inverse time feed mode (G93)".into());
        }
        if matches!(request.non_modal, Some((NonModal::MachineCoords, _))) {
            return Err("G53 moves only with G0 or G1".into());
        }
        if let Some(w) = request.axes[3..].iter().flatten().next() {
            return Err(format!("{} cannot be given in a canned cycle", w.name()));
        }
        let same = self.cycle.code == Some(cycle);
        let (a, b, c) = self.modal.plane.axes();
        let normal = (b'X' + c.index() as u8) as char;
        let r_word = match (request.radius, same) {
            (Some(w), _) => w.value,
            (None, true) => self.cycle.r,
            (None, false) => return Err("no R level (the retract plane)".into()),
        };
        let bottom_word = match (request.axes[c.index()], same) {
            (Some(w), _) => w.value,
            (None, true) => self.cycle.bottom,
            (None, false) => return Err(format!("no {normal} word (the bottom of the hole)")),
        };
        let repeats = match request.l {
            None => 1,
            Some(l) if l.value.fract() == 0.0 && (1.0..=10_000.0).contains(&l.value) => {
                l.value as u32
            }
            Some(l) => {
                return Err(format!(
                    "{}: the repeats L are a whole number from 1 to 10000",
                    l.name()
                ))
            }
        };
        let p = match (request.p, self.cycle.p) {
            (Some(p), _) if p.value < 0.0 => {
                return Err(format!("{}: a dwell must not be negative", p.name()))
            }
            (Some(p), _) => Some(p.value),
            (None, kept) => kept.filter(|_| same),
        };
        let q = match (request.q, self.cycle.q) {
            (Some(q), _) if q.value <= 0.0 => {
                return Err(format!("{}: the peck depth Q must be positive", q.name()))
            }
            (Some(q), _) => Some(q.value),
            (None, kept) => kept.filter(|_| same),
        };
        let needs_p = matches!(
            cycle,
            Cycle::DrillDwell | Cycle::BoreStop | Cycle::BoreManual | Cycle::BoreDwell
        );
        if needs_p && p.is_none() {
            return Err("no P word (the dwell at the bottom, seconds)".into());
        }
        if matches!(cycle, Cycle::ChipBreak | Cycle::Peck) && q.is_none() {
            return Err("no Q word (the peck depth)".into());
        }
        match cycle {
            Cycle::Tap if self.modal.spindle != SpindleState::Clockwise => {
                return Err("tapping needs the spindle turning clockwise (M3)".into())
            }
            Cycle::BoreStop | Cycle::BackBore | Cycle::BoreManual
                if self.modal.spindle == SpindleState::Off =>
            {
                return Err("needs the spindle turning (M3 or M4)".into())
            }
            _ => {}
        }
        let scale = self.scale();
        let here = self.to_program(self.position);
        let program = |i: usize| here[i] / scale;
        let current = [program(a.index()), program(b.index()), program(c.index())];
        let initial = *self.cycle.initial_level.get_or_insert(current[2]);
        // LinuxCNC starts from the initial level under G98, from where the tool is under
        // G99; G91's R counts from the initial level in both.
        let start_level = if self.modal.retract_to_r {
            current[2]
        } else {
            initial
        };
        let word = |i: usize| request.axes[i].map(|w| w.value);
        let polar = self.cycle_polar(request)?;
        let (start, step, r, bottom) = match self.modal.distance {
            Distance::Absolute => {
                let start = [
                    word(a.index()).unwrap_or(current[0]),
                    word(b.index()).unwrap_or(current[1]),
                ];
                let start = match polar {
                    Some(words) => polar_point(start, words, Distance::Absolute),
                    None => start,
                };
                (start, [0.0, 0.0], r_word, bottom_word)
            }
            Distance::Incremental => {
                let r = r_word + initial;
                let step = [
                    word(a.index()).unwrap_or(0.0),
                    word(b.index()).unwrap_or(0.0),
                ];
                ([current[0], current[1]], step, r, r + bottom_word)
            }
        };
        let far = |v: f64| !v.is_finite() || v.abs() > 1e9;
        let polar_words = polar.into_iter().flatten().flatten();
        if far(r) || far(bottom) || start.iter().chain(&step).any(|&v| far(v)) {
            return Err("a level or position is out of range (beyond 1e9)".into());
        }
        if polar_words.into_iter().any(far) {
            return Err("a level or position is out of range (beyond 1e9)".into());
        }
        let pecks = match q.filter(|_| matches!(cycle, Cycle::ChipBreak | Cycle::Peck)) {
            Some(q) => ((r - bottom) / q).max(1.0),
            None => 1.0,
        };
        if pecks * f64::from(repeats) > MAX_PECKS {
            return Err(format!(
                "more than {MAX_PECKS} pecks in one block (L{repeats}, from R{r} to \
                 {normal}{bottom} by Q{})",
                q.unwrap_or(0.0)
            ));
        }
        if r < bottom {
            return Err(format!(
                "the R level {r} is below the bottom {normal}{bottom}"
            ));
        }
        let middle = if cycle == Cycle::BackBore {
            let Some(k) = request.offsets[c.index()] else {
                let letter = (b'I' + c.index() as u8) as char;
                return Err(format!("no {letter} word (the top of the back bore)"));
            };
            let shift = [
                request.offsets[a.index()].map_or(0.0, |w| w.value),
                request.offsets[b.index()].map_or(0.0, |w| w.value),
            ];
            let middle = match self.modal.distance {
                Distance::Absolute => k.value,
                Distance::Incremental => bottom + k.value,
            };
            Some((middle, shift))
        } else {
            None
        };
        self.cycle.code = Some(cycle);
        self.cycle.r = r_word;
        self.cycle.bottom = bottom_word;
        self.cycle.p = p;
        self.cycle.q = q;
        Ok(Plan {
            current,
            start_level,
            start,
            step,
            r,
            bottom,
            repeats,
            p: p.unwrap_or(0.0),
            q: q.unwrap_or(0.0),
            middle,
            polar: polar.filter(|_| self.modal.distance == Distance::Incremental),
        })
    }

    /// The block's polar words (`@`, `^`), which place its holes in G17 instead of X
    /// and Y; `None` without them.
    fn cycle_polar(&self, request: &Request) -> Result<Option<[Option<f64>; 2]>, String> {
        let words = request.polar.map(|w| w.map(|w| w.value));
        if words.iter().all(Option::is_none) {
            return Ok(None);
        }
        if request.axes[0].is_some() || request.axes[1].is_some() {
            return Err("polar words (@, ^) replace X and Y; give one or the other".into());
        }
        if self.modal.plane != Plane::XY {
            return Err("polar words (@, ^) work in G17 only".into());
        }
        Ok(Some(words))
    }

    fn run_cycle(&mut self, cycle: Cycle, plan: &Plan, request: &Request, block: &Block) {
        let r = plan.r;
        let mut old = plan.start_level;
        let [mut x, mut y] = plan.start;
        if old < r {
            let at = [plan.current[0], plan.current[1], r];
            if !self.cycle_line(Motion::Rapid, at, request, block) {
                return;
            }
            old = r;
        }
        let clear = if self.modal.retract_to_r { r } else { old };
        // The holes run in exact path mode (G61), as LinuxCNC runs them.
        let saved = self.modal.path;
        let switch = saved != PathControl::ExactPath;
        if switch {
            self.hand_on_control(PathControl::ExactPath);
        }
        for _ in 0..plan.repeats {
            [x, y] = plan.next_hole([x, y]);
            let ok = self.cycle_line(Motion::Rapid, [x, y, old], request, block)
                && (old == r || self.cycle_line(Motion::Rapid, [x, y, r], request, block))
                && self.cycle_body(cycle, plan, [x, y], clear, request, block);
            if !ok {
                break;
            }
            old = clear;
        }
        if switch {
            self.hand_on_control(saved);
        }
    }

    /// One hole at `at`, from R to the bottom and back to `clear`; false after an error.
    fn cycle_body(
        &mut self,
        cycle: Cycle,
        plan: &Plan,
        at: [f64; 2],
        clear: f64,
        request: &Request,
        block: &Block,
    ) -> bool {
        let [x, y] = at;
        let (r, bottom) = (plan.r, plan.bottom);
        let line = block.line;
        let direction = self.modal.spindle;
        let feed = |me: &mut Self, z: f64| me.cycle_line(Motion::Feed, [x, y, z], request, block);
        let rapid = |me: &mut Self, z: f64| me.cycle_line(Motion::Rapid, [x, y, z], request, block);
        match cycle {
            Cycle::Drill => feed(self, bottom) && rapid(self, clear),
            Cycle::DrillDwell => {
                let ok = feed(self, bottom);
                self.event(EventKind::Dwell { seconds: plan.p }, line);
                ok && rapid(self, clear)
            }
            Cycle::ChipBreak | Cycle::Peck => {
                let delta = plan.q;
                let back = match self.modal.units {
                    Units::Inch => 0.01,
                    Units::Millimetre => 0.254,
                };
                let mut depth = r - delta;
                while depth > bottom {
                    if !feed(self, depth) {
                        return false;
                    }
                    if cycle == Cycle::Peck && !rapid(self, r) {
                        return false;
                    }
                    if !rapid(self, depth + back) {
                        return false;
                    }
                    depth -= delta;
                }
                feed(self, bottom) && rapid(self, clear)
            }
            Cycle::Tap => {
                let spindle = |me: &mut Self, state| me.event(EventKind::Spindle { state }, line);
                if !feed(self, bottom) {
                    return false;
                }
                spindle(self, SpindleState::Off);
                spindle(self, SpindleState::CounterClockwise);
                // rs274 dwells P (0 without one) with the spindle reversed.
                self.event(EventKind::Dwell { seconds: plan.p }, line);
                let ok = feed(self, clear);
                spindle(self, SpindleState::Off);
                spindle(self, SpindleState::Clockwise);
                ok
            }
            Cycle::Bore => feed(self, bottom) && feed(self, r) && rapid(self, clear),
            Cycle::BoreStop | Cycle::BoreManual => {
                if !feed(self, bottom) {
                    return false;
                }
                self.event(EventKind::Dwell { seconds: plan.p }, line);
                let off = SpindleState::Off;
                self.event(EventKind::Spindle { state: off }, line);
                let ok = if cycle == Cycle::BoreStop {
                    rapid(self, clear)
                } else {
                    self.event(EventKind::Pause { optional: false }, line);
                    true
                };
                self.event(EventKind::Spindle { state: direction }, line);
                ok
            }
            Cycle::BoreDwell => {
                let ok = feed(self, bottom);
                self.event(EventKind::Dwell { seconds: plan.p }, line);
                ok && feed(self, clear)
            }
            Cycle::BackBore => {
                let Some((middle, [i, j])) = plan.middle else {
                    return false;
                };
                let (ox, oy) = (x + i, y + j);
                let off = |me: &mut Self| {
                    me.event(
                        EventKind::Spindle {
                            state: SpindleState::Off,
                        },
                        line,
                    )
                };
                let on = |me: &mut Self| me.event(EventKind::Spindle { state: direction }, line);
                let go = |me: &mut Self, motion, p: Point| me.cycle_line(motion, p, request, block);
                if !go(self, Motion::Rapid, [ox, oy, r]) {
                    return false;
                }
                off(self);
                let ok = go(self, Motion::Rapid, [ox, oy, bottom])
                    && go(self, Motion::Rapid, [x, y, bottom]);
                on(self);
                let ok = ok
                    && go(self, Motion::Feed, [x, y, middle])
                    && go(self, Motion::Feed, [x, y, bottom]);
                off(self);
                let ok = ok
                    && go(self, Motion::Rapid, [ox, oy, bottom])
                    && go(self, Motion::Rapid, [ox, oy, clear])
                    && go(self, Motion::Rapid, [x, y, clear]);
                on(self);
                ok
            }
        }
    }

    /// A straight move of a cycle to program point `p` (plane axes), at rest at its end;
    /// false when a feed move has no feed (reported once).
    fn cycle_line(&mut self, motion: Motion, p: Point, request: &Request, block: &Block) -> bool {
        let (a, b, c) = self.modal.plane.axes();
        let scale = self.scale();
        let mut end = self.position;
        if self.rotation() != 0.0 {
            let here = self.to_program(self.position);
            let mut program = here;
            for (k, axis) in [a, b, c].into_iter().enumerate() {
                program[axis.index()] = p[k] * scale;
            }
            // Where X and Y stay in the program they stay exactly in the machine.
            let placed = match program[..2] == here[..2] {
                true => self.position,
                false => self.to_machine(program),
            };
            for i in [0, 1, a.index(), b.index(), c.index()] {
                end[i] = match i < 2 {
                    true => placed[i],
                    false => program[i] + self.offset(i),
                };
            }
        } else {
            for (k, axis) in [a, b, c].into_iter().enumerate() {
                let i = axis.index();
                end[i] = p[k] * scale + self.offset(i);
            }
        }
        let start = self.machine_position();
        let feed = match motion {
            Motion::Rapid => Some(self.rapid_rate()),
            Motion::Feed => self.feed_rate(request, block, || 0.0),
        };
        let Some(feed) = feed else { return false };
        self.position = end;
        if !super::motion::no_move(&start, &end) {
            self.straight(motion, start, end, feed, block);
        }
        self.end_contour();
        true
    }
}

/// One cycle block's levels and positions, program units.
struct Plan {
    /// The position before the block: first, second, normal.
    current: Point,
    /// The level the first move of the block starts from (see [`CycleMemory`]).
    start_level: f64,
    /// The first hole (before G91's first step), and the step between holes.
    start: [f64; 2],
    step: [f64; 2],
    r: f64,
    bottom: f64,
    repeats: u32,
    p: f64,
    q: f64,
    /// G87: the top of the back bore and the I/J shift of the retract position.
    middle: Option<(f64, [f64; 2])>,
    /// The polar words (`@`, `^`) of a G17 block under G91, which step from hole to hole.
    polar: Option<[Option<f64>; 2]>,
}

impl Plan {
    /// The hole after the one at `at`: one step on (none in G90), or under G91 with polar
    /// words `@` added to its radius and `^` to its angle.
    fn next_hole(&self, at: [f64; 2]) -> [f64; 2] {
        match self.polar {
            Some(words) => polar_point(at, words, Distance::Incremental),
            None => [at[0] + self.step[0], at[1] + self.step[1]],
        }
    }
}
