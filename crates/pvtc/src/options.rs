//! The plain data every phase of a compile shares: what the command line asked
//! ([`Asked`], with the side files it names read once: [`read_offsets`],
//! [`read_tool_table`]), the input ([`Source`], [`InputKind`]), the resolved options
//! ([`CompileOptions`], [`DrawingOptions`], built by `settings` alone) and a diagnostic
//! labelling a source line ([`at_line`]); why a run failed is [`crate::failure`]'s
//! (re-exported).
//!
//! Owns these types so that data flows one way: `settings`, `front` and `route` (and
//! the rest of the CLI) import them from here, and this module imports no pvtc module
//! but `machine` and `failure` (`tests/tidy.rs` fails on an import cycle between pvtc's
//! modules). It must not apply a default, read an input's format, plan or write.

use miette::{LabeledSpan, NamedSource, Report};
use pvt_core::{Axis, Planner, Rounding, Timing, Units};
use pvt_emit::Format;
use std::io::Read;
use std::path::Path;
use std::sync::Arc;

pub use crate::failure::Failure;

/// A distance as given on the command line: a length (kept in millimetres) or a number
/// of counts (`diff --tolerance`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Distance {
    /// Millimetres.
    Millimetres(f64),
    /// Counts (microsteps) of a format written in counts, at `--counts-per-unit`.
    Counts(f64),
}

/// An input, read whole.
#[derive(Debug, Clone)]
pub struct Source {
    /// The name diagnostics and headers use: the path as given, or `<stdin>`.
    pub name: String,
    /// The bytes read.
    pub bytes: Vec<u8>,
}

impl Source {
    /// Reads `path`, or standard input for `-`.
    pub fn read(path: &Path) -> Result<Source, Failure> {
        let io_failure = |error| Failure::Io {
            path: path.to_path_buf(),
            action: "read",
            error,
        };
        if path == Path::new("-") {
            let mut bytes = Vec::new();
            std::io::stdin()
                .read_to_end(&mut bytes)
                .map_err(io_failure)?;
            return Ok(Source {
                name: "<stdin>".into(),
                bytes,
            });
        }
        let bytes = std::fs::read(path).map_err(io_failure)?;
        Ok(Source {
            name: path.display().to_string(),
            bytes,
        })
    }

    /// A source from text already in memory.
    pub fn from_text(name: &str, text: &str) -> Source {
        Source {
            name: name.into(),
            bytes: text.as_bytes().to_vec(),
        }
    }

    /// The source as text (invalid UTF-8 becomes U+FFFD, a `\r` inside a line a blank:
    /// [`shown`]) with its name, for diagnostics;
    /// shared, so each diagnostic that clones it holds no copy of the text.
    pub fn named_text(&self) -> NamedSource<Arc<str>> {
        NamedSource::new(self.name.clone(), Arc::from(shown(&self.bytes)))
    }
}

/// Text as diagnostics show it: a `\r` that does not end a line (CR CR LF, as PyCAM 0.5
/// writes, or a lone one mid-line) is a blank, as `rs274` reads it, so the renderer
/// counts lines as the front ends do (at `\n`). The length stays.
pub fn shown(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    if !bytes.contains(&b'\r') {
        return text.into_owned();
    }
    let mut chars = text.chars().peekable();
    let mut out = String::with_capacity(text.len());
    while let Some(c) = chars.next() {
        let ends_line = chars.peek() == Some(&'\n');
        out.push(if c == '\r' && !ends_line { ' ' } else { c });
    }
    out
}

/// The front ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// RS274/NGC G-code.
    Gcode,
    /// DXF drawing.
    Dxf,
    /// Point-time series as CSV.
    Csv,
}

impl InputKind {
    /// The front end a file name suggests: `.dxf` drawing, `.csv` series, else G-code.
    pub fn from_name(name: &str) -> InputKind {
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".dxf") {
            InputKind::Dxf
        } else if lower.ends_with(".csv") {
            InputKind::Csv
        } else {
            InputKind::Gcode
        }
    }
}

/// Options only drawings use.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DrawingOptions {
    /// Layers to cut; empty is every layer.
    pub layers: Vec<String>,
    /// Join tolerance, drawing units; `None` is 0.01 mm.
    pub join_tolerance: Option<f64>,
    /// Where the machine starts (X, Y).
    pub start_point: [f64; 2],
    /// Safe Z for travel between contours.
    pub safe_z: Option<f64>,
    /// Most points a DXF drawing may hold; `None` is [`pvt_dxf::DEFAULT_MAX_POINTS`].
    pub max_points: Option<usize>,
    /// Units: G-code output converted into them; DXF and CSV read in them.
    pub units: Option<Units>,
}

/// Everything a compilation depends on besides the source.
#[derive(Debug, Clone, PartialEq)]
pub struct CompileOptions {
    /// Output format.
    pub format: Format,
    /// Front end.
    pub input: InputKind,
    /// Machine limits from `--machine`.
    pub machine: Option<crate::machine::Machine>,
    /// How far the path planner may round a corner between two lines, program units.
    pub corner_tolerance: Option<f64>,
    /// Feed for moves before the first F word (required for drawings), units per minute.
    pub feed: Option<f64>,
    /// Rapid rate, program units per minute; `None` is 5000 mm/min.
    pub rapid: Option<f64>,
    /// Chord tolerance, program units; `None` is 0.001 mm.
    pub tolerance: Option<f64>,
    /// The planner.
    pub planner: Planner,
    /// Piece times of the time-based planners.
    pub timing: Timing,
    /// Acceleration for lspb, units/s².
    pub accel: Option<f64>,
    /// Piece-time quantum, seconds (by default the format's, [`pvt_emit::Caps`]).
    pub quantize: Option<f64>,
    /// Counts per program unit of axes (`--counts-per-unit`), over the machine file's.
    pub counts_per_unit: Vec<(pvt_core::Axis, f64)>,
    /// Which way piece times go onto the quantum grid.
    pub quantize_rounding: Rounding,
    /// G-code work offsets, G54…G59.3 rows of X Y Z (mm) A B C (degrees).
    pub work_offsets: [[f64; 6]; 9],
    /// G-code `--subroutine-path` values (folders or `:`-separated lists).
    pub subroutine_path: Vec<String>,
    /// G-code tool table (G43 H), millimetres and degrees.
    pub tool_table: pvt_gcode::ToolTable,
    /// G-code HAL pin values (`--hal NAME=VALUE`).
    pub hal_pins: Vec<(String, f64)>,
    /// G-code probing results, in order (`--probe-result X,Y,Z`).
    pub probe_results: Vec<[f64; 3]>,
    /// What G-code's spindle-synchronised motion becomes (`--spindle-rpm-exact`).
    pub spindle_sync: pvt_gcode::SpindleSync,
    /// G-code arc check: absolute radius tolerance, mm; `None`: LinuxCNC's for the
    /// program's units ([`pvt_core::defaults::arc_abs_tolerance`]).
    pub arc_abs_tolerance_mm: Option<f64>,
    /// G-code arc check: relative radius tolerance.
    pub arc_rel_tolerance: f64,
    /// Options only drawings use.
    pub drawing: DrawingOptions,
    /// Where a point-time series' velocities come from; `None`: the file's columns when
    /// it has them and the planner takes velocities.
    pub velocities: Option<VelocitySource>,
    /// PMAC output: program number, coordinate system, axis definitions, event commands.
    pub pmac: pvt_emit::PmacSettings,
    /// `--trigger-every`: a time, or a path length in millimetres.
    pub triggers: Option<pvt_emit::TriggerEvery>,
}

/// Where the velocities of a point-time series come from (`--velocities`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VelocitySource {
    /// The series' `v<axis>` columns, used as given.
    File,
    /// The planner's own method; the columns are ignored.
    Plan,
}

/// A diagnostic labelling the whole of 1-based `line` of the source.
pub(crate) fn at_line(code: &str, message: &str, line: u32, source: &Source) -> Report {
    let range = pvt_core::text::line_range(&source.bytes, line as usize);
    miette::miette!(
        code = code.to_string(),
        labels = vec![LabeledSpan::at(range, "this line")],
        "{message}"
    )
}

/// What the command line asked for a compile, as given: `None` (or empty) where an
/// option was not given, with the side files it names already read. `settings` turns it
/// into [`CompileOptions`], applying every default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Asked {
    /// `--input-format`.
    pub input: Option<InputKind>,
    /// `--planner`.
    pub planner: Option<Planner>,
    /// The `--machine` file, read.
    pub machine: Option<crate::machine::Machine>,
    /// `--corner-tolerance`, program units.
    pub corner_tolerance: Option<f64>,
    /// `--feed`, units per minute.
    pub feed: Option<f64>,
    /// `--rapid`, program units per minute.
    pub rapid: Option<f64>,
    /// `--tolerance`, program units.
    pub tolerance: Option<f64>,
    /// `--time-slice`, seconds.
    pub time_slice: Option<f64>,
    /// `--accel`, units/s².
    pub accel: Option<f64>,
    /// `--quantize`: `Some(None)` is `off`.
    pub quantize: Option<Option<f64>>,
    /// `--quantize-rounding`.
    pub quantize_rounding: Option<Rounding>,
    /// `--counts-per-unit`.
    pub counts_per_unit: Vec<(Axis, f64)>,
    /// The `--offsets` table, read.
    pub work_offsets: Option<[[f64; 6]; 9]>,
    /// `--subroutine-path`.
    pub subroutine_path: Vec<String>,
    /// The `--tool-table` file, read (millimetres).
    pub tool_table: Option<pvt_gcode::ToolTable>,
    /// `--hal`.
    pub hal_pins: Vec<(String, f64)>,
    /// `--probe-result`.
    pub probe_results: Vec<[f64; 3]>,
    /// `--spindle-rpm-exact`.
    pub spindle_sync: pvt_gcode::SpindleSync,
    /// `--arc-abs-tolerance`, mm.
    pub arc_abs_tolerance_mm: Option<f64>,
    /// `--arc-rel-tolerance`.
    pub arc_rel_tolerance: Option<f64>,
    /// `--layer`.
    pub layers: Vec<String>,
    /// `--join-tolerance`.
    pub join_tolerance: Option<f64>,
    /// `--start-point`.
    pub start_point: Option<[f64; 2]>,
    /// `--safe-z`.
    pub safe_z: Option<f64>,
    /// `--max-points`.
    pub max_points: Option<usize>,
    /// `--units`.
    pub units: Option<Units>,
    /// `--velocities`.
    pub velocities: Option<VelocitySource>,
}

/// Reads a file that holds the same for every input of a run (the `--offsets` table, the
/// `--tool-table`) and parses it; a parse error is shown on the file's own text.
fn read_side_file<T, E>(path: &Path, parse: impl FnOnce(&str) -> Result<T, E>) -> Result<T, Failure>
where
    E: miette::Diagnostic + Send + Sync + 'static,
{
    let text = std::fs::read_to_string(path).map_err(|error| Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    })?;
    parse(&text).map_err(|e| {
        let named = NamedSource::new(path.display().to_string(), text.clone());
        Failure::Input(vec![Report::new(e).with_source_code(named)])
    })
}

/// Reads the `--offsets` table at `path` (G-code words, parsed by pvt-gcode).
pub fn read_offsets(path: &Path) -> Result<[[f64; 6]; 9], Failure> {
    read_side_file(path, pvt_gcode::parse_offsets)
}

/// Reads the `--tool-table` file at `path`, its lengths in inches when `inch`, into
/// millimetres.
pub fn read_tool_table(path: &Path, inch: bool) -> Result<pvt_gcode::ToolTable, Failure> {
    let mut table = read_side_file(path, pvt_gcode::ToolTable::parse)?;
    if inch {
        table.scale_lengths(25.4);
    }
    Ok(table)
}
