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
//! time is the difference of two `t`s. With `--trigger-every` ([`crate::triggers`]) the
//! table has a last column `trigger`: 1 on the row where a trigger fires (the pieces are
//! cut there), else 0. It must not plan or round.

use crate::lines::Lines;
use crate::rules::Caps;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{EventKind, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Write};

/// Streams a CSV table to `W`.
pub struct TableWriter<W> {
    lines: Lines<W>,
    time: f64,
    /// The last row's positions.
    last: Vec<f64>,
    started: bool,
    /// The table has a `trigger` column (`--trigger-every`).
    triggers: bool,
    /// The last row waits for its `trigger` field.
    open_row: bool,
}

impl<W: Write> TableWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> TableWriter<W> {
        TableWriter {
            lines: Lines::new(out),
            time: 0.0,
            last: Vec::new(),
            started: false,
            triggers: false,
            open_row: false,
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
        if self.triggers {
            self.open_row = true;
            return Ok(());
        }
        self.lines.end_line()
    }

    /// Ends the open row with its `trigger` field.
    fn close_row(&mut self, trigger: bool) -> io::Result<()> {
        if !self.open_row {
            return Ok(());
        }
        self.open_row = false;
        self.lines.str(if trigger { ",1" } else { ",0" });
        self.lines.end_line()
    }
}

impl<W: Write> ProgramWriter for TableWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        self.last = vec![0.0; header.axes.len()];
        self.triggers = header.options.triggers.is_some();
        self.lines.str("t");
        for axis in header.axes {
            self.lines.str(&format!(",{axis},v{axis}"));
        }
        if self.triggers {
            self.lines.str(",trigger");
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
        self.close_row(false)?;
        self.time += seg.duration;
        self.row(seg.end, seg.velocity)
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        if let EventKind::Dwell { seconds } = event.kind {
            if seconds > 0.0 {
                self.close_row(false)?;
                self.time += seconds;
                if self.started {
                    let (here, rest) = (self.last.clone(), vec![0.0; self.last.len()]);
                    return self.row(&here, &rest);
                }
            }
        }
        Ok(())
    }

    fn trigger(&mut self) -> io::Result<()> {
        self.close_row(true)
    }

    fn finish(&mut self) -> io::Result<()> {
        self.close_row(false)?;
        self.lines.finish()
    }

    fn caps(&self) -> Caps {
        crate::Format::Csv.caps()
    }
}
