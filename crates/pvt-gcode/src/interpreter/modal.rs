//! The modal state a block leaves for the next, gathered in one struct ([`Modal`]), and
//! M70–M73, which save it, invalidate the saved copy, restore it, and restore it when the
//! subroutine that saved it returns.
//!
//! Owns what LinuxCNC's `save_settings` records (its active G codes, M codes and
//! settings: plane, cutter compensation side, units, distance, feed mode, coordinate
//! system, tool length offset on or off, retract mode, path control with P and Q, spindle
//! speed mode, arc distance, lathe diameter mode, G92 applied; F, S; spindle, mist and
//! flood) and how `restore_settings` brings it back: a block of the saved G20/G21 first,
//! then one block of the F, S and G codes that differ (F with one decimal and S with none,
//! as rs274 writes them), then the M codes that differ, each block run as a program block
//! would be, so a restore does exactly what those blocks would. One saved copy per call
//! level, cleared when a subroutine is entered. It must not read words (that is
//! [`crate::request`]).

use pvt_core::{PathControl, Plane, SpindleState, Units};

use super::{Flow, Interpreter};
use crate::block::{Block, Word};
use crate::codes::{Context, Distance, FeedMode, MotionMode};
use crate::diagnostic::{span, GcodeDiagnostic};

/// The feed in effect: the number an F word gave (or 0 where G94/G95 reset it) and the
/// units in force when it was set, which it keeps: LinuxCNC converts a feed into machine
/// units when it is set, so `G20 F6` (F before the units of its block) is 6 mm/min after
/// G21, and `G21 F254` then `G20` still feeds at 254 mm/min.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Feed {
    /// The number as written.
    pub written: f64,
    /// The units in force when it was set.
    pub units: Units,
    /// The code that set it to 0 (G94, G95), when that set it.
    pub reset_by: Option<&'static str>,
}

/// G90.1/G91.1, incremental by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ArcCenters(pub Distance);

impl Default for ArcCenters {
    fn default() -> Self {
        ArcCenters(Distance::Incremental)
    }
}

/// The modal state RS274NGC keeps between blocks (the part pvtc uses).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Modal {
    pub motion: Option<MotionMode>,
    pub plane: Plane,
    pub units: Units,
    pub distance: Distance,
    pub arc_centers: ArcCenters,
    pub feed_mode: FeedMode,
    /// G61, G61.1 or G64 with its P and Q, program units as written.
    pub path: PathControl,
    /// G7: X words are diameters.
    pub diameter: bool,
    /// Work coordinate system, 0 (G54) … 8 (G59.3).
    pub coord_system: usize,
    /// The F in force; `None` before any F.
    pub feed: Option<Feed>,
    /// The last S number (`#<_rpm>`).
    pub speed: f64,
    /// The spindle as the last M3/M4/M5 (or a cycle) left it.
    pub spindle: SpindleState,
    /// M7 is on.
    pub mist: bool,
    /// M8 is on.
    pub flood: bool,
    /// G96 (constant surface speed) is in effect: S is a surface speed, not rpm.
    pub surface_speed: bool,
    /// G99 (the default): a canned cycle returns to R; G98: to the initial level.
    pub retract_to_r: bool,
}

impl Default for Modal {
    /// G17 G21 G90 G91.1 G94 G64 G54 G8 G97 G99, spindle and coolant off, no feed.
    fn default() -> Self {
        Modal {
            motion: None,
            plane: Plane::XY,
            units: Units::Millimetre,
            distance: Distance::Absolute,
            arc_centers: ArcCenters::default(),
            feed_mode: FeedMode::PerMinute,
            path: PathControl::Continuous {
                tolerance: 0.0,
                naive_cam_tolerance: 0.0,
            },
            diameter: false,
            coord_system: 0,
            feed: None,
            speed: 0.0,
            spindle: SpindleState::Off,
            mist: false,
            flood: false,
            surface_speed: false,
            retract_to_r: true,
        }
    }
}

/// What M70/M73 saved, as LinuxCNC records it: each modal group's code (tenths of its
/// number), F, S, P, Q, and the spindle and coolant M codes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Saved {
    /// The units' code (G20, G21), restored first.
    units: u32,
    /// The other groups' codes, in LinuxCNC's group order.
    groups: [u32; 11],
    /// The path control code (G61, G61.1, G64).
    control: u32,
    feed: f64,
    speed: f64,
    tolerance: f64,
    naive_cam_tolerance: f64,
    /// M3, M4 or M5.
    spindle: u32,
    /// LinuxCNC's mist slot: 7 (mist on), 9 (both off) or none (flood alone on).
    mist: Option<u32>,
    /// 8 while flood is on.
    flood: Option<u32>,
}

/// The saved state of one call level.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    saved: Saved,
    /// The copy is valid (M70 or M73 since the last M71).
    valid: bool,
    /// M73: restore it when the subroutine returns.
    restore_on_return: bool,
}

impl Interpreter<'_> {
    /// M70, M71, M72, M73 (`code`, the word `word`).
    pub(super) fn modal_context(&mut self, code: Context, word: Word, line: u32) -> Flow {
        let level = self.frames.len().saturating_sub(1);
        match code {
            Context::Save | Context::SaveAndRestoreOnReturn => {
                let restore_on_return = code == Context::SaveAndRestoreOnReturn && level > 0;
                self.frames[level] = Some(Frame {
                    saved: self.active_codes(),
                    valid: true,
                    restore_on_return,
                });
            }
            Context::Invalidate => {
                if let Some(frame) = self.frames[level].as_mut() {
                    frame.valid = false;
                }
            }
            Context::Restore => match self.frames[level].filter(|f| f.valid) {
                Some(frame) => self.restore(frame.saved, word, line),
                None => self.push(GcodeDiagnostic::NoSavedState {
                    span: span(word.span()),
                }),
            },
        }
        Flow::Continue
    }

    /// A subroutine is entered: its level has no saved state yet.
    pub(crate) fn enter_call(&mut self) {
        self.frames.push(None);
    }

    /// A subroutine returns (its call at `at`, on line `line`): the state M73 saved in
    /// it is restored.
    pub(crate) fn leave_call(&mut self, at: std::ops::Range<usize>, line: u32) {
        let Some(frame) = self.frames.pop().flatten() else {
            return;
        };
        if frame.valid && frame.restore_on_return && !self.frames.is_empty() {
            let word = Word {
                letter: b'M',
                value: 73.0,
                start: at.start,
                end: at.end,
            };
            self.restore(frame.saved, word, line);
        }
    }

    /// The codes M70 records of the state now.
    fn active_codes(&self) -> Saved {
        let m = &self.modal;
        let (control, tolerance, naive_cam_tolerance) = match m.path {
            PathControl::ExactPath => (610, 0.0, 0.0),
            PathControl::ExactStop => (611, 0.0, 0.0),
            PathControl::Continuous {
                tolerance,
                naive_cam_tolerance,
            } => (640, tolerance, naive_cam_tolerance),
        };
        let plane = match m.plane {
            Plane::XY => 170,
            Plane::ZX => 180,
            Plane::YZ => 190,
        };
        let cutter = self.compensation_code();
        let distance = |d: Distance, absolute: u32, incremental: u32| match d {
            Distance::Absolute => absolute,
            Distance::Incremental => incremental,
        };
        let feed_mode = match m.feed_mode {
            FeedMode::InverseTime => 930,
            FeedMode::PerMinute => 940,
            FeedMode::PerRevolution => 950,
        };
        let coord = match m.coord_system {
            s @ 0..=5 => 540 + 10 * s as u32,
            s => 585 + s as u32,
        };
        let tool = match self.tool.offset.iter().any(|v| *v != 0.0) {
            true => 430,
            false => 490,
        };
        let groups = [
            plane,
            cutter,
            distance(m.distance, 900, 910),
            feed_mode,
            coord,
            tool,
            if m.retract_to_r { 990 } else { 980 },
            if m.surface_speed { 960 } else { 970 },
            distance(m.arc_centers.0, 901, 911),
            if m.diameter { 70 } else { 80 },
            if self.g92.iter().any(|v| *v != 0.0) {
                923
            } else {
                922
            },
        ];
        Saved {
            units: if m.units == Units::Inch { 200 } else { 210 },
            groups,
            control,
            feed: m.feed.map_or(0.0, |f| f.written),
            speed: m.speed,
            tolerance,
            naive_cam_tolerance,
            spindle: match m.spindle {
                SpindleState::Clockwise => 3,
                SpindleState::CounterClockwise => 4,
                SpindleState::Off => 5,
            },
            mist: match (m.mist, m.flood) {
                (true, _) => Some(7),
                (false, true) => None,
                (false, false) => Some(9),
            },
            flood: m.flood.then_some(8),
        }
    }

    /// Brings `saved` back as rs274's `restore_settings` does: the blocks that set what
    /// differs, run at `word` (M72, or the call M73 restores after) on `line`.
    fn restore(&mut self, saved: Saved, word: Word, line: u32) {
        let now = self.active_codes();
        let code = |letter: u8, tenths: u32| (letter, f64::from(tenths) / 10.0);
        if now.units != saved.units {
            self.run_restore_block(&[code(b'G', saved.units)], word, line);
        }
        let now = self.active_codes();
        let mut words = Vec::new();
        if now.feed != saved.feed {
            words.push((b'F', (saved.feed * 10.0).round() / 10.0));
        }
        if now.speed != saved.speed {
            words.push((b'S', saved.speed.round()));
        }
        for (was, is) in saved.groups.iter().zip(now.groups) {
            if *was != is {
                words.push(code(b'G', *was));
            }
        }
        let tolerances_differ = now.tolerance != saved.tolerance
            || now.naive_cam_tolerance != saved.naive_cam_tolerance;
        match saved.control {
            640 if now.control != 640 || tolerances_differ => {
                words.push(code(b'G', 640));
                // `P%f Q%f`: six decimals.
                let written = |v: f64| (v * 1e6).round() / 1e6;
                words.push((b'P', written(saved.tolerance)));
                words.push((b'Q', written(saved.naive_cam_tolerance)));
            }
            control if control != now.control => words.push(code(b'G', control)),
            _ => {}
        }
        let m_codes = [
            (saved.spindle != now.spindle).then_some(saved.spindle),
            saved.mist.filter(|_| saved.mist != now.mist),
            saved.flood.filter(|_| saved.flood != now.flood),
        ];
        let mut m_codes = m_codes.into_iter().flatten();
        // rs274 writes the first M code on the line of the G codes.
        if let Some(m) = m_codes.next() {
            words.push((b'M', f64::from(m)));
        }
        if !words.is_empty() {
            self.run_restore_block(&words, word, line);
        }
        for m in m_codes {
            self.run_restore_block(&[(b'M', f64::from(m))], word, line);
        }
    }

    /// Runs a block of `words` (letter, value) written at `word`, on `line`.
    fn run_restore_block(&mut self, words: &[(u8, f64)], word: Word, line: u32) {
        let block = Block {
            start: word.start,
            end: word.end,
            line,
            words: words
                .iter()
                .map(|&(letter, value)| Word {
                    letter,
                    value,
                    ..word
                })
                .collect(),
            ..Block::default()
        };
        self.execute(&block);
    }
}
