//! The G and M code table: which codes pvtc executes, which are RS274NGC features it
//! does not (named, for the `unsupported` diagnostic), and what other letters mean.
//!
//! Owns the classification only; it must not hold modal state or execute anything.
//! Growing the dialect (issue 4) means moving rows from [`Feature`] to executed codes.

use pvt_core::compensate::Side;
use pvt_core::{ArcDirection, CoolantState, Plane, SpindleState, Units};

/// A motion mode (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MotionMode {
    /// G0.
    Rapid,
    /// G1.
    Linear,
    /// G2 (clockwise) or G3 (counter-clockwise).
    Arc(ArcDirection),
    /// G80: motion cancelled; axis words are an error until the next motion code.
    Cancel,
    /// G73, G81…G89: a canned cycle, expanded by [`crate::cycles`].
    Cycle(Cycle),
    /// G38.2…G38.5 (the code in tenths): a probing move, run where a result is given.
    Probe(u32),
    /// G5 (cubic, `quadratic` false) or G5.1 (quadratic): a spline in the XY plane.
    Spline {
        /// G5.1.
        quadratic: bool,
    },
    /// G5.2: a NURBS block's opening line and its control point lines.
    Nurbs,
    /// G5.3: the end of a NURBS block.
    NurbsEnd,
    /// G6.2: a NURBS block with its own knots (K) and weights (R), LinuxCNC 2.10's.
    NurbsKnots,
    /// G33: a move synchronised to the spindle, K per revolution.
    Thread,
    /// G33.1: rigid tapping, K per revolution.
    RigidTap,
    /// G76: LinuxCNC's threading cycle.
    ThreadCycle,
    /// G70, G71, G72 and their .1 and .2 forms: LinuxCNC's lathe cycles.
    LatheCycle(LatheCycle),
    /// A motion code pvtc does not execute, or an unknown code's; blocks in this mode
    /// are skipped (the code itself was reported).
    Unsupported,
}

impl MotionMode {
    /// The code as a machinist writes it.
    pub fn name(self) -> &'static str {
        match self {
            MotionMode::Rapid => "G0",
            MotionMode::Linear => "G1",
            MotionMode::Arc(ArcDirection::Clockwise) => "G2",
            MotionMode::Arc(ArcDirection::CounterClockwise) => "G3",
            MotionMode::Cancel => "G80",
            MotionMode::Cycle(cycle) => cycle.name(),
            MotionMode::Probe(382) => "G38.2",
            MotionMode::Probe(383) => "G38.3",
            MotionMode::Probe(384) => "G38.4",
            MotionMode::Probe(_) => "G38.5",
            MotionMode::Spline { quadratic: false } => "G5",
            MotionMode::Spline { quadratic: true } => "G5.1",
            MotionMode::Nurbs => "G5.2",
            MotionMode::NurbsEnd => "G5.3",
            MotionMode::NurbsKnots => "G6.2",
            MotionMode::Thread => "G33",
            MotionMode::RigidTap => "G33.1",
            MotionMode::ThreadCycle => "G76",
            MotionMode::LatheCycle(cycle) => cycle.name(),
            MotionMode::Unsupported => "an unsupported cycle",
        }
    }
}

/// A canned cycle (G73, G81…G89).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Cycle {
    /// G73: peck drilling with chip breaking (Q).
    ChipBreak,
    /// G81: drilling.
    Drill,
    /// G82: drilling with a dwell (P) at the bottom.
    DrillDwell,
    /// G83: peck drilling (Q), retracting to R between pecks.
    Peck,
    /// G84: right-hand tapping.
    Tap,
    /// G85: boring, feed out.
    Bore,
    /// G86: boring, spindle stop, rapid out.
    BoreStop,
    /// G87: back boring (I, J, K).
    BackBore,
    /// G88: boring, spindle stop, manual out.
    BoreManual,
    /// G89: boring with a dwell, feed out.
    BoreDwell,
}

impl Cycle {
    /// The code as a machinist writes it.
    pub fn name(self) -> &'static str {
        match self {
            Cycle::ChipBreak => "G73",
            Cycle::Drill => "G81",
            Cycle::DrillDwell => "G82",
            Cycle::Peck => "G83",
            Cycle::Tap => "G84",
            Cycle::Bore => "G85",
            Cycle::BoreStop => "G86",
            Cycle::BackBore => "G87",
            Cycle::BoreManual => "G88",
            Cycle::BoreDwell => "G89",
        }
    }
}

/// A lathe cycle: G70 (finishing) or G71/G72 (roughing along Z / along X, the .1 forms
/// cutting no pockets, the .2 forms only after the first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LatheCycle {
    /// G70.
    Finishing,
    /// G71 (`facing` false), G72 (`facing` true); `pockets` 0, 1 or 2 (G7x, .1, .2).
    Roughing { facing: bool, pockets: u8 },
}

impl LatheCycle {
    /// The code as a machinist writes it.
    pub fn name(self) -> &'static str {
        match self {
            LatheCycle::Finishing => "G70",
            LatheCycle::Roughing { facing, pockets } => {
                ["G71", "G71.1", "G71.2", "G72", "G72.1", "G72.2"]
                    [usize::from(facing) * 3 + usize::from(pockets.min(2))]
            }
        }
    }
}

/// Tool length offset mode (modal group 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ToolLength {
    /// G43: the offsets of the tool table entry H (the current tool without H).
    Table,
    /// G43.1: the offsets given by the block's axis words.
    Dynamic,
    /// G43.2: add the offsets of entry H (or the axis words) to those in effect.
    Add,
    /// G49: no tool length offset.
    Cancel,
}

/// Distance mode (G90/G91).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Distance {
    /// G90: axis words are positions.
    #[default]
    Absolute,
    /// G91: axis words are increments.
    Incremental,
}

/// Feed rate mode (G93/G94/G95).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum FeedMode {
    /// G93: F is the inverse of the minutes each feed move takes.
    InverseTime,
    /// G94: F is units per minute.
    #[default]
    PerMinute,
    /// G95: F is units per spindle revolution (planned only with `--spindle-rpm-exact`).
    PerRevolution,
}

impl FeedMode {
    /// The code as a machinist writes it.
    pub fn name(self) -> &'static str {
        match self {
            FeedMode::InverseTime => "G93",
            FeedMode::PerMinute => "G94",
            FeedMode::PerRevolution => "G95",
        }
    }
}

/// Path control mode (G61/G61.1/G64).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum PathMode {
    /// G61: exact path; pvtc comes to rest at the end of every move, as for G61.1.
    ExactPath,
    /// G61.1: exact stop, the machine comes to rest at the end of every move.
    ExactStop,
    /// G64: continuous contouring.
    #[default]
    Continuous,
}

/// M70…M73: the modal state saved and restored (LinuxCNC's modal group 7, with the
/// spindle).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Context {
    /// M70: save the modal state at this call level.
    Save,
    /// M71: invalidate the state saved at this call level.
    Invalidate,
    /// M72: restore the state saved at this call level.
    Restore,
    /// M73: save it, and restore it when the subroutine returns.
    SaveAndRestoreOnReturn,
}

/// Non-modal codes (modal group 0) pvtc executes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NonModal {
    /// G4: dwell P seconds.
    Dwell,
    /// G53: this block's axis words are machine coordinates.
    MachineCoords,
    /// G92: offset the coordinate system so the axes given read their values here.
    SetOffset,
    /// G92.1 or G92.2: clear the G92 offsets (G92.2 keeps them for G92.3).
    ClearOffset {
        /// G92.2: keep the values for G92.3.
        keep: bool,
    },
    /// G92.3: restore offsets cleared by G92.2.
    RestoreOffset,
    /// G28 (0) or G30 (1): rapid through the axis words to the stored home position.
    Home(usize),
    /// G28.1 (0) or G30.1 (1): store the current position as that home position.
    SetHome(usize),
    /// G10: write a coordinate system (L2, L20) or a tool table entry (L1, L10, L11).
    SetTable,
    /// G52: a local offset, kept where G92 keeps its offset (as LinuxCNC does).
    LocalOffset,
}

/// Modal group 7: cutter-radius compensation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CutterComp {
    /// G40.
    Off,
    /// G41/G42 on a side; `true` for G41.1/G42.1, whose D is the tool's diameter.
    On(Side, bool),
}

/// An RS274NGC feature beyond what pvtc compiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Feature {
    /// The feature in machinist's words.
    pub name: &'static str,
    /// True when the code uses the block's axis words for something other than a move.
    pub uses_axis_words: bool,
}

/// What a G code does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum GCode {
    /// Modal group 1.
    Motion(MotionMode),
    /// G17/G18/G19.
    Plane(Plane),
    /// G20/G21.
    Units(Units),
    /// G90/G91.
    Distance(Distance),
    /// G93/G94/G95.
    FeedMode(FeedMode),
    /// G61 (exact path), G61.1 (exact stop) or G64 (continuous).
    PathMode(PathMode),
    /// G90.1/G91.1: arc centres absolute or incremental.
    ArcCenters(Distance),
    /// G7 (diameter, `true`) or G8 (radius) lathe mode.
    Diameter(bool),
    /// G54…G59, G59.1…G59.3: work coordinate system 0…8.
    CoordSystem(usize),
    /// Modal group 0: G4, G53, G92 and friends.
    NonModal(NonModal),
    /// G43, G43.1, G43.2, G49.
    ToolLength(ToolLength),
    /// G98 (`false`: back to the start level) or G99 (`true`: back to R) after a cycle.
    Retract(bool),
    /// G96 (`true`, constant surface speed) or G97 (spindle speed in rpm).
    SurfaceSpeed(bool),
    /// G40, G41/G42 (D: a tool of the table), G41.1/G42.1 (D: a diameter).
    CutterComp(CutterComp),
    /// A known code pvtc does not execute.
    Unsupported(Feature),
}

/// The code number in tenths (`G38.2` → 382), if it is a plausible code number.
pub(crate) fn tenths(value: f64) -> Option<u32> {
    let t = value * 10.0;
    let rounded = t.round();
    ((0.0..=9999.0).contains(&rounded) && (t - rounded).abs() < 1e-6).then_some(rounded as u32)
}

const fn feature(name: &'static str, uses_axis_words: bool) -> Feature {
    Feature {
        name,
        uses_axis_words,
    }
}

/// The G code with number `tenths`, if RS274NGC knows it.
pub(crate) fn g_code(tenths: u32) -> Option<GCode> {
    use GCode::*;
    Some(match tenths {
        0 => Motion(MotionMode::Rapid),
        10 => Motion(MotionMode::Linear),
        20 => Motion(MotionMode::Arc(ArcDirection::Clockwise)),
        30 => Motion(MotionMode::Arc(ArcDirection::CounterClockwise)),
        800 => Motion(MotionMode::Cancel),
        170 => Plane(pvt_core::Plane::XY),
        180 => Plane(pvt_core::Plane::ZX),
        190 => Plane(pvt_core::Plane::YZ),
        200 => Units(pvt_core::Units::Inch),
        210 => Units(pvt_core::Units::Millimetre),
        900 => Distance(self::Distance::Absolute),
        910 => Distance(self::Distance::Incremental),
        930 => FeedMode(self::FeedMode::InverseTime),
        940 => FeedMode(self::FeedMode::PerMinute),
        950 => FeedMode(self::FeedMode::PerRevolution),
        610 => PathMode(self::PathMode::ExactPath),
        611 => PathMode(self::PathMode::ExactStop),
        640 => PathMode(self::PathMode::Continuous),
        901 => ArcCenters(self::Distance::Absolute),
        911 => ArcCenters(self::Distance::Incremental),
        70 => Diameter(true),
        80 => Diameter(false),
        540 | 550 | 560 | 570 | 580 | 590 => CoordSystem((tenths as usize - 540) / 10),
        591..=593 => CoordSystem(tenths as usize - 585),
        40 => NonModal(self::NonModal::Dwell),
        530 => NonModal(self::NonModal::MachineCoords),
        920 => NonModal(self::NonModal::SetOffset),
        921 => NonModal(self::NonModal::ClearOffset { keep: false }),
        922 => NonModal(self::NonModal::ClearOffset { keep: true }),
        923 => NonModal(self::NonModal::RestoreOffset),
        400 => CutterComp(self::CutterComp::Off),
        410 => CutterComp(self::CutterComp::On(Side::Left, false)),
        411 => CutterComp(self::CutterComp::On(Side::Left, true)),
        420 => CutterComp(self::CutterComp::On(Side::Right, false)),
        421 => CutterComp(self::CutterComp::On(Side::Right, true)),
        490 => ToolLength(self::ToolLength::Cancel),
        430 => ToolLength(self::ToolLength::Table),
        431 => ToolLength(self::ToolLength::Dynamic),
        432 => ToolLength(self::ToolLength::Add),
        980 => Retract(false),
        990 => Retract(true),
        960 => SurfaceSpeed(true),
        970 => SurfaceSpeed(false),
        280 => NonModal(self::NonModal::Home(0)),
        300 => NonModal(self::NonModal::Home(1)),
        281 => NonModal(self::NonModal::SetHome(0)),
        100 => NonModal(self::NonModal::SetTable),
        520 => NonModal(self::NonModal::LocalOffset),
        301 => NonModal(self::NonModal::SetHome(1)),
        730 => Motion(MotionMode::Cycle(self::Cycle::ChipBreak)),
        810 => Motion(MotionMode::Cycle(self::Cycle::Drill)),
        820 => Motion(MotionMode::Cycle(self::Cycle::DrillDwell)),
        830 => Motion(MotionMode::Cycle(self::Cycle::Peck)),
        840 => Motion(MotionMode::Cycle(self::Cycle::Tap)),
        850 => Motion(MotionMode::Cycle(self::Cycle::Bore)),
        860 => Motion(MotionMode::Cycle(self::Cycle::BoreStop)),
        870 => Motion(MotionMode::Cycle(self::Cycle::BackBore)),
        880 => Motion(MotionMode::Cycle(self::Cycle::BoreManual)),
        890 => Motion(MotionMode::Cycle(self::Cycle::BoreDwell)),
        382..=385 => Motion(MotionMode::Probe(tenths)),
        50 => Motion(MotionMode::Spline { quadratic: false }),
        51 => Motion(MotionMode::Spline { quadratic: true }),
        52 => Motion(MotionMode::Nurbs),
        53 => Motion(MotionMode::NurbsEnd),
        62 => Motion(MotionMode::NurbsKnots),
        330 => Motion(MotionMode::Thread),
        331 => Motion(MotionMode::RigidTap),
        760 => Motion(MotionMode::ThreadCycle),
        700 => Motion(MotionMode::LatheCycle(self::LatheCycle::Finishing)),
        710..=712 | 720..=722 => Motion(MotionMode::LatheCycle(self::LatheCycle::Roughing {
            facing: tenths >= 720,
            pockets: (tenths % 10) as u8,
        })),
        _ => return unsupported_g(tenths).map(Unsupported),
    })
}

/// The feature of a G code pvtc knows but does not execute (motion group excluded).
fn unsupported_g(tenths: u32) -> Option<Feature> {
    Some(match tenths {
        171 | 181 | 191 => feature("UVW planes", false),
        _ => return None,
    })
}

/// The feature of a motion-group code pvtc does not execute.
pub(crate) fn motion_feature(_tenths: u32) -> &'static str {
    "motion modes"
}

/// What an M code does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MCode {
    /// M0 (`false`) or M1 (optional, `true`): program pause; ends the current contour.
    Pause(bool),
    /// M3/M4/M5.
    Spindle(SpindleState),
    /// M70…M73.
    Context(Context),
    /// M7/M8/M9.
    Coolant(CoolantState),
    /// M6.
    ToolChange,
    /// M2/M30: program end; nothing after it is read.
    End,
    /// M48…M53: override switches, accepted as state (pvtc plans at 100 %).
    Override,
    /// M62…M68: digital and analog I/O, an event with its words.
    Io(u16),
    /// M100…M199: a user-defined code, an event with its P and Q.
    User(u16),
    /// A known code pvtc does not execute.
    Unsupported(&'static str),
}

/// The M code with number `tenths`, if RS274NGC knows it.
pub(crate) fn m_code(tenths: u32) -> Option<MCode> {
    use MCode::*;
    Some(match tenths {
        0 => Pause(false),
        10 => Pause(true),
        20 | 300 => End,
        30 => Spindle(SpindleState::Clockwise),
        40 => Spindle(SpindleState::CounterClockwise),
        50 => Spindle(SpindleState::Off),
        60 => ToolChange,
        70 => Coolant(CoolantState::Mist),
        80 => Coolant(CoolantState::Flood),
        90 => Coolant(CoolantState::Off),
        190 => Unsupported("spindle orientation"),
        480..=530 if tenths.is_multiple_of(10) => Override,
        600 => Unsupported("pallet change"),
        610 => Unsupported("setting the current tool"),
        620..=680 if tenths.is_multiple_of(10) => Io((tenths / 10) as u16),
        700 => Context(self::Context::Save),
        710 => Context(self::Context::Invalidate),
        720 => Context(self::Context::Restore),
        730 => Context(self::Context::SaveAndRestoreOnReturn),
        1000..=1990 if tenths.is_multiple_of(10) => User((tenths / 10) as u16),
        _ => return None,
    })
}

/// What a letter pvtc does not read means in RS274NGC (for `unknown_word`).
pub(crate) fn letter_meaning(letter: u8) -> &'static str {
    match letter {
        b'E' => {
            "E is read only with M66, M67 and M68 (an extruder or a thread lead in other dialects)"
        }
        b'O' => "O words (subroutines, program numbers) are not read by pvtc",
        b'U' | b'V' | b'W' => "U, V and W are secondary axes, which pvtc does not drive",
        _ => "pvtc does not know this letter",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tenths_reads_decimal_codes() {
        assert_eq!(tenths(1.0), Some(10));
        assert_eq!(tenths(38.2), Some(382));
        assert_eq!(tenths(91.1), Some(911));
        assert_eq!(tenths(1.25), None);
        assert_eq!(tenths(-1.0), None);
        assert_eq!(tenths(1e300), None);
    }

    #[test]
    fn tables_classify_codes() {
        assert_eq!(g_code(10), Some(GCode::Motion(MotionMode::Linear)));
        assert_eq!(
            g_code(810),
            Some(GCode::Motion(MotionMode::Cycle(Cycle::Drill)))
        );
        assert_eq!(g_code(382), Some(GCode::Motion(MotionMode::Probe(382))));
        assert_eq!(g_code(430), Some(GCode::ToolLength(ToolLength::Table)));
        assert_eq!(
            g_code(421),
            Some(GCode::CutterComp(CutterComp::On(Side::Right, true)))
        );
        assert_eq!(g_code(7000), None);
        assert_eq!(m_code(60), Some(MCode::ToolChange));
        assert_eq!(m_code(600), Some(MCode::Unsupported("pallet change")));
        assert_eq!(m_code(500), Some(MCode::Override));
        assert_eq!(m_code(300), Some(MCode::End));
        assert_eq!(m_code(485), None);
        assert_eq!(m_code(15), None);
    }
}
