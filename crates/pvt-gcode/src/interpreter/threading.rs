//! Spindle-synchronised motion: G33 (a move at K per spindle revolution), G33.1 (rigid
//! tapping), G76 (LinuxCNC's threading cycle) and G95 feeds (units per revolution).
//!
//! Owns the refusal, and the moves planned in its place. A PVT program runs on time, and
//! a spindle-synchronised move follows the spindle's encoder, so each such code is
//! `pvtc::gcode::spindle_sync` unless [`SpindleSync::ProgrammedSpeed`]
//! (`--spindle-rpm-exact`), where the programmed S is taken as exact: a G95 feed is F × S
//! per minute, G33 and G76 passes run at pitch × S (the pitch per revolution along the
//! move), G33.1 taps in at K × S and out at that times I, and a warning says so once. A
//! synchronised move is a contour of its own, at rest at both ends (LinuxCNC waits for
//! the spindle's index before it). G76's passes are LinuxCNC's (`convert_threading_cycle`
//! in `interp_convert.cc`): depths from J to K by J · pass^(1/R), the compound angle Q,
//! H spring passes, E and L tapers. It must not read words (that is [`crate::request`]).

use pvt_core::{Motion, Position, SpindleState};

use super::Interpreter;
use crate::block::{cover, Block, Word};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;
use crate::SpindleSync;

/// The most G76 passes one block may make (a tiny J with a large K); more is refused.
const MAX_PASSES: u32 = 10_000;

/// A G76 block's numbers, program units (I, J, K halved under G7).
#[derive(Debug, Clone, Copy)]
struct ThreadCycle {
    /// Where the cycle starts (X, Z) and where it ends (the block's X, Z).
    start: [f64; 2],
    end: [f64; 2],
    /// +1 for an internal thread (I > 0), −1 for an external one.
    side: f64,
    /// |I|: from the start X to the thread's crest.
    crest: f64,
    /// |J|: the first cut's depth.
    first_cut: f64,
    /// |K|: the thread's depth.
    depth: f64,
    pitch: f64,
    /// tan of the compound angle Q, signed as the passes step along Z.
    slope: f64,
    degression: f64,
    spring_passes: u32,
    /// E: the taper's length along Z, signed as the thread runs; 0 without a taper.
    taper: f64,
    /// L: 1 entry taper, 2 exit taper, 3 both.
    taper_ends: u32,
}

impl Interpreter<'_> {
    /// A spindle-synchronised `code` at `word`: refused unless
    /// [`SpindleSync::ProgrammedSpeed`], where a warning says (once) how it is planned.
    pub(super) fn spindle_sync(&mut self, code: &str, word: std::ops::Range<usize>) {
        match self.options.spindle_sync {
            SpindleSync::Refuse => self.push(GcodeDiagnostic::SpindleSync {
                code: code.to_owned(),
                span: span(word),
            }),
            SpindleSync::ProgrammedSpeed if !self.spindle_sync_warned => {
                self.spindle_sync_warned = true;
                self.warn(GcodeDiagnostic::SpindleRpmExact {
                    code: code.to_owned(),
                    span: span(word),
                });
            }
            SpindleSync::ProgrammedSpeed => {}
        }
    }

    /// True when spindle-synchronised motion is refused: its moves are not made (the
    /// position taken), and nothing more is reported about them.
    pub(super) fn spindle_sync_refused(&self) -> bool {
        self.options.spindle_sync == SpindleSync::Refuse
    }

    /// The feed of a move at `pitch` (program units per revolution) at the programmed S,
    /// output units per second; `None` after reporting why there is none, or when
    /// synchronised motion is refused.
    fn synced_rate(&mut self, pitch: f64, code: &str, at: std::ops::Range<usize>) -> Option<f64> {
        if self.spindle_sync_refused() {
            return None;
        }
        let why = match self.modal.spindle {
            SpindleState::Off => Some("the spindle is not turning (M3 or M4 first)"),
            _ if self.modal.surface_speed => Some("S is a surface speed under G96 (G97 first)"),
            _ if self.modal.speed <= 0.0 => Some("the spindle speed is 0 (an S word first)"),
            _ if !(pitch > 0.0 && pitch.is_finite()) => Some("the pitch must be positive"),
            _ => None,
        };
        if let Some(why) = why {
            self.push(GcodeDiagnostic::Cycle {
                code: code_name(code),
                detail: why.to_owned(),
                span: span(at),
            });
            return None;
        }
        Some(pitch * self.scale() * self.modal.speed / 60.0)
    }

    /// G33: a straight move at K per revolution.
    pub(super) fn thread_move(&mut self, request: &Request, block: &Block) {
        let Some((end, rate)) = self.synced_block("G33", request, block) else {
            return;
        };
        self.synced_line(end, rate, block);
    }

    /// G33.1: rigid tapping to the block's end at K per revolution and back out at that
    /// times I (at least 1), at rest at the bottom (the spindle reverses).
    pub(super) fn rigid_tap(&mut self, request: &Request, block: &Block) {
        let start = self.machine_position();
        let Some((end, rate)) = self.synced_block("G33.1", request, block) else {
            return;
        };
        let out = request.offsets[0].map_or(1.0, |i| i.value.max(1.0));
        self.synced_line(end, rate, block);
        self.synced_line(start, rate.map(|r| r * out), block);
    }

    /// The end and rate (`None`: refused or reported) of a G33 or G33.1 (`code`) block
    /// at its K per revolution; `None` when the block has no end to go to (reported).
    fn synced_block(
        &mut self,
        code: &'static str,
        request: &Request,
        block: &Block,
    ) -> Option<(Position, Option<f64>)> {
        let at = super::motion::move_span(request, block);
        self.spindle_sync(code, at.clone());
        let k = request.offsets[2].map_or(0.0, |k| k.value);
        if request.offsets[2].is_none() && !self.spindle_sync_refused() {
            let word = request.motion.map_or(at.clone(), |(_, w)| w.span());
            self.push(super::missing_at(code, word, "a K word (the pitch)"));
            return None;
        }
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => {
                self.push(diagnostic);
                return None;
            }
        };
        Some((end, self.synced_rate(k, code, at)))
    }

    /// A synchronised straight move to `end` at `rate` (none: not sent, the position
    /// taken), a contour of its own.
    fn synced_line(&mut self, end: Position, rate: Option<f64>, block: &Block) {
        let start = self.machine_position();
        self.position = end;
        let Some(rate) = rate else { return };
        self.end_contour();
        if !super::motion::no_move(&start, &end) {
            self.straight(Motion::Feed, start, end, rate, block);
        }
        self.end_contour();
    }

    /// G76: LinuxCNC's threading cycle from here to the block's X and Z.
    pub(super) fn thread_cycle(&mut self, request: &Request, block: &Block) {
        let at = cover(
            request
                .motion
                .iter()
                .map(|(_, w)| w)
                .chain(request.axis_words()),
        )
        .unwrap_or_else(|| block.span());
        self.spindle_sync("G76", at.clone());
        let cycle = match self.thread_cycle_plan(request) {
            Ok(cycle) => cycle,
            Err(_) if self.spindle_sync_refused() => return,
            Err(detail) => {
                return self.push(GcodeDiagnostic::Cycle {
                    code: "G76",
                    detail,
                    span: span(at),
                })
            }
        };
        let Some(rate) = self.synced_rate(cycle.pitch, "G76", at.clone()) else {
            if let Ok(end) = self.target(request) {
                self.position = end;
            }
            return;
        };
        let taper_pitch = match cycle.taper {
            0.0 => cycle.pitch,
            t => cycle.pitch * libm::hypot(t, cycle.depth) / t.abs(),
        };
        let taper_rate = rate * taper_pitch / cycle.pitch;
        let passes = cycle.depths();
        if passes.len() as u32 > MAX_PASSES {
            let detail = format!("more than {MAX_PASSES} passes (J is too small for K)");
            return self.push(GcodeDiagnostic::Cycle {
                code: "G76",
                detail,
                span: span(at),
            });
        }
        for depth in passes {
            self.thread_pass(&cycle, depth, [rate, taper_rate], block);
        }
        if let Ok(end) = self.target(request) {
            self.rapid_to(end, block);
        }
    }

    /// The block's G76 numbers, checked as LinuxCNC checks them.
    fn thread_cycle_plan(&self, request: &Request) -> Result<ThreadCycle, String> {
        if self.cutter_on() {
            return Err("cannot run with cutter radius compensation on".into());
        }
        let value = |w: Option<Word>| w.map(|w| w.value);
        let [i, j, k] = request.offsets.map(value);
        let halve = |v: f64| if self.modal.diameter { v / 2.0 } else { v };
        let (i, j, k) = (
            halve(i.unwrap_or(0.0)),
            halve(j.unwrap_or(0.0)),
            halve(k.unwrap_or(0.0)),
        );
        if i == 0.0 {
            return Err("I (the thread's offset from the start X) must not be 0".into());
        }
        if j <= 0.0 {
            return Err("J (the first cut's depth) must be greater than 0".into());
        }
        if k <= j {
            return Err("K (the thread's depth) must be greater than J".into());
        }
        let Some(pitch) = value(request.p).filter(|p| *p > 0.0) else {
            return Err("no P word (the pitch), or not positive".into());
        };
        if request.axes[3..].iter().any(Option::is_some) {
            return Err("rotary axes cannot move in a threading cycle".into());
        }
        let scale = self.scale();
        let here = self.to_program(self.position);
        let start = [here[0] / scale, here[2] / scale];
        let end = match self.target(request) {
            Ok(end) => {
                let end = self.to_program(end);
                [end[0] / scale, end[2] / scale]
            }
            Err(_) => return Err("the end point is out of range".into()),
        };
        let away = if end[1] > start[1] { -1.0 } else { 1.0 };
        // Q-1 (LinuxCNC's mark of no angle) is 0.
        let angle = match value(request.q).unwrap_or(0.0) {
            -1.0 => 0.0,
            q => q,
        };
        let taper = value(request.e).unwrap_or(0.0).max(0.0);
        Ok(ThreadCycle {
            start,
            end,
            side: if i > 0.0 { 1.0 } else { -1.0 },
            crest: i.abs(),
            first_cut: j.abs(),
            depth: k.abs(),
            pitch,
            slope: libm::tan(angle.to_radians()) * away,
            degression: value(request.radius).filter(|r| *r >= 1.0).unwrap_or(1.0),
            spring_passes: value(request.h).map_or(0, |h| h.max(0.0) as u32),
            taper: taper * away,
            taper_ends: value(request.l).map_or(0, |l| l.max(0.0) as u32) & 3,
        })
    }

    /// One threading pass `depth` (from the start X) deep: in (rapid, or along the entry
    /// taper), over at the pitch (the exit taper at its own pitch), and out.
    fn thread_pass(&mut self, c: &ThreadCycle, depth: f64, rates: [f64; 2], block: &Block) {
        let full = c.crest + c.depth;
        let x = |d: f64| c.start[0] + c.side * d;
        let shift = (depth - c.crest) * c.slope;
        let (z0, z1) = (c.start[1] - shift, c.end[1] + c.depth * c.slope - shift);
        let [rate, taper_rate] = rates;
        let clear = x(depth - full);
        self.rapid_to(self.program_xz(clear, z0), block);
        let mut path = Vec::new();
        if c.taper != 0.0 && c.taper_ends & 1 != 0 {
            path.push(([x(depth - c.depth), z0], taper_rate));
            path.push(([x(depth), z0 - c.taper], taper_rate));
        } else {
            self.rapid_to(self.program_xz(x(depth), z0), block);
        }
        if c.taper != 0.0 && c.taper_ends & 2 != 0 {
            path.push(([x(depth), z1 + c.taper], rate));
            path.push(([x(depth - c.depth), z1], taper_rate));
        } else {
            path.push(([x(depth), z1], rate));
        }
        self.end_contour();
        for (point, rate) in path {
            let end = self.program_xz(point[0], point[1]);
            let start = self.machine_position();
            self.position = end;
            if !super::motion::no_move(&start, &end) {
                self.straight(Motion::Feed, start, end, rate, block);
            }
        }
        self.end_contour();
        self.rapid_to(self.program_xz(clear, z1), block);
    }
}

impl ThreadCycle {
    /// The depth (from the start X) of every pass: from J, each the first cut times
    /// the pass number to the power 1/R beyond the crest, while short of the full depth;
    /// then the full depth, once and once more per spring pass.
    fn depths(&self) -> Vec<f64> {
        let full = self.crest + self.depth;
        let mut depths = Vec::new();
        let mut depth = self.crest + self.first_cut;
        let mut pass = 1.0f64;
        while depth < full && depths.len() as u32 <= MAX_PASSES {
            depths.push(depth);
            pass += 1.0;
            depth = self.crest + self.first_cut * libm::pow(pass, 1.0 / self.degression);
        }
        for _ in 0..=self.spring_passes.min(MAX_PASSES) {
            depths.push(full);
        }
        depths
    }
}

/// `code` as the `&'static str` the cycle diagnostic names.
fn code_name(code: &str) -> &'static str {
    match code {
        "G33" => "G33",
        "G33.1" => "G33.1",
        "G76" => "G76",
        _ => "G95",
    }
}
