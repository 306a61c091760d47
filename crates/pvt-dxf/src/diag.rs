//! Errors and warnings of the DXF front end, each with a stable `pvtc::dxf::*` code.
//!
//! Owns the wording and codes of every diagnostic. It must not decide when one is raised:
//! the reading and chaining modules do.

use std::fmt;

use miette::Diagnostic;
use pvt_core::Span;
use thiserror::Error;

/// Which entity a diagnostic is about: type, handle and layer.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct EntityRef {
    /// DXF type name, e.g. `SPLINE`.
    pub kind: String,
    /// Handle in hexadecimal as the file writes it; empty when the entity has none.
    pub handle: String,
    /// Layer name.
    pub layer: String,
}

impl fmt::Display for EntityRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.kind)?;
        if !self.handle.is_empty() {
            write!(f, " (handle {})", self.handle)?;
        }
        write!(f, " on layer {:?}", self.layer)
    }
}

/// Formats a span's line for messages: `line N`, or `unknown line` when 0.
pub struct At(pub Span);

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.line == 0 {
            write!(f, "at an unknown line")
        } else {
            write!(f, "at line {}", self.0.line)
        }
    }
}

/// One error that stops a drawing from being compiled.
///
/// `span.line` is the 1-based DXF line where it can be known; 0 where it cannot (binary
/// files, entities without a handle, errors the `dxf` crate reports without a position).
#[derive(Debug, Clone, Error, Diagnostic, PartialEq)]
pub enum DxfError {
    /// The `dxf` crate could not parse the bytes (truncated file, wrong group codes, …).
    #[error("cannot read the DXF file {}: {message}", At(*span))]
    #[diagnostic(
        code(pvtc::dxf::read),
        help("is this a complete ASCII or binary DXF file?")
    )]
    Read {
        /// What the parser said.
        message: String,
        /// Where, when the parser said.
        span: Span,
    },
    /// More points than [`crate::DxfOptions::max_points`]: the drawing is refused before
    /// it is parsed, so its memory stays bounded.
    #[error("the drawing holds {points} points, over the limit of {limit}")]
    #[diagnostic(
        code(pvtc::dxf::too_many_points),
        help("raise the limit with --max-points N (about 400 bytes of memory per point), or split the drawing")
    )]
    TooManyPoints {
        /// Group-10 coordinates found in the BLOCKS and ENTITIES sections.
        points: usize,
        /// The limit.
        limit: usize,
    },
    /// The model space holds no entity at all.
    #[error("the drawing is empty: model space holds no entities")]
    #[diagnostic(code(pvtc::dxf::empty_drawing))]
    EmptyDrawing,
    /// Entities exist, but none of them (on the selected layers) is geometry to cut.
    #[error("nothing to cut: {detail}")]
    #[diagnostic(
        code(pvtc::dxf::nothing_to_cut),
        help("only LINE, ARC, CIRCLE, LWPOLYLINE, POLYLINE, SPLINE, ELLIPSE and INSERT are cut")
    )]
    NothingToCut {
        /// What the drawing held instead.
        detail: String,
    },
    /// A layer named in the options exists neither in the layer table nor on any entity.
    #[error("no layer named {layer:?} in the drawing (layers: {available})")]
    #[diagnostic(code(pvtc::dxf::no_such_layer))]
    NoSuchLayer {
        /// The layer asked for.
        layer: String,
        /// The layers the drawing has, comma separated.
        available: String,
    },
    /// An entity whose geometry cannot be cut: NaN, zero length, invalid knots, …
    #[error("{entity} {}: {reason}", At(*span))]
    #[diagnostic(code(pvtc::dxf::bad_geometry))]
    BadGeometry {
        /// The entity.
        entity: EntityRef,
        /// What is wrong with it.
        reason: String,
        /// Where it is.
        span: Span,
    },
    /// An INSERT of a block that does not exist or that inserts itself.
    #[error("{entity} {}: {reason}", At(*span))]
    #[diagnostic(code(pvtc::dxf::bad_block))]
    BadBlock {
        /// The INSERT.
        entity: EntityRef,
        /// What is wrong.
        reason: String,
        /// Where it is.
        span: Span,
    },
    /// An option value that cannot be used (feed not positive, tolerance not finite, …).
    #[error("bad option {option}: {reason}")]
    #[diagnostic(code(pvtc::dxf::bad_option))]
    BadOption {
        /// The option's name.
        option: &'static str,
        /// Why.
        reason: String,
    },
}

impl DxfError {
    /// The source span (line 0 where unknown).
    pub fn span(&self) -> Span {
        match self {
            DxfError::Read { span, .. }
            | DxfError::BadGeometry { span, .. }
            | DxfError::BadBlock { span, .. } => *span,
            _ => Span::default(),
        }
    }

    /// The stable code, e.g. `pvtc::dxf::read`.
    pub fn code_str(&self) -> String {
        self.code().map(|c| c.to_string()).unwrap_or_default()
    }
}

/// All the errors found in one drawing (at least one); the first one is the main one.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfErrors {
    /// The errors, in the order found.
    pub errors: Vec<DxfError>,
}

impl DxfErrors {
    /// Wraps a single error.
    pub fn one(error: DxfError) -> DxfErrors {
        DxfErrors {
            errors: vec![error],
        }
    }

    /// The codes of every error, in order.
    pub fn codes(&self) -> Vec<String> {
        self.errors.iter().map(DxfError::code_str).collect()
    }
}

impl fmt::Display for DxfErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.errors.as_slice() {
            [] => write!(f, "the DXF drawing has errors"),
            [one] => write!(f, "{one}"),
            [first, rest @ ..] => write!(f, "{first} (and {} more errors)", rest.len()),
        }
    }
}

impl std::error::Error for DxfErrors {}

impl Diagnostic for DxfErrors {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.errors.first().and_then(|e| e.code())
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.errors.first().and_then(|e| e.help())
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn Diagnostic> + 'a>> {
        if self.errors.len() < 2 {
            return None;
        }
        Some(Box::new(
            self.errors[1..].iter().map(|e| e as &dyn Diagnostic),
        ))
    }
}

/// A warning: the drawing compiles, but something in it was ignored or assumed.
#[derive(Debug, Clone, Error, Diagnostic, PartialEq)]
pub enum DxfDiagnostic {
    /// Entities of a type that is not cut, listed once per type with a count.
    #[error("{count} {kind} entit{} ignored: not a supported entity", if *count == 1 { "y" } else { "ies" })]
    #[diagnostic(code(pvtc::dxf::unsupported_entity), severity(Warning))]
    Unsupported {
        /// DXF type name (`TEXT`, `HATCH`, `POLYLINE (mesh)`, …).
        kind: String,
        /// How many.
        count: usize,
    },
    /// Entities in paper space (layouts), which are not part of the part.
    #[error("{count} entit{} in paper space ignored", if *count == 1 { "y" } else { "ies" })]
    #[diagnostic(code(pvtc::dxf::paper_space), severity(Warning))]
    PaperSpace {
        /// How many.
        count: usize,
    },
    /// `$INSUNITS` is absent or unitless and no units were given: millimetres assumed.
    #[error("the drawing does not say its units ($INSUNITS unitless): millimetres assumed")]
    #[diagnostic(
        code(pvtc::dxf::units_assumed),
        severity(Warning),
        help("pass the units explicitly if the drawing is in inches")
    )]
    UnitsAssumed,
    /// An entity of zero length (a LINE from a point to itself, a radius of 0, equal arc
    /// angles, coinciding vertices): dropped, as G-code drops a zero-length move.
    #[error("{entity} {}: zero length; it is dropped", At(*span))]
    #[diagnostic(
        code(pvtc::dxf::zero_length),
        severity(Warning),
        help("remove the entity from the drawing if it is not needed")
    )]
    ZeroLength {
        /// The entity.
        entity: EntityRef,
        /// Where it is.
        span: Span,
    },
    /// Zero-length entities beyond the first [`crate::entities::MAX_ZERO_LENGTH_WARNINGS`],
    /// dropped as well, counted here instead of named.
    #[error("{count} more zero-length entit{} dropped", if *count == 1 { "y" } else { "ies" })]
    #[diagnostic(code(pvtc::dxf::zero_length), severity(Warning))]
    MoreZeroLength {
        /// How many.
        count: usize,
    },
}

impl DxfDiagnostic {
    /// The stable code, e.g. `pvtc::dxf::unsupported_entity`.
    pub fn code_str(&self) -> String {
        self.code().map(|c| c.to_string()).unwrap_or_default()
    }

    /// The source span (line 0 where unknown or not about one entity).
    pub fn span(&self) -> Span {
        match self {
            DxfDiagnostic::ZeroLength { span, .. } => *span,
            _ => Span::default(),
        }
    }
}
