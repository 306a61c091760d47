//! Machine parameters as a view of the interpreter's state: LinuxCNC's readable numbered
//! parameters (#5161–#5428) and predefined named ones (`#<_x>`, `#<_metric>`, …).
//!
//! Owns the meaning of each number and name, answered from a [`MachineView`] the
//! interpreter fills after every block (one function each: [`numbered`], [`named`]). It
//! must not hold state of its own nor change the interpreter's; values only a running
//! machine knows (probe results, M66 inputs, HAL pins, ini values) are [`Answer::Machine`]
//! with the feature's name, for one `unsupported` diagnostic per feature.

/// What the interpreter knows at the end of a block, as LinuxCNC reports its
/// parameters: the position in program units, stored offsets in the machine's units,
/// which for pvtc are millimetres (a metric LinuxCNC machine; rs274 run alone has inch
/// machine units and reads them in inches). Rotary axes in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MachineView {
    /// The position in the active coordinate system, every offset applied (#5420–#5425).
    pub position: [f64; 6],
    /// The G92 offsets (#5211–#5216), millimetres.
    pub g92: [f64; 6],
    /// G92 offsets are in effect (#5210).
    pub g92_active: bool,
    /// Work coordinate system, 0 (G54) … 8 (G59.3).
    pub coord_system: usize,
    /// Millimetres per program unit (1 under G21, 25.4 under G20).
    pub mm_per_unit: f64,
    /// G90 (not G91).
    pub absolute: bool,
    /// G93 (not G94).
    pub inverse_time: bool,
    /// The motion mode as ten times its G number (G1 is 10, G80 is 800); -1 when none.
    pub motion_tenths: i32,
    /// The plane as ten times its G number (170, 180, 190).
    pub plane_tenths: i32,
    /// The F number in force, as written.
    pub feed: f64,
    /// The S number in force.
    pub rpm: f64,
    /// The tool in the spindle (after M6, #5400) and the one selected by T.
    pub current_tool: f64,
    pub selected_tool: f64,
    /// The tool length offset in effect (#5401–#5406), millimetres.
    pub tool_offset: [f64; 6],
    /// The loaded tool's diameter (#5410), millimetres.
    pub tool_diameter: f64,
    /// Work offsets G54…G59.3 as G10 left them, millimetres.
    pub work_offsets: [[f64; 6]; 9],
    /// The XY rotation of each coordinate system, degrees (#5230, #5250, …).
    pub rotations: [f64; 9],
    /// G28 and G30 home positions, millimetres.
    pub homes: [[f64; 6]; 2],
    /// The line being read (file line number).
    pub line: u32,
    /// Subroutine call depth (0 in the main program).
    pub call_level: u32,
    /// Where the last probing move tripped (#5061–#5066, program units), from
    /// [`crate::GcodeOptions::probe_results`]; `None` before any.
    pub probe: Option<[f64; 6]>,
}

impl Default for MachineView {
    fn default() -> Self {
        MachineView {
            position: [0.0; 6],
            g92: [0.0; 6],
            g92_active: false,
            coord_system: 0,
            mm_per_unit: 1.0,
            absolute: true,
            inverse_time: false,
            motion_tenths: 0,
            plane_tenths: 170,
            feed: 0.0,
            rpm: 0.0,
            current_tool: 0.0,
            selected_tool: 0.0,
            tool_offset: [0.0; 6],
            tool_diameter: 0.0,
            work_offsets: [[0.0; 6]; 9],
            rotations: [0.0; 9],
            homes: [[0.0; 6]; 2],
            line: 0,
            call_level: 0,
            probe: None,
        }
    }
}

/// How a machine parameter reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Answer {
    /// Its value.
    Value(f64),
    /// Only a running machine knows it: the feature, for the `unsupported` diagnostic.
    Machine(&'static str),
    /// Not a machine parameter: the store answers.
    NotMachine,
}

/// Probe results #5061–#5070.
pub(crate) const PROBE_FEATURE: &str = "probe results (#5061–#5070)";
/// The M66 input result #5399.
pub(crate) const INPUT_FEATURE: &str = "M66 input results (#5399)";

/// The parameter `#index` as LinuxCNC defines it. `assigned` says whether the program
/// wrote the parameter: a written offset or home reads back as written (as LinuxCNC's
/// stored parameters do), while the position, tool and coordinate system are live.
pub(crate) fn numbered(view: &MachineView, index: usize, assigned: bool) -> Answer {
    let axis9 = |first: usize| index.checked_sub(first).filter(|i| *i < 9);
    // Live values: U V W (indices 6–8) are 0, pvtc has no such axes.
    if let Some(i) = axis9(5420) {
        return Answer::Value(view.position.get(i).copied().unwrap_or(0.0));
    }
    match index {
        5061..=5066 if view.probe.is_some() => {
            return Answer::Value(view.probe.map_or(0.0, |p| p[index - 5061]))
        }
        // Tripped: a result was given.
        5070 if view.probe.is_some() => return Answer::Value(1.0),
        5067..=5069 if view.probe.is_some() => return Answer::Value(0.0),
        5061..=5070 => return Answer::Machine(PROBE_FEATURE),
        5399 => return Answer::Machine(INPUT_FEATURE),
        5220 => return Answer::Value((view.coord_system + 1) as f64),
        5400 => return Answer::Value(view.current_tool),
        5401..=5406 => return Answer::Value(view.tool_offset[index - 5401]),
        5410 => return Answer::Value(view.tool_diameter),
        // U V W offsets, front and back angles, orientation: 0 in pvtc.
        5407..=5409 | 5411..=5413 => return Answer::Value(0.0),
        5210 => return Answer::Value(if view.g92_active { 1.0 } else { 0.0 }),
        _ => {}
    }
    if assigned {
        return Answer::NotMachine;
    }
    if let Some(i) = axis9(5211) {
        return Answer::Value(view.g92.get(i).copied().unwrap_or(0.0));
    }
    for (row, first) in [(0, 5161), (1, 5181)] {
        if let Some(i) = axis9(first) {
            return Answer::Value(view.homes[row].get(i).copied().unwrap_or(0.0));
        }
    }
    if (5221..=5390).contains(&index) {
        let (system, field) = ((index - 5221) / 20, (index - 5221) % 20);
        // Fields 0–8 are X…W, 9 is the XY rotation.
        let value = match field {
            9 => view.rotations[system],
            _ => view.work_offsets[system].get(field).copied().unwrap_or(0.0),
        };
        return Answer::Value(value);
    }
    Answer::NotMachine
}

/// The predefined named parameter `name` (normalized, with its leading `_`), or
/// [`Answer::NotMachine`] when LinuxCNC has no such name (the store answers).
pub(crate) fn named(view: &MachineView, name: &str) -> Answer {
    let truth = |t: bool| Answer::Value(if t { 1.0 } else { 0.0 });
    let axis = |i: usize| Answer::Value(view.position[i]);
    match name {
        "_x" => axis(0),
        "_y" => axis(1),
        "_z" => axis(2),
        "_a" => axis(3),
        "_b" => axis(4),
        "_c" => axis(5),
        "_u" | "_v" | "_w" => Answer::Value(0.0),
        "_metric" => truth(view.mm_per_unit == 1.0),
        "_imperial" => truth(view.mm_per_unit != 1.0),
        "_absolute" => truth(view.absolute),
        "_incremental" => truth(!view.absolute),
        "_inverse_time" => truth(view.inverse_time),
        "_units_per_minute" => truth(!view.inverse_time),
        "_units_per_rev" => truth(false),
        "_feed" => Answer::Value(view.feed),
        "_rpm" => Answer::Value(view.rpm),
        "_current_tool" | "_current_pocket" => Answer::Value(view.current_tool),
        "_selected_tool" | "_selected_pocket" => Answer::Value(view.selected_tool),
        "_motion_mode" => Answer::Value(f64::from(view.motion_tenths)),
        "_plane" => Answer::Value(f64::from(view.plane_tenths)),
        "_coord_system" => Answer::Value(coord_system_code(view.coord_system)),
        "_line" => Answer::Value(f64::from(view.line)),
        "_call_level" => Answer::Value(f64::from(view.call_level)),
        // Cutter compensation off (G40), no tool length offset, preview (not a task).
        "_ccomp" => Answer::Value(400.0),
        "_tool_offset" | "_task" | "_remap_level" => Answer::Value(0.0),
        _ if name.starts_with("_hal[") => {
            Answer::Machine("HAL pins (#<_hal[…]>) without --hal NAME=VALUE")
        }
        _ if name.starts_with("_ini[") => Answer::Machine("ini values (#<_ini[…]>)"),
        _ => Answer::NotMachine,
    }
}

/// `#<_coord_system>`: 540, 550, …, 590, 591, 592, 593.
fn coord_system_code(system: usize) -> f64 {
    match system {
        0..=5 => 540.0 + 10.0 * system as f64,
        _ => 585.0 + system as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stored() -> MachineView {
        let mut work_offsets = [[0.0; 6]; 9];
        work_offsets[1] = [25.4, 50.8, -254.0, 90.0, 0.0, 0.0];
        MachineView {
            work_offsets,
            homes: [[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [0.0; 6]],
            ..MachineView::default()
        }
    }

    #[test]
    fn offsets_read_in_millimetres_whatever_the_program_units() {
        let view = MachineView {
            mm_per_unit: 25.4,
            ..stored()
        };
        // G55 is the second row: #5241 X, #5242 Y, #5243 Z, #5244 A.
        assert_eq!(numbered(&view, 5241, false), Answer::Value(25.4));
        assert_eq!(numbered(&view, 5242, false), Answer::Value(50.8));
        assert_eq!(numbered(&view, 5243, false), Answer::Value(-254.0));
        assert_eq!(numbered(&view, 5244, false), Answer::Value(90.0));
        assert_eq!(numbered(&view, 5250, false), Answer::Value(0.0));
        assert_eq!(numbered(&view, 5164, false), Answer::Value(4.0));
        // Written by the program: the store answers.
        assert_eq!(numbered(&view, 5241, true), Answer::NotMachine);
    }

    #[test]
    fn live_values_and_machine_only_ones() {
        let view = MachineView {
            position: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            coord_system: 8,
            current_tool: 7.0,
            tool_offset: [0.0, 0.0, 1.5, 0.0, 0.0, 0.0],
            ..stored()
        };
        assert_eq!(numbered(&view, 5420, true), Answer::Value(1.0));
        assert_eq!(numbered(&view, 5425, false), Answer::Value(6.0));
        assert_eq!(numbered(&view, 5428, false), Answer::Value(0.0));
        assert_eq!(numbered(&view, 5220, false), Answer::Value(9.0));
        assert_eq!(numbered(&view, 5400, false), Answer::Value(7.0));
        assert_eq!(numbered(&view, 5403, false), Answer::Value(1.5));
        assert_eq!(numbered(&view, 5063, false), Answer::Machine(PROBE_FEATURE));
        assert_eq!(numbered(&view, 100, false), Answer::NotMachine);
        assert_eq!(named(&view, "_coord_system"), Answer::Value(593.0));
        assert_eq!(named(&view, "_c"), Answer::Value(6.0));
        assert!(matches!(named(&view, "_hal[x]"), Answer::Machine(_)));
        assert_eq!(named(&view, "_nope"), Answer::NotMachine);
    }
}
