//! pvt-emit: the back ends that turn PVT motion into what a controller takes.
//!
//! Owns the output formats: PMAC PVT motion program text ([`pmac`]), MovePVT arrays as C
//! source ([`movepvt`]) and the versioned pvtc JSON document ([`json`]), and the
//! interpreted toolpath before planning as JSON lines ([`toolpath`]). Each back end of
//! motion is a [`ProgramWriter`] fed one piece at a time ([`stream`]), so output of any length goes
//! out in constant memory; [`Checked`] validates every value before a back end sees it,
//! so a NaN, an infinity or a non-positive piece time never reaches an output.
//!
//! Architecture invariants: back ends never plan, never read files and never change a
//! number's value; the same program and options always give byte-identical output.

pub mod json;
pub mod movepvt;
mod number;
pub mod plot;
pub mod pmac;
pub mod stream;
pub mod toolpath;
pub mod validate;

use pvt_core::PvtProgram;
use std::io::Write;

pub use pmac::{AxisDefinition, PmacEvents, PmacSettings};
pub use stream::{Checked, Header, ProgramWriter, StreamError};
pub use validate::{validate, InvalidProgram};

/// The output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// PMAC motion program in PVT mode.
    Pmac,
    /// MovePVT position/velocity/time arrays as C source.
    MovePvt,
    /// The pvtc JSON document.
    Json,
}

impl Format {
    /// Every format, in the order the CLI lists them.
    pub const ALL: [Format; 3] = [Format::Pmac, Format::MovePvt, Format::Json];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Format::Pmac => "pmac",
            Format::MovePvt => "movepvt",
            Format::Json => "json",
        }
    }

    /// The resolution positions are written with, program units: PMAC text rounds them to
    /// [`pmac::POSITION_DECIMALS`] decimals ([`pmac::POSITION_RESOLUTION`]); MovePVT and JSON write the shortest
    /// round-trip number, exactly (0).
    pub fn position_resolution(self) -> f64 {
        match self {
            Format::Pmac => pmac::POSITION_RESOLUTION,
            Format::MovePvt | Format::Json => 0.0,
        }
    }

    /// The usual file extension of the format.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Pmac => "pmac",
            Format::MovePvt => "c",
            Format::Json => "json",
        }
    }

    /// The longest piece time the format can express, seconds (`None`: no limit); longer
    /// pieces must be cut first ([`pvt_core::split_long_pieces`]).
    pub fn max_piece_seconds(self) -> Option<f64> {
        match self {
            Format::Pmac => Some(pmac::MAX_PIECE_SECONDS),
            Format::MovePvt | Format::Json => None,
        }
    }

    /// The time its controller rounds piece times to, seconds (PMAC: whole milliseconds);
    /// a long piece whose time is whole is cut into pieces whose times are whole.
    pub fn piece_time_quantum(self) -> Option<f64> {
        match self {
            Format::Pmac => Some(0.001),
            Format::MovePvt | Format::Json => None,
        }
    }

    /// A streaming writer of this format into `out`.
    pub fn writer<'a, W: Write + 'a>(self, out: W) -> Box<dyn ProgramWriter + 'a> {
        match self {
            Format::Pmac => Box::new(pmac::PmacWriter::new(out)),
            Format::MovePvt => Box::new(movepvt::MovePvtWriter::new(out)),
            Format::Json => Box::new(json::JsonWriter::new(out)),
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
    let mut events = program.events.iter().peekable();
    for (index, contour) in program.contours.iter().enumerate() {
        while let Some(event) = events.next_if(|e| e.before_contour <= index) {
            writer.event(event)?;
        }
        writer.contour(
            contour.motion,
            &contour.start,
            contour.lines.first().copied().unwrap_or(0),
        )?;
        for seg in contour.segments() {
            writer.segment(&seg)?;
        }
    }
    for event in events {
        writer.event(event)?;
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
