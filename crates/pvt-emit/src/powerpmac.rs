//! Power PMAC motion program text in PVT mode (`--format powerpmac`).
//!
//! Owns the Power PMAC spelling of a program, which differs from Turbo PMAC's
//! ([`crate::pmac`]): the piece time is the `pvt{ms}` statement itself, written again
//! whenever the time changes (no `TA`, whose meaning for PVT depends on Turbo PMAC's
//! `I42`), in milliseconds as a floating-point number with no whole-millisecond rounding and no
//! 4095 ms ceiling; comments are `//`; keywords are lower case. Sources: Delta Tau,
//! *Turbo PMAC/PMAC2 Software Reference*, "PVT{data}" and "{axis}{data}:{data}"
//! (<http://www.manualshelf.com/manual/delta-tau/turbo-pmac2-pci/reference-manual-english/page-463.html>),
//! which Power PMAC's `pvt` statement follows, and the notes on Power PMAC
//! (`pvt(ms)`, `A(pos):(vel)`, velocity in EGU/s).
//!
//! - positions: absolute (`abs`), program units, 6 decimals;
//! - velocities: signed, program units per second, 6 decimals — this assumes the
//!   coordinate system's `Coord[x].FeedTime = 1000` (ms per velocity time unit, the
//!   default);
//! - piece times: `pvt` in milliseconds with 6 decimals (1 ns).
//!
//! The program is `open prog 1 … close`; a dwell is `dwell{ms}` (followed by a fresh
//! `pvt` statement), other events are comments.
//!
//! Triggers (`--trigger-every`): as on Turbo PMAC ([`crate::pmac`]), a synchronous
//! assignment `M1==1` / `M1==0` after the piece that ends at the trigger; assumed, not
//! found in the pages searched: that Power PMAC keeps Turbo PMAC's `==` form.
//!
//! Assumed, not found in the pages searched: Power PMAC's own PVT time range; none is
//! assumed (no longest piece, and the shortest is the written time's resolution, 1 ns). `--quantize` defaults
//! to 1 ms all the same ([`CAPS`]).

use crate::lines::Lines;
use crate::rules::{Caps, Positions};
use crate::triggers::TriggerSupport;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{Axis, EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// Power PMAC's rules: absolute program units, any positive time. `--quantize` defaults
/// to 1 ms, pvtc's choice rather than the controller's: a piece of a few µs (a
/// jerk-limited plan makes some) turns the 6-decimal rounding of its positions into
/// accelerations far over the limits.
pub const CAPS: Caps = Caps {
    controller: "Power PMAC",
    time_quantum: None,
    quantum_required: false,
    default_quantum: Some(0.001),
    min_piece_seconds: MIN_PIECE_SECONDS,
    max_piece_seconds: None,
    positions: Positions::Absolute,
    position_unit: "program units",
    velocity_unit: "program units/s (Coord[x].FeedTime = 1000)",
    scaled: false,
    buffer_depth: None,
    verifies: false,
    triggers: TriggerSupport::Written,
    velocity_per_count: 1.0,
};

/// The shortest piece: the resolution of the written time (6 decimals of a ms), so no
/// written time reads 0.
pub const MIN_PIECE_SECONDS: f64 = 1e-9;

/// Decimals of positions, velocities and milliseconds.
const DECIMALS: usize = 6;

/// Streams a Power PMAC PVT motion program to `W`.
pub struct PowerPmacWriter<W> {
    lines: Lines<W>,
    axes: Vec<Axis>,
    /// The last `pvt` time written, ms (`None`: the next piece states its time).
    time: Option<f64>,
    /// The trigger output's level after the last trigger.
    trigger_level: bool,
}

impl<W: Write> PowerPmacWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> PowerPmacWriter<W> {
        PowerPmacWriter {
            lines: Lines::new(out),
            axes: Vec::new(),
            time: None,
            trigger_level: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.lines.into_inner()
    }
}

impl<W: Write> ProgramWriter for PowerPmacWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.axes = header.axes.to_vec();
        let units = header.units.name();
        let l = &mut self.lines;
        l.source_comment("// ", "Power PMAC PVT motion program", header)?;
        let axes: Vec<String> = self.axes.iter().map(|a| a.to_string()).collect();
        l.str(&format!(
            "// axes: {}; positions in {units}, absolute; velocities in {units}/s: requires Coord[x].FeedTime=1000",
            axes.join(" ")
        ));
        l.end_line()?;
        l.str("// piece times: pvt in ms, stated before the pieces it times");
        l.end_line()?;
        if header.options.triggers.is_some() {
            l.str(&format!(
                "// triggers: {0} toggles at each (synchronous {0}==1 / {0}==0: at the start of the next move); define {0} as the output",
                crate::pmac::TRIGGER_OUTPUT
            ));
            l.end_line()?;
        }
        l.str("open prog 1");
        l.end_line()?;
        l.str("abs");
        l.end_line()
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        let l = &mut self.lines;
        l.str(&format!("// {} contour from", motion.name()));
        for (axis, p) in self.axes.iter().zip(start) {
            l.str(&format!(" {axis}"));
            l.fixed::<DECIMALS>(*p);
        }
        l.end_line()
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        let ms = seg.duration * 1000.0;
        let l = &mut self.lines;
        if self.time != Some(ms) {
            self.time = Some(ms);
            l.str("pvt");
            l.fixed::<DECIMALS>(ms);
            l.end_line()?;
        }
        for (i, ((axis, p), v)) in self.axes.iter().zip(seg.end).zip(seg.velocity).enumerate() {
            if i > 0 {
                l.str(" ");
            }
            l.str(&axis.to_string());
            l.fixed::<DECIMALS>(*p);
            l.str(":");
            l.fixed::<DECIMALS>(*v);
        }
        l.end_line()
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        let l = &mut self.lines;
        if let EventKind::Dwell { seconds } = event.kind {
            self.time = None;
            l.str("dwell");
            l.fixed::<DECIMALS>(seconds * 1000.0);
            l.str(&format!(" // G4 from line {}", event.line));
            return l.end_line();
        }
        l.str(&format!(
            "// event {} from line {}",
            event.kind.name(),
            event.line
        ));
        l.end_line()
    }

    fn trigger(&mut self) -> io::Result<()> {
        self.trigger_level = !self.trigger_level;
        let level = u8::from(self.trigger_level);
        self.lines
            .str(&format!("{}=={level}", crate::pmac::TRIGGER_OUTPUT));
        self.lines.end_line()
    }

    fn finish(&mut self) -> io::Result<()> {
        self.lines.str("close");
        self.lines.end_line()?;
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        CAPS
    }
}
