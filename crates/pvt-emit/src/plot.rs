//! The plot back end: what a program's motion looks like, for a reader.
//!
//! Owns `pvtc plot`'s picture: one SVG document (plotters' SVG backend) or PNG image
//! (plotters' bitmap backend, encoded by `image`) with the programmed path (true arcs,
//! from the toolpath, in grey) under the motion in its plane coloured by vector speed,
//! the programmed end points of the elements marked, then the vector speed, each axis'
//! velocity and each axis' acceleration against time, and the third axis against time
//! when it moves. The motion is drawn from the pieces as the controller interpolates them
//! (cubic Hermite for PVT, constant velocity for PT), sampled densely but capped
//! ([`sample`]), so a program of any length gives a file of bounded size.
//!
//! It must not plan, change a value of the program or read files, and its output
//! carries no time stamp: the same program and options give a byte-identical file.
//! Labels are laid out (and, in PNG, drawn) with DejaVu Sans built into the binary
//! (`plot/font/`, ASCII and Latin-1 only; its licence is `plot/font/LICENSE`), so no
//! system font is read; SVG labels are `<text>` elements the viewer draws.

mod draw;
mod path;
pub mod sample;
mod scale;

use crate::validate::{validate, InvalidProgram};
use pvt_core::PvtProgram;

pub use sample::{sample_every, sample_program, SampleAt, SampleOptions, Samples};

/// How the plot looks.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotOptions {
    /// Title printed over the whole document (e.g. the source's name).
    pub title: String,
    /// Width of the document, pixels (400 at least).
    pub width: u32,
    /// Height of the document, pixels (600 at least).
    pub height: u32,
    /// Per-axis limits drawn as ± lines on the velocity and acceleration panels.
    pub limits: std::collections::BTreeMap<pvt_core::Axis, pvt_core::AxisLimits>,
    /// The programmed geometry the program was planned from, drawn under the motion
    /// (true arcs); without it the piece ends are marked instead of element ends.
    pub geometry: Option<pvt_core::Toolpath>,
}

impl Default for PlotOptions {
    fn default() -> PlotOptions {
        PlotOptions {
            title: "pvtc motion".to_string(),
            width: 1000,
            height: 1500,
            limits: std::collections::BTreeMap::new(),
            geometry: None,
        }
    }
}

/// Why a program could not be plotted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// A value of the program is not finite or a piece time is not positive.
    #[error(transparent)]
    Invalid(#[from] InvalidProgram),
    /// The program has no segment.
    #[error("nothing to plot: the program has no segment")]
    Empty,
    /// An evaluated value overflowed to infinity or NaN.
    #[error("cannot plot: the evaluated motion has a value that is not finite")]
    NotFinite,
    /// The plotting library failed.
    #[error("plotting failed: {0}")]
    Draw(String),
}

/// The SVG document plotting `program`'s motion.
pub fn plot_svg(program: &PvtProgram, options: &PlotOptions) -> Result<String, PlotError> {
    let samples = checked_samples(program)?;
    draw::render(program, &samples, options)
}

/// The same plot as a PNG image (`options.width` × `options.height` pixels).
pub fn plot_png(program: &PvtProgram, options: &PlotOptions) -> Result<Vec<u8>, PlotError> {
    let samples = checked_samples(program)?;
    draw::render_png(program, &samples, options)
}

/// The samples of a valid, non-empty program.
fn checked_samples(program: &PvtProgram) -> Result<Samples, PlotError> {
    validate(program)?;
    if program.segment_count() == 0 {
        return Err(PlotError::Empty);
    }
    Ok(sample_program(program, &SampleOptions::default()))
}

/// Registers the built-in fonts with plotters, once.
fn fonts() -> Result<(), PlotError> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        use plotters::style::{register_font, FontStyle};
        let regular = include_bytes!("plot/font/DejaVuSans-subset.ttf");
        let bold = include_bytes!("plot/font/DejaVuSans-Bold-subset.ttf");
        register_font(draw::FONT, FontStyle::Normal, regular).is_ok()
            && register_font(draw::FONT, FontStyle::Bold, bold).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Draw(
            "the built-in font could not be read".into(),
        ))
    }
}
