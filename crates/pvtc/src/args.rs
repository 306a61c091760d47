//! Command-line arguments.
//!
//! Owns the flags, their help text, the usage errors of options that would do nothing,
//! and their conversion into what was asked ([`crate::options::Asked`], as given, the
//! `--offsets`, `--tool-table` and `--machine` files read once per run,
//! [`PipelineArgs::read_files`]). It must not apply a default (`settings` does) or
//! compile anything.

use crate::options::{Asked, CompileOptions, Distance, Failure, InputKind, VelocitySource};
use clap::{Parser, Subcommand, ValueEnum};
use pvt_core::{AxisLimits, Planner, Rounding, Units};
use pvt_emit::Format;
use std::path::PathBuf;

/// pvtc compiles G-code part programs, DXF drawings and point-time series into
/// position-velocity-time motion for controllers.
#[derive(Debug, Parser)]
#[command(name = "pvtc", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compile inputs into PVT motion (PMAC program, MovePVT arrays or JSON).
    Compile(CompileArgs),
    /// Report what a program's motion will do: peaks, servo-sampled values, path error,
    /// speed against feed; exit 1 when a given limit is exceeded.
    Check(CheckArgs),
    /// Plot a program's path, speed, velocities and accelerations as SVG, PNG or an
    /// interactive HTML page.
    Plot(PlotArgs),
    /// Compare two programs as motion (any formats, or sources): exit 0 when they are
    /// the same within the tolerances, 1 when not.
    Diff(DiffArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish or powershell) on standard
    /// output, e.g. `pvtc completions bash > ~/.local/share/bash-completion/completions/pvtc`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the manual page (roff) on standard output, e.g. `pvtc man | man -l -`.
    Man,
}

/// Output format names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// Turbo PMAC motion program in PVT mode (`TA<ms> X<pos>:<vel> …`), whole ms.
    Pmac,
    /// MovePVT (or, for --planner pt, MovePT) arrays as C source.
    Movepvt,
    /// The pvtc JSON document, version 1.
    Json,
    /// Newport XPS PVT trajectory file (`dt, dX, vX, …`, relative).
    Xps,
    /// Galil DMC PVT mode commands (`PVA=p,v,t` in counts and samples); needs counts per unit.
    Galil,
    /// Zaber ASCII PVT sequence commands (`pvt 1 point abs p … v … t …`); needs counts per unit.
    Zaber,
    /// Power PMAC motion program in PVT mode (`pvt<ms>`, `X<pos>:<vel>`).
    Powerpmac,
    /// A CSV table `t,X,vX,…` with absolute time.
    Csv,
    /// The interpreted elements and events as JSON lines, before planning (one input).
    Toolpath,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Pmac => Format::Pmac,
            FormatArg::Movepvt => Format::MovePvt,
            FormatArg::Json => Format::Json,
            FormatArg::Xps => Format::Xps,
            FormatArg::Galil => Format::Galil,
            FormatArg::Zaber => Format::Zaber,
            FormatArg::Powerpmac => Format::PowerPmac,
            FormatArg::Csv => Format::Csv,
            // `toolpath` stops before planning (crate::commands::toolpath): no back end sees it.
            FormatArg::Toolpath => Format::Json,
        }
    }
}

/// `--quantize`: a piece-time quantum in seconds, or `off` (none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantum(pub Option<f64>);

/// Input kind names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InputArg {
    /// RS274/NGC G-code.
    Gcode,
    /// DXF drawing (ASCII or binary).
    Dxf,
    /// Point-time series (CSV with a header row).
    Csv,
}

/// Unit names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum UnitsArg {
    /// Millimetres.
    Mm,
    /// Inches.
    In,
}

/// Where a series' velocities come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum VelocitiesArg {
    /// The series' velocity columns, as given.
    File,
    /// The planner's own method; velocity columns are ignored.
    Plan,
}

/// How diagnostics are printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DiagnosticsArg {
    /// For people: file, line, column, the offending text underlined, a help line.
    Human,
    /// For tools: one JSON object per diagnostic per line on standard error.
    Json,
}

/// Options shared by every subcommand that compiles a source.
#[derive(Debug, Clone, clap::Args)]
pub struct PipelineArgs {
    /// Kind of input; by default from the file name (.dxf, .csv, otherwise G-code).
    #[arg(long = "input-format", value_enum)]
    pub input_format: Option<InputArg>,
    /// Planner: path (motion within --tolerance of the drawn geometry; default for G-code
    /// and DXF), contour (bisector velocities at the feed, mid-segment speed = mean of end
    /// speeds), pt (constant velocity between points), chord-forward
    /// (velocity = outgoing chord / time, as the quad-circle MovePVT example; `chord` is an
    /// alias), chord-back (velocity = incoming chord / time, as AN208), const-accel
    /// (constant acceleration within each piece), spline (C2 cubic spline through the
    /// points at their times; default for CSV) or lspb (linear segments with parabolic
    /// blends at --accel).
    #[arg(long, value_name = "NAME", value_parser = planner)]
    pub planner: Option<Planner>,
    /// Machine file (TOML) with per-axis velocity, acceleration and jerk limits that the
    /// path planner keeps (`compile` refuses it with any other planner) and `check`
    /// verifies.
    #[arg(long, value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Path planner: round a corner between two lines within this distance, program
    /// units, without stopping (without --machine too, at the feed) [default: corners
    /// blend within the path tolerance with --machine, and stop without it].
    #[arg(long = "corner-tolerance", value_name = "T", value_parser = tolerance_number)]
    pub corner_tolerance: Option<f64>,
    /// Fixed time per piece for pt/chord-forward/chord-back/const-accel/spline/lspb, e.g. 5ms;
    /// default: time = distance / feed.
    #[arg(long = "time-slice", value_name = "T", value_parser = duration)]
    pub time_slice: Option<f64>,
    /// Acceleration for lspb blends, program units/s².
    #[arg(long, value_name = "A", value_parser = positive_number)]
    pub accel: Option<f64>,
    /// Make every piece time a whole multiple of this, e.g. 1ms, or `off` [default: the
    /// output format's: pmac and powerpmac 1ms, xps 100us, galil 1/512 s (2 samples), zaber 0.1ms
    /// (with --machine, galil and zaber longer, so that whole counts keep the limits), others off].
    #[arg(long, value_name = "T|off", value_parser = quantum)]
    pub quantize: Option<Quantum>,
    /// Which way --quantize rounds piece times: up (never faster than planned) or
    /// nearest (as PMAC rounds TA) [default: up].
    #[arg(long = "quantize-rounding", value_name = "up|nearest", value_parser = rounding)]
    pub quantize_rounding: Option<Rounding>,
    /// Feed, program units per minute: for moves before the first F word; required for
    /// drawings, which have none.
    #[arg(long, value_name = "F", value_parser = positive_number)]
    pub feed: Option<f64>,
    /// Counts (galil) or microsteps (zaber) per program unit of an axis, `AXIS=N`
    /// (repeatable); overrides the machine file's `counts_per_unit`.
    #[arg(long = "counts-per-unit", value_name = "AXIS=N", value_parser = axis_limit)]
    pub counts_per_unit: Vec<(pvt_core::Axis, f64)>,
    /// Rapid (G0) rate, program units per minute [default: 5000 mm/min in program units].
    #[arg(long, value_name = "F", value_parser = positive_number)]
    pub rapid: Option<f64>,
    /// Path tolerance: the farthest the motion may be from the programmed geometry (path
    /// planner; a program's G64 P overrides it), or the chord tolerance of arcs and curves
    /// (other planners), program units, at least 0.000001 [default: 0.001 mm].
    #[arg(long, value_name = "T", value_parser = tolerance_number)]
    pub tolerance: Option<f64>,
    /// DXF: cut only this layer (repeatable; default every layer).
    #[arg(long = "layer", value_name = "NAME")]
    pub layers: Vec<String>,
    /// DXF: end points closer than this are joined, drawing units [default: 0.01 mm].
    #[arg(long = "join-tolerance", value_name = "T", value_parser = positive_number)]
    pub join_tolerance: Option<f64>,
    /// DXF: where the machine starts, `X,Y`; the nearest contour is cut first [default: 0,0].
    #[arg(long = "start-point", value_name = "X,Y", value_parser = point, allow_hyphen_values = true)]
    pub start_point: Option<[f64; 2]>,
    /// DXF: travel between contours at this Z, plunging at the feed.
    #[arg(long = "safe-z", value_name = "Z", value_parser = finite_number, allow_hyphen_values = true)]
    pub safe_z: Option<f64>,
    /// DXF: most points a drawing may hold (it is read in memory, ~400 bytes per point)
    /// [default: 2000000].
    #[arg(long = "max-points", value_name = "N")]
    pub max_points: Option<usize>,
    /// Units: G-code output is converted into them (default: the program's own); DXF
    /// and CSV input is read in them (DXF: overriding $INSUNITS; CSV default: mm).
    #[arg(long, value_enum)]
    pub units: Option<UnitsArg>,
    /// G-code: work offsets for G54–G59.3 from this file (lines like `G54 X100 Y50 Z-20`,
    /// millimetres and degrees) [default: all zero].
    #[arg(long, value_name = "FILE")]
    pub offsets: Option<PathBuf>,
    /// The rows of the `--offsets` file, once [`PipelineArgs::read_files`] has read it.
    #[arg(skip)]
    pub work_offsets: Option<[[f64; 6]; 9]>,
    /// The `--tool-table` file, once [`PipelineArgs::read_files`] has read it.
    #[arg(skip)]
    pub tools_read: Option<pvt_gcode::ToolTable>,
    /// The `--machine` file, once [`PipelineArgs::read_files`] has read it.
    #[arg(skip)]
    pub machine_read: Option<crate::machine::Machine>,
    /// G-code: folders where `o<name> call` finds `name.ngc` (repeatable, or a
    /// `:`-separated list, like LinuxCNC's SUBROUTINE_PATH).
    #[arg(long = "subroutine-path", value_name = "DIR")]
    pub subroutine_path: Vec<String>,
    /// G-code: the tool table G43 H reads, in LinuxCNC's `.tbl` format (lines like
    /// `T1 P1 Z0.5 D6 ;comment`, millimetres and degrees) [default: no tools].
    #[arg(long = "tool-table", value_name = "FILE")]
    pub tool_table: Option<PathBuf>,
    /// G-code: the value a HAL pin `#<_hal[NAME]>` reads, `NAME=VALUE` (repeatable);
    /// a pin without one is `unsupported`.
    #[arg(long = "hal", value_name = "NAME=VALUE", value_parser = hal_pin)]
    pub hal: Vec<(String, f64)>,
    /// G-code: where the next probing move (G38.2–G38.5) trips, `X,Y,Z` in the
    /// program's coordinates (repeatable, one per probing move, in order); a probing
    /// move without one is an error.
    #[arg(long = "probe-result", value_name = "X,Y,Z", value_parser = probe_result)]
    pub probe_result: Vec<[f64; 3]>,
    /// G-code: plan spindle-synchronised motion (G33, G33.1, G76, G95) at the programmed
    /// S taken as exact (feed per revolution × S, pitch × S) instead of refusing it
    /// [default: refused: a time-based PVT program cannot follow a spindle encoder].
    #[arg(long = "spindle-rpm-exact")]
    pub spindle_rpm_exact: bool,
    /// G-code: the units of the --tool-table file's lengths (LinuxCNC reads a table in
    /// its machine units; the standalone `rs274` in inches) [default: mm].
    #[arg(long = "tool-table-units", value_enum, value_name = "UNITS")]
    pub tool_table_units: Option<UnitsArg>,
    /// G-code: a centre-format arc is refused when its start and end radii differ by
    /// more than 100 times this many mm, or by more than it and by more than
    /// --arc-rel-tolerance (LinuxCNC's rule; within, it runs as a spiral) [default:
    /// LinuxCNC's, 0.0283 mm in a G21 program, 0.00283 in in a G20 program].
    #[arg(long = "arc-abs-tolerance", value_name = "MM", value_parser = positive_number)]
    pub arc_abs_tolerance: Option<f64>,
    /// G-code: relative arc radius tolerance, of the larger radius (0.001 = 0.1 %)
    /// [default: 0.001].
    #[arg(long = "arc-rel-tolerance", value_name = "R", value_parser = positive_number)]
    pub arc_rel_tolerance: Option<f64>,
    /// CSV: where the velocities come from: `file` (the series' v<axis> columns, as given)
    /// or `plan` (the planner's method; the columns are ignored) [default: file when the
    /// series has velocity columns and the planner takes velocities].
    #[arg(long, value_name = "file|plan", value_enum)]
    pub velocities: Option<VelocitiesArg>,
    /// Fail when there is any warning (notes never fail).
    #[arg(long = "deny-warnings")]
    pub deny_warnings: bool,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value = "human")]
    pub diagnostics: DiagnosticsArg,
}

impl PipelineArgs {
    /// Refuses an option that would do nothing for this input and planner (a usage
    /// error): `--time-slice` for `path`, `contour` or a CSV series (which brings its own
    /// times), `--accel` for any planner but `lspb`, `--layer` for anything but a drawing.
    fn check_used(&self, input: InputKind, planner: Planner) -> Result<(), Failure> {
        let name = planner.name();
        if self.time_slice.is_some() {
            if input == InputKind::Csv {
                return Err(Failure::Usage(
                    "--time-slice does nothing for a CSV series, which brings its own times".into(),
                ));
            }
            if matches!(planner, Planner::Path | Planner::Contour) {
                return Err(Failure::Usage(format!(
                    "--time-slice does nothing with the {name} planner: it times pt, \
                     chord-forward, chord-back, const-accel, spline and lspb (--planner NAME)"
                )));
            }
        }
        if self.accel.is_some() && planner != Planner::Lspb {
            return Err(Failure::Usage(format!(
                "--accel does nothing with the {name} planner: it sets the blends of lspb \
                 (--planner lspb)"
            )));
        }
        if !self.subroutine_path.is_empty() && input != InputKind::Gcode {
            return Err(Failure::Usage(
                "--subroutine-path does nothing here: it finds G-code subroutines".into(),
            ));
        }
        if self.tool_table_units.is_some() && self.tool_table.is_none() {
            return Err(Failure::Usage(
                "--tool-table-units does nothing without --tool-table FILE".into(),
            ));
        }
        if !self.hal.is_empty() && input != InputKind::Gcode {
            return Err(Failure::Usage(
                "--hal does nothing here: #<_hal[…]> in a G-code program reads it".into(),
            ));
        }
        if self.spindle_rpm_exact && input != InputKind::Gcode {
            return Err(Failure::Usage(
                "--spindle-rpm-exact does nothing here: it plans G-code's spindle-synchronised \
                 motion"
                    .into(),
            ));
        }
        if !self.probe_result.is_empty() && input != InputKind::Gcode {
            return Err(Failure::Usage(
                "--probe-result does nothing here: G38.2–G38.5 in a G-code program take it".into(),
            ));
        }
        if self.tool_table.is_some() && input != InputKind::Gcode {
            return Err(Failure::Usage(
                "--tool-table does nothing here: G43 H in a G-code program reads it".into(),
            ));
        }
        if self.velocities.is_some() && input != InputKind::Csv {
            return Err(Failure::Usage(
                "--velocities does nothing here: it chooses the velocities of a CSV series".into(),
            ));
        }
        if input != InputKind::Dxf {
            if let Some(option) = self.drawing_option() {
                return Err(Failure::Usage(format!(
                    "{option} does nothing here: it reads or orders a DXF drawing"
                )));
            }
        }
        if input == InputKind::Csv {
            self.check_series_options(planner)?;
        }
        Ok(())
    }

    /// The first DXF-only option given, as written on the command line.
    fn drawing_option(&self) -> Option<&'static str> {
        [
            (!self.layers.is_empty(), "--layer"),
            (self.join_tolerance.is_some(), "--join-tolerance"),
            (self.start_point.is_some(), "--start-point"),
            (self.safe_z.is_some(), "--safe-z"),
            (self.max_points.is_some(), "--max-points"),
        ]
        .into_iter()
        .find_map(|(given, option)| given.then_some(option))
    }

    /// Refuses an option that does nothing for a CSV series (a usage error): the series
    /// brings its own times and has no feed, rapid, arc or curve; `--tolerance` and
    /// `--corner-tolerance` bound only the `path` planner there; drawing and G-code
    /// options read no series.
    fn check_series_options(&self, planner: Planner) -> Result<(), Failure> {
        let path = planner == Planner::Path;
        let unused = [
            (
                self.feed.is_some(),
                "--feed",
                "the series' times set every speed",
            ),
            (
                self.rapid.is_some(),
                "--rapid",
                "a series has no rapid moves",
            ),
            (
                self.tolerance.is_some() && !path,
                "--tolerance",
                "a series has no arcs or curves to divide (it bounds only --planner path)",
            ),
            (
                self.corner_tolerance.is_some() && !path,
                "--corner-tolerance",
                "it rounds corners only with --planner path",
            ),
            (
                self.offsets.is_some()
                    || self.arc_abs_tolerance.is_some()
                    || self.arc_rel_tolerance.is_some(),
                "--offsets, --arc-abs-tolerance and --arc-rel-tolerance",
                "they read G-code programs",
            ),
        ];
        match unused.into_iter().find(|(given, _, _)| *given) {
            Some((_, option, why)) => Err(Failure::Usage(format!(
                "{option} does nothing for a CSV series: {why}"
            ))),
            None => Ok(()),
        }
    }

    /// Reads the files the options name that hold the same for every input of a run
    /// (the `--offsets` table, the `--tool-table` and the `--machine` file), once:
    /// [`PipelineArgs::compile_options`] then reads none.
    pub fn read_files(&mut self) -> Result<(), Failure> {
        if let (Some(path), None) = (&self.offsets, self.work_offsets) {
            self.work_offsets = Some(crate::options::read_offsets(path)?);
        }
        if self.tools_read.is_none() {
            self.tools_read = Some(self.read_tool_table()?.unwrap_or_default());
        }
        if let (Some(path), None) = (&self.machine, &self.machine_read) {
            self.machine_read = Some(crate::machine::Machine::read(path)?);
        }
        Ok(())
    }

    /// The `--tool-table` file in millimetres, if one is given.
    fn read_tool_table(&self) -> Result<Option<pvt_gcode::ToolTable>, Failure> {
        let inch = self.tool_table_units == Some(UnitsArg::In);
        self.tool_table
            .as_deref()
            .map(|path| crate::options::read_tool_table(path, inch))
            .transpose()
    }

    /// What these arguments ask for, as given (no defaults), with the side files: those
    /// [`PipelineArgs::read_files`] read, else read here.
    pub fn asked(&self) -> Result<Asked, Failure> {
        let work_offsets = match (&self.offsets, self.work_offsets) {
            (_, Some(rows)) => Some(rows),
            (Some(path), None) => Some(crate::options::read_offsets(path)?),
            (None, None) => None,
        };
        let tool_table = match &self.tools_read {
            Some(table) => Some(table.clone()),
            None => self.read_tool_table()?,
        };
        let machine = match (&self.machine, &self.machine_read) {
            (_, Some(machine)) => Some(machine.clone()),
            (Some(path), None) => Some(crate::machine::Machine::read(path)?),
            (None, None) => None,
        };
        Ok(Asked {
            input: self.input_format.map(|kind| match kind {
                InputArg::Gcode => InputKind::Gcode,
                InputArg::Dxf => InputKind::Dxf,
                InputArg::Csv => InputKind::Csv,
            }),
            planner: self.planner,
            machine,
            corner_tolerance: self.corner_tolerance,
            feed: self.feed,
            rapid: self.rapid,
            tolerance: self.tolerance,
            time_slice: self.time_slice,
            accel: self.accel,
            quantize: self.quantize.map(|Quantum(q)| q),
            quantize_rounding: self.quantize_rounding,
            counts_per_unit: self.counts_per_unit.clone(),
            work_offsets,
            subroutine_path: self.subroutine_path.clone(),
            tool_table,
            hal_pins: self.hal.clone(),
            probe_results: self.probe_result.clone(),
            spindle_sync: match self.spindle_rpm_exact {
                true => pvt_gcode::SpindleSync::ProgrammedSpeed,
                false => pvt_gcode::SpindleSync::Refuse,
            },
            arc_abs_tolerance_mm: self.arc_abs_tolerance,
            arc_rel_tolerance: self.arc_rel_tolerance,
            layers: self.layers.clone(),
            join_tolerance: self.join_tolerance,
            start_point: self.start_point,
            safe_z: self.safe_z,
            max_points: self.max_points,
            units: self.units.map(|u| match u {
                UnitsArg::Mm => Units::Millimetre,
                UnitsArg::In => Units::Inch,
            }),
            velocities: self.velocities.map(|v| match v {
                VelocitiesArg::File => VelocitySource::File,
                VelocitiesArg::Plan => VelocitySource::Plan,
            }),
        })
    }

    /// The pipeline options these arguments ask for, for a source named `name`, every
    /// default applied by [`crate::settings::compile_options`]; a usage error for an
    /// option that would do nothing there.
    pub fn compile_options(&self, name: &str, format: Format) -> Result<CompileOptions, Failure> {
        let options = crate::settings::compile_options(&self.asked()?, name, format);
        self.check_used(options.input, options.planner)?;
        Ok(options)
    }
}

/// Arguments of `pvtc compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// Part programs, drawings or point-time series: files, directories (searched
    /// recursively for .ngc .nc .gcode .tap .cnc .dxf .csv) or glob patterns; `-` is
    /// standard input.
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,
    /// Where to write the result of a single input; `-` or none writes standard output.
    #[arg(short, long, value_name = "OUTPUT", conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Compile every input into this directory, in parallel, one output per input.
    #[arg(long = "out-dir", value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Parallel jobs for --out-dir [default: one per core].
    #[arg(short, long, value_name = "N")]
    pub jobs: Option<std::num::NonZeroUsize>,
    /// Output format.
    #[arg(long, value_enum, default_value = "pmac")]
    pub format: FormatArg,
    /// How to read and plan the input.
    #[command(flatten)]
    pub pipeline: PipelineArgs,
    /// PMAC program settings.
    #[command(flatten)]
    pub pmac: PmacArgs,
    /// A trigger event every N of path (`5mm`, `0.2in`: the length of the X Y Z motion)
    /// or every T of motion time (`0.1s`, `20ms`), written as the format's controller
    /// takes it: pmac and powerpmac toggle M1 synchronously, zaber `pvt 1 io set do 1`,
    /// json a `triggers` list, csv a `trigger` column; xps, galil and movepvt refuse.
    #[arg(long = "trigger-every", value_name = "N|T", value_parser = trigger_every)]
    pub trigger_every: Option<pvt_emit::TriggerEvery>,
}

/// How PMAC events are written, on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PmacEventsArg {
    /// Comments (`; event spindle_cw from line 5`); G4 as DWELL.
    Comments,
    /// PMAC commands: M03/M04/M05, M07/M08/M09, M06 and M01 (calls of PROG 1001), T<n>
    /// (PROG 1002), S<rpm>, STOP for M0, SEND"…" for a message, DWELL for G4.
    Commands,
}

/// The PMAC program settings of `pvtc compile` (PMAC output only).
#[derive(Debug, Clone, clap::Args)]
pub struct PmacArgs {
    /// PMAC: motion program number, OPEN PROG N (1–32767, not 1000–1003) [default: 1].
    #[arg(long = "pmac-program", value_name = "N")]
    pub program: Option<u32>,
    /// PMAC: address coordinate system &N (1–16) before the program.
    #[arg(long = "pmac-coord", value_name = "N")]
    pub coord: Option<u32>,
    /// PMAC: an axis definition written after &N, like '#1->1000X' (motor 1 is X at 1000
    /// counts per unit); repeatable; every moved axis then needs one. Needs --pmac-coord.
    #[arg(long = "pmac-axis", value_name = "#M->SA", requires = "coord", value_parser = pvt_emit::AxisDefinition::parse)]
    pub axes: Vec<pvt_emit::AxisDefinition>,
    /// PMAC: write the program into the coordinate system's rotary buffer of this many
    /// words (DEFINE ROT), streamed by the host, instead of OPEN PROG: for programs larger
    /// than the controller's memory.
    #[arg(long = "pmac-rotary", value_name = "WORDS", conflicts_with = "program", value_parser = clap::value_parser!(u32).range(1..))]
    pub rotary: Option<u32>,
    /// PMAC: write events (spindle, coolant, tool, pause, message) as comments or as PMAC
    /// commands [default: comments].
    #[arg(long = "pmac-events", value_enum, value_name = "comments|commands")]
    pub events: Option<PmacEventsArg>,
}

impl PmacArgs {
    /// The settings asked for; a usage error when they are out of range or the output
    /// is not PMAC (where they would do nothing).
    pub fn settings(&self, format: FormatArg) -> Result<pvt_emit::PmacSettings, Failure> {
        let given = self.program.is_some()
            || self.coord.is_some()
            || !self.axes.is_empty()
            || self.events.is_some()
            || self.rotary.is_some();
        if given && format != FormatArg::Pmac {
            let name = format
                .to_possible_value()
                .map(|v| v.get_name().to_string())
                .unwrap_or_default();
            return Err(Failure::Usage(format!(
                "--pmac-program, --pmac-coord, --pmac-axis, --pmac-events and --pmac-rotary do \
                 nothing with --format {name}: they set up PMAC output"
            )));
        }
        let settings = pvt_emit::PmacSettings {
            program: self
                .program
                .unwrap_or(pvt_emit::PmacSettings::default().program),
            coord: self.coord,
            axes: self.axes.clone(),
            events: match self.events {
                Some(PmacEventsArg::Commands) => pvt_emit::PmacEvents::Commands,
                Some(PmacEventsArg::Comments) | None => pvt_emit::PmacEvents::Comments,
            },
            rotary: self.rotary,
        };
        settings.validate().map_err(Failure::Usage)?;
        Ok(settings)
    }
}

impl CompileArgs {
    /// The pipeline options for a source named `name`.
    pub fn compile_options(&self, name: &str) -> Result<CompileOptions, Failure> {
        if self.jobs.is_some() && self.out_dir.is_none() {
            return Err(Failure::Usage(
                "-j does nothing without --out-dir: it sets how many files compile at once".into(),
            ));
        }
        let pmac = self.pmac.settings(self.format)?;
        let mut options = self.pipeline.compile_options(name, self.format.into())?;
        if options.machine.is_some() && options.planner != Planner::Path {
            return Err(Failure::Usage(format!(
                "--machine is kept only by the path planner, not by {}: compile with \
                 --planner path, or check the {} motion against the machine with \
                 `pvtc check --machine`",
                options.planner.name(),
                options.planner.name()
            )));
        }
        options.pmac = pmac;
        options.triggers = self.trigger_every;
        Ok(options)
    }
}

/// Arguments of `pvtc check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// A source (compiled first with the options below) or a pvtc JSON program (.json).
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Servo period the controller samples at, e.g. 0.5ms or 250us [default: the machine
    /// file's servo_period, else 0.5ms].
    #[arg(long = "servo-period", value_name = "T", value_parser = duration)]
    pub servo_period: Option<f64>,
    /// Fail (exit 1) when the motion is farther than this from the programmed geometry,
    /// program units.
    #[arg(long = "max-path-error", value_name = "T", value_parser = positive_number)]
    pub max_path_error: Option<f64>,
    /// Most servo samples to take (the motion's time over the servo period); a longer
    /// program is refused rather than sampled for hours. A guard on time only: sampling
    /// streams in constant memory.
    #[arg(
        long = "max-samples",
        value_name = "N",
        default_value_t = 1_000_000_000
    )]
    pub max_samples: u64,
    /// Velocity limit of an axis, `X=500` (units/s); repeatable.
    #[arg(long = "max-vel", value_name = "AXIS=V", value_parser = axis_limit)]
    pub max_vel: Vec<(pvt_core::Axis, f64)>,
    /// Acceleration limit of an axis, `X=5000` (units/s²); repeatable.
    #[arg(long = "max-accel", value_name = "AXIS=A", value_parser = axis_limit)]
    pub max_accel: Vec<(pvt_core::Axis, f64)>,
    /// Jerk limit of an axis, `X=1e6` (units/s³); repeatable.
    #[arg(long = "max-jerk", value_name = "AXIS=J", value_parser = axis_limit)]
    pub max_jerk: Vec<(pvt_core::Axis, f64)>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// How to read and plan the input.
    #[command(flatten)]
    pub pipeline: PipelineArgs,
}

impl CheckArgs {
    /// The limits per axis these arguments give.
    pub fn limits(&self) -> std::collections::BTreeMap<pvt_core::Axis, AxisLimits> {
        let mut limits: std::collections::BTreeMap<pvt_core::Axis, AxisLimits> = Default::default();
        for (axis, v) in &self.max_vel {
            limits.entry(*axis).or_default().velocity = Some(*v);
        }
        for (axis, a) in &self.max_accel {
            limits.entry(*axis).or_default().acceleration = Some(*a);
        }
        for (axis, j) in &self.max_jerk {
            limits.entry(*axis).or_default().jerk = Some(*j);
        }
        limits
    }
}

/// Arguments of `pvtc plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// A source (compiled first with the options below) or a pvtc JSON program (.json).
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// The file to write: FILE.svg (SVG) or FILE.png (PNG); `-` writes SVG on standard
    /// output.
    #[arg(short, long, value_name = "FILE.svg|FILE.png")]
    pub output: PathBuf,
    /// How to read and plan the input.
    #[command(flatten)]
    pub pipeline: PipelineArgs,
}

/// Arguments of `pvtc diff`.
#[derive(Debug, clap::Args)]
#[command(mut_arg("tolerance", |a| a.long("path-tolerance")))]
pub struct DiffArgs {
    /// The first program: any format pvtc writes (.pmac, .pmc, .c, .trj, .dmc, .zaber,
    /// .json, a .csv table), or a source compiled with the options below.
    #[arg(value_name = "A")]
    pub first: PathBuf,
    /// The second program, likewise.
    #[arg(value_name = "B")]
    pub second: PathBuf,
    /// Farthest apart the positions may be: a length (1um, 0.01mm, 0.0001in) or counts
    /// (2counts, at --counts-per-unit) [default: 1um].
    #[arg(long = "tolerance", value_name = "LENGTH", value_parser = distance)]
    pub position_tolerance: Option<Distance>,
    /// Largest time shift and difference of total times, e.g. 1ms [default: 1ms].
    #[arg(long = "time-tolerance", value_name = "T", value_parser = duration)]
    pub time_tolerance: Option<f64>,
    /// Largest relative difference of each axis' velocity, acceleration and jerk peak,
    /// e.g. 1% [default: 1%].
    #[arg(long = "peak-tolerance", value_name = "P%", value_parser = share)]
    pub peak_tolerance: Option<f64>,
    /// The format a source is compiled to [default: the other program's, else json].
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Print one JSON object instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also write an interactive HTML page of both motions and their difference.
    #[arg(short, long, value_name = "FILE.html")]
    pub output: Option<PathBuf>,
    /// How to read and plan a source (its path tolerance is --path-tolerance here).
    #[command(flatten)]
    pub pipeline: PipelineArgs,
}

fn planner(text: &str) -> Result<Planner, String> {
    text.parse::<Planner>().map_err(|e| e.to_string())
}

fn rounding(text: &str) -> Result<Rounding, String> {
    text.parse::<Rounding>()
}

/// `--quantize`'s value: a [`duration`] or `off`.
fn quantum(text: &str) -> Result<Quantum, String> {
    match text.trim() {
        "off" => Ok(Quantum(None)),
        t => duration(t).map(|q| Quantum(Some(q))),
    }
}

/// A length with its unit, `mm`, `um` (`µm`) or `in`, in millimetres; `None` without
/// one of them.
fn length(text: &str) -> Option<Result<f64, String>> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("mm") {
        (n, 1.0)
    } else if let Some(n) = t.strip_suffix("um").or_else(|| t.strip_suffix("µm")) {
        (n, 1e-3)
    } else {
        (t.strip_suffix("in")?, 25.4)
    };
    Some(positive_number(number).map(|x| x * scale))
}

/// `--tolerance` of `diff`: a [`length`] or a number of counts (`2counts`).
fn distance(text: &str) -> Result<Distance, String> {
    let t = text.trim();
    if let Some(n) = t.strip_suffix("counts").or_else(|| t.strip_suffix("count")) {
        return positive_number(n).map(Distance::Counts);
    }
    match length(t) {
        Some(mm) => mm.map(Distance::Millimetres),
        None => Err(format!(
            "pvtc::usage: a tolerance needs a unit: a length (1um, 0.01mm, 0.0001in) or counts (2counts), not {t:?}"
        )),
    }
}

/// A share: a percentage (`1%`) or a fraction (`0.01`).
fn share(text: &str) -> Result<f64, String> {
    let t = text.trim();
    match t.strip_suffix('%') {
        Some(n) => positive_number(n).map(|x| x / 100.0),
        None => positive_number(t),
    }
}

/// `--trigger-every`'s value: a [`length`] (kept in millimetres) or a [`duration`].
fn trigger_every(text: &str) -> Result<pvt_emit::TriggerEvery, String> {
    let t = text.trim();
    if let Some(mm) = length(t) {
        return mm.map(pvt_emit::TriggerEvery::Distance);
    }
    match duration(t) {
        Ok(s) => Ok(pvt_emit::TriggerEvery::Seconds(s)),
        Err(_) => Err(format!(
            "pvtc::usage: a trigger interval needs a unit: a length (5mm, 0.2in) or a time (0.1s, 20ms), not {t:?}"
        )),
    }
}

/// A duration: a number with `s`, `ms` or `us`. A bare number is refused (`pvtc::usage`)
/// rather than read in some unit: `--quantize 1` could mean 1 s or 1 ms.
pub fn duration(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix("us").or_else(|| t.strip_suffix("µs")) {
        (n, 1e-6)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        positive_number(t)?;
        return Err(format!(
            "pvtc::usage: a duration needs a unit (s, ms or us): write {t}ms or {t}s"
        ));
    };
    Ok(positive_number(number)? * scale)
}

fn axis_limit(text: &str) -> Result<(pvt_core::Axis, f64), String> {
    let (axis, value) = text
        .split_once('=')
        .ok_or("expected AXIS=VALUE, e.g. X=500")?;
    let mut chars = axis.trim().chars();
    let axis = match (
        chars.next().and_then(pvt_core::Axis::from_letter),
        chars.next(),
    ) {
        (Some(a), None) => a,
        _ => return Err(format!("unknown axis {axis:?}: one of X Y Z A B C")),
    };
    Ok((axis, positive_number(value)?))
}

fn finite_number(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err("must be a finite number".into()),
        Err(e) => Err(e.to_string()),
    }
}

fn point(text: &str) -> Result<[f64; 2], String> {
    let (x, y) = text.split_once(',').ok_or("expected X,Y")?;
    Ok([finite_number(x)?, finite_number(y)?])
}

fn positive_number(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        Ok(_) => Err("must be a finite number greater than zero".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// `--tolerance`, `--corner-tolerance`: a finite number of at least
/// [`pvt_core::ChordTolerance::SMALLEST`] program units.
fn tolerance_number(text: &str) -> Result<f64, String> {
    let smallest = pvt_core::ChordTolerance::SMALLEST;
    match positive_number(text)? {
        x if x >= smallest => Ok(x),
        _ => Err(format!(
            "must be at least {smallest} (program units): pvtc plans to no finer tolerance"
        )),
    }
}

/// `--probe-result X,Y,Z`: three finite numbers.
fn probe_result(text: &str) -> Result<[f64; 3], String> {
    let values: Vec<Result<f64, _>> = text.split(',').map(|v| v.trim().parse::<f64>()).collect();
    match values.as_slice() {
        [Ok(x), Ok(y), Ok(z)] if [x, y, z].iter().all(|v| v.is_finite()) => Ok([*x, *y, *z]),
        _ => Err("give where the probe trips as X,Y,Z, three numbers, e.g. 10,5,-2.5".into()),
    }
}

/// `--hal NAME=VALUE`: a HAL pin's name and a finite value.
fn hal_pin(text: &str) -> Result<(String, f64), String> {
    let Some((name, value)) = text.split_once('=') else {
        return Err("give a pin and its value as NAME=VALUE, e.g. motion.digital-in-00=1".into());
    };
    let name = name.trim();
    if name.is_empty() || name.contains([']', '[']) {
        return Err(format!("{name:?} is not a HAL pin name"));
    }
    match value.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok((name.to_owned(), v)),
        Ok(_) => Err("the value must be a finite number".into()),
        Err(e) => Err(format!("the value {value:?}: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_need_units() {
        assert_eq!(duration("0.5ms"), Ok(0.0005));
        assert_eq!(duration("250us"), Ok(0.00025));
        assert_eq!(duration("2s"), Ok(2.0));
        assert!(duration("-1ms").is_err() && duration("fast").is_err());
        let bare = duration("1").unwrap_err();
        assert!(
            bare.contains("pvtc::usage") && bare.contains("write 1ms or 1s"),
            "{bare}"
        );
        assert!(duration("0.001").is_err() && duration(" 5 ").is_err());
    }

    #[test]
    fn the_offsets_file_is_read_once_per_run() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("offsets.txt");
        std::fs::write(&path, "G55 X100 Y50\n").unwrap();
        let cli = Cli::try_parse_from(
            ["pvtc", "compile", "a.ngc", "b.ngc", "--offsets"]
                .iter()
                .copied()
                .chain([path.to_str().unwrap()]),
        )
        .unwrap();
        let Command::Compile(mut args) = cli.command else {
            panic!("a compile command");
        };
        args.pipeline.read_files().unwrap();
        // Gone after the one read: every job's options still have its rows.
        std::fs::remove_file(&path).unwrap();
        for name in ["a.ngc", "b.ngc"] {
            let options = args.compile_options(name).unwrap();
            assert_eq!(options.work_offsets[1], [100.0, 50.0, 0.0, 0.0, 0.0, 0.0]);
        }
        // Without the run's read, the file is read (and here missing).
        args.pipeline.work_offsets = None;
        assert!(matches!(
            args.compile_options("a.ngc"),
            Err(Failure::Io { .. })
        ));
    }

    #[test]
    fn the_tool_table_and_machine_file_are_read_once_per_run() {
        let dir = tempfile::tempdir().unwrap();
        let tools = dir.path().join("tools.tbl");
        let machine = dir.path().join("machine.toml");
        std::fs::write(&tools, "T1 P1 Z2.5 D1 ;drill\n").unwrap();
        let root = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../samples/machines/mill.toml"
        );
        std::fs::copy(root, &machine).unwrap();
        let (tools_arg, machine_arg) = (tools.to_str().unwrap(), machine.to_str().unwrap());
        let cli = Cli::try_parse_from([
            "pvtc",
            "compile",
            "a.ngc",
            "b.ngc",
            "--tool-table",
            tools_arg,
            "--machine",
            machine_arg,
        ])
        .unwrap();
        let Command::Compile(mut args) = cli.command else {
            panic!("a compile command");
        };
        args.pipeline.read_files().unwrap();
        std::fs::remove_file(&tools).unwrap();
        std::fs::remove_file(&machine).unwrap();
        for name in ["a.ngc", "b.ngc"] {
            let options = args.compile_options(name).unwrap();
            assert!(options.machine.is_some(), "{name}: the machine read once");
            assert_eq!(
                options.tool_table,
                args.pipeline.tools_read.clone().unwrap()
            );
        }
        args.pipeline.tools_read = None;
        assert!(
            args.compile_options("a.ngc").is_err(),
            "read again: missing"
        );
    }

    #[test]
    fn tolerances_need_units() {
        assert_eq!(distance("1um"), Ok(Distance::Millimetres(0.001)));
        assert_eq!(distance("0.5 mm"), Ok(Distance::Millimetres(0.5)));
        assert_eq!(distance("0.001in"), Ok(Distance::Millimetres(0.0254)));
        assert_eq!(distance("2counts"), Ok(Distance::Counts(2.0)));
        assert!(distance("1").unwrap_err().contains("needs a unit"));
        assert!(distance("-1um").is_err() && distance("0mm").is_err());
        assert_eq!(share("1%"), Ok(0.01));
        assert_eq!(share("0.02"), Ok(0.02));
        assert!(share("0%").is_err());
        assert_eq!(
            trigger_every("5mm"),
            Ok(pvt_emit::TriggerEvery::Distance(5.0))
        );
    }

    #[test]
    fn axis_limits_parse() {
        assert_eq!(axis_limit("x=500"), Ok((pvt_core::Axis::X, 500.0)));
        assert!(
            axis_limit("Q=1").is_err()
                && axis_limit("X500").is_err()
                && axis_limit("X=-1").is_err()
        );
    }
}
