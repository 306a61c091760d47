//! Command-line arguments.
//!
//! Owns the flags and their help text. It must not read files or compile anything.

use crate::pipeline::{CompileOptions, DrawingOptions, InputKind};
use clap::{Parser, Subcommand, ValueEnum};
use pvt_core::Units;
use pvt_emit::Format;
use std::path::PathBuf;

/// pvtc compiles G-code part programs into position-velocity-time motion for controllers.
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
    /// Compile a part program into PVT motion.
    Compile(CompileArgs),
}

/// Output format names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// PMAC motion program in PVT mode (`TA<ms> X<pos>:<vel> …`).
    Pmac,
    /// MovePVT position, velocity and time arrays as C source.
    Movepvt,
    /// The pvtc JSON document, version 1.
    Json,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Pmac => Format::Pmac,
            FormatArg::Movepvt => Format::MovePvt,
            FormatArg::Json => Format::Json,
        }
    }
}

/// Input kind names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InputArg {
    /// RS274/NGC G-code.
    Gcode,
    /// DXF drawing (ASCII or binary).
    Dxf,
}

/// Unit names on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum UnitsArg {
    /// Millimetres.
    Mm,
    /// Inches.
    In,
}

/// Arguments of `pvtc compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// Part programs or drawings to compile: files, directories (searched recursively
    /// for .ngc .nc .gcode .tap .cnc .dxf) or glob patterns; `-` reads standard input.
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
    /// Kind of input; by default taken from the file name (G-code otherwise).
    #[arg(long = "input-format", value_enum)]
    pub input_format: Option<InputArg>,
    /// Feed for feed moves before the program's first F word, program units per minute.
    #[arg(long, value_name = "F", value_parser = positive_number)]
    pub feed: Option<f64>,
    /// Rapid (G0) rate, program units per minute [default: 5000 mm/min in program units].
    #[arg(long, value_name = "F", value_parser = positive_number)]
    pub rapid: Option<f64>,
    /// Chord tolerance for arcs, program units [default: 0.001 mm in program units].
    #[arg(long, value_name = "T", value_parser = positive_number)]
    pub tolerance: Option<f64>,
    /// DXF: cut only this layer (repeatable; default every layer).
    #[arg(long = "layer", value_name = "NAME")]
    pub layers: Vec<String>,
    /// DXF: end points closer than this are joined, drawing units [default: 0.01 mm].
    #[arg(long = "join-tolerance", value_name = "T", value_parser = positive_number)]
    pub join_tolerance: Option<f64>,
    /// DXF: where the machine starts, `X,Y`; the nearest contour is cut first [default: 0,0].
    #[arg(long = "start-point", value_name = "X,Y", value_parser = point)]
    pub start_point: Option<[f64; 2]>,
    /// DXF: travel between contours at this Z, plunging at the feed [default: stay in the drawing's Z].
    #[arg(long = "safe-z", value_name = "Z", value_parser = finite_number)]
    pub safe_z: Option<f64>,
    /// DXF: the drawing's units, overriding its $INSUNITS.
    #[arg(long, value_enum)]
    pub units: Option<UnitsArg>,
}

impl CompileArgs {
    /// The pipeline options these arguments ask for, for a source named `name`.
    pub fn compile_options(&self, name: &str) -> CompileOptions {
        CompileOptions {
            format: self.format.into(),
            input: match self.input_format {
                Some(InputArg::Gcode) => InputKind::Gcode,
                Some(InputArg::Dxf) => InputKind::Dxf,
                None => InputKind::from_name(name),
            },
            feed: self.feed,
            rapid: self.rapid,
            tolerance: self.tolerance,
            drawing: DrawingOptions {
                layers: self.layers.clone(),
                join_tolerance: self.join_tolerance,
                start_point: self.start_point.unwrap_or([0.0, 0.0]),
                safe_z: self.safe_z,
                units: self.units.map(|u| match u {
                    UnitsArg::Mm => Units::Millimetre,
                    UnitsArg::In => Units::Inch,
                }),
            },
        }
    }
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
