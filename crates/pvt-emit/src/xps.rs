//! Newport XPS PVT trajectory file (`--format xps`).
//!
//! Owns the XPS spelling of a program. Source: Newport, *XPS-Q8 Universal
//! High-Performance Motion Controller/Driver User's Manual, Software Tools and Tutorial*,
//! V1.4.x (EDH0301En1060, 10/17), §8.3 "PVT Trajectories", §8.3.6 "Trajectory File
//! Description" and §8.3.8 "PVT Trajectory Verification and Execution"
//! (<https://www.manualslib.com/manual/1309985/Newport-Xps-Q8.html?page=116>), and the
//! EPICS motor driver `XPSController.cpp` (`buildProfile`), which writes such files:
//!
//! - one line per element, no header: `duration, dX, vX, dY, vY, …`, the duration in
//!   seconds, then per positioner its displacement from the previous point and its
//!   velocity at the end of the element, in the group's user units and units/s;
//! - the positioners in the order of the MultipleAxes group (1 to 8) in `system.ini`:
//!   here the program's axes in order (`X Y Z A B C` as moved);
//! - `MultipleAxesPVTVerification` refuses a trajectory with −68 (velocity too high),
//!   −69 (acceleration too high), −70 (final velocity not zero) or −75 (non-positive
//!   time); pvtc checks the same before writing ([`crate::rules`], with the machine
//!   file's limits) and names the code in its diagnostic;
//! - the file is relative, so the XPS cannot check travel limits (the EPICS driver
//!   checks them on the host): pvtc checks the machine file's `min_position` and
//!   `max_position` for every piece.
//!
//! Numbers are the shortest round-trip form, so durations and velocities are the
//! planner's exactly; each displacement is the difference of two planned positions.
//! The trajectory starts wherever the group is: the host moves it to the first contour's
//! start (`GroupMoveAbsolute`) before `MultipleAxesPVTExecution`. A dwell is an element
//! at rest; other events have no place in the file and are left out.
//!
//! Assumed, not found in the manual pages searched: the shortest element the XPS takes.
//! [`CAPS`] takes one cycle of a 10 kHz servo loop, 100 µs.

use crate::lines::Lines;
use crate::rules::{Caps, Positions};
use crate::triggers::TriggerSupport;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// The XPS's rules: relative positions, verification of the whole trajectory, no time
/// grid of its own; the shortest element (100 µs) is assumed, and `--quantize` defaults to
/// it so that shorter pieces (a jerk-limited plan makes some of a few µs) are merged.
pub const CAPS: Caps = Caps {
    controller: "Newport XPS",
    time_quantum: None,
    quantum_required: false,
    default_quantum: Some(1e-4),
    min_piece_seconds: 1e-4,
    max_piece_seconds: None,
    positions: Positions::Relative,
    position_unit: "user units, relative",
    velocity_unit: "user units/s",
    scaled: false,
    buffer_depth: None,
    verifies: true,
    triggers: TriggerSupport::None(
        "the trajectory file holds motion only; for a pulse every T s the host calls \
         MultipleAxesPVTPulseOutputSet(group, first element, last element, T) before \
         MultipleAxesPVTExecution",
    ),
    velocity_per_count: 1.0,
};

/// Streams an XPS PVT trajectory file to `W`.
pub struct XpsWriter<W> {
    lines: Lines<W>,
    /// The position the next displacement starts from.
    last: Vec<f64>,
}

impl<W: Write> XpsWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> XpsWriter<W> {
        XpsWriter {
            lines: Lines::new(out),
            last: Vec::new(),
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.lines.into_inner()
    }

    fn element(&mut self, duration: f64, end: &[f64], velocity: &[f64]) -> io::Result<()> {
        self.lines.exact(duration);
        for ((last, p), v) in self.last.iter_mut().zip(end).zip(velocity) {
            self.lines.str(", ");
            self.lines.exact(p - *last);
            self.lines.str(", ");
            self.lines.exact(*v);
            *last = *p;
        }
        self.lines.end_line()
    }
}

impl<W: Write> ProgramWriter for XpsWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.last = vec![0.0; header.axes.len()];
        Ok(())
    }

    fn contour(&mut self, _: Motion, start: &[f64]) -> io::Result<()> {
        self.last.copy_from_slice(start);
        Ok(())
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        self.element(seg.duration, seg.end, seg.velocity)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if let EventKind::Dwell { seconds } = event.kind {
            if seconds > 0.0 {
                let here = self.last.clone();
                let rest = vec![0.0; here.len()];
                return self.element(seconds, &here, &rest);
            }
        }
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        CAPS
    }
}
