//! Galil DMC PVT mode commands (`--format galil`).
//!
//! Owns the Galil spelling of a program. Sources: Galil, *DMC-40x0 User Manual*,
//! chapter 6 "Programming Motion", "PVT Mode"
//! (<https://manualshive.com/en/manual/galil-motion-control/dmc-4040/dmc-4040_user-manual_3262751-103.html>),
//! and Galil's ServoTrends 10/09 "PVT mode"
//! (<http://galilmc.com/support/servotrends/st_10_09/pvt-mode.php>):
//!
//! - `PVa=p,v,t`: a segment of axis `a` moving `p` counts (incremental), ending at `v`
//!   counts/s, in `t` samples; with the default `TM 1000` a sample is 976 µs and 1024
//!   samples are one second, whatever `TM` the velocity stays in counts/s;
//! - `BT` begins PVT motion on the axes named; `PVa=0,0,0` ends an axis' motion;
//! - each axis buffers 255 segments (`_PVa` holds the free slots, `_BTa` those executed),
//!   so a longer program is streamed by the host.
//!
//! The program's axes are the Galil axes `A`, `B`, `C`, … in order. Positions and
//! velocities are whole counts at each axis' counts per unit (`--counts-per-unit` or the
//! machine file's `counts_per_unit`); each displacement is the difference of two rounded
//! absolute positions, so rounding never accumulates. Times are whole samples.
//!
//! Streaming: the first 255 segments of every axis come first, then `BT` (motion starts),
//! then the rest, which the host sends line by line while `_PVa` shows a free slot; the
//! last segment of each axis is `PVa=0,0,0`. A program of at most 255 pieces is sent
//! whole. A dwell is rest segments (its time rounded up to whole segments); other events
//! are comments (`'`).
//!
//! Assumed, not found in the pages searched: `t` is even, 2 to 2048 samples (the issue's
//! notes and Galil's command reference as remembered; the examples use even `t`), so the
//! time quantum is 2 samples (1/512 s) and the longest piece 2 s.

use crate::lines::{all_counts, scales, Lines};
use crate::rules::{Caps, Positions};
use crate::triggers::TriggerSupport;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// Samples per second at the default `TM 1000`.
pub const SAMPLES_PER_SECOND: f64 = 1024.0;
/// Segments each axis buffers.
pub const BUFFER_SEGMENTS: usize = 255;
/// Longest segment, samples (assumed).
pub const MAX_SAMPLES: i64 = 2048;

/// Galil's rules: times on a grid of 2 samples, incremental counts, a 255-segment buffer.
pub const CAPS: Caps = Caps {
    controller: "Galil DMC",
    time_quantum: Some(2.0 / SAMPLES_PER_SECOND),
    quantum_required: true,
    default_quantum: Some(2.0 / SAMPLES_PER_SECOND),
    min_piece_seconds: 2.0 / SAMPLES_PER_SECOND,
    max_piece_seconds: Some(MAX_SAMPLES as f64 / SAMPLES_PER_SECOND),
    positions: Positions::Relative,
    position_unit: "counts, relative",
    velocity_unit: "counts/s",
    scaled: true,
    buffer_depth: Some(BUFFER_SEGMENTS),
    verifies: false,
    triggers: TriggerSupport::None(
        "a PV segment holds motion only; Galil's output compare (OC) fires on one axis' \
         encoder position, not along the path: set it up on the controller",
    ),
    velocity_per_count: 1.0,
};

/// Streams Galil PV commands to `W`.
pub struct GalilWriter<W> {
    lines: Lines<W>,
    letters: Vec<char>,
    scales: Vec<f64>,
    /// The absolute count of each axis after the last segment.
    last: Vec<i64>,
    /// Segments written per axis.
    segments: usize,
    started: bool,
    begun: bool,
}

impl<W: Write> GalilWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> GalilWriter<W> {
        GalilWriter {
            lines: Lines::new(out),
            letters: Vec::new(),
            scales: Vec::new(),
            last: Vec::new(),
            segments: 0,
            started: false,
            begun: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.lines.into_inner()
    }

    /// `BTAB…`: motion starts once the buffers hold their first segments.
    fn begin_motion(&mut self) -> io::Result<()> {
        self.begun = true;
        let axes: String = self.letters.iter().collect();
        self.lines.str(&format!("BT{axes}"));
        self.lines.end_line()
    }

    /// One segment of every axis: displacements `p` and end velocities `v` in counts.
    fn segment_counts(&mut self, p: &[i64], v: &[i64], samples: i64) -> io::Result<()> {
        if !self.begun && self.segments == BUFFER_SEGMENTS {
            self.begin_motion()?;
            self.lines.str(
                "' stream each line below when _PV of its axis shows a free slot (255 buffered)",
            );
            self.lines.end_line()?;
        }
        self.segments += 1;
        for ((letter, p), v) in self.letters.iter().zip(p).zip(v) {
            self.lines.str(&format!("PV{letter}="));
            self.lines.int(*p);
            self.lines.str(",");
            self.lines.int(*v);
            self.lines.str(",");
            self.lines.int(samples);
            self.lines.end_line()?;
        }
        Ok(())
    }
}

impl<W: Write> ProgramWriter for GalilWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.scales = scales(header);
        self.letters = (b'A'..=b'H')
            .take(header.axes.len())
            .map(char::from)
            .collect();
        self.last = vec![0; header.axes.len()];
        self.lines
            .source_comment("' ", "Galil PVT program", header)?;
        let map: Vec<String> = header
            .axes
            .iter()
            .zip(&self.letters)
            .zip(&self.scales)
            .map(|((axis, letter), scale)| {
                format!("{axis}->{letter} at {scale} counts/{}", header.units.name())
            })
            .collect();
        self.lines.str(&format!("' axes: {}", map.join(", ")));
        self.lines.end_line()?;
        self.lines.str(
            "' PVa=p,v,t: p counts (incremental), v counts/s, t samples; requires TM 1000 (1024 samples/s)",
        );
        self.lines.end_line()
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        let here = all_counts(start, &self.scales, 1.0);
        if !self.started {
            self.started = true;
            self.last = here.clone();
            let at: Vec<String> = here.iter().map(i64::to_string).collect();
            self.lines.str(&format!(
                "' start at {} counts: move there first (PA {};BG;AM)",
                at.join(","),
                at.join(",")
            ));
            self.lines.end_line()?;
        }
        self.lines.str(&format!("' {} contour", motion.name()));
        self.lines.end_line()
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        let ends = all_counts(seg.end, &self.scales, 1.0);
        let p: Vec<i64> = ends.iter().zip(&self.last).map(|(e, l)| e - l).collect();
        let v = all_counts(seg.velocity, &self.scales, 1.0);
        self.last = ends;
        let samples = libm::round(seg.duration * SAMPLES_PER_SECOND) as i64;
        self.segment_counts(&p, &v, samples)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if let EventKind::Dwell { seconds } = event.kind {
            // Whole segments of 2 samples, rounded up: never shorter than asked.
            let mut left = 2 * libm::ceil(seconds * SAMPLES_PER_SECOND / 2.0) as i64;
            let rest = vec![0; self.letters.len()];
            while left > 0 {
                let t = left.min(MAX_SAMPLES);
                self.segment_counts(&rest, &rest, t)?;
                left -= t;
            }
            return Ok(());
        }
        self.lines.str(&format!(
            "' event {} from line {}",
            event.kind.name(),
            event.line
        ));
        self.lines.end_line()
    }

    fn finish(&mut self) -> io::Result<()> {
        let full = self.segments >= BUFFER_SEGMENTS;
        if full && !self.begun {
            self.begin_motion()?;
        }
        for letter in self.letters.clone() {
            self.lines.str(&format!("PV{letter}=0,0,0"));
            self.lines.end_line()?;
        }
        if !self.begun && !self.letters.is_empty() {
            self.begin_motion()?;
        }
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        CAPS
    }
}
