//! The SVG plot back end: what a program's motion looks like, for a reader.
//!
//! Owns `pvtc plot`'s picture: one SVG document (drawn with plotters' SVG backend) with
//! the path in its plane coloured by vector speed and the programmed points marked,
//! then the vector speed, each axis' velocity and each axis' acceleration against
//! time. The motion is drawn from the pieces as the controller interpolates them
//! (cubic Hermite for PVT, constant velocity for PT), sampled densely but capped
//! ([`sample`]), so a program of any length gives a file of bounded size.
//!
//! It must not plan, change a value of the program or read files, and its output
//! carries no time stamp: the same program and options give a byte-identical SVG.
//! Labels are SVG `<text>` elements, so no font file is needed.

mod draw;
mod path;
pub mod sample;
mod scale;

use crate::validate::{validate, InvalidProgram};
use pvt_core::PvtProgram;

pub use sample::{sample_program, SampleAt, SampleOptions, Samples};

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
}

impl Default for PlotOptions {
    fn default() -> PlotOptions {
        PlotOptions {
            title: "pvtc motion".to_string(),
            width: 1000,
            height: 1500,
            limits: std::collections::BTreeMap::new(),
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
    validate(program)?;
    if program.segment_count() == 0 {
        return Err(PlotError::Empty);
    }
    let samples = sample_program(program, &SampleOptions::default());
    draw::render(program, &samples, options)
}
