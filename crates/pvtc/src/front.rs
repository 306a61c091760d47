//! Choosing and calling a front end: bytes in, a toolpath or point series out.
//!
//! Owns the mapping from CLI options to each front end's options and from each front
//! end's diagnostics to printable reports. It must not plan or write output.

use crate::options::{at_line, CompileOptions, Failure, InputKind, Source};
use miette::Report;
use pvt_core::{Toolpath, Units};
use pvt_csv::PointSeries;

/// What a front end produced.
#[derive(Debug)]
pub enum Input {
    /// Geometry with feeds (G-code, DXF).
    Toolpath(Toolpath),
    /// Points with times (CSV).
    Series(PointSeries),
}

impl Input {
    /// Units of the input's coordinates.
    pub fn units(&self) -> Units {
        match self {
            Input::Toolpath(t) => t.units,
            Input::Series(s) => s.units,
        }
    }
}

/// An input with the warnings met while reading it.
pub type FrontResult = Result<(Input, Vec<Report>), Failure>;

/// Reads `source` with the front end `options.input` selects.
pub fn read(source: &Source, options: &CompileOptions) -> FrontResult {
    match options.input {
        InputKind::Gcode => gcode(source, options),
        InputKind::Dxf => dxf(source, options),
        InputKind::Csv => csv(source, options),
    }
}

fn gcode(source: &Source, options: &CompileOptions) -> FrontResult {
    // Invalid UTF-8 (a Latin-1 comment, say) becomes U+FFFD; spans refer to this text.
    let named = source.named_text();
    let gcode_options = gcode_options(options);
    match pvt_gcode::compile(named.inner(), &gcode_options) {
        Ok(compiled) => {
            let warnings = compiled
                .warnings
                .into_iter()
                .map(|w| Report::new(w).with_source_code(named.clone()))
                .collect();
            Ok((Input::Toolpath(compiled.toolpath), warnings))
        }
        Err(errors) => Err(Failure::Input(
            errors
                .diagnostics
                .into_iter()
                .map(|e| Report::new(e).with_source_code(named.clone()))
                .collect(),
        )),
    }
}

/// The G-code front end's options for these pipeline options.
pub fn gcode_options(options: &CompileOptions) -> pvt_gcode::GcodeOptions {
    pvt_gcode::GcodeOptions {
        default_feed: options.feed,
        rapid: options.rapid,
        arc_abs_tolerance_mm: options.arc_abs_tolerance_mm,
        arc_rel_tolerance: options.arc_rel_tolerance,
        units: options.drawing.units,
        work_offsets: options.work_offsets,
        subroutines: pvt_gcode::Subroutines(match options.subroutine_path.is_empty() {
            true => None,
            false => Some(std::sync::Arc::new(
                crate::subroutines::SubroutinePath::from_args(&options.subroutine_path),
            )),
        }),
        tool_table: options.tool_table.clone(),
        hal_pins: options.hal_pins.clone(),
        probe_results: options.probe_results.clone(),
    }
}

fn dxf(source: &Source, options: &CompileOptions) -> FrontResult {
    let bytes = &source.bytes;
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
        curve_share: options.curve_share(),
        join_tolerance: d.join_tolerance,
        layers: d.layers.clone(),
        units: d.units,
        start_point: d.start_point,
        safe_z: d.safe_z,
        max_points: d.max_points.unwrap_or(pvt_dxf::DEFAULT_MAX_POINTS),
    };
    match pvt_dxf::read_drawing(bytes, &dxf_options) {
        Ok(drawing) => Ok((
            Input::Toolpath(drawing.toolpath),
            drawing.warnings.into_iter().map(Report::new).collect(),
        )),
        Err(errors) => Err(Failure::Input(
            errors
                .errors
                .into_iter()
                .map(|e| dxf_report(e, source))
                .collect(),
        )),
    }
}

fn csv(source: &Source, options: &CompileOptions) -> FrontResult {
    let named = source.named_text();
    let units = options.drawing.units.unwrap_or_default();
    match pvt_csv::read_points(named.inner(), units) {
        Ok(series) => Ok((Input::Series(series), Vec::new())),
        Err(errors) => Err(Failure::Input(
            errors
                .diagnostics
                .into_iter()
                .map(|e| Report::new(e).with_source_code(named.clone()))
                .collect(),
        )),
    }
}

/// A drawing's error, labelling its line of the file where the line is known (a text
/// DXF), as every other input's errors are labelled.
fn dxf_report(e: pvt_dxf::DxfError, source: &Source) -> Report {
    let line = e.span().line;
    if line == 0 {
        return Report::new(e);
    }
    at_line(&e.code_str(), &e.to_string(), line, source).with_source_code(source.named_text())
}
