//! Zaber ASCII protocol PVT sequence commands (`--format zaber`).
//!
//! Owns the Zaber spelling of a program. Sources: Zaber Motion Library API reference,
//! "Pvt" (<https://software.zaber.com/motion-library/api/py/ascii/pvt>: PVT sequences and
//! buffers, firmware 7.33 and later), Zaber's ASCII Protocol Manual
//! (<https://www.zaber.com/protocol-manual>, commands `pvt` and the velocity unit of
//! `maxspeed`), and the EPICS Zaber motor driver's tests, which show the commands on the
//! wire (`pvt 1 setup store 1 2`, `pvt 1 point abs p 88693 161260 v 31705 0 t 500.0`,
//! `pvt 1 setup disable`):
//!
//! - positions are absolute, whole microsteps (`p`, one per axis);
//! - velocities are whole native units, microsteps/s × 1.6384 (`v`);
//! - the time is the point's time from the previous one, in milliseconds, written with
//!   one decimal (`t`).
//!
//! Each line is the data of one command, for the host to send to the device
//! (`/1 0 pvt …`, or `device.generic_command(line)` in the Zaber Motion Library): the
//! sequence stores the program in buffer 1 (`pvt 1 setup store 1 N` for N axes), ends
//! with `pvt 1 setup disable`; the host then runs it with `pvt 1 setup live 1 2 …` and
//! `pvt 1 call 1` after moving the axes to the first contour's start. The program's axes
//! are the device's axes 1, 2, … in order, each at its microsteps per unit
//! (`--counts-per-unit` or the machine file's `counts_per_unit`). The protocol has no
//! comments: a dwell is a point at rest, other events are left out.
//!
//! Triggers (`--trigger-every`): the point is cut at the trigger and
//! `pvt 1 io set do 1 1` (then `… 0` at the next, so every trigger is an edge) follows
//! the point that ends there: a PVT sequence queues I/O actions between its points and
//! runs them in order (Zaber Motion Library guide "Position Velocity Time (PVT)": "PVT
//! sequences can perform other actions such as controlling device's IO",
//! <https://software.zaber.com/motion-library/docs/guides/device_features/pvt>; API
//! `PvtSequence.io`, `PvtSetDigitalOutputAction`). Assumed, not found in the pages
//! searched: the wire form `pvt 1 io set do CHANNEL VALUE`, from the stream command
//! `stream 1 io set do …`.
//!
//! Assumed, not found in the pages searched: the time resolution, 0.1 ms (the one
//! decimal the EPICS driver writes), which is also the shortest point; no longest time
//! and no buffer size are assumed.

use crate::lines::{all_counts, scales, Lines};
use crate::rules::{Caps, Positions};
use crate::triggers::TriggerSupport;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// The digital output a trigger toggles.
pub const TRIGGER_CHANNEL: u32 = 1;

/// Native velocity units per microstep/s.
pub const NATIVE_VELOCITY: f64 = 1.6384;

/// Zaber's rules: absolute microsteps, times on an assumed grid of 0.1 ms.
pub const CAPS: Caps = Caps {
    controller: "Zaber",
    time_quantum: Some(1e-4),
    quantum_required: true,
    default_quantum: Some(1e-4),
    min_piece_seconds: 1e-4,
    max_piece_seconds: None,
    positions: Positions::Absolute,
    position_unit: "microsteps",
    velocity_unit: "microsteps/s x 1.6384",
    scaled: true,
    buffer_depth: None,
    verifies: false,
    triggers: TriggerSupport::Written,
    velocity_per_count: NATIVE_VELOCITY,
};

/// Streams Zaber PVT commands to `W`.
pub struct ZaberWriter<W> {
    lines: Lines<W>,
    scales: Vec<f64>,
    /// The absolute position of each axis after the last point, microsteps.
    last: Vec<i64>,
    /// The trigger output's level after the last trigger.
    trigger_level: bool,
}

impl<W: Write> ZaberWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> ZaberWriter<W> {
        ZaberWriter {
            lines: Lines::new(out),
            scales: Vec::new(),
            last: Vec::new(),
            trigger_level: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.lines.into_inner()
    }

    fn point(&mut self, velocity: &[i64], ms: f64) -> io::Result<()> {
        self.lines.str("pvt 1 point abs p");
        for p in self.last.clone() {
            self.lines.str(" ");
            self.lines.int(p);
        }
        self.lines.str(" v");
        for v in velocity {
            self.lines.str(" ");
            self.lines.int(*v);
        }
        self.lines.str(" t ");
        self.lines.fixed::<1>(ms);
        self.lines.end_line()
    }
}

impl<W: Write> ProgramWriter for ZaberWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.scales = scales(header);
        self.last = vec![0; header.axes.len()];
        self.lines.str("pvt 1 setup disable");
        self.lines.end_line()?;
        self.lines.str("pvt buffer 1 erase");
        self.lines.end_line()?;
        self.lines
            .str(&format!("pvt 1 setup store 1 {}", header.axes.len()));
        self.lines.end_line()
    }

    fn contour(&mut self, _: Motion, start: &[f64]) -> io::Result<()> {
        self.last = all_counts(start, &self.scales, 1.0);
        Ok(())
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        self.last = all_counts(seg.end, &self.scales, 1.0);
        let v = all_counts(seg.velocity, &self.scales, NATIVE_VELOCITY);
        self.point(&v, seg.duration * 1000.0)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if let EventKind::Dwell { seconds } = event.kind {
            if seconds > 0.0 {
                // Whole tenths of a millisecond, rounded up: never shorter than asked.
                let ms = libm::ceil(seconds * 10_000.0) / 10.0;
                let rest = vec![0; self.last.len()];
                return self.point(&rest, ms);
            }
        }
        Ok(())
    }

    fn trigger(&mut self) -> io::Result<()> {
        self.trigger_level = !self.trigger_level;
        let level = u8::from(self.trigger_level);
        self.lines
            .str(&format!("pvt 1 io set do {TRIGGER_CHANNEL} {level}"));
        self.lines.end_line()
    }

    fn finish(&mut self) -> io::Result<()> {
        self.lines.str("pvt 1 setup disable");
        self.lines.end_line()?;
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        CAPS
    }
}
