//! Choosing and calling a front end: bytes in, a toolpath and its warnings out.
//!
//! Owns the mapping from CLI options to each front end's options and from each front
//! end's diagnostics to printable reports. It must not plan or write output.

use crate::pipeline::{CompileOptions, Failure, InputKind};
use miette::{NamedSource, Report};
use pvt_core::Toolpath;

/// A toolpath with the warnings met while reading it.
pub type FrontResult = Result<(Toolpath, Vec<Report>), Failure>;

/// Reads `bytes` (named `name`) with the front end `options.input` selects.
pub fn read(name: &str, bytes: &[u8], options: &CompileOptions) -> FrontResult {
    match options.input {
        InputKind::Gcode => gcode(name, bytes, options),
        InputKind::Dxf => dxf(bytes, options),
    }
}

fn gcode(name: &str, bytes: &[u8], options: &CompileOptions) -> FrontResult {
    // Invalid UTF-8 (a Latin-1 comment, say) becomes U+FFFD; spans refer to this text.
    let text = String::from_utf8_lossy(bytes).into_owned();
    let named = || NamedSource::new(name, text.clone());
    let gcode_options = pvt_gcode::GcodeOptions {
        default_feed: options.feed,
        rapid: options.rapid,
        ..Default::default()
    };
    match pvt_gcode::compile(&text, &gcode_options) {
        Ok(compiled) => {
            let warnings = compiled
                .warnings
                .into_iter()
                .map(|w| Report::new(w).with_source_code(named()))
                .collect();
            Ok((compiled.toolpath, warnings))
        }
        Err(errors) => Err(Failure::Input(
            errors
                .diagnostics
                .into_iter()
                .map(|e| Report::new(e).with_source_code(named()))
                .collect(),
        )),
    }
}

fn dxf(bytes: &[u8], options: &CompileOptions) -> FrontResult {
    let Some(feed) = options.feed else {
        return Err(Failure::Usage(
            "a drawing has no feed: give one with --feed F (units per minute), e.g. --feed 1200"
                .into(),
        ));
    };
    let d = &options.drawing;
    let dxf_options = pvt_dxf::DxfOptions {
        feed,
        rapid: options.rapid,
        tolerance: options.tolerance,
        join_tolerance: d.join_tolerance,
        layers: d.layers.clone(),
        units: d.units,
        start_point: d.start_point,
        safe_z: d.safe_z,
    };
    match pvt_dxf::read_drawing(bytes, &dxf_options) {
        Ok(drawing) => Ok((
            drawing.toolpath,
            drawing.warnings.into_iter().map(Report::new).collect(),
        )),
        Err(errors) => Err(Failure::Input(
            errors.errors.into_iter().map(Report::new).collect(),
        )),
    }
}
