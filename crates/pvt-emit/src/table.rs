//! A CSV table of the motion (`--format csv`): `t,X,vX,Y,vY,…`, one row per point.
//!
//! Owns the table form, for spreadsheets, Python and controllers that load tables. The
//! first line names the columns (`t` and, per axis, its position and velocity); `t` is
//! the absolute time in seconds from the start of the program, positions are absolute
//! in program units, velocities in program units per second. The first row is the start
//! at rest at `t = 0` (after any dwell before it); every piece adds the row of its end. Contours chain, so a contour's
//! start is the previous row. A dwell is a row at rest after its time; other events have
//! no column and are left out. Numbers are the shortest round-trip form (RFC 4180 fields
//! without quotes), so positions and velocities are the planner's exactly and each piece
//! time is the difference of two `t`s. It must not plan or round.

use crate::lines::Lines;
use crate::rules::Caps;
use crate::stream::{Header, ProgramWriter};
use pvt_core::{EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// Streams a CSV table to `W`.
pub struct TableWriter<W> {
    lines: Lines<W>,
    time: f64,
    /// The last row's positions.
    last: Vec<f64>,
    started: bool,
}

impl<W: Write> TableWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> TableWriter<W> {
        TableWriter {
            lines: Lines::new(out),
            time: 0.0,
            last: Vec::new(),
            started: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.lines.into_inner()
    }

    fn row(&mut self, end: &[f64], velocity: &[f64]) -> io::Result<()> {
        self.lines.exact(self.time);
        for (p, v) in end.iter().zip(velocity) {
            self.lines.str(",");
            self.lines.exact(*p);
            self.lines.str(",");
            self.lines.exact(*v);
        }
        self.last.copy_from_slice(end);
        self.lines.end_line()
    }
}

impl<W: Write> ProgramWriter for TableWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.last = vec![0.0; header.axes.len()];
        self.lines.str("t");
        for axis in header.axes {
            self.lines.str(&format!(",{axis},v{axis}"));
        }
        self.lines.end_line()
    }

    fn contour(&mut self, _: Motion, start: &[f64]) -> io::Result<()> {
        if !self.started {
            self.started = true;
            let rest = vec![0.0; start.len()];
            return self.row(start, &rest);
        }
        Ok(())
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        self.time += seg.duration;
        self.row(seg.end, seg.velocity)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if let EventKind::Dwell { seconds } = event.kind {
            if seconds > 0.0 {
                self.time += seconds;
                if self.started {
                    let (here, rest) = (self.last.clone(), vec![0.0; self.last.len()]);
                    return self.row(&here, &rest);
                }
            }
        }
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        crate::Format::Csv.caps()
    }
}
