//! MovePVT arrays as C source (seed 002's quad-circle example).
//!
//! Owns the array form: for each contour, interleaved positions (`p0x, p0y, p1x, …`),
//! interleaved velocities, one time per point in seconds (the time to reach that point
//! from the previous one), the point count, and the start position the axes must be set
//! to (`PositionSet`) before `MovePVT(position, velocity, time, count, -1, false, true)`.
//! Numbers are written in their shortest exact form, so the arrays carry the planner's
//! values bit for bit. A table `pvtc_contours` lists every contour in execution order.
//!
//! PT motion (constant velocity between points, application note AN208's PT) is written
//! as MovePT arrays: the same positions, times and counts without a velocity array (a
//! PT controller takes each piece's velocity as chord / time), for
//! `MovePT(position, time, count, -1, false, true)`; the table's `velocity` is null.
//!
//! Everything is `static`, for a program that includes the file. Such a program uses
//! either the table or the arrays it lists; the table is marked `PVTC_MAYBE_UNUSED`
//! (`__attribute__((unused))` under GCC and Clang), so the file compiles warning-free under
//! `-Wall -Wextra` either way, and alone.
//!
//! Buffering: C wants each array whole, so while a contour's positions stream out, its
//! velocity and time arrays are held as text until the contour ends — the least this
//! layout allows. Each held array keeps at most [`HOLD_IN_MEMORY`] bytes in memory and
//! the rest in an anonymous temporary file (removed by the system when closed), so a
//! contour of any length is written in bounded memory; where no temporary file can be
//! made, the array is held in memory whole. Counts come from `sizeof` after
//! the arrays, so nothing needs a count up front. It must not plan or round.

use crate::gather::Gathered;
use crate::writer::{Header, ProgramWriter};
use pvt_core::{EventKind, Interpolation, Motion, ProgramEvent, SegmentRef};
use std::io::{self, Seek, SeekFrom, Write};

/// Bytes of text gathered before they are written.
const TEXT_BATCH: usize = 64 * 1024;

/// Bytes of a held array kept in memory; beyond them its text goes to a temporary file.
pub const HOLD_IN_MEMORY: usize = 64 * 1024;

/// The text of an array held until its contour ends: in memory up to a bound, the text
/// before it in an anonymous temporary file.
struct Held {
    text: Gathered,
    spilled: Option<std::fs::File>,
    bound: usize,
}

impl Held {
    fn new(bound: usize) -> Held {
        Held {
            text: Gathered::with_capacity(0),
            spilled: None,
            bound,
        }
    }

    /// Appends a row of `values`, moving the text held in memory to the file once it
    /// passes the bound.
    fn row(&mut self, values: &[f64]) -> io::Result<()> {
        push_row(&mut self.text, values);
        if self.text.len() < self.bound {
            return Ok(());
        }
        let file = match &mut self.spilled {
            Some(file) => file,
            None => match tempfile::tempfile() {
                Ok(file) => self.spilled.insert(file),
                Err(_) => {
                    // No temporary file can be made (a pipe with no temporary
                    // directory): the array is held in memory whole instead.
                    self.bound = usize::MAX;
                    return Ok(());
                }
            },
        };
        file.write_all(self.text.text())?;
        self.text.clear();
        Ok(())
    }

    /// Writes the whole held text to `out`, in order, and empties it (the file is kept,
    /// emptied, for the next contour).
    fn write_to(&mut self, out: &mut impl Write) -> io::Result<()> {
        if let Some(file) = &mut self.spilled {
            file.seek(SeekFrom::Start(0))?;
            io::copy(file, out)?;
            file.set_len(0)?;
            file.seek(SeekFrom::Start(0))?;
        }
        out.write_all(self.text.text())?;
        self.text.clear();
        Ok(())
    }
}

/// Streams MovePVT arrays as C source to `W`.
pub struct MovePvtWriter<W> {
    out: W,
    text: Gathered,
    velocities: Held,
    times: Held,
    kinds: Vec<Motion>,
    /// The last contour's arrays are already closed (an event followed it).
    closed: bool,
    /// PT motion: MovePT arrays, no velocities.
    pt: bool,
}

impl<W: Write> MovePvtWriter<W> {
    /// A writer into `out`.
    pub fn new(out: W) -> MovePvtWriter<W> {
        MovePvtWriter::holding(out, HOLD_IN_MEMORY)
    }

    /// A writer into `out` that keeps at most `bound` bytes of each held array in memory.
    fn holding(out: W, bound: usize) -> MovePvtWriter<W> {
        MovePvtWriter {
            out,
            text: Gathered::with_capacity(TEXT_BATCH + 1024),
            velocities: Held::new(bound),
            times: Held::new(bound),
            kinds: Vec::new(),
            closed: false,
            pt: false,
        }
    }

    /// The output, once finished.
    pub fn into_inner(self) -> W {
        self.out
    }

    fn flush_text(&mut self) -> io::Result<()> {
        self.out.write_all(self.text.text())?;
        self.text.clear();
        Ok(())
    }

    /// [`Self::flush_text`] once a batch of text is gathered: each piece's text is not
    /// copied into the output's buffer on its own.
    fn flush_batch(&mut self) -> io::Result<()> {
        if self.text.len() >= TEXT_BATCH {
            self.flush_text()?;
        }
        Ok(())
    }

    /// Closes the open contour's arrays and writes its count.
    fn end_contour(&mut self) -> io::Result<()> {
        let n = self.kinds.len();
        if n == 0 || self.closed {
            return Ok(());
        }
        self.text.push_str("};\n");
        if !self.pt {
            self.text
                .push_str(&format!("static double pvtc_c{n}_velocity[] = {{\n"));
            self.flush_text()?;
            self.velocities.write_to(&mut self.out)?;
            self.text.push_str("};\n");
        }
        self.text
            .push_str(&format!("static double pvtc_c{n}_time[] = {{\n"));
        self.flush_text()?;
        self.times.write_to(&mut self.out)?;
        self.text.push_str("};\n");
        self.text.push_str(&format!(
            "#define PVTC_C{n}_POINTS ((long)(sizeof pvtc_c{n}_time / sizeof pvtc_c{n}_time[0]))\n"
        ));
        self.flush_text()
    }
}

/// Appends one row of an array: `    a, b, c,` and its newline.
#[inline]
fn push_row(text: &mut Gathered, values: &[f64]) {
    text.push_slice(b"    ");
    for x in values {
        text.exact(*x);
        text.push_slice(b", ");
    }
    text.pop();
    text.push(b'\n');
}

fn c_comment(s: &str) -> String {
    s.replace("*/", "* /")
}

impl<W: Write> ProgramWriter for MovePvtWriter<W> {
    fn begin(&mut self, header: &Header<'_>) -> io::Result<()> {
        let units = header.units.name();
        self.pt = header.interpolation == Interpolation::Pt;
        let t = &mut self.text;
        t.push_str(&format!(
            "/* {} arrays generated by pvtc from {}\n",
            if self.pt { "MovePT" } else { "MovePVT" },
            c_comment(&header.options.source)
        ));
        for (name, value) in &header.options.settings {
            t.push_str(&format!(" * {name}: {}\n", c_comment(value)));
        }
        let axes: Vec<String> = header.axes.iter().map(|a| a.to_string()).collect();
        t.push_str(&format!(
            " * axes: {} (interleaved in this order)\n",
            axes.join(" ")
        ));
        if self.pt {
            t.push_str(&format!(
                " * position: {units}; time: s from the previous point; PT: each axis moves at\n * constant velocity (chord / time) from point to point, so no velocity array\n"
            ));
            t.push_str(
                " * For each contour N: set each axis to pvtc_cN_start (PositionSet), then\n",
            );
            t.push_str(
                " *   MovePT(pvtc_cN_position, pvtc_cN_time, PVTC_CN_POINTS, -1, false, true);\n",
            );
        } else {
            t.push_str(&format!(
                " * position: {units}; velocity: {units}/s; time: s from the previous point\n"
            ));
            t.push_str(
                " * For each contour N: set each axis to pvtc_cN_start (PositionSet), then\n",
            );
            t.push_str(" *   MovePVT(pvtc_cN_position, pvtc_cN_velocity, pvtc_cN_time, PVTC_CN_POINTS, -1, false, true);\n");
        }
        t.push_str(
            " * Every contour starts and ends at rest; pvtc_contours lists them in order.\n */\n",
        );
        t.push_str(&format!("#define PVTC_AXIS_COUNT {}\n", header.axes.len()));
        self.flush_text()
    }

    fn contour(&mut self, motion: Motion, start: &[f64]) -> io::Result<()> {
        self.end_contour()?;
        self.kinds.push(motion);
        self.closed = false;
        let n = self.kinds.len();
        self.text
            .push_str(&format!("\n/* contour {n}: {} */\n", motion.name()));
        self.text.push_str(&format!(
            "static double pvtc_c{n}_start[PVTC_AXIS_COUNT] = {{\n"
        ));
        push_row(&mut self.text, start);
        self.text
            .push_str(&format!("}};\nstatic double pvtc_c{n}_position[] = {{\n"));
        self.flush_text()
    }

    fn segment(&mut self, seg: &SegmentRef<'_>) -> io::Result<()> {
        push_row(&mut self.text, seg.end);
        if !self.pt {
            self.velocities.row(seg.velocity)?;
        }
        self.times.row(&[seg.duration])?;
        self.flush_batch()
    }

    fn event(&mut self, event: &ProgramEvent) -> io::Result<()> {
        self.end_contour()?;
        self.closed = true;
        let detail = match &event.kind {
            EventKind::Dwell { seconds } => format!(" {seconds} s"),
            EventKind::SpindleSpeed { rpm } => format!(" {rpm} rpm"),
            EventKind::ToolSelect { tool } => format!(" T{tool}"),
            EventKind::Message { text } => format!(" {}", c_comment(text)),
            EventKind::MachineCode { .. } => {
                format!(" {}", event.kind.code_written().unwrap_or_default())
            }
            _ => String::new(),
        };
        self.text.push_str(&format!(
            "\n/* event at rest: {}{detail} (line {}) */\n",
            event.kind.name(),
            event.line
        ));
        self.flush_text()
    }

    fn supports(&self, _: Interpolation) -> bool {
        true
    }

    fn caps(&self) -> crate::Caps {
        crate::Format::MovePvt.caps()
    }

    fn finish(&mut self) -> io::Result<()> {
        self.end_contour()?;
        let t = &mut self.text;
        t.push_str(&format!(
            "\n#define PVTC_CONTOUR_COUNT {}\n",
            self.kinds.len()
        ));
        t.push_str(
            "\n/* A program may use the table below or the arrays above: the table is marked as\n * possibly unused. */\n",
        );
        t.push_str("#ifndef PVTC_MAYBE_UNUSED\n#if defined(__GNUC__)\n#define PVTC_MAYBE_UNUSED __attribute__((unused))\n#else\n#define PVTC_MAYBE_UNUSED\n#endif\n#endif\n");
        t.push_str("\n/* Every contour in execution order. */\n");
        t.push_str(
            "typedef struct {\n    const char *kind;\n    long count;\n    double *start;\n",
        );
        t.push_str(
            "    double *position;\n    double *velocity;\n    double *time;\n} pvtc_contour;\n\n",
        );
        if self.kinds.is_empty() {
            t.push_str("static const pvtc_contour *const pvtc_contours PVTC_MAYBE_UNUSED = 0;\n");
        } else {
            t.push_str(
                "static const pvtc_contour pvtc_contours[PVTC_CONTOUR_COUNT] PVTC_MAYBE_UNUSED = {\n",
            );
            for (c, kind) in self.kinds.iter().enumerate() {
                let n = c + 1;
                let velocity = if self.pt {
                    "0".to_string()
                } else {
                    format!("pvtc_c{n}_velocity")
                };
                t.push_str(&format!(
                    "    {{\"{}\", PVTC_C{n}_POINTS, pvtc_c{n}_start, pvtc_c{n}_position, {velocity}, pvtc_c{n}_time}},\n",
                    kind.name()
                ));
            }
            t.push_str("};\n");
        }
        self.flush_text()?;
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::EmitOptions;
    use pvt_core::{Axis, Units};

    /// Three contours of `pieces` each (the second after an event), written by `writer`.
    fn program(mut writer: MovePvtWriter<Vec<u8>>, pt: bool, pieces: usize) -> Vec<u8> {
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let options = EmitOptions::default();
        let header = Header {
            axes: &axes,
            units: Units::Millimetre,
            interpolation: if pt {
                Interpolation::Pt
            } else {
                Interpolation::Pvt
            },
            options: &options,
        };
        writer.begin(&header).unwrap();
        for c in 0..3 {
            if c == 1 {
                let kind = EventKind::Dwell { seconds: 0.5 };
                let event = ProgramEvent {
                    before_contour: 1,
                    kind,
                    line: 7,
                };
                writer.event(&event).unwrap();
            }
            writer.contour(Motion::Feed, &[c as f64, 0.0, 0.0]).unwrap();
            for i in 0..pieces {
                let x = i as f64 * 0.1 + c as f64;
                let end = [x, libm::sin(x), -x / 3.0];
                let velocity = [1.0 / (i + 1) as f64, 0.25, -0.125 * i as f64];
                let seg = SegmentRef {
                    end: &end,
                    velocity: &velocity,
                    duration: 0.001 * (1 + i % 7) as f64,
                    line: 10 + i as u32,
                };
                writer.segment(&seg).unwrap();
            }
        }
        writer.finish().unwrap();
        writer.into_inner()
    }

    /// Held arrays moved to a temporary file many times over (a bound of 1 KiB) give the
    /// same text as arrays held whole in memory, for PVT and PT, and no held array
    /// keeps more than the bound and one row in memory.
    #[test]
    fn arrays_held_in_a_file_are_the_arrays_held_in_memory() {
        for pt in [false, true] {
            let whole = program(MovePvtWriter::holding(Vec::new(), usize::MAX), pt, 3_000);
            let spilled = program(MovePvtWriter::holding(Vec::new(), 1024), pt, 3_000);
            assert!(whole.len() > 200_000, "{} bytes", whole.len());
            assert!(whole == spilled, "PT {pt}: the texts differ");
            let text = String::from_utf8(whole).unwrap();
            // Independently: three time arrays of 3,000 rows each.
            assert_eq!(text.matches("_time[] = {").count(), 3);
            for array in text.split("_time[] = {\n").skip(1) {
                let rows = array.split("};").next().unwrap().lines().count();
                assert_eq!(rows, 3_000, "time rows");
            }
        }
        let mut writer = MovePvtWriter::holding(Vec::new(), 1024);
        writer.contour(Motion::Feed, &[0.0; 3]).unwrap();
        for i in 0..2_000 {
            let v = [i as f64 / 7.0, 1e-3 / (i + 1) as f64, 123.456789];
            let seg = SegmentRef {
                end: &v,
                velocity: &v,
                duration: 0.001,
                line: 1,
            };
            writer.segment(&seg).unwrap();
            assert!(writer.velocities.text.len() < 1024 + 128);
            assert!(writer.times.text.len() < 1024 + 128);
        }
        assert!(writer.velocities.spilled.is_some() && writer.times.spilled.is_some());
    }
}
