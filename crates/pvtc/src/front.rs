//! Choosing and calling a front end: bytes in, a toolpath or point series out.
//!
//! Owns the mapping from CLI options to each front end's options and from each front
//! end's diagnostics to printable reports. It must not plan or write output.

use crate::options::{at_line, CompileOptions, Failure, InputKind, Source};
use miette::{Diagnostic, Report};
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
    if let Some(hint) = dxf_read_as_gcode(&source.bytes) {
        return Err(hint);
    }
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
        spindle_sync: options.spindle_sync,
        tolerance: options.tolerance,
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
        curve_share: crate::settings::curve_share(options),
        join_tolerance: d.join_tolerance,
        layers: d.layers.clone(),
        units: d.units,
        start_point: d.start_point,
        safe_z: d.safe_z,
        max_points: crate::settings::max_points(options),
    };
    match pvt_dxf::read_drawing(bytes, &dxf_options) {
        Ok(drawing) => Ok((
            Input::Toolpath(drawing.toolpath),
            drawing
                .warnings
                .into_iter()
                .map(|w| dxf_warning(w, source))
                .collect(),
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

/// A drawing's warning, labelling its line of the file where the line is known (a text
/// DXF), so that repeats of one code group into one diagnostic with their places.
fn dxf_warning(w: pvt_dxf::DxfDiagnostic, source: &Source) -> Report {
    let line = w.span().line;
    if line == 0 {
        return Report::new(w);
    }
    let range = entity_lines(&source.bytes, w.span().start);
    let help = w.help().map(|h| h.to_string()).unwrap_or_default();
    miette::miette!(
        severity = miette::Severity::Warning,
        code = w.code_str(),
        labels = vec![miette::LabeledSpan::at(range, "this entity")],
        help = help,
        "{w}"
    )
    .with_source_code(source.named_text())
}

/// Refuses a DXF drawing read as G-code (standard input has no name to tell the kind
/// by): one `pvtc::input::dxf_as_gcode` error with the option to pass, instead of a
/// syntax error on every line.
pub(crate) fn dxf_read_as_gcode(start: &[u8]) -> Option<Failure> {
    looks_like_dxf(start).then(|| {
        Failure::Input(vec![miette::miette!(
            code = "pvtc::input::dxf_as_gcode",
            help = "pass --input-format dxf (and --feed F) to cut the drawing",
            "this input is a DXF drawing, not G-code: it starts with a DXF header"
        )])
    })
}

/// True when the bytes start as a DXF file does: binary DXF's sentinel, or a text DXF's
/// first group (`0` / `SECTION`, after any `999` comment group).
pub(crate) fn looks_like_dxf(start: &[u8]) -> bool {
    if start.starts_with(b"AutoCAD Binary DXF") {
        return true;
    }
    let head = &start[..start.len().min(4096)];
    let text = String::from_utf8_lossy(head);
    let mut lines = text.lines().map(str::trim).skip_while(|l| l.is_empty());
    let mut first = lines.next();
    if first == Some("999") {
        lines.next();
        first = lines.next();
    }
    first == Some("0")
        && lines
            .next()
            .is_some_and(|l| l.eq_ignore_ascii_case("SECTION"))
}

/// The byte range of an entity's first two lines: its group code `0` (the line its
/// diagnostics name) and its type (`LINE`), so that the excerpt shows what the entity is,
/// not a lone `0`.
/// `start` is the byte offset of the `0` line, which the entity's span holds.
fn entity_lines(bytes: &[u8], start: usize) -> std::ops::Range<usize> {
    let start = start.min(bytes.len());
    let end = bytes[start..]
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .nth(1)
        .map_or(bytes.len(), |(i, _)| start + i);
    // The line end is not part of the label (a CR before the LF).
    let end = if end > start && bytes[end - 1] == b'\r' {
        end - 1
    } else {
        end
    };
    start..end
}

/// A drawing's error, labelling its line of the file where the line is known (a text
/// DXF), as every other input's errors are labelled: an entity's error labels the entity
/// ([`entity_lines`]). A binary file's errors have no line, and no excerpt.
fn dxf_report(e: pvt_dxf::DxfError, source: &Source) -> Report {
    let line = e.span().line;
    if line == 0 {
        return Report::new(e);
    }
    let entity = matches!(
        e,
        pvt_dxf::DxfError::BadGeometry { .. } | pvt_dxf::DxfError::BadBlock { .. }
    );
    if !entity {
        return at_line(&e.code_str(), &e.to_string(), line, source)
            .with_source_code(source.named_text());
    }
    miette::miette!(
        code = e.code_str(),
        labels = vec![miette::LabeledSpan::at(
            entity_lines(&source.bytes, e.span().start),
            "this entity"
        )],
        "{e}"
    )
    .with_source_code(source.named_text())
}
