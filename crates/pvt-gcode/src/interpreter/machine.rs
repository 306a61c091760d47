//! Tools, homes and the modes pvtc accepts as state: T and M6, tool length offsets
//! (G43, G43.1, G43.2, G49) from the tool table, G28/G30 and G28.1/G30.1, G96/G97,
//! M48…M53, G64 Q, and the checks on words only these codes use (H, D, L, Q).
//!
//! Owns the tool and home state, kept as plain fields of the interpreter (current tool
//! #5400, offsets #5401…, homes #5161…/#5181…) and what each of these codes does to it.
//! Homes and tool offsets are output units; a home is a machine position without the
//! tool offset, as LinuxCNC stores it. It must not read words nor expand cycles.

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

    /// The offsets of tool `number` in output units; H0 is none. `None` after reporting
    /// a tool the table lacks.
    fn table_offset(&mut self, number: u32, at: crate::block::Word) -> Option<Position> {
        if number == 0 {
            return Some([0.0; AXIS_COUNT]);
        }
        let Some(tool) = self.options.tool_table.get(number) else {
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
                for i in 0..AXIS_COUNT {
                    self.homes[k][i] = self.position[i] - self.tool.offset[i];
                }
            }
            NonModal::Home(k) => {
                self.output_units.get_or_insert(self.modal.units);
                let via = match self.target(request) {
                    Ok(via) => via,
                    Err(diagnostic) => return self.push(diagnostic),
                };
                let all = !request.has_axis_words();
                let mut end = via;
                for i in 0..AXIS_COUNT {
                    if all || request.axes[i].is_some() {
                        end[i] = self.homes[k][i] + self.tool.offset[i];
                    }
                }
                let rate = self.rapid_rate();
                for point in [via, end] {
                    let start = self.position;
                    self.position = point;
                    if point != start {
                        self.straight(Motion::Rapid, start, point, rate, block);
                    }
                }
            }
            _ => {}
        }
    }

    /// M6 loads the selected tool; G96/G97 and G64 Q are kept as state.
    pub(super) fn machine_state(&mut self, request: &Request) {
        if let Some(t) = request.t.and_then(|t| super::whole(t.value)) {
            self.tool.selected = Some(t);
        }
        if request.tool_change.is_some() {
            if let Some(t) = self.tool.selected {
                self.tool.current = t;
            }
        }
        if let Some((css, _)) = request.surface_speed {
            self.surface_speed = css;
        }
        if let (Some((PathMode::Continuous, _)), Some(q)) = (request.path_mode, request.q) {
            self.naive_cam_tolerance = Some(q.value.abs() * self.scale());
        }
    }

    /// Warnings for H, D, L and Q words no code of the block uses.
    pub(super) fn check_words(&mut self, request: &Request) {
        let cycle = matches!(self.modal.motion, Some(MotionMode::Cycle(_)));
        let h_used = matches!(
            request.tool_length,
            Some((ToolLength::Table | ToolLength::Add, _))
        );
        let q_used = cycle || matches!(request.path_mode, Some((PathMode::Continuous, _)));
        let d_used = self.surface_speed;
        let checks = [
            (request.h, h_used, "no code of this block takes H (G43, G43.2 do)"),
            (request.d, d_used, "D is the maximum spindle speed of G96 only"),
            (request.l, cycle, "no code of this block takes L (canned cycles do)"),
            (request.q, q_used, "no code of this block takes Q (G64, G73, G83 do)"),
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
