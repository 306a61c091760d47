//! Diagnostics: every error and warning the front end reports, with its stable code and span.
//!
//! Owns the wording, the codes (`pvtc::gcode::<name>`) and the help lines; it must not
//! decide when a diagnostic applies (the parser and interpreter do) nor render anything
//! (the CLI does, through miette).

use std::ops::Range;

use miette::SourceSpan;

/// One error or warning about a G-code program, labelled under the offending text.
///
/// Match on [`GcodeDiagnostic::code`] rather than on variants: the fuller dialect adds more.
#[derive(Debug, Clone, PartialEq, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum GcodeDiagnostic {
    /// Malformed text: a letter without a number, a bad number, an unclosed comment.
    #[error("syntax error: {detail}")]
    #[diagnostic(code(pvtc::gcode::syntax), help("{hint}"))]
    Syntax {
        /// What is wrong, quoting the text.
        detail: String,
        /// How to write it instead.
        hint: &'static str,
        /// The malformed text.
        #[label("not valid G-code")]
        span: SourceSpan,
    },

    /// A word whose letter pvtc does not know (`E5`, `~`) or a code that is no G-code.
    #[error("unknown word `{word}`: {meaning}")]
    #[diagnostic(
        code(pvtc::gcode::unknown_word),
        help("pvtc reads G, M, N, F, S, T, P, Q, L, H, D, X, Y, Z, A, B, C, I, J, K and R words; remove this one")
    )]
    UnknownWord {
        /// The word as written.
        word: String,
        /// What the letter means in RS274NGC, or why the word is not G-code.
        meaning: &'static str,
        /// The word.
        #[label("unknown word")]
        span: SourceSpan,
    },

    /// An RS274NGC feature pvtc does not compile (`G81`, `G41`, `O100 sub`, `#<_hal[…]>`);
    /// reported once per feature, at its first place, with the number of places.
    #[error("{code} ({feature}) is not supported by pvtc{}", places_note(*places))]
    #[diagnostic(
        code(pvtc::gcode::unsupported),
        help("post the program without {feature}, or remove the blocks that use it")
    )]
    Unsupported {
        /// The code or token, e.g. `G81`.
        code: String,
        /// The feature it belongs to, in machinist's words.
        feature: &'static str,
        /// How many places in the program use the feature (the span is the first).
        places: usize,
        /// The code.
        #[label("{feature}")]
        span: SourceSpan,
    },

    /// Two motion codes (G0, G1, G2, G3, G80, cycles) in one block.
    #[error("two motion codes in one block: {first} and {second}")]
    #[diagnostic(
        code(pvtc::gcode::conflicting_motion),
        help("put each move in its own block")
    )]
    ConflictingMotion {
        /// The first motion code.
        first: String,
        /// The second motion code.
        second: String,
        /// The second motion code.
        #[label("second motion code")]
        span: SourceSpan,
    },

    /// Two codes of one modal group other than motion (`G20 G21`, `G90 G91`, `M0 M2`).
    #[error("{first} and {second} in one block both set the {group}")]
    #[diagnostic(
        code(pvtc::gcode::conflicting_modes),
        help("keep one of the two codes")
    )]
    ConflictingModes {
        /// The first code.
        first: String,
        /// The second code.
        second: String,
        /// The modal group both belong to.
        group: &'static str,
        /// The second code.
        #[label("conflicts with {first}")]
        span: SourceSpan,
    },

    /// The same axis twice in one block (`X1 X2`).
    #[error("axis {axis} appears twice in one block: {first} and {second}")]
    #[diagnostic(
        code(pvtc::gcode::repeated_axis),
        help("give each axis once per block")
    )]
    RepeatedAxis {
        /// The axis letter.
        axis: char,
        /// The first word.
        first: String,
        /// The second word.
        second: String,
        /// The second word.
        #[label("repeated axis")]
        span: SourceSpan,
    },

    /// The same non-axis word twice in one block (`F100 F200`, `I1 I2`).
    #[error("word {letter} appears twice in one block: {first} and {second}")]
    #[diagnostic(
        code(pvtc::gcode::repeated_word),
        help("give each word once per block")
    )]
    RepeatedWord {
        /// The letter.
        letter: char,
        /// The first word.
        first: String,
        /// The second word.
        second: String,
        /// The second word.
        #[label("repeated word")]
        span: SourceSpan,
    },

    /// Axis words while no motion mode is in effect (before any G0/G1, or after G80).
    #[error("axis word {word} but no motion mode (G0, G1, G2 or G3) is in effect")]
    #[diagnostic(
        code(pvtc::gcode::no_motion_mode),
        help("program G0 or G1 in this block or before it")
    )]
    NoMotionMode {
        /// The first axis word of the block.
        word: String,
        /// The axis word.
        #[label("which motion?")]
        span: SourceSpan,
    },

    /// An arc word (I, J, K, R) in a block whose motion is not G2/G3.
    #[error("{word} is an arc word but the motion mode is {mode}")]
    #[diagnostic(
        code(pvtc::gcode::arc_word_without_arc),
        help("I, J, K and R belong to G2/G3 blocks; remove the word or program G2/G3")
    )]
    ArcWordWithoutArc {
        /// The arc word.
        word: String,
        /// The motion mode in effect, e.g. `G1`.
        mode: &'static str,
        /// The arc word.
        #[label("not an arc")]
        span: SourceSpan,
    },

    /// G2/G3 with neither I/J/K centre offsets nor R.
    #[error("{mode} arc without a centre: neither I/J/K offsets nor R given")]
    #[diagnostic(
        code(pvtc::gcode::arc_missing_center),
        help("give the centre as I/J/K offsets from the start point, or the radius as R")
    )]
    ArcMissingCenter {
        /// `G2` or `G3`.
        mode: &'static str,
        /// The motion code or the axis words.
        #[label("arc without centre")]
        span: SourceSpan,
    },

    /// R together with I/J/K in one arc.
    #[error("R together with I/J/K: an arc takes either centre offsets or a radius")]
    #[diagnostic(
        code(pvtc::gcode::arc_r_with_center),
        help("remove R or the I/J/K words")
    )]
    ArcRWithCenter {
        /// The R word.
        #[label("R with I/J/K")]
        span: SourceSpan,
    },

    /// An R-form arc whose end point is its start point.
    #[error("R-form arc ends where it starts: a radius cannot define a full circle")]
    #[diagnostic(
        code(pvtc::gcode::arc_full_circle_r),
        help("program a full circle with I/J/K centre offsets")
    )]
    ArcFullCircleR {
        /// The R word.
        #[label("full circle by radius")]
        span: SourceSpan,
    },

    /// An R-form arc whose radius cannot reach the end point.
    #[error("arc radius {} {units} is smaller than half the distance to the end point ({} {units})", show(*radius), show(*half_chord))]
    #[diagnostic(
        code(pvtc::gcode::arc_radius_too_small),
        help("the radius must be at least half the chord from start to end point")
    )]
    ArcRadiusTooSmall {
        /// |R| in output units.
        radius: f64,
        /// Half the distance from start to end point in the arc's plane.
        half_chord: f64,
        /// `mm` or `in`.
        units: &'static str,
        /// The R word.
        #[label("radius too small")]
        span: SourceSpan,
    },

    /// A centre-form arc whose end point is not on the circle through its start point.
    #[error("arc start radius {} {units} and end radius {} {units} differ by {} {units}", show(*start_radius), show(*end_radius), show((start_radius - end_radius).abs()))]
    #[diagnostic(
        code(pvtc::gcode::arc_radius_mismatch),
        help("the end point must lie on the circle about the centre: the radii may differ by {} {units}, or by up to {} {units} within {}% of the radius (LinuxCNC's rule; the arc then runs as a spiral); check I/J/K and the end point", show(*abs_tolerance), show(abs_tolerance * 100.0), show(rel_tolerance * 100.0))
    )]
    ArcRadiusMismatch {
        /// Distance from centre to start point, output units.
        start_radius: f64,
        /// Distance from centre to end point, output units.
        end_radius: f64,
        /// Absolute tolerance in output units.
        abs_tolerance: f64,
        /// Relative tolerance (fraction of the larger radius).
        rel_tolerance: f64,
        /// `mm` or `in`.
        units: &'static str,
        /// The end point and centre words.
        #[label("end point off the circle")]
        span: SourceSpan,
    },

    /// A centre-form arc whose centre is its start point.
    #[error("arc centre is the start point: radius 0")]
    #[diagnostic(
        code(pvtc::gcode::arc_zero_radius),
        help("I/J/K are offsets from the start point to the centre, not the centre itself")
    )]
    ArcZeroRadius {
        /// The centre words.
        #[label("zero radius")]
        span: SourceSpan,
    },

    /// A centre offset that does not belong to the active plane (K in G17).
    #[error("{word} is not a centre offset in the {plane} plane")]
    #[diagnostic(
        code(pvtc::gcode::arc_offset_off_plane),
        help("G17 takes I and J, G18 takes K and I, G19 takes J and K")
    )]
    ArcOffsetOffPlane {
        /// The offset word.
        word: String,
        /// The plane, e.g. `XY (G17)`.
        plane: &'static str,
        /// The offset word.
        #[label("off the plane")]
        span: SourceSpan,
    },

    /// A feed move before any F word and without a default feed.
    #[error("feed move before any F word, and no default feed was given")]
    #[diagnostic(
        code(pvtc::gcode::no_feed),
        help("add an F word (units per minute) at or before the first G1/G2/G3, or give a default feed")
    )]
    NoFeed {
        /// The move.
        #[label("at what feed?")]
        span: SourceSpan,
    },

    /// A feed move at F0 or a negative feed.
    #[error("feed move at {feed}: the feed must be positive")]
    #[diagnostic(code(pvtc::gcode::zero_feed), help("program a positive F word"))]
    ZeroFeed {
        /// The F word in effect, e.g. `F0`.
        feed: String,
        /// The F word, or the move when F came from an earlier block.
        #[label("feed not positive")]
        span: SourceSpan,
    },

    /// A coordinate, centre or feed too large to represent.
    #[error("{what} is out of range ({value})")]
    #[diagnostic(
        code(pvtc::gcode::out_of_range),
        help("check the numbers of this block")
    )]
    OutOfRange {
        /// What overflowed, e.g. `X coordinate`.
        what: &'static str,
        /// The value reached.
        value: f64,
        /// The block.
        #[label("out of range")]
        span: SourceSpan,
    },

    /// Warning: a move that ends where it starts; it is dropped.
    #[error("move ends where it starts; it is dropped")]
    #[diagnostic(
        code(pvtc::gcode::zero_length_move),
        severity(Warning),
        help("remove the block if it is not needed")
    )]
    ZeroLengthMove {
        /// The block.
        #[label("zero-length move")]
        span: SourceSpan,
    },

    /// O-word control flow that cannot run: an unknown keyword, a construct without its
    /// end, `break` outside a loop, a malformed condition or argument list.
    #[error("O-word error: {detail}")]
    #[diagnostic(
        code(pvtc::gcode::oword),
        help("O-words are `oN sub`/`endsub`/`return`/`call`, `if`/`elseif`/`else`/`endif`, `while`/`endwhile`, `do`/`while`, `repeat`/`endrepeat`, `break`, `continue`, with one label per construct")
    )]
    Oword {
        /// What is wrong.
        detail: String,
        /// The O-word.
        #[label("here")]
        span: SourceSpan,
    },

    /// A call of a subroutine defined neither earlier in the program nor in a file
    /// `name.ngc` on the subroutine path.
    #[error("no subroutine {name}{}", searched_note(.searched))]
    #[diagnostic(
        code(pvtc::gcode::unknown_subroutine),
        help("define it before the call (`oN sub` … `oN endsub`), after the program for M98 (`O<n>` … `M99`), or in a file `NAME.ngc` in a folder given with --subroutine-path")
    )]
    UnknownSubroutine {
        /// The subroutine's label as written, e.g. `<bore>` or `100`.
        name: String,
        /// What was searched (folders, or why a file could not be read).
        searched: String,
        /// The call.
        #[label("called here")]
        span: SourceSpan,
    },

    /// Calls nested deeper than [`crate::MAX_CALL_DEPTH`] (runaway recursion).
    #[error("subroutine calls nested more than {limit} deep")]
    #[diagnostic(
        code(pvtc::gcode::recursion_limit),
        help(
            "a recursive subroutine needs a condition that ends it; LinuxCNC allows the same depth"
        )
    )]
    RecursionLimit {
        /// The depth limit.
        limit: usize,
        /// The call that went too deep.
        #[label("one call too many")]
        span: SourceSpan,
    },

    /// A loop that ran [`crate::MAX_LOOP_ITERATIONS`] times without ending, or loops that
    /// ran [`crate::MAX_TOTAL_ITERATIONS`] times in all.
    #[error("{}", loop_message(*limit, *all))]
    #[diagnostic(
        code(pvtc::gcode::loop_limit),
        help("check the loop's condition; pvtc stops a loop after this many iterations rather than hang")
    )]
    LoopLimit {
        /// The iteration limit.
        limit: u64,
        /// The limit of all loops of the run together (not of this loop).
        all: bool,
        /// The loop's O-word.
        #[label("this loop")]
        span: SourceSpan,
    },

    /// Subroutine and loop bodies held in memory went past [`crate::MAX_BUFFERED_BYTES`].
    #[error("subroutine and loop bodies exceed {limit} bytes")]
    #[diagnostic(
        code(pvtc::gcode::body_too_large),
        help("pvtc holds the bodies of subroutines and loops in memory (the rest of a program streams); split the body")
    )]
    BodyTooLarge {
        /// The limit, bytes.
        limit: usize,
        /// The construct whose body went past it.
        #[label("this body")]
        span: SourceSpan,
    },

    /// A diagnostic in a subroutine file, shown at the call in the main program.
    #[error("in {file} line {line} column {column} (called here): {inner}")]
    #[diagnostic(
        code(pvtc::gcode::in_subroutine_file),
        help("the error in the subroutine file is {inner_code}")
    )]
    InSubroutineFile {
        /// The subroutine file.
        file: String,
        /// Line and column of the diagnostic in that file.
        line: usize,
        /// Column (characters, from 1).
        column: usize,
        /// The diagnostic itself, with its span in that file.
        inner: Box<GcodeDiagnostic>,
        /// Its code.
        inner_code: &'static str,
        /// The call in the main program.
        #[label("called here")]
        span: SourceSpan,
    },

    /// Note: a rapid to the point the axes are already at, as CAM output writes to start
    /// from a known point; nothing moves, so it is dropped. A note, not a warning:
    /// `--deny-warnings` does not fail on it.
    #[error("rapid to the current point; nothing moves")]
    #[diagnostic(
        code(pvtc::gcode::rapid_to_current_point),
        severity(Advice),
        help("ordinary in CAM output; nothing to do")
    )]
    RapidToCurrentPoint {
        /// The block.
        #[label("already here")]
        span: SourceSpan,
    },

    /// Warning: an F word with G20/G21 in its block is read in the units before the
    /// block, as LinuxCNC reads it (F is executed before the units); a CAM post that
    /// wrote `G20 F6` almost certainly meant the new units.
    #[error(
        "`{feed}` is read before `{code}` of its block, in {old}/min: {} {old}/min ({} {new}/min), not {} {new}/min",
        show(*value), show(*converted), show(*value)
    )]
    #[diagnostic(
        code(pvtc::gcode::feed_before_units),
        severity(Warning),
        help("LinuxCNC sets F before G20/G21 of the same block; to mean {} {new}/min, put {code} on a line of its own before `{feed}`", show(*value))
    )]
    FeedBeforeUnits {
        /// The F word as written, e.g. `F6`.
        feed: String,
        /// Its number.
        value: f64,
        /// The feed in the new units.
        converted: f64,
        /// The units it is read in, `mm` or `in`.
        old: &'static str,
        /// The block's units, `mm` or `in`.
        new: &'static str,
        /// The units code, `G20` or `G21`.
        code: String,
        /// The F word.
        #[label("read in {old}/min")]
        span: SourceSpan,
    },

    /// Spindle-synchronised motion (G33, G33.1, G76, G95) without `--spindle-rpm-exact`.
    #[error(
        "{code} is spindle-synchronised: a time-based PVT program cannot follow a spindle encoder"
    )]
    #[diagnostic(
        code(pvtc::gcode::spindle_sync),
        help("give --spindle-rpm-exact to plan it at the programmed S taken as exact (feed per revolution × S, pitch × S), or post the program without it")
    )]
    SpindleSync {
        /// The code, e.g. `G76`.
        code: String,
        /// The code.
        #[label("follows the spindle")]
        span: SourceSpan,
    },

    /// Warning: spindle-synchronised motion planned at the programmed S (`--spindle-rpm-exact`).
    #[error("{code} and the program's other spindle-synchronised moves are planned at the programmed S taken as exact (feed per revolution × S, pitch × S)")]
    #[diagnostic(
        code(pvtc::gcode::spindle_rpm_exact),
        severity(Warning),
        help("the machine follows its spindle's encoder; these moves are right only while the spindle turns at exactly S")
    )]
    SpindleRpmExact {
        /// The first such code, e.g. `G33`.
        code: String,
        /// The code.
        #[label("timed at S")]
        span: SourceSpan,
    },

    /// M72 with no state saved at this call level (no M70 or M73 since its last M71).
    #[error("M72 restores no saved state: no M70 or M73 saved one at this call level")]
    #[diagnostic(
        code(pvtc::gcode::no_saved_state),
        help(
            "save the modal state with M70 (or M73 in a subroutine) before M72, and do not M71 it"
        )
    )]
    NoSavedState {
        /// The M72.
        #[label("nothing to restore")]
        span: SourceSpan,
    },

    /// Warning: blocks after the program end (M2, M30, closing `%`) are ignored.
    #[error("blocks after {end} are ignored")]
    #[diagnostic(
        code(pvtc::gcode::after_program_end),
        severity(Warning),
        help("move the program end to the last block")
    )]
    AfterProgramEnd {
        /// The end code, e.g. `M30`.
        end: String,
        /// The first ignored block.
        #[label("never executed")]
        span: SourceSpan,
    },

    /// An expression with no value: division by zero, SQRT of a negative number, …
    #[error("expression error: {detail}")]
    #[diagnostic(
        code(pvtc::gcode::math_error),
        help("check the operands of this operator or function")
    )]
    MathError {
        /// What went wrong, with the operands.
        detail: String,
        /// The operator or function call.
        #[label("no value")]
        span: SourceSpan,
    },

    /// A named parameter read before any assignment.
    #[error("parameter {name} is read before it is assigned")]
    #[diagnostic(
        code(pvtc::gcode::undefined_parameter),
        help("assign it on an earlier line, e.g. {name} = 1.0 (assignments take effect after their line)")
    )]
    UndefinedParameter {
        /// The parameter as written, e.g. `#<depth>`.
        name: String,
        /// The parameter read.
        #[label("not assigned yet")]
        span: SourceSpan,
    },

    /// A `*nn` checksum that does not match the line.
    #[error("checksum *{written} does not match the line (its checksum is {computed})")]
    #[diagnostic(
        code(pvtc::gcode::checksum_mismatch),
        help("the checksum is the XOR of every byte of the line before `*`; the line may be corrupted")
    )]
    ChecksumMismatch {
        /// The checksum written.
        written: u64,
        /// The checksum of the text before `*`.
        computed: u64,
        /// The checksum.
        #[label("wrong checksum")]
        span: SourceSpan,
    },

    /// A code that needs a word the block does not give (G4 without P, G92 without axes).
    #[error("{code} needs {needs}")]
    #[diagnostic(code(pvtc::gcode::missing_word), help("add {needs} to the block"))]
    MissingWord {
        /// The code, e.g. `G4`.
        code: String,
        /// What it needs, e.g. `a P word (seconds)`.
        needs: &'static str,
        /// The code.
        #[label("incomplete")]
        span: SourceSpan,
    },

    /// A feed move in inverse time mode (G93) without its own F word.
    #[error("feed move in inverse time mode (G93) without an F word")]
    #[diagnostic(
        code(pvtc::gcode::inverse_time_feed),
        help(
            "under G93 every G1/G2/G3 block needs F (1 / minutes the move takes); or program G94"
        )
    )]
    InverseTimeFeed {
        /// The move.
        #[label("for how long?")]
        span: SourceSpan,
    },

    /// A word whose value is not one its code accepts (T-1, G2 P0, G4 P-1).
    #[error("{word}: {expected}")]
    #[diagnostic(code(pvtc::gcode::bad_value), help("correct the value of this word"))]
    BadValue {
        /// The word as read.
        word: String,
        /// What the value must be.
        expected: &'static str,
        /// The word.
        #[label("bad value")]
        span: SourceSpan,
    },

    /// Warning: a word pvtc reads but that has no effect on the toolpath.
    #[error("{word} is ignored: {reason}")]
    #[diagnostic(
        code(pvtc::gcode::ignored_word),
        severity(Warning),
        help("remove the word if the program does not need it")
    )]
    IgnoredWord {
        /// The word as read.
        word: String,
        /// Why it has no effect.
        reason: &'static str,
        /// The word.
        #[label("ignored")]
        span: SourceSpan,
    },

    /// A line longer than [`crate::MAX_LINE_BYTES`]: no G-code line is that long, so the
    /// file is not a part program (or is damaged); the line is skipped unread.
    #[error("line {line} is {length} bytes long; pvtc reads lines of at most {limit} bytes")]
    #[diagnostic(
        code(pvtc::gcode::line_too_long),
        help("a G-code block fits on one short line; check that this is a part program")
    )]
    LineTooLong {
        /// 1-based line number.
        line: u32,
        /// Its length in bytes, line end not counted.
        length: usize,
        /// The limit, [`crate::MAX_LINE_BYTES`].
        limit: usize,
        /// The line (its first bytes are shown).
        #[label("this line")]
        span: SourceSpan,
    },

    /// More errors than [`crate::MAX_KEPT_DIAGNOSTICS`]: the rest are counted, not kept.
    #[error("{count} more errors after these are not listed")]
    #[diagnostic(
        code(pvtc::gcode::more_errors),
        help("correct the errors listed and compile again")
    )]
    MoreErrors {
        /// Errors not kept.
        count: usize,
        /// The first error not kept (unlabelled).
        span: SourceSpan,
    },

    /// Warning: more warnings than [`crate::MAX_KEPT_DIAGNOSTICS`]; the rest are counted.
    #[error("{count} more warnings after these are not listed")]
    #[diagnostic(
        code(pvtc::gcode::more_warnings),
        severity(Warning),
        help("correct the warnings listed and compile again")
    )]
    MoreWarnings {
        /// Warnings not kept.
        count: usize,
        /// The first warning not kept (unlabelled).
        span: SourceSpan,
    },

    /// A canned cycle (G73, G81…G89) that cannot run as written: no R or Z level, R
    /// below the bottom, a bad Q or L, tapping without the spindle turning clockwise.
    #[error("canned cycle {code}: {detail}")]
    #[diagnostic(
        code(pvtc::gcode::cycle),
        help("give the cycle its R level, bottom and the words its code needs (LinuxCNC's rules)")
    )]
    Cycle {
        /// The cycle's code, e.g. `G83`.
        code: &'static str,
        /// What is wrong.
        detail: String,
        /// The block's cycle words.
        #[label("cannot run")]
        span: SourceSpan,
    },

    /// The first move after G41/G42 ends within one tool radius of where it starts, so
    /// the tool cannot reach its side of the path (LinuxCNC: "Length of cutter
    /// compensation entry move is not greater than the tool radius").
    #[error(
        "the cutter compensation entry move is not longer than the tool radius ({radius} {units})"
    )]
    #[diagnostic(
        code(pvtc::gcode::compensation_entry),
        help("start compensation farther from the path: the entry move must be longer than the tool radius")
    )]
    CompensationEntry {
        /// The tool radius.
        radius: f64,
        /// Output units.
        units: &'static str,
        /// The entry move's block.
        #[label("too short for the tool")]
        span: SourceSpan,
    },

    /// An arc with the tool inside it is no larger than the tool (LinuxCNC: "Tool radius
    /// not less than arc radius with comp").
    #[error("the tool radius ({radius} {units}) is not less than the arc radius")]
    #[diagnostic(
        code(pvtc::gcode::tool_radius_over_arc),
        help("use a smaller tool, or a larger arc")
    )]
    ToolRadiusOverArc {
        /// The tool radius.
        radius: f64,
        /// Output units.
        units: &'static str,
        /// The arc's block.
        #[label("tool larger than this arc")]
        span: SourceSpan,
    },

    /// An inside corner the compensated tool cannot cut without gouging: the move before
    /// it is shorter than the cut back, or the offset paths never meet (LinuxCNC's
    /// "… in concave corner cannot be reached by the tool without gouging").
    #[error("concave corner too tight for the tool: {detail}")]
    #[diagnostic(
        code(pvtc::gcode::concave_corner),
        help("use a smaller tool, or program the corner with room for the tool's radius")
    )]
    ConcaveCorner {
        /// Which corner and why.
        detail: &'static str,
        /// The block after the corner (the one whose move decides it).
        #[label("the tool would gouge here")]
        span: SourceSpan,
    },

    /// A code or move that cutter radius compensation does not allow (LinuxCNC refuses
    /// these too): G41/G42 while on, an arc straight after G40, a plane, offset or tool
    /// change while on, a spline while on.
    #[error("{what} with cutter radius compensation")]
    #[diagnostic(
        code(pvtc::gcode::compensation_conflict),
        help(
            "turn compensation off with G40 first, or move the code outside the compensated path"
        )
    )]
    CompensationConflict {
        /// What is refused.
        what: &'static str,
        /// The code.
        #[label("not allowed here")]
        span: SourceSpan,
    },

    /// G43/G43.2 H (or M6 T with G43) naming a tool the tool table does not have.
    #[error("tool {tool} is not in the tool table")]
    #[diagnostic(
        code(pvtc::gcode::unknown_tool),
        help("give its offsets in the --tool-table file (a line like `T{tool} P{tool} Z0.5`)")
    )]
    UnknownTool {
        /// The tool number.
        tool: u32,
        /// The word naming it.
        #[label("no such tool")]
        span: SourceSpan,
    },

    /// A `%` line that neither opens the program (its first line) nor closes one it
    /// opened, or a `%` with text after it: `rs274` stops there ("Bad character '%'
    /// used").
    #[error("`%` is not a block: rs274 stops here (\"Bad character '%' used\")")]
    #[diagnostic(
        code(pvtc::gcode::percent_line),
        help("`%` alone opens a program on its first line and closes it on a later one; make this line a comment `( … )` or remove it")
    )]
    PercentLine {
        /// The `%`.
        #[label("not the opening or closing `%`")]
        span: SourceSpan,
    },

    /// The file ends without M2, M30 or the closing `%` of a program opened with `%`,
    /// which `rs274` reports ("File ended with no percent sign or program end").
    #[error("{}", no_end_message(*opened))]
    #[diagnostic(
        code(pvtc::gcode::no_program_end),
        severity(Warning),
        help("end the program with M2 or M30 (or close a program that starts with `%` with a `%` line)")
    )]
    NoProgramEnd {
        /// The program opened with a `%` line.
        opened: bool,
        /// The end of the file.
        #[label("the file ends here")]
        span: SourceSpan,
    },

    /// A full-circle arc with more turns than one block may make, or arcs with more
    /// turns than a run may make ([`crate::MAX_ARC_TURNS`], [`crate::MAX_TOTAL_ARC_TURNS`]).
    #[error("{}", turn_message(*limit, *all))]
    #[diagnostic(
        code(pvtc::gcode::turn_limit),
        help("pvtc stops at this many arc turns rather than run for hours; split the program")
    )]
    TurnLimit {
        /// The limit, turns.
        limit: u64,
        /// The limit of all arcs of the run together (not of this block).
        all: bool,
        /// The P word.
        #[label("too many turns")]
        span: SourceSpan,
    },

    /// A probing move (G38.2…G38.5) without a result to continue with (`--probe-result`).
    #[error("{code} probes: where it stops is only known on the machine")]
    #[diagnostic(
        code(pvtc::gcode::probe),
        help("give the position the probe trips at with --probe-result X,Y,Z (the move then ends there), or remove the probing block")
    )]
    Probe {
        /// The probing code, e.g. `G38.2`.
        code: String,
        /// The code.
        #[label("probing move")]
        span: SourceSpan,
    },

    /// A program without any motion (empty, or only comments and modes).
    #[error("the program has no motion")]
    #[diagnostic(
        code(pvtc::gcode::no_motion),
        help("a part program needs at least one G0, G1, G2 or G3 move")
    )]
    NoMotion {
        /// The start of the file.
        #[label("no move in this file")]
        span: SourceSpan,
    },
}

impl GcodeDiagnostic {
    /// The stable code, e.g. `pvtc::gcode::arc_radius_mismatch`.
    pub fn code(&self) -> &'static str {
        use GcodeDiagnostic as D;
        match self {
            D::Syntax { .. } => "pvtc::gcode::syntax",
            D::UnknownWord { .. } => "pvtc::gcode::unknown_word",
            D::Unsupported { .. } => "pvtc::gcode::unsupported",
            D::ConflictingMotion { .. } => "pvtc::gcode::conflicting_motion",
            D::ConflictingModes { .. } => "pvtc::gcode::conflicting_modes",
            D::RepeatedAxis { .. } => "pvtc::gcode::repeated_axis",
            D::RepeatedWord { .. } => "pvtc::gcode::repeated_word",
            D::NoMotionMode { .. } => "pvtc::gcode::no_motion_mode",
            D::ArcWordWithoutArc { .. } => "pvtc::gcode::arc_word_without_arc",
            D::ArcMissingCenter { .. } => "pvtc::gcode::arc_missing_center",
            D::ArcRWithCenter { .. } => "pvtc::gcode::arc_r_with_center",
            D::ArcFullCircleR { .. } => "pvtc::gcode::arc_full_circle_r",
            D::ArcRadiusTooSmall { .. } => "pvtc::gcode::arc_radius_too_small",
            D::ArcRadiusMismatch { .. } => "pvtc::gcode::arc_radius_mismatch",
            D::ArcZeroRadius { .. } => "pvtc::gcode::arc_zero_radius",
            D::ArcOffsetOffPlane { .. } => "pvtc::gcode::arc_offset_off_plane",
            D::NoFeed { .. } => "pvtc::gcode::no_feed",
            D::ZeroFeed { .. } => "pvtc::gcode::zero_feed",
            D::OutOfRange { .. } => "pvtc::gcode::out_of_range",
            D::ZeroLengthMove { .. } => "pvtc::gcode::zero_length_move",
            D::RapidToCurrentPoint { .. } => "pvtc::gcode::rapid_to_current_point",
            D::FeedBeforeUnits { .. } => "pvtc::gcode::feed_before_units",
            D::NoSavedState { .. } => "pvtc::gcode::no_saved_state",
            D::SpindleSync { .. } => "pvtc::gcode::spindle_sync",
            D::SpindleRpmExact { .. } => "pvtc::gcode::spindle_rpm_exact",
            D::AfterProgramEnd { .. } => "pvtc::gcode::after_program_end",
            D::NoMotion { .. } => "pvtc::gcode::no_motion",
            D::LineTooLong { .. } => "pvtc::gcode::line_too_long",
            D::MoreErrors { .. } => "pvtc::gcode::more_errors",
            D::MoreWarnings { .. } => "pvtc::gcode::more_warnings",
            D::MathError { .. } => "pvtc::gcode::math_error",
            D::UndefinedParameter { .. } => "pvtc::gcode::undefined_parameter",
            D::ChecksumMismatch { .. } => "pvtc::gcode::checksum_mismatch",
            D::MissingWord { .. } => "pvtc::gcode::missing_word",
            D::InverseTimeFeed { .. } => "pvtc::gcode::inverse_time_feed",
            D::BadValue { .. } => "pvtc::gcode::bad_value",
            D::IgnoredWord { .. } => "pvtc::gcode::ignored_word",
            D::Oword { .. } => "pvtc::gcode::oword",
            D::UnknownSubroutine { .. } => "pvtc::gcode::unknown_subroutine",
            D::RecursionLimit { .. } => "pvtc::gcode::recursion_limit",
            D::LoopLimit { .. } => "pvtc::gcode::loop_limit",
            D::BodyTooLarge { .. } => "pvtc::gcode::body_too_large",
            D::InSubroutineFile { .. } => "pvtc::gcode::in_subroutine_file",
            D::Cycle { .. } => "pvtc::gcode::cycle",
            D::UnknownTool { .. } => "pvtc::gcode::unknown_tool",
            D::PercentLine { .. } => "pvtc::gcode::percent_line",
            D::NoProgramEnd { .. } => "pvtc::gcode::no_program_end",
            D::TurnLimit { .. } => "pvtc::gcode::turn_limit",
            D::Probe { .. } => "pvtc::gcode::probe",
            D::CompensationEntry { .. } => "pvtc::gcode::compensation_entry",
            D::ToolRadiusOverArc { .. } => "pvtc::gcode::tool_radius_over_arc",
            D::ConcaveCorner { .. } => "pvtc::gcode::concave_corner",
            D::CompensationConflict { .. } => "pvtc::gcode::compensation_conflict",
        }
    }

    /// Byte range of the offending text in the source.
    pub fn span(&self) -> Range<usize> {
        let span = *self.source_span();
        span.offset()..span.offset() + span.len()
    }

    /// True for warnings and notes (the program still compiles), false for errors.
    pub fn is_warning(&self) -> bool {
        if let Self::InSubroutineFile { inner, .. } = self {
            return inner.is_warning();
        }
        matches!(
            self,
            Self::ZeroLengthMove { .. }
                | Self::RapidToCurrentPoint { .. }
                | Self::FeedBeforeUnits { .. }
                | Self::SpindleRpmExact { .. }
                | Self::AfterProgramEnd { .. }
                | Self::NoProgramEnd { .. }
                | Self::IgnoredWord { .. }
                | Self::MoreWarnings { .. }
        )
    }

    fn source_span(&self) -> &SourceSpan {
        use GcodeDiagnostic as D;
        match self {
            D::Syntax { span, .. }
            | D::UnknownWord { span, .. }
            | D::Unsupported { span, .. }
            | D::ConflictingMotion { span, .. }
            | D::ConflictingModes { span, .. }
            | D::RepeatedAxis { span, .. }
            | D::RepeatedWord { span, .. }
            | D::NoMotionMode { span, .. }
            | D::ArcWordWithoutArc { span, .. }
            | D::ArcMissingCenter { span, .. }
            | D::ArcRWithCenter { span }
            | D::ArcFullCircleR { span }
            | D::ArcRadiusTooSmall { span, .. }
            | D::ArcRadiusMismatch { span, .. }
            | D::ArcZeroRadius { span }
            | D::ArcOffsetOffPlane { span, .. }
            | D::NoFeed { span }
            | D::ZeroFeed { span, .. }
            | D::OutOfRange { span, .. }
            | D::ZeroLengthMove { span }
            | D::RapidToCurrentPoint { span }
            | D::FeedBeforeUnits { span, .. }
            | D::NoSavedState { span }
            | D::SpindleSync { span, .. }
            | D::SpindleRpmExact { span, .. }
            | D::AfterProgramEnd { span, .. }
            | D::NoMotion { span }
            | D::LineTooLong { span, .. }
            | D::MoreErrors { span, .. }
            | D::MoreWarnings { span, .. }
            | D::MathError { span, .. }
            | D::UndefinedParameter { span, .. }
            | D::ChecksumMismatch { span, .. }
            | D::MissingWord { span, .. }
            | D::InverseTimeFeed { span }
            | D::BadValue { span, .. }
            | D::IgnoredWord { span, .. }
            | D::Oword { span, .. }
            | D::UnknownSubroutine { span, .. }
            | D::RecursionLimit { span, .. }
            | D::LoopLimit { span, .. }
            | D::BodyTooLarge { span, .. }
            | D::InSubroutineFile { span, .. } => span,
            D::Cycle { span, .. } | D::UnknownTool { span, .. } => span,
            D::PercentLine { span }
            | D::NoProgramEnd { span, .. }
            | D::TurnLimit { span, .. }
            | D::Probe { span, .. } => span,
            D::CompensationEntry { span, .. }
            | D::ToolRadiusOverArc { span, .. }
            | D::ConcaveCorner { span, .. }
            | D::CompensationConflict { span, .. } => span,
        }
    }
}

/// Every error of one program, in source order; the CLI renders them all.
#[derive(Debug, Clone, PartialEq, thiserror::Error, miette::Diagnostic)]
#[error("{}", count_errors(.diagnostics.len()))]
#[diagnostic(code(pvtc::gcode::errors))]
pub struct GcodeErrors {
    /// The errors, sorted by source position.
    #[related]
    pub diagnostics: Vec<GcodeDiagnostic>,
}

/// ` (N places; the first is shown)` for a feature used in more than one place.
fn places_note(places: usize) -> String {
    if places > 1 {
        format!(" ({places} places; the first is shown)")
    } else {
        String::new()
    }
}

fn count_errors(n: usize) -> String {
    match n {
        1 => "the G-code program has 1 error".to_owned(),
        n => format!("the G-code program has {n} errors"),
    }
}

fn loop_message(limit: u64, all: bool) -> String {
    if all {
        format!("loops ran {limit} times in all")
    } else {
        format!("loop ran {limit} times without ending")
    }
}

fn turn_message(limit: u64, all: bool) -> String {
    match all {
        true => format!("arcs of this run make more than {limit} turns in all"),
        false => format!("an arc of more than {limit} turns"),
    }
}

fn no_end_message(opened: bool) -> String {
    match opened {
        true => "the program opened with `%` ends without its closing `%`".to_owned(),
        false => "the program ends without M2, M30 or a closing `%`".to_owned(),
    }
}

fn searched_note(searched: &str) -> String {
    if searched.is_empty() {
        String::new()
    } else {
        format!(" ({searched})")
    }
}

/// A length or angle for a message: up to six decimals, trailing zeros trimmed.
pub(crate) fn show(x: f64) -> String {
    let s = format!("{x:.6}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// `line_too_long` for line `line`, `length` bytes from byte `start`.
pub(crate) fn line_too_long(line: u32, length: usize, start: usize) -> GcodeDiagnostic {
    GcodeDiagnostic::LineTooLong {
        line,
        length,
        limit: crate::MAX_LINE_BYTES,
        span: span(start..start),
    }
}

/// A span for miette from a byte range.
pub(crate) fn span(range: Range<usize>) -> SourceSpan {
    SourceSpan::from(range.start..range.end.max(range.start))
}

#[cfg(test)]
mod tests {
    use super::*;
    use miette::Diagnostic;

    #[test]
    fn code_matches_miette_code() {
        let s = span(0..1);
        let all = [
            GcodeDiagnostic::ArcRWithCenter { span: s },
            GcodeDiagnostic::NoFeed { span: s },
            GcodeDiagnostic::NoMotion { span: s },
            GcodeDiagnostic::ZeroLengthMove { span: s },
            GcodeDiagnostic::Syntax {
                detail: String::new(),
                hint: "",
                span: s,
            },
        ];
        for d in all {
            assert_eq!(d.code(), Diagnostic::code(&d).unwrap().to_string());
            assert_eq!(d.span(), 0..1);
        }
    }

    #[test]
    fn show_trims_zeros() {
        assert_eq!(show(7.0), "7");
        assert_eq!(show(7.01), "7.01");
        assert_eq!(show(0.0000787), "0.000079");
    }
}
