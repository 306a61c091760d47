//! What one block asks for: its words sorted by meaning, conflicts and unknowns reported.
//!
//! Owns the per-block checks that need no modal state (unknown letters and codes,
//! unsupported features, two codes of one modal group, a repeated word); it must not
//! change modal state or produce motion (that is [`crate::interpreter`]).

use pvt_core::{Axis, CoolantState, Plane, SpindleState, Units, AXIS_COUNT};

use crate::block::{Block, Word};
use crate::codes::{
    self, Distance, FeedMode, GCode, MCode, MotionMode, NonModal, PathMode, ToolLength,
};
use crate::diagnostic::{span, GcodeDiagnostic};

/// A program stop (modal group 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// M0 (`false`) or M1 (optional, `true`).
    Pause(bool),
    /// M2/M30.
    End,
}

/// The words of one block, by meaning; each with the word that gave it.
#[derive(Debug, Clone, Default)]
pub(crate) struct Request {
    pub motion: Option<(MotionMode, Word)>,
    pub plane: Option<(Plane, Word)>,
    pub units: Option<(Units, Word)>,
    pub distance: Option<(Distance, Word)>,
    pub stop: Option<(Stop, Word)>,
    pub feed_mode: Option<(FeedMode, Word)>,
    pub path_mode: Option<(PathMode, Word)>,
    pub arc_centers: Option<(Distance, Word)>,
    pub diameter: Option<(bool, Word)>,
    pub coord_system: Option<(usize, Word)>,
    pub non_modal: Option<(NonModal, Word)>,
    pub spindle: Option<(SpindleState, Word)>,
    /// M70…M73 (modal group 7 with M3…M5: one of them per block).
    pub context: Option<(codes::Context, Word)>,
    pub coolant: Option<(CoolantState, Word)>,
    pub tool_change: Option<((), Word)>,
    pub tool_length: Option<(ToolLength, Word)>,
    /// G98 (`false`) or G99 (`true`).
    pub retract: Option<(bool, Word)>,
    /// G96 (`true`) or G97.
    pub surface_speed: Option<(bool, Word)>,
    /// G40, G41, G41.1, G42, G42.1.
    pub cutter_comp: Option<(codes::CutterComp, Word)>,
    /// M48…M53, accepted as state.
    pub overrides: Option<((), Word)>,
    /// M62…M68 (digital and analog I/O).
    pub io: Option<(u16, Word)>,
    /// M100…M199 (user-defined).
    pub user: Option<(u16, Word)>,
    /// E: the analog channel of M66…M68, G76's taper.
    pub e: Option<Word>,
    pub p: Option<Word>,
    pub q: Option<Word>,
    pub l: Option<Word>,
    pub h: Option<Word>,
    pub d: Option<Word>,
    pub s: Option<Word>,
    pub t: Option<Word>,
    /// X Y Z A B C, indexed by [`Axis::index`].
    pub axes: [Option<Word>; AXIS_COUNT],
    /// I J K.
    pub offsets: [Option<Word>; 3],
    /// `@` (polar radius) and `^` (polar angle, degrees).
    pub polar: [Option<Word>; 2],
    pub radius: Option<Word>,
    pub feed: Option<Word>,
    /// The block makes no move: an unsupported code uses its axis words, or its motion
    /// codes conflict (both reported).
    pub no_move: bool,
    /// The block has a G code pvtc does not know: it is skipped whole, so that no mode
    /// drifts, and the motion mode becomes unknown until the next motion code.
    pub unknown_g: bool,
}

impl Request {
    /// Becomes the request of `block`: sorts its words, reporting unknown, unsupported and
    /// conflicting ones. Filled in place, as a request is large and read once per block.
    pub fn read(&mut self, block: &Block, errors: &mut Vec<GcodeDiagnostic>) {
        *self = Request::default();
        let request = self;
        for &word in &block.words {
            match word.letter {
                b'X' | b'Y' | b'Z' => {
                    let slot = &mut request.axes[usize::from(word.letter - b'X')];
                    put_word(slot, word, errors);
                }
                b'A' | b'B' | b'C' => {
                    let slot = &mut request.axes[3 + usize::from(word.letter - b'A')];
                    put_word(slot, word, errors);
                }
                b'G' => request.read_g(word, errors),
                b'M' => request.read_m(word, errors),
                b'I' | b'J' | b'K' => {
                    let slot = &mut request.offsets[usize::from(word.letter - b'I')];
                    put_word(slot, word, errors);
                }
                b'R' => put_word(&mut request.radius, word, errors),
                b'@' => put_word(&mut request.polar[0], word, errors),
                b'^' => put_word(&mut request.polar[1], word, errors),
                b'F' => put_word(&mut request.feed, word, errors),
                b'P' => put_word(&mut request.p, word, errors),
                b'Q' => put_word(&mut request.q, word, errors),
                b'L' => put_word(&mut request.l, word, errors),
                b'H' => put_word(&mut request.h, word, errors),
                b'D' => put_word(&mut request.d, word, errors),
                b'S' => put_word(&mut request.s, word, errors),
                b'T' => put_word(&mut request.t, word, errors),
                b'E' => put_word(&mut request.e, word, errors),
                b'$' => errors.push(ignored(
                    word,
                    "spindle selection ($) is not part of a toolpath",
                )),
                // A program number (`O1000` alone on its line) names the program only.
                b'O' => {}
                letter => errors.push(unknown_letter(word, letter)),
            }
        }
        // E belongs to M66…M68 and G76 only, as rs274 reads it.
        let analog = matches!(request.io, Some((66..=68, _)))
            || matches!(
                request.motion,
                Some((MotionMode::ThreadCycle | MotionMode::LatheCycle(_), _))
            );
        if let Some(e) = request.e.filter(|_| !analog) {
            errors.push(unknown_letter(e, b'E'));
        }
    }

    /// True when the block has any axis word.
    pub fn has_axis_words(&self) -> bool {
        self.axes.iter().chain(&self.polar).any(Option::is_some)
    }

    /// The block's axis words, in X Y Z A B C `@` `^` order.
    pub fn axis_words(&self) -> impl Iterator<Item = &Word> {
        self.axes.iter().chain(&self.polar).flatten()
    }

    fn read_g(&mut self, word: Word, errors: &mut Vec<GcodeDiagnostic>) {
        let tenths = codes::tenths(word.value);
        let Some(code) = tenths.and_then(codes::g_code) else {
            self.unknown_g = true;
            return errors.push(unknown_code(word, "not an RS274NGC G code"));
        };
        let modes =
            |group| move |first: Word, second: Word| conflicting_modes(first, second, group);
        match code {
            GCode::Motion(mode) => {
                if mode == MotionMode::Unsupported {
                    let feature = codes::motion_feature(tenths.unwrap_or(0));
                    errors.push(unsupported(word, feature));
                }
                // G80 beside another motion code is dropped, as rs274 drops it: the
                // safety line `G0 G17 G40 G49 G80 G90` is a G0.
                match self.motion {
                    Some(_) if mode == MotionMode::Cancel => {}
                    Some((MotionMode::Cancel, _)) => self.motion = Some((mode, word)),
                    _ => {
                        self.no_move |= self.motion.is_some();
                        put_mode(&mut self.motion, mode, word, errors, conflicting_motion);
                    }
                }
            }
            GCode::Plane(p) => put_mode(&mut self.plane, p, word, errors, modes("plane")),
            GCode::Units(u) => put_mode(&mut self.units, u, word, errors, modes("length units")),
            GCode::Distance(d) => {
                put_mode(&mut self.distance, d, word, errors, modes("distance mode"))
            }
            GCode::FeedMode(m) => {
                put_mode(&mut self.feed_mode, m, word, errors, modes("feed mode"))
            }
            GCode::PathMode(m) => {
                put_mode(&mut self.path_mode, m, word, errors, modes("path mode"))
            }
            GCode::ArcCenters(d) => put_mode(
                &mut self.arc_centers,
                d,
                word,
                errors,
                modes("arc centre mode"),
            ),
            GCode::Diameter(d) => {
                put_mode(&mut self.diameter, d, word, errors, modes("lathe mode"))
            }
            GCode::CoordSystem(c) => put_mode(
                &mut self.coord_system,
                c,
                word,
                errors,
                modes("coordinate system"),
            ),
            GCode::NonModal(n) => put_mode(
                &mut self.non_modal,
                n,
                word,
                errors,
                modes("non-modal group"),
            ),
            GCode::ToolLength(t) => put_mode(
                &mut self.tool_length,
                t,
                word,
                errors,
                modes("tool length offset"),
            ),
            GCode::Retract(r) => put_mode(
                &mut self.retract,
                r,
                word,
                errors,
                modes("canned cycle return level"),
            ),
            GCode::SurfaceSpeed(c) => put_mode(
                &mut self.surface_speed,
                c,
                word,
                errors,
                modes("spindle speed mode"),
            ),
            GCode::CutterComp(c) => put_mode(
                &mut self.cutter_comp,
                c,
                word,
                errors,
                modes("cutter radius compensation"),
            ),
            GCode::Unsupported(feature) => {
                errors.push(unsupported(word, feature.name));
                self.no_move |= feature.uses_axis_words;
            }
        }
    }

    fn read_m(&mut self, word: Word, errors: &mut Vec<GcodeDiagnostic>) {
        let modes =
            |group| move |first: Word, second: Word| conflicting_modes(first, second, group);
        match codes::tenths(word.value).and_then(codes::m_code) {
            Some(MCode::Pause(optional)) => put_mode(
                &mut self.stop,
                Stop::Pause(optional),
                word,
                errors,
                stop_conflict,
            ),
            Some(MCode::Spindle(s)) => match self.context {
                Some((_, first)) => errors.push(conflicting_modes(first, word, "spindle")),
                None => put_mode(&mut self.spindle, s, word, errors, modes("spindle")),
            },
            Some(MCode::Context(c)) => match self.spindle {
                Some((_, first)) => errors.push(conflicting_modes(first, word, "spindle")),
                None => put_mode(&mut self.context, c, word, errors, modes("spindle")),
            },
            Some(MCode::Coolant(c)) => {
                put_mode(&mut self.coolant, c, word, errors, modes("coolant"))
            }
            Some(MCode::ToolChange) => put_mode(
                &mut self.tool_change,
                (),
                word,
                errors,
                modes("tool change"),
            ),
            Some(MCode::End) => put_mode(&mut self.stop, Stop::End, word, errors, stop_conflict),
            Some(MCode::Override) => {
                put_mode(&mut self.overrides, (), word, errors, modes("override"))
            }
            Some(MCode::Io(code)) => put_mode(&mut self.io, code, word, errors, modes("I/O")),
            Some(MCode::User(code)) => put_mode(
                &mut self.user,
                code,
                word,
                errors,
                modes("user-defined M code"),
            ),
            Some(MCode::Unsupported(feature)) => errors.push(unsupported(word, feature)),
            None => errors.push(unknown_code(word, "not an RS274NGC M code")),
        }
    }
}

/// Stores a modal code, or reports a conflict with the one already there.
fn put_mode<T>(
    slot: &mut Option<(T, Word)>,
    value: T,
    word: Word,
    errors: &mut Vec<GcodeDiagnostic>,
    conflict: impl FnOnce(Word, Word) -> GcodeDiagnostic,
) {
    match slot {
        Some((_, first)) => errors.push(conflict(*first, word)),
        None => *slot = Some((value, word)),
    }
}

/// Stores a value word, or reports it as repeated.
#[inline]
fn put_word(slot: &mut Option<Word>, word: Word, errors: &mut Vec<GcodeDiagnostic>) {
    let Some(first) = slot else {
        *slot = Some(word);
        return;
    };
    repeated_word(*first, word, errors);
}

/// Reports `second`, a word whose letter `first` already gave in the block.
#[cold]
fn repeated_word(first: Word, word: Word, errors: &mut Vec<GcodeDiagnostic>) {
    let (first, second, span) = (first.name(), word.name(), span(word.span()));
    let letter = word.letter_char();
    errors.push(match Axis::from_letter(letter) {
        Some(_) => GcodeDiagnostic::RepeatedAxis {
            axis: letter,
            first,
            second,
            span,
        },
        None => GcodeDiagnostic::RepeatedWord {
            letter,
            first,
            second,
            span,
        },
    });
}

fn conflicting_motion(first: Word, second: Word) -> GcodeDiagnostic {
    GcodeDiagnostic::ConflictingMotion {
        first: first.name(),
        second: second.name(),
        span: span(second.span()),
    }
}

fn conflicting_modes(first: Word, second: Word, group: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::ConflictingModes {
        first: first.name(),
        second: second.name(),
        group,
        span: span(second.span()),
    }
}

fn stop_conflict(first: Word, second: Word) -> GcodeDiagnostic {
    conflicting_modes(first, second, "program stop")
}

fn ignored(word: Word, reason: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::IgnoredWord {
        word: word.name(),
        reason,
        span: span(word.span()),
    }
}

fn unsupported(word: Word, feature: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::Unsupported {
        code: word.name(),
        feature,
        places: 1,
        span: span(word.span()),
    }
}

fn unknown_letter(word: Word, letter: u8) -> GcodeDiagnostic {
    GcodeDiagnostic::UnknownWord {
        word: word.name(),
        meaning: codes::letter_meaning(letter),
        span: span(word.span()),
    }
}

fn unknown_code(word: Word, meaning: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::UnknownWord {
        word: word.name(),
        meaning,
        span: span(word.span()),
    }
}
