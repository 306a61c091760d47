//! The order in which one block takes effect: LinuxCNC's, step for step.
//!
//! Owns [`ORDER`], the one table of the steps of a block, which
//! [`super::Interpreter::execute`] runs in turn, and what each step reads of the block
//! ([`Step`]'s documentation). The order is rs274's `execute_block`, `convert_m` and
//! `convert_g` (LinuxCNC 2.9): a word takes effect at its step whatever its place in the
//! line, so `G20 F6` reads F6 in the units in force before the block (F is step 4, units
//! step 16), as LinuxCNC runs it. It must hold no state and do nothing itself: the
//! interpreter's functions do what each step names.

/// One step of a block's execution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step {
    /// `(MSG, …)`: a message to the operator.
    Comment,
    /// G96/G97: spindle speed mode (S a surface speed, or rpm).
    SpindleMode,
    /// G93/G94/G95: feed mode; G94 and G95 set the feed to 0, as LinuxCNC does.
    FeedMode,
    /// F: the feed, in the units in force at this step (before the block's G20/G21).
    Feed,
    /// S: the spindle speed.
    Speed,
    /// T: select a tool.
    SelectTool,
    /// M62…M68: digital and analog I/O.
    Io,
    /// M6: change to the selected tool.
    ChangeTool,
    /// M3/M4/M5, and M70…M73 (save, invalidate, restore, auto-restore the modal state),
    /// which share LinuxCNC's modal group 7.
    Spindle,
    /// M7/M8/M9.
    Coolant,
    /// M48…M53: override switches.
    Overrides,
    /// M100…M199: user-defined codes.
    User,
    /// G4: dwell.
    Dwell,
    /// G17/G18/G19.
    Plane,
    /// G20/G21.
    Units,
    /// G7/G8: lathe diameter or radius mode.
    LatheDiameter,
    /// G40, G41/G42, G41.1/G42.1.
    CutterComp,
    /// G43, G43.1, G43.2, G49.
    ToolLength,
    /// G54…G59.3.
    CoordSystem,
    /// G61, G61.1, G64 (P, Q).
    PathControl,
    /// G90/G91.
    Distance,
    /// G90.1/G91.1: arc centre distance mode.
    ArcDistance,
    /// G98/G99: canned cycle return level.
    Retract,
    /// G10, G28/G30, G28.1/G30.1, G52, G92, G92.1, G92.2, G92.3.
    NonModal,
    /// The motion mode's move (G0…G3, G5…, G33, G38.n, G7x, G73, G76, G80…G89), G53
    /// applying to it.
    Motion,
    /// M0, M1, M2, M30.
    Stop,
}

/// The steps of a block, in the order they run.
pub(crate) const ORDER: [Step; 26] = [
    Step::Comment,
    Step::SpindleMode,
    Step::FeedMode,
    Step::Feed,
    Step::Speed,
    Step::SelectTool,
    Step::Io,
    Step::ChangeTool,
    Step::Spindle,
    Step::Coolant,
    Step::Overrides,
    Step::User,
    Step::Dwell,
    Step::Plane,
    Step::Units,
    Step::LatheDiameter,
    Step::CutterComp,
    Step::ToolLength,
    Step::CoordSystem,
    Step::PathControl,
    Step::Distance,
    Step::ArcDistance,
    Step::Retract,
    Step::NonModal,
    Step::Motion,
    Step::Stop,
];

#[cfg(test)]
mod tests {
    use super::*;

    fn at(step: Step) -> usize {
        ORDER.iter().position(|s| *s == step).expect("in the table")
    }

    /// Each step runs once, and the orderings LinuxCNC documents hold.
    #[test]
    fn the_table_is_linuxcnc_order() {
        for (i, step) in ORDER.iter().enumerate() {
            assert_eq!(at(*step), i, "{step:?} appears once");
        }
        assert!(at(Step::FeedMode) < at(Step::Feed));
        assert!(at(Step::Feed) < at(Step::Units), "F before G20/G21");
        assert!(at(Step::Speed) < at(Step::Spindle), "S before M3");
        assert!(at(Step::ChangeTool) < at(Step::ToolLength), "M6 before G43");
        assert!(at(Step::Dwell) < at(Step::Plane));
        assert!(at(Step::Units) < at(Step::CutterComp));
        assert!(at(Step::CoordSystem) < at(Step::Distance));
        assert!(at(Step::NonModal) < at(Step::Motion));
        assert_eq!(ORDER.last(), Some(&Step::Stop));
    }
}
