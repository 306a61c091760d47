//! pvt-emit: the back ends that turn PVT motion into what a controller takes.
//!
//! Owns the output formats: Turbo PMAC PVT motion program text ([`pmac`]), MovePVT arrays
//! as C source ([`movepvt`]), the versioned pvtc JSON document ([`json`]), the Newport
//! XPS trajectory file ([`xps`]), Galil PV commands ([`galil`]), Zaber ASCII PVT commands
//! ([`zaber`]), Power PMAC PVT program text ([`powerpmac`]) and a CSV table ([`table`]),
//! the plots ([`plot`]: SVG, PNG; [`view`]: an interactive HTML page),
//! each controller's rules in one table ([`Format::caps`], checked by [`rules`]), trigger
//! events along the motion ([`triggers`]), the readers of what they emit for `pvtc
//! check` ([`readback`]), and the
//! interpreted toolpath before planning as JSON lines ([`toolpath`]). Each back end of
//! motion is a [`ProgramWriter`] fed one piece at a time ([`writer`]), so output of any length goes
//! out in constant memory; [`Checked`] validates every value before a back end sees it,
//! so a NaN, an infinity or a non-positive piece time never reaches an output.
//!
//! Architecture invariants: back ends never plan, never read files and never change a
//! number's value (a piece cut at a trigger is cut along its own cubic: the same
//! motion); the same program and options always give byte-identical output.

pub mod galil;
mod gather;
pub mod json;
mod lines;
pub mod movepvt;
mod number;
pub mod plot;
pub mod pmac;
pub mod powerpmac;
pub mod readback;
pub mod rules;
pub mod table;
pub mod toolpath;
pub mod triggers;
pub mod validate;
pub mod view;
pub mod writer;
pub mod xps;
pub mod zaber;

use pvt_core::traverse::Step;
use pvt_core::{Axis, PvtProgram};
use std::collections::BTreeMap;
use std::io::Write;

pub use pmac::{AxisDefinition, PmacEvents, PmacSettings};
pub use rules::{AxisSetup, Caps, Positions};
pub use triggers::{TriggerEvery, TriggerSupport, Triggers};
pub use validate::{validate, InvalidProgram};
pub use writer::{
    Checked, Collected, Header, PieceLine, PieceLines, ProgramWriter, StreamError, Unwritten,
};

/// The output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Turbo PMAC motion program in PVT mode.
    Pmac,
    /// MovePVT position/velocity/time arrays as C source.
    MovePvt,
    /// The pvtc JSON document.
    Json,
    /// Newport XPS PVT trajectory file.
    Xps,
    /// Galil DMC PVT mode (`PVA=p,v,t`) commands.
    Galil,
    /// Zaber ASCII protocol PVT sequence commands.
    Zaber,
    /// Power PMAC motion program in PVT mode.
    PowerPmac,
    /// A table `t, X, vX, …` with absolute time.
    Csv,
}

impl Format {
    /// Every format, in the order the CLI lists them.
    pub const ALL: [Format; 8] = [
        Format::Pmac,
        Format::MovePvt,
        Format::Json,
        Format::Xps,
        Format::Galil,
        Format::Zaber,
        Format::PowerPmac,
        Format::Csv,
    ];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Format::Pmac => "pmac",
            Format::MovePvt => "movepvt",
            Format::Json => "json",
            Format::Xps => "xps",
            Format::Galil => "galil",
            Format::Zaber => "zaber",
            Format::PowerPmac => "powerpmac",
            Format::Csv => "csv",
        }
    }

    /// What the format's controller accepts: the one table of controller rules (each
    /// back end's module doc cites where each number comes from).
    pub fn caps(self) -> Caps {
        match self {
            Format::Pmac => pmac::CAPS,
            Format::MovePvt => Caps {
                controller: "MovePVT",
                triggers: TriggerSupport::None(
                    "the arrays hold motion only; --format json or csv give the trigger times",
                ),
                ..Caps::FREE
            },
            Format::Json => Caps {
                controller: "pvtc JSON",
                ..Caps::FREE
            },
            Format::Xps => xps::CAPS,
            Format::Galil => galil::CAPS,
            Format::Zaber => zaber::CAPS,
            Format::PowerPmac => powerpmac::CAPS,
            Format::Csv => Caps {
                controller: "CSV table",
                ..Caps::FREE
            },
        }
    }

    /// The resolution positions are written with, program units: PMAC and Power PMAC
    /// text round them to [`pmac::POSITION_DECIMALS`] decimals
    /// ([`pmac::POSITION_RESOLUTION`]); the other formats write the shortest round-trip
    /// number, exactly (0), or counts, whose size depends on the axis' scale (0 here).
    pub fn position_resolution(self) -> f64 {
        match self {
            Format::Pmac | Format::PowerPmac => pmac::POSITION_RESOLUTION,
            _ => 0.0,
        }
    }

    /// The usual file extension of the format.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Pmac => "pmac",
            Format::MovePvt => "c",
            Format::Json => "json",
            Format::Xps => "trj",
            Format::Galil => "dmc",
            Format::Zaber => "zaber",
            Format::PowerPmac => "pmc",
            Format::Csv => "csv",
        }
    }

    /// The longest piece time the format can express, seconds (`None`: no limit); longer
    /// pieces must be cut first ([`pvt_core::split_long_pieces`]).
    pub fn max_piece_seconds(self) -> Option<f64> {
        self.caps().max_piece_seconds
    }

    /// The time its controller rounds piece times to, seconds (PMAC: whole milliseconds);
    /// a long piece whose time is whole is cut into pieces whose times are whole.
    pub fn piece_time_quantum(self) -> Option<f64> {
        self.caps().time_quantum
    }

    /// A streaming writer of this format into `out`.
    pub fn writer<'a, W: Write + 'a>(self, out: W) -> Box<dyn ProgramWriter + 'a> {
        match self {
            Format::Pmac => Box::new(pmac::PmacWriter::new(out)),
            Format::MovePvt => Box::new(movepvt::MovePvtWriter::new(out)),
            Format::Json => Box::new(json::JsonWriter::new(out)),
            Format::Xps => Box::new(xps::XpsWriter::new(out)),
            Format::Galil => Box::new(galil::GalilWriter::new(out)),
            Format::Zaber => Box::new(zaber::ZaberWriter::new(out)),
            Format::PowerPmac => Box::new(powerpmac::PowerPmacWriter::new(out)),
            Format::Csv => Box::new(table::TableWriter::new(out)),
        }
    }
}

/// What a back end says about where the program came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmitOptions {
    /// Name of the source, as the user gave it.
    pub source: String,
    /// The settings that shaped the program, as (name, value) pairs, in a fixed order.
    pub settings: Vec<(String, String)>,
    /// PMAC program number, coordinate system, axis definitions and event commands.
    pub pmac: pmac::PmacSettings,
    /// Per axis: travel limits (checked for every format), the limits a verifying
    /// controller checks, and counts per unit for formats written in counts.
    pub axes: BTreeMap<Axis, AxisSetup>,
    /// Trigger events along the motion (`--trigger-every`), where the format takes them.
    pub triggers: Option<Triggers>,
}

/// Validates the whole of `program`, then writes it in `format` to `out`.
pub fn emit(
    program: &PvtProgram,
    format: Format,
    options: &EmitOptions,
    out: &mut dyn Write,
) -> Result<(), StreamError> {
    validate(program)?;
    let mut writer = Checked::new(format.writer(out));
    let header = Header {
        axes: &program.axes,
        units: program.units,
        interpolation: program.interpolation,
        options,
    };
    writer.begin(&header)?;
    for step in pvt_core::traverse::program(program) {
        match step {
            Step::Event(event) => writer.event(event)?,
            Step::PathTolerance(_) => {}
            Step::Contour(contour) => {
                writer.contour(
                    contour.motion,
                    &contour.start,
                    contour.lines.first().copied().unwrap_or(0),
                )?;
                for seg in contour.segments() {
                    writer.segment(&seg)?;
                }
            }
        }
    }
    writer.finish()?;
    Ok(())
}

/// Validates `program` and returns it in `format` as bytes.
pub fn emit_to_vec(
    program: &PvtProgram,
    format: Format,
    options: &EmitOptions,
) -> Result<Vec<u8>, StreamError> {
    let mut out = Vec::new();
    emit(program, format, options, &mut out)?;
    Ok(out)
}
