//! pvt-dxf: the DXF front end of pvtc — drawing entities chained into contours.
//!
//! [`read_drawing`] turns the bytes of an ASCII or binary DXF file into a
//! [`pvt_core::Toolpath`]: every supported entity of the selected layers becomes lines and
//! arcs in the output units, pieces meeting end to end are chained into feed contours, and
//! the contours are ordered nearest-neighbour from the start point with rapids between.
//!
//! Modules and what they own:
//! - [`source`]: line and byte spans of entity records, by handle (no geometry);
//! - [`entities`]: the meaning of each entity (OCS, bulges, blocks, units, layers);
//! - [`curve`]: exact NURBS / fit-spline / ellipse evaluation and flattening by tolerance;
//! - [`chain`]: joining, closing, ordering, rapids and safe Z;
//! - [`geom`]: vectors and affine maps;
//! - [`diag`]: every error and warning with its `pvtc::dxf::*` code.
//!
//! Architecture invariants: this crate reads bytes and returns data (no file or terminal
//! I/O); it never panics on any input; equal bytes and options give bit-identical output
//! (all transcendental functions go through `libm`, all choices have a stable tie rule).
//!
//! # Units
//! Output units are [`DxfOptions::units`] when given (the drawing is then read as being in
//! those units, whatever `$INSUNITS` says). Otherwise `$INSUNITS` decides: imperial units
//! (inches, feet, mils, yards, …) give inch output, metric ones millimetre output, each
//! converted exactly; unitless or absent `$INSUNITS` is read as millimetres with a
//! `pvtc::dxf::units_assumed` warning. A block whose BLOCK_RECORD gives insertion units is
//! scaled into the units of the drawing (or block) that inserts it.
//!
//! # Z
//! Positions carry the drawing's true Z (elevation, OCS, 3D polylines and splines); a flat
//! drawing at Z = 0 therefore moves only X and Y. The machine starts at
//! ([`DxfOptions::start_point`], Z = 0), or at Z = safe Z when [`DxfOptions::safe_z`] is set;
//! see [`chain`] for the rapid / plunge / retract sequence.
//!
//! # Spans
//! Element spans point at the entity record (for POLYLINE segments, the VERTEX record) in
//! an ASCII file: looked up by handle in model space, and by block, type and rank inside a
//! block (the `dxf` crate renumbers the handles of block entities as it reads them; a
//! diagnostic names the handle the file gives). Rapids, plunges and retracts carry the
//! span of an entity (see [`chain`]). Binary files and model-space entities without a
//! handle get `Span::default()` (line 0: unknown).

pub mod chain;
pub mod curve;
pub mod diag;
pub mod entities;
pub mod geom;
pub mod source;

use std::collections::BTreeMap;
use std::io::Cursor;

use pvt_core::{Span, Toolpath, Units};

pub use diag::{DxfDiagnostic, DxfError, DxfErrors, EntityRef};
pub use entities::MAX_ZERO_LENGTH_WARNINGS;

use crate::entities::{is_imperial, mm_per_unit, Reader};
use crate::geom::Affine;
use crate::source::SourceMap;

/// Default [`DxfOptions::max_points`] ([`pvt_core::defaults::DXF_MAX_POINTS`]).
pub use pvt_core::defaults::DXF_MAX_POINTS as DEFAULT_MAX_POINTS;
/// Default join tolerance, millimetres (raised to the chord tolerance if that is larger).
pub use pvt_core::defaults::JOIN_TOLERANCE_MM as DEFAULT_JOIN_MM;
/// Default rapid rate, millimetres per minute.
pub use pvt_core::defaults::RAPID_MM_PER_MIN as DEFAULT_RAPID_MM_PER_MIN;

/// How to read a drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfOptions {
    /// Cutting feed, output units per minute (required: a drawing has none).
    pub feed: f64,
    /// Rapid rate, output units per minute; `None` is 5000 mm/min in the output units.
    pub rapid: Option<f64>,
    /// Chord tolerance in output units; `None` is 0.001 mm in the output units.
    pub tolerance: Option<f64>,
    /// Share of the chord tolerance that splines and ellipses are flattened within (1:
    /// all of it; the path planner takes half, keeping the other half for the motion).
    pub curve_share: f64,
    /// End points closer than this are joined; `None` is the larger of 0.01 mm (in the
    /// output units) and the chord tolerance.
    pub join_tolerance: Option<f64>,
    /// Layers to cut (case-insensitive); empty means every layer.
    pub layers: Vec<String>,
    /// Units of the drawing, overriding `$INSUNITS`; also the output units.
    pub units: Option<Units>,
    /// Where the machine starts (X, Y); contour ordering starts here.
    pub start_point: [f64; 2],
    /// If set, rapids travel at this Z with a feed plunge and a rapid retract per contour.
    pub safe_z: Option<f64>,
    /// Most points (group-10 coordinates) a drawing may hold; more is
    /// `pvtc::dxf::too_many_points`, found by a scan before the drawing is parsed.
    pub max_points: usize,
}

impl DxfOptions {
    /// Options with this feed (units per minute) and every other option at its default.
    pub fn with_feed(feed: f64) -> DxfOptions {
        DxfOptions {
            feed,
            rapid: None,
            tolerance: None,
            curve_share: 1.0,
            join_tolerance: None,
            layers: Vec::new(),
            units: None,
            start_point: [0.0, 0.0],
            safe_z: None,
            max_points: DEFAULT_MAX_POINTS,
        }
    }
}

/// A drawing read into a toolpath, with the warnings raised on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawing {
    /// The contours to cut and the rapids between them, in execution order.
    pub toolpath: Toolpath,
    /// Things ignored or assumed (unsupported entities, paper space, units).
    pub warnings: Vec<DxfDiagnostic>,
}

/// Entity types the `dxf` crate reads (others it skips silently; the scan counts them).
const KNOWN_TO_DXF: &[&str] = &[
    "3DFACE",
    "3DSOLID",
    "ACAD_PROXY_ENTITY",
    "ARC",
    "ARCALIGNEDTEXT",
    "ATTDEF",
    "ATTRIB",
    "BODY",
    "CIRCLE",
    "DIMENSION",
    "ELLIPSE",
    "HELIX",
    "IMAGE",
    "INSERT",
    "LEADER",
    "LIGHT",
    "LINE",
    "3DLINE",
    "LWPOLYLINE",
    "MLINE",
    "MTEXT",
    "OLEFRAME",
    "OLE2FRAME",
    "POINT",
    "POLYLINE",
    "RAY",
    "REGION",
    "RTEXT",
    "SECTION",
    "SEQEND",
    "SHAPE",
    "SOLID",
    "SPLINE",
    "TEXT",
    "TOLERANCE",
    "TRACE",
    "DGNUNDERLAY",
    "DWFUNDERLAY",
    "PDFUNDERLAY",
    "VERTEX",
    "WIPEOUT",
    "XLINE",
];

/// Reads a DXF drawing (ASCII or binary) into a toolpath.
///
/// Errors: every problem found, each with a `pvtc::dxf::*` code (see [`DxfError`]).
pub fn read_drawing(bytes: &[u8], options: &DxfOptions) -> Result<Drawing, DxfErrors> {
    check_options(options).map_err(DxfErrors::one)?;
    let source = SourceMap::scan(bytes);
    if source.points > options.max_points {
        return Err(DxfErrors::one(DxfError::TooManyPoints {
            points: source.points,
            limit: options.max_points,
        }));
    }
    let drawing = load(bytes).map_err(DxfErrors::one)?;

    let mut warnings = Vec::new();
    let insunits = drawing.header.default_drawing_units;
    let (units, drawing_mm) = match options.units {
        Some(u) => (u, Some(u.mm_per_unit())),
        None => match mm_per_unit(insunits) {
            Some(mm) if is_imperial(insunits) => (Units::Inch, Some(mm)),
            Some(mm) => (Units::Millimetre, Some(mm)),
            None => {
                warnings.push(DxfDiagnostic::UnitsAssumed);
                (Units::Millimetre, None)
            }
        },
    };
    let to_output = drawing_mm.unwrap_or(1.0) / units.mm_per_unit();
    let tolerance = pvt_core::defaults::tolerance(options.tolerance, units);
    let join = options
        .join_tolerance
        .unwrap_or_else(|| units.from_mm(DEFAULT_JOIN_MM).max(tolerance));
    let feed = options.feed / 60.0;
    let rapid = pvt_core::defaults::rapid_per_minute(options.rapid, units) / 60.0;

    // Entities the `dxf` crate skipped, from the raw scan.
    let unknown: Vec<&source::Record> = source
        .records
        .iter()
        .filter(|r| r.in_entities && !KNOWN_TO_DXF.contains(&r.kind.as_str()))
        .collect();
    let paper = drawing
        .entities()
        .filter(|e| e.common.is_in_paper_space)
        .count()
        + unknown.iter().filter(|r| r.paper_space).count();
    let model: Vec<&dxf::entities::Entity> = drawing
        .entities()
        .filter(|e| !e.common.is_in_paper_space)
        .collect();
    let unknown_model: Vec<&&source::Record> = unknown.iter().filter(|r| !r.paper_space).collect();
    if model.is_empty() && unknown_model.is_empty() {
        return Err(DxfErrors::one(DxfError::EmptyDrawing));
    }
    check_layers(&drawing, &source, &options.layers).map_err(DxfErrors::one)?;

    let curves = tolerance * options.curve_share.clamp(f64::MIN_POSITIVE, 1.0);
    let mut reader = Reader::new(&drawing, &source, curves, &options.layers);
    reader.read_model(model.into_iter(), Affine::scaling(to_output), drawing_mm);
    for r in unknown_model {
        let layer = if r.layer.is_empty() {
            "0"
        } else {
            r.layer.as_str()
        };
        if reader.layer_selected(layer) {
            reader.selected += 1;
            *reader.unsupported.entry(r.kind.clone()).or_default() += 1;
        }
    }
    if !reader.errors.is_empty() {
        return Err(DxfErrors {
            errors: reader.errors,
        });
    }
    if reader.pieces.is_empty() {
        return Err(DxfErrors::one(nothing_to_cut(
            &reader.unsupported,
            reader.zero_length_count,
            reader.selected,
            &options.layers,
        )));
    }
    let more_zero_length = reader.zero_length_count - reader.zero_length.len();
    warnings.append(&mut reader.zero_length);
    if more_zero_length > 0 {
        warnings.push(DxfDiagnostic::MoreZeroLength {
            count: more_zero_length,
        });
    }
    for (kind, count) in &reader.unsupported {
        warnings.push(DxfDiagnostic::Unsupported {
            kind: kind.clone(),
            count: *count,
        });
    }
    if paper > 0 {
        warnings.push(DxfDiagnostic::PaperSpace { count: paper });
    }

    let chains = chain::order_chains(
        chain::chain_pieces(&reader.pieces, join),
        options.start_point,
    );
    let contours = chain::build_contours(&chains, options.start_point, options.safe_z, feed, rapid);
    Ok(Drawing {
        toolpath: Toolpath {
            units,
            contours,
            events: Vec::new(),
            path_tolerances: Vec::new(),
        },
        warnings,
    })
}

fn check_options(o: &DxfOptions) -> Result<(), DxfError> {
    let positive = |option: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(DxfError::BadOption {
                option,
                reason: format!("{v} is not a positive number"),
            })
        }
    };
    positive("feed", o.feed)?;
    if let Some(v) = o.rapid {
        positive("rapid", v)?;
    }
    if let Some(v) = o.tolerance {
        positive("tolerance", v)?;
    }
    if let Some(v) = o.join_tolerance {
        positive("join-tolerance", v)?;
    }
    let finite = |option: &'static str, v: f64| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(DxfError::BadOption {
                option,
                reason: format!("{v} is not a finite number"),
            })
        }
    };
    finite("start-point", o.start_point[0])?;
    finite("start-point", o.start_point[1])?;
    if let Some(z) = o.safe_z {
        finite("safe-z", z)?;
    }
    Ok(())
}

thread_local! {
    /// True while this thread is inside the `dxf` crate's parse in [`load`].
    static INSIDE_DXF_PARSE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// True while the current thread is inside the `dxf` crate's parse, whose panics
/// [`read_drawing`] catches and reports as `pvtc::dxf::read`: a panic hook may stay
/// quiet about a panic raised while this holds, and must treat any other as a bug.
pub fn panic_is_contained() -> bool {
    INSIDE_DXF_PARSE.with(std::cell::Cell::get)
}

/// Sets [`INSIDE_DXF_PARSE`] for its lifetime (cleared on unwind too).
struct InsideDxfParse;

impl InsideDxfParse {
    fn enter() -> Self {
        INSIDE_DXF_PARSE.with(|c| c.set(true));
        InsideDxfParse
    }
}

impl Drop for InsideDxfParse {
    fn drop(&mut self) {
        INSIDE_DXF_PARSE.with(|c| c.set(false));
    }
}

/// Parses the bytes with the `dxf` crate, turning its errors (and panics) into `read`.
fn load(bytes: &[u8]) -> Result<dxf::Drawing, DxfError> {
    // Only the third-party parse is inside the catch: a panic in pvt-dxf's own code
    // stays a bug.
    let result = std::panic::catch_unwind(|| {
        let _inside = InsideDxfParse::enter();
        dxf::Drawing::load(&mut Cursor::new(bytes))
    });
    let ascii = source::is_ascii_dxf(bytes);
    match result {
        Ok(Ok(d)) => Ok(d),
        Ok(Err(e)) => Err(DxfError::Read {
            message: strip_position(&e.to_string()),
            span: error_span(&e, bytes, ascii),
        }),
        Err(_) => Err(DxfError::Read {
            message: "the DXF parser failed on this input".to_string(),
            span: Span::default(),
        }),
    }
}

/// The parser's message without its own "at line/offset N" (the span carries it).
fn strip_position(message: &str) -> String {
    match message.find(" at line/offset ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

fn error_span(e: &dxf::DxfError, bytes: &[u8], ascii: bool) -> Span {
    use dxf::DxfError as E;
    let offset = match e {
        E::ParseFloatError(_, o)
        | E::ParseIntError(_, o)
        | E::ParseError(o)
        | E::UnexpectedCode(_, o)
        | E::UnexpectedByte(_, o)
        | E::UnexpectedEnumValue(o)
        | E::ExpectedTableType(o)
        | E::WrongValueType(o) => Some(*o),
        E::UnexpectedCodePair(pair, _) => Some(pair.offset),
        E::UnexpectedEndOfInput if ascii => {
            // The end of the file: its last line.
            Some(pvt_core::text::last_line(bytes))
        }
        _ => None,
    };
    let Some(offset) = offset else {
        return Span::default();
    };
    if !ascii {
        return Span {
            start: offset.min(bytes.len()),
            end: offset.min(bytes.len()),
            line: 0,
        };
    }
    // In an ASCII file the parser's position is a line number.
    Span::of_line(bytes, offset)
}

fn check_layers(
    drawing: &dxf::Drawing,
    source: &SourceMap,
    wanted: &[String],
) -> Result<(), DxfError> {
    if wanted.is_empty() {
        return Ok(());
    }
    let mut known: BTreeMap<String, String> = BTreeMap::new();
    let mut add = |name: &str| {
        known
            .entry(name.to_lowercase())
            .or_insert_with(|| name.to_string());
    };
    drawing.layers().for_each(|l| add(&l.name));
    drawing.entities().for_each(|e| add(&e.common.layer));
    drawing
        .blocks()
        .flat_map(|b| &b.entities)
        .for_each(|e| add(&e.common.layer));
    source
        .records
        .iter()
        .filter(|r| !r.layer.is_empty())
        .for_each(|r| add(&r.layer));
    for layer in wanted {
        if !known.contains_key(&layer.to_lowercase()) {
            let available: Vec<&str> = known.values().map(String::as_str).collect();
            return Err(DxfError::NoSuchLayer {
                layer: layer.clone(),
                available: available.join(", "),
            });
        }
    }
    Ok(())
}

fn nothing_to_cut(
    unsupported: &BTreeMap<String, usize>,
    zero_length: usize,
    selected: usize,
    layers: &[String],
) -> DxfError {
    let detail = if selected == 0 && zero_length == 0 {
        format!("no entity on the selected layers ({})", layers.join(", "))
    } else {
        let mut held: Vec<String> = unsupported
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect();
        if zero_length > 0 {
            held.push(format!("{zero_length} of zero length, dropped"));
        }
        let what = match (unsupported.is_empty(), zero_length > 0) {
            (false, false) => "unsupported entities",
            (true, _) => "entities of zero length",
            (false, true) => "unsupported entities and entities of zero length",
        };
        format!("the drawing holds only {what} ({})", held.join(", "))
    };
    DxfError::NothingToCut { detail }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_spans_count_from_one() {
        let text = b"0\nSECTION\n2\nENTITIES";
        assert_eq!(
            Span::of_line(text, 3),
            Span {
                start: 10,
                end: 11,
                line: 3
            }
        );
        assert_eq!(Span::of_line(text, 9).start, text.len());
        assert_eq!(strip_position("bad at line/offset 7"), "bad");
    }

    #[test]
    fn options_are_checked() {
        let mut o = DxfOptions::with_feed(0.0);
        assert!(matches!(
            check_options(&o),
            Err(DxfError::BadOption { option: "feed", .. })
        ));
        o.feed = 100.0;
        o.tolerance = Some(f64::NAN);
        assert!(matches!(
            check_options(&o),
            Err(DxfError::BadOption {
                option: "tolerance",
                ..
            })
        ));
    }
}
