//! Tools, homes and the modes pvtc accepts as state: T and M6, tool length offsets
//! (G43, G43.1, G43.2, G49) from the tool table, G28/G30 and G28.1/G30.1, G96/G97,
//! M48…M53, G64 Q, and the checks on words only these codes use (H, D, L, Q).
//!
//! Owns the tool and home state, kept as plain fields of the interpreter (current tool
//! #5400, offsets #5401…, homes #5161…/#5181…) and what each of these codes does to it.
//! Homes and tool offsets are output units; a home is a machine position, which G28/G30
//! reach whatever tool offset is in effect (as G53 does); in a turned system the home is
//! read in the turned frame, as rs274 reads it. It must not read words nor expand cycles.

use pvt_core::{Axis, Motion, Position, AXIS_COUNT};

use super::Interpreter;
use crate::block::Block;
use crate::codes::{MotionMode, NonModal, PathMode, ToolLength};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;

/// The tool state: selected (T), loaded (M6), and the tool length offset in effect.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ToolState {
    /// The tool a T word selected, until M6 loads it.
    pub selected: Option<u32>,
    /// The loaded tool (#5400); 0 is no tool.
    pub current: u32,
    /// The tool length offset in effect, X Y Z A B C, output units (degrees).
    pub offset: Position,
    /// The tool length offset in effect at the end of the last move.
    pub moved_with: Position,
    /// Where the machine is while the interpreter's position is rs274's re-reading after
    /// M6 (see [`Interpreter::reread_after_tool_change`]); the next move starts here.
    pub machine_at: Option<Position>,
}

impl Interpreter<'_> {
    /// G43, G43.1, G43.2, G49.
    pub(super) fn set_tool_length(&mut self, request: &Request) {
        let Some((mode, word)) = request.tool_length else {
            return;
        };
        self.output_units.get_or_insert(self.modal.units);
        match mode {
            ToolLength::Cancel => self.tool.offset = [0.0; AXIS_COUNT],
            ToolLength::Table => {
                let number = match request.h {
                    Some(h) => match super::whole(h.value) {
                        Some(n) => n,
                        None => return self.push(super::bad_value(h, "a tool number ≥ 0")),
                    },
                    None => self.tool.current,
                };
                let at = request.h.unwrap_or(word);
                if let Some(offset) = self.table_offset(number, at) {
                    self.tool.offset = offset;
                }
            }
            ToolLength::Dynamic | ToolLength::Add => {
                if mode == ToolLength::Add {
                    if let Some(h) = request.h {
                        let Some(number) = super::whole(h.value) else {
                            return self.push(super::bad_value(h, "a tool number ≥ 0"));
                        };
                        if let Some(offset) = self.table_offset(number, h) {
                            for (sum, add) in self.tool.offset.iter_mut().zip(offset) {
                                *sum += add;
                            }
                        }
                    }
                }
                for axis in Axis::ALL {
                    if let Some(w) = request.axes[axis.index()] {
                        let value = self.program_value(axis, w.value);
                        match mode {
                            ToolLength::Add => self.tool.offset[axis.index()] += value,
                            _ => self.tool.offset[axis.index()] = value,
                        }
                    }
                }
                if mode == ToolLength::Dynamic && !request.has_axis_words() {
                    self.push(super::missing(word, "at least one axis word"));
                }
            }
        }
    }

    /// After a block with M6, rs274 re-reads its position as its last move left it in
    /// program coordinates, without the tool length offsets set since (in that block or
    /// before): the offset change moves where the program is, not where the machine
    /// is. The interpreter takes that position; the machine stays where it is until the
    /// next move, which starts from there ([`ToolState::machine_at`]).
    pub(super) fn reread_after_tool_change(&mut self, request: &Request) {
        if request.tool_change.is_none() {
            return;
        }
        // After G40 the tool stands off the programmed point; rs274 reads where it is.
        if let Some(at) = self.take_exit_point() {
            self.position = at;
        }
        let shift: Position =
            std::array::from_fn(|i| self.tool.offset[i] - self.tool.moved_with[i]);
        if shift.iter().all(|s| *s == 0.0) {
            return;
        }
        self.tool.machine_at.get_or_insert(self.position);
        for (p, s) in self.position.iter_mut().zip(shift) {
            *p += s;
        }
        self.tool.moved_with = self.tool.offset;
    }

    /// Where the machine is: the position, or where a move after M6 starts from.
    pub(super) fn machine_position(&self) -> Position {
        self.tool.machine_at.unwrap_or(self.position)
    }

    /// The offsets of tool `number` in output units; H0 is none. `None` after reporting
    /// a tool the table lacks.
    fn table_offset(&mut self, number: u32, at: crate::block::Word) -> Option<Position> {
        if number == 0 {
            return Some([0.0; AXIS_COUNT]);
        }
        let Some(tool) = self.tools.get(number) else {
            self.push(GcodeDiagnostic::UnknownTool {
                tool: number,
                span: span(at.span()),
            });
            return None;
        };
        let mut offset = tool.offsets;
        for axis in Axis::ALL {
            if !axis.is_rotary() {
                offset[axis.index()] = self.output().from_mm(offset[axis.index()]);
            }
        }
        Some(offset)
    }

    /// G28/G30: rapid to the axis words (the intermediate point), then those axes (all
    /// without axis words) to the home; G28.1/G30.1: store the home.
    pub(super) fn home(&mut self, request: &Request, block: &Block) {
        let Some((code, _)) = request.non_modal else {
            return;
        };
        match code {
            NonModal::SetHome(k) => {
                self.homes[k] = self.position;
            }
            NonModal::Home(k) => {
                self.output_units.get_or_insert(self.modal.units);
                let via = match self.target(request) {
                    Ok(via) => via,
                    Err(diagnostic) => return self.push(diagnostic),
                };
                let all = !request.has_axis_words();
                let mut end = via;
                for ((end, home), word) in end.iter_mut().zip(self.homes[k]).zip(request.axes) {
                    if all || word.is_some() {
                        *end = home;
                    }
                }
                if self.rotation() != 0.0 && (all || request.axes[0].or(request.axes[1]).is_some())
                {
                    // As rs274: the home read in the program's (turned) frame gives the
                    // X and Y with words; the other one keeps the intermediate point's.
                    let mut program = self.to_program(via);
                    let home = self.to_program(self.homes[k]);
                    for i in [0, 1] {
                        if all || request.axes[i].is_some() {
                            program[i] = home[i];
                        }
                    }
                    let placed = self.to_machine(program);
                    end[..2].copy_from_slice(&placed[..2]);
                }
                let rate = self.rapid_rate();
                for point in [via, end] {
                    let start = self.machine_position();
                    self.position = point;
                    if point != start {
                        self.straight(Motion::Rapid, start, point, rate, block);
                    }
                }
            }
            _ => {}
        }
    }

    /// G10 L1/L10/L11 (tool table) and L2/L20 (coordinate systems); G52.
    pub(super) fn set_tables(&mut self, request: &Request) {
        let Some((code @ (NonModal::SetTable | NonModal::LocalOffset), word)) = request.non_modal
        else {
            return;
        };
        self.output_units.get_or_insert(self.modal.units);
        if code == NonModal::LocalOffset {
            for axis in Axis::ALL {
                if let Some(w) = request.axes[axis.index()] {
                    self.g92[axis.index()] = self.program_value(axis, w.value);
                }
            }
            return;
        }
        let Some(l) = request.l else {
            return self.push(super::missing(word, "an L word (L1, L2, L10, L11 or L20)"));
        };
        let Some(p) = request.p else {
            return self.push(super::missing(word, "a P word (which table entry)"));
        };
        let Some(p_number) = super::whole(p.value) else {
            return self.push(super::bad_value(p, "a whole number ≥ 0"));
        };
        if let (Some(r), false) = (request.radius, l.value == 2.0) {
            return self.push(super::bad_value(r, "R (a rotation) with G10 L2 only"));
        }
        let mm = |me: &Self, axis: Axis, value: f64| match axis.is_rotary() {
            true => value,
            false => value * me.output().mm_per_unit(),
        };
        match l.value {
            2.0 | 20.0 => {
                let row = match p_number {
                    0 => self.modal.coord_system,
                    1..=9 => p_number as usize - 1,
                    _ => {
                        return self.push(super::bad_value(p, "P0 (current) or P1…P9 (G54…G59.3)"))
                    }
                };
                let rotation = self.rotations[row];
                // L20 in a rotated system: the current position read in the program's
                // frame (axis words replacing X, Y) sets the X and Y offsets together,
                // turned by the row's rotation, as LinuxCNC does.
                let turned = l.value == 20.0
                    && (rotation != 0.0 || self.rotation() != 0.0)
                    && (request.axes[0].is_some() || request.axes[1].is_some());
                if turned {
                    let mut program = self.to_program(self.position);
                    for axis in [Axis::X, Axis::Y] {
                        if let Some(w) = request.axes[axis.index()] {
                            program[axis.index()] = self.program_value(axis, w.value);
                        }
                    }
                    let (sin, cos) = libm::sincos(rotation.to_radians());
                    let (x, y) = (program[0] + self.g92[0], program[1] + self.g92[1]);
                    let turned = [x * cos - y * sin, x * sin + y * cos];
                    for axis in [Axis::X, Axis::Y] {
                        let i = axis.index();
                        let offset = self.position[i] - self.tool.offset[i] - turned[i];
                        self.work_offsets[row][i] = mm(self, axis, offset);
                    }
                }
                for axis in Axis::ALL {
                    let i = axis.index();
                    let Some(w) = request.axes[i] else { continue };
                    if turned && i < 2 {
                        continue;
                    }
                    let value = self.program_value(axis, w.value);
                    let offset = match l.value == 2.0 {
                        true => value,
                        false => self.position[i] - self.g92[i] - self.tool.offset[i] - value,
                    };
                    self.work_offsets[row][i] = mm(self, axis, offset);
                }
                if let Some(r) = request.radius {
                    self.rotations[row] = r.value;
                }
            }
            1.0 | 10.0 | 11.0 => {
                if self.tools.get(p_number).is_none() {
                    return self.push(GcodeDiagnostic::UnknownTool {
                        tool: p_number,
                        span: span(p.span()),
                    });
                }
                let rotation = match l.value {
                    10.0 => self.rotation(),
                    _ => self.rotations[8],
                };
                if let (Some(w), true) = (request.axes[0].or(request.axes[1]), rotation != 0.0) {
                    return self.push(GcodeDiagnostic::Unsupported {
                        code: format!("G10 L{}", l.value),
                        feature: "X/Y tool offsets from a rotated coordinate system",
                        places: 1,
                        span: span(w.span()),
                    });
                }
                let mut values = [None; AXIS_COUNT];
                for axis in Axis::ALL {
                    let i = axis.index();
                    let Some(w) = request.axes[i] else { continue };
                    let value = self.program_value(axis, w.value);
                    let offset = match l.value {
                        1.0 => value,
                        // L10: the current position reads `value` with this tool's
                        // offset; L11 as L10 in G59.3 without G92.
                        10.0 => self.position[i] - (self.offset(i) - self.tool.offset[i]) - value,
                        _ => {
                            let work = self.work_offsets[8][i];
                            let work = match axis.is_rotary() {
                                true => work,
                                false => self.output().from_mm(work),
                            };
                            self.position[i] - work - value
                        }
                    };
                    values[i] = Some(mm(self, axis, offset));
                }
                if let Some(tool) = self.tools.get_mut(p_number) {
                    for (slot, value) in tool.offsets.iter_mut().zip(values) {
                        if let Some(v) = value {
                            *slot = v;
                        }
                    }
                }
            }
            _ => self.push(super::bad_value(l, "L1, L2, L10, L11 or L20 with G10")),
        }
    }

    /// Warnings for H, D, L and Q words no code of the block uses.
    pub(super) fn check_words(&mut self, request: &Request) {
        if self.modal.motion == Some(MotionMode::Unsupported) {
            return; // the unsupported code was reported; its words are not checked
        }
        let cycle = matches!(
            self.modal.motion,
            Some(MotionMode::Cycle(_) | MotionMode::ThreadCycle)
        );
        let h_used = matches!(
            request.tool_length,
            Some((ToolLength::Table | ToolLength::Add, _))
        ) || self.modal.motion == Some(MotionMode::ThreadCycle);
        let codes = request.io.is_some() || request.user.is_some();
        let compensation_on = matches!(
            request.cutter_comp,
            Some((crate::codes::CutterComp::On(..), _))
        );
        let q_used = cycle
            || codes
            || self.modal.motion == Some(MotionMode::NurbsKnots)
            || matches!(request.path_mode, Some((PathMode::Continuous, _)));
        let lathe = matches!(self.modal.motion, Some(MotionMode::LatheCycle(_)));
        let q_used = q_used || lathe;
        let d_used = self.modal.surface_speed || compensation_on || lathe;
        let l_used = cycle
            || self.modal.motion == Some(MotionMode::Nurbs)
            || compensation_on
            || matches!(request.io, Some((66, _)))
            || matches!(request.non_modal, Some((NonModal::SetTable, _)));
        let checks = [
            (
                request.h,
                h_used,
                "no code of this block takes H (G43, G43.2 do)",
            ),
            (
                request.d,
                d_used,
                "D is the maximum spindle speed of G96 only",
            ),
            (
                request.l,
                l_used,
                "no code of this block takes L (G10, canned cycles do)",
            ),
            (
                request.q,
                q_used,
                "no code of this block takes Q (G64, G73, G83 do)",
            ),
        ];
        for (word, used, reason) in checks {
            if let (Some(word), false) = (word, used) {
                self.push(GcodeDiagnostic::IgnoredWord {
                    word: word.name(),
                    reason,
                    span: span(word.span()),
                });
            }
        }
    }
}
