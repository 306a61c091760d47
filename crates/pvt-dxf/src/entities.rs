//! Entities to pieces: every supported DXF entity as world-space lines and arcs.
//!
//! Owns the meaning of each entity's group values: OCS extrusion, bulges, elevation, NURBS
//! data, ellipse parameters, block insertion (scale, rotation, translation, MINSERT grids,
//! nesting, block units) and layer inheritance (an entity on layer `0` inside a block takes
//! the INSERT's layer). It must not chain or order anything, and it must not fail fast:
//! every bad entity is reported and the rest still read.
//!
//! An entity of zero length (a LINE from a point to itself, a CIRCLE or ARC of radius 0,
//! an ARC whose angles are equal, a polyline or curve whose points all coincide) is not an
//! error: like a zero-length G-code move it is dropped with a `pvtc::dxf::zero_length`
//! warning. An ELLIPSE whose axis ratio is above 1 (CAD files write 1.0000001 for a
//! circle) is read with its axes swapped: the minor axis becomes the major one, the ratio
//! is inverted and the parameters move back by π/2, which describes the same points.
//!
//! Circular arcs lying in a plane parallel to XY after all transforms stay arcs (pvt-core
//! discretizes them); every other curve (ellipses, arcs seen skewed through a non-uniform
//! INSERT scale or a tilted extrusion, splines) is flattened by [`crate::curve`].

use std::collections::{BTreeMap, HashMap};

use dxf::entities::{Entity, EntityType};
use dxf::enums::Units as DxfUnits;
use pvt_core::Span;

use crate::chain::{Piece, Seg, SegKind};
use crate::curve::{
    flatten, Cubic, CubicCurve, EllipseArc, FitSpline, Nurbs, NurbsCurve, PieceCurve,
};
use crate::diag::{DxfDiagnostic, DxfError, EntityRef};
use crate::geom::{cross, dist, dot, norm, scale, Affine, P3};
use crate::source::SourceMap;

const TAU: f64 = 2.0 * std::f64::consts::PI;
/// Deepest nesting of INSERTs followed.
pub const MAX_NESTING: usize = 32;
/// Most copies one MINSERT grid may make.
pub const MAX_GRID: i64 = 10_000;
/// Most entities read in all, block copies included (nested grids multiply).
pub const MAX_VISITS: usize = 1_000_000;
/// Most zero-length entities named one warning each; the rest are counted in one more.
pub const MAX_ZERO_LENGTH_WARNINGS: usize = 1000;

/// Why an entity gives no piece to cut.
#[derive(Debug, Clone, PartialEq)]
pub enum NoPiece {
    /// Its geometry cannot be cut (the reason): an error.
    Bad(String),
    /// It has zero length: dropped with a warning.
    ZeroLength,
}

impl From<String> for NoPiece {
    fn from(reason: String) -> NoPiece {
        NoPiece::Bad(reason)
    }
}

impl From<&str> for NoPiece {
    fn from(reason: &str) -> NoPiece {
        NoPiece::Bad(reason.to_string())
    }
}

/// What reading an entity gives: its piece, or why there is none.
pub type PieceResult = Result<Piece, NoPiece>;

/// Millimetres per drawing unit; `None` for unitless.
pub fn mm_per_unit(units: DxfUnits) -> Option<f64> {
    use DxfUnits::*;
    Some(match units {
        Unitless => return None,
        Inches => 25.4,
        Feet => 304.8,
        Miles => 1_609_344.0,
        Millimeters => 1.0,
        Centimeters => 10.0,
        Meters => 1000.0,
        Kilometers => 1e6,
        Microinches => 25.4e-6,
        Mils => 0.0254,
        Yards => 914.4,
        Angstroms => 1e-7,
        Nanometers => 1e-6,
        Microns => 1e-3,
        Decimeters => 100.0,
        Decameters => 1e4,
        Hectometers => 1e5,
        Gigameters => 1e12,
        AstronomicalUnits => 1.495_978_707e14,
        LightYears => 9.460_730_472_580_8e18,
        Parsecs => 3.085_677_581_491_367e19,
        USSurveyFeet => 1200.0 / 3937.0 * 1000.0,
        USSurveyInch => 1200.0 / 3937.0 * 1000.0 / 12.0,
        USSurveyYard => 3.0 * 1200.0 / 3937.0 * 1000.0,
        USSurveyMile => 5280.0 * 1200.0 / 3937.0 * 1000.0,
    })
}

/// True for the imperial units, whose drawings are output in inches.
pub fn is_imperial(units: DxfUnits) -> bool {
    use DxfUnits::*;
    matches!(
        units,
        Inches
            | Feet
            | Miles
            | Microinches
            | Mils
            | Yards
            | USSurveyFeet
            | USSurveyInch
            | USSurveyYard
            | USSurveyMile
    )
}

/// The DXF type name of an entity.
pub fn type_name(e: &EntityType) -> &'static str {
    use EntityType::*;
    match e {
        Face3D(_) => "3DFACE",
        Solid3D(_) => "3DSOLID",
        ProxyEntity(_) => "ACAD_PROXY_ENTITY",
        Arc(_) => "ARC",
        ArcAlignedText(_) => "ARCALIGNEDTEXT",
        AttributeDefinition(_) => "ATTDEF",
        Attribute(_) => "ATTRIB",
        Body(_) => "BODY",
        Circle(_) => "CIRCLE",
        RotatedDimension(_)
        | RadialDimension(_)
        | DiameterDimension(_)
        | AngularThreePointDimension(_)
        | OrdinateDimension(_) => "DIMENSION",
        Ellipse(_) => "ELLIPSE",
        Helix(_) => "HELIX",
        Image(_) => "IMAGE",
        Insert(_) => "INSERT",
        Leader(_) => "LEADER",
        Light(_) => "LIGHT",
        Line(_) => "LINE",
        LwPolyline(_) => "LWPOLYLINE",
        MLine(_) => "MLINE",
        MText(_) => "MTEXT",
        OleFrame(_) => "OLEFRAME",
        Ole2Frame(_) => "OLE2FRAME",
        ModelPoint(_) => "POINT",
        Polyline(_) => "POLYLINE",
        Ray(_) => "RAY",
        Region(_) => "REGION",
        RText(_) => "RTEXT",
        Section(_) => "SECTION",
        Seqend(_) => "SEQEND",
        Shape(_) => "SHAPE",
        Solid(_) => "SOLID",
        Spline(_) => "SPLINE",
        Text(_) => "TEXT",
        Tolerance(_) => "TOLERANCE",
        Trace(_) => "TRACE",
        DgnUnderlay(_) => "DGNUNDERLAY",
        DwfUnderlay(_) => "DWFUNDERLAY",
        PdfUnderlay(_) => "PDFUNDERLAY",
        Vertex(_) => "VERTEX",
        Wipeout(_) => "WIPEOUT",
        XLine(_) => "XLINE",
    }
}

fn p3(p: &dxf::Point) -> P3 {
    [p.x, p.y, p.z]
}

fn v3(v: &dxf::Vector) -> P3 {
    [v.x, v.y, v.z]
}

/// Which record of the file an entity was read from.
#[derive(Debug, Clone, Copy)]
struct Origin {
    /// Index into [`SourceMap::records`], when the scan found the record.
    record: Option<usize>,
    /// The entity is in model space (not inside a block): its handle in memory is the
    /// file's (the `dxf` crate gives block entities new handles).
    top: bool,
}

/// Where an entity is being read: transform to output coordinates, inherited layer, units.
#[derive(Clone)]
struct Place {
    xf: Affine,
    /// The INSERT's layer, for entities on layer `0` inside a block.
    layer: Option<String>,
    /// Millimetres per unit of the coordinates being read (None: unitless).
    mm_per_unit: Option<f64>,
    /// Blocks being expanded, outermost first (lower case).
    blocks: Vec<String>,
}

/// Reads entities into pieces, collecting errors and counts as it goes.
pub struct Reader<'a> {
    source: &'a SourceMap,
    tolerance: f64,
    layers: Option<Vec<String>>,
    blocks: HashMap<String, &'a dxf::Block>,
    block_units: HashMap<String, DxfUnits>,
    /// Pieces in drawing order.
    pub pieces: Vec<Piece>,
    /// Errors found.
    pub errors: Vec<DxfError>,
    /// One `pvtc::dxf::zero_length` warning per dropped entity, the first
    /// [`MAX_ZERO_LENGTH_WARNINGS`] of them.
    pub zero_length: Vec<DxfDiagnostic>,
    /// Zero-length entities dropped, all of them.
    pub zero_length_count: usize,
    /// Unsupported entities by type.
    pub unsupported: BTreeMap<String, usize>,
    /// Model-space entities read on the selected layers (supported or not).
    pub selected: usize,
    visits: usize,
}

impl<'a> Reader<'a> {
    /// A reader for one drawing; `layers` empty means all (compared case-insensitively).
    pub fn new(
        drawing: &'a dxf::Drawing,
        source: &'a SourceMap,
        tolerance: f64,
        layers: &[String],
    ) -> Reader<'a> {
        let blocks = drawing
            .blocks()
            .map(|b| (b.name.to_lowercase(), b))
            .collect();
        // A name recorded twice (some writers do) keeps the first record that has units.
        let mut block_units: HashMap<String, DxfUnits> = HashMap::new();
        for r in drawing.block_records() {
            let known = block_units
                .get(&r.name.to_lowercase())
                .is_some_and(|u| *u != DxfUnits::Unitless);
            if !known {
                block_units.insert(r.name.to_lowercase(), r.insertion_units);
            }
        }
        Reader {
            source,
            tolerance,
            layers: (!layers.is_empty()).then(|| layers.iter().map(|l| l.to_lowercase()).collect()),
            blocks,
            block_units,
            pieces: Vec::new(),
            errors: Vec::new(),
            zero_length: Vec::new(),
            zero_length_count: 0,
            unsupported: BTreeMap::new(),
            selected: 0,
            visits: 0,
        }
    }

    /// True when `layer` is one of the selected layers.
    pub fn layer_selected(&self, layer: &str) -> bool {
        let layer = layer.to_lowercase();
        self.layers.as_ref().is_none_or(|v| v.contains(&layer))
    }

    /// Reads the model-space entities with `xf` mapping drawing units to output units.
    pub fn read_model<'e>(
        &mut self,
        entities: impl Iterator<Item = &'e Entity>,
        xf: Affine,
        mm_per_unit: Option<f64>,
    ) {
        let place = Place {
            xf,
            layer: None,
            mm_per_unit,
            blocks: Vec::new(),
        };
        for e in entities {
            let kind = type_name(&e.specific);
            let record = (!e.common.handle.is_empty())
                .then(|| self.source.find(e.common.handle.0, kind))
                .flatten();
            self.entity(e, &place, Origin { record, top: true });
        }
    }

    fn entity_ref(&self, e: &Entity, place: &Place, origin: Origin) -> EntityRef {
        let written = origin
            .record
            .map(|i| self.source.records[i].handle)
            .filter(|&h| h != 0);
        let handle = match written {
            Some(h) => format!("{h:X}"),
            None if origin.top && !e.common.handle.is_empty() => e.common.handle.as_string(),
            None => String::new(),
        };
        EntityRef {
            kind: type_name(&e.specific).to_string(),
            handle,
            layer: effective_layer(e, place),
        }
    }

    fn span(&self, origin: Origin) -> Span {
        origin
            .record
            .map(|i| self.source.records[i].span)
            .unwrap_or_default()
    }

    fn bad(&mut self, e: &Entity, place: &Place, origin: Origin, reason: impl Into<String>) {
        let entity = self.entity_ref(e, place, origin);
        let span = self.span(origin);
        self.errors.push(DxfError::BadGeometry {
            entity,
            reason: reason.into(),
            span,
        });
    }

    fn entity(&mut self, e: &Entity, place: &Place, origin: Origin) {
        self.visits += 1;
        if self.visits > MAX_VISITS {
            if self.visits == MAX_VISITS + 1 {
                let entity = self.entity_ref(e, place, origin);
                let span = self.span(origin);
                self.errors.push(DxfError::BadBlock {
                    entity,
                    reason: format!(
                        "the block insertions expand to more than {MAX_VISITS} entities"
                    ),
                    span,
                });
            }
            return;
        }
        let layer = effective_layer(e, place);
        let kind = type_name(&e.specific);
        if let EntityType::Insert(ins) = &e.specific {
            self.insert(e, ins, place, origin);
            return;
        }
        if !self.layer_selected(&layer) {
            return;
        }
        if origin.top {
            self.selected += 1;
        }
        let span = self.span(origin);
        let result = match &e.specific {
            EntityType::Line(l) => self.line(p3(&l.p1), p3(&l.p2), place, span),
            EntityType::Arc(a) => self.arc(
                &a.center,
                a.radius,
                &a.normal,
                Some((a.start_angle, a.end_angle)),
                place,
                span,
            ),
            EntityType::Circle(c) => self.arc(&c.center, c.radius, &c.normal, None, place, span),
            EntityType::Ellipse(el) => self.ellipse(el, place, span),
            EntityType::LwPolyline(pl) => {
                let verts: Vec<(P3, f64, Span)> = pl
                    .vertices
                    .iter()
                    .map(|v| ([v.x, v.y, e.common.elevation], v.bulge, span))
                    .collect();
                self.polyline(
                    &verts,
                    pl.flags & 1 != 0,
                    &v3(&pl.extrusion_direction),
                    place,
                )
            }
            EntityType::Polyline(pl) => {
                if pl.flags & (16 | 64) != 0 {
                    *self
                        .unsupported
                        .entry("POLYLINE (mesh)".to_string())
                        .or_default() += 1;
                    return;
                }
                let is_3d = pl.flags & 8 != 0;
                // The dxf crate drops VERTEX handles: the scan gives their spans in order.
                let vertex_spans = origin
                    .record
                    .map(|i| self.source.following(i, "VERTEX"))
                    .unwrap_or_default();
                let verts: Vec<(P3, f64, Span)> = pl
                    .__vertices_and_handles
                    .iter()
                    .enumerate()
                    .filter(|(_, (v, _))| v.flags & 16 == 0)
                    .map(|(i, (v, _))| {
                        let vspan = vertex_spans.get(i).copied().unwrap_or(span);
                        if is_3d {
                            (p3(&v.location), 0.0, vspan)
                        } else {
                            ([v.location.x, v.location.y, pl.location.z], v.bulge, vspan)
                        }
                    })
                    .collect();
                let normal = if is_3d {
                    [0.0, 0.0, 1.0]
                } else {
                    v3(&pl.normal)
                };
                self.polyline(&verts, pl.flags & 1 != 0, &normal, place)
            }
            EntityType::Spline(s) => self.spline(s, place, span),
            _ => {
                *self.unsupported.entry(kind.to_string()).or_default() += 1;
                return;
            }
        };
        match result {
            Ok(piece) => self.pieces.push(piece),
            Err(NoPiece::Bad(reason)) => self.bad(e, place, origin, reason),
            Err(NoPiece::ZeroLength) => {
                self.zero_length_count += 1;
                if self.zero_length.len() < MAX_ZERO_LENGTH_WARNINGS {
                    let entity = self.entity_ref(e, place, origin);
                    self.zero_length
                        .push(DxfDiagnostic::ZeroLength { entity, span });
                }
            }
        }
    }

    fn line(&self, a: P3, b: P3, place: &Place, span: Span) -> PieceResult {
        let (a, b) = (place.xf.point(a), place.xf.point(b));
        check_points(&[a, b])?;
        if a == b {
            return Err(NoPiece::ZeroLength);
        }
        Ok(vec![Seg {
            kind: SegKind::Line,
            a,
            b,
            span,
        }])
    }

    fn arc(
        &self,
        center: &dxf::Point,
        radius: f64,
        normal: &dxf::Vector,
        angles: Option<(f64, f64)>,
        place: &Place,
        span: Span,
    ) -> PieceResult {
        let ocs = Affine::ocs(v3(normal)).ok_or("the extrusion direction is zero or not finite")?;
        if radius == 0.0 {
            return Err(NoPiece::ZeroLength);
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(format!("the radius {radius} is not a positive number").into());
        }
        let (t0, sweep) = match angles {
            None => (0.0, TAU),
            Some((a0, a1)) => {
                if !(a0.is_finite() && a1.is_finite()) {
                    return Err("an angle is not finite".into());
                }
                let sweep = (a1 - a0).rem_euclid(360.0);
                if sweep <= 1e-9 {
                    return Err(NoPiece::ZeroLength); // equal start and end angles
                }
                (a0.to_radians(), sweep.to_radians())
            }
        };
        let m = place.xf.then_after(&ocs);
        let e = EllipseArc {
            c: m.point(p3(center)),
            u: m.vector([radius, 0.0, 0.0]),
            v: m.vector([0.0, radius, 0.0]),
            t0,
            t1: t0 + sweep,
        };
        ellipse_segs(&e, self.tolerance, span, None)
    }

    fn ellipse(&self, el: &dxf::entities::Ellipse, place: &Place, span: Span) -> PieceResult {
        let major = v3(&el.major_axis);
        let normal = v3(&el.normal);
        let ratio = el.minor_axis_ratio;
        let (lm, ln) = (norm(major), norm(normal));
        if !(lm.is_finite() && ln.is_finite() && ln > 0.0) {
            return Err("the major axis or the normal is not finite, or the normal is zero".into());
        }
        if lm == 0.0 {
            return Err(NoPiece::ZeroLength);
        }
        if !(ratio.is_finite() && ratio > 0.0) {
            return Err(format!("the axis ratio {ratio} is not a positive number").into());
        }
        let (s, e) = (el.start_parameter, el.end_parameter);
        if !(s.is_finite() && e.is_finite()) {
            return Err("a parameter is not finite".into());
        }
        let n = scale(normal, 1.0 / ln);
        if dot(n, major).abs() > 1e-9 * lm {
            return Err("the major axis is not perpendicular to the normal".into());
        }
        let (major, ratio, s, e) = normalize_ellipse(n, major, ratio, s, e);
        let minor = scale(cross(n, major), ratio);
        let mut sweep = (e - s).rem_euclid(TAU);
        if sweep <= 1e-12 {
            sweep = TAU;
        }
        let ea = EllipseArc {
            c: place.xf.point(p3(&el.center)),
            u: place.xf.vector(major),
            v: place.xf.vector(minor),
            t0: s,
            t1: s + sweep,
        };
        ellipse_segs(&ea, self.tolerance, span, None)
    }

    fn polyline(
        &self,
        verts: &[(P3, f64, Span)],
        closed: bool,
        normal: &P3,
        place: &Place,
    ) -> PieceResult {
        let ocs = Affine::ocs(*normal).ok_or("the extrusion direction is zero or not finite")?;
        let m = place.xf.then_after(&ocs);
        if verts
            .iter()
            .any(|(p, b, _)| !(p.iter().all(|v| v.is_finite()) && b.is_finite()))
        {
            return Err("a vertex or bulge is not finite".into());
        }
        let mut piece = Vec::new();
        let count = if closed {
            verts.len()
        } else {
            verts.len().saturating_sub(1)
        };
        for i in 0..count {
            let (p, bulge, span) = verts[i];
            let (q, _, _) = verts[(i + 1) % verts.len()];
            if p == q {
                continue; // repeated vertex
            }
            let (a, b) = (m.point(p), m.point(q));
            if bulge.abs() < 1e-12 {
                if a != b {
                    piece.push(Seg {
                        kind: SegKind::Line,
                        a,
                        b,
                        span,
                    });
                }
                continue;
            }
            // Bulge = tan(θ/4), θ the included angle, positive counter-clockwise (in OCS).
            let theta = 4.0 * libm::atan(bulge);
            let chord = [q[0] - p[0], q[1] - p[1]];
            let d = libm::hypot(chord[0], chord[1]);
            let left = [-chord[1] / d, chord[0] / d];
            let off = d * (1.0 - bulge * bulge) / (4.0 * bulge);
            let c = [
                0.5 * (p[0] + q[0]) + left[0] * off,
                0.5 * (p[1] + q[1]) + left[1] * off,
                p[2],
            ];
            let r = d * (1.0 + bulge * bulge) / (4.0 * bulge.abs());
            let t0 = libm::atan2(p[1] - c[1], p[0] - c[0]);
            let e = EllipseArc {
                c: m.point(c),
                u: m.vector([r, 0.0, 0.0]),
                v: m.vector([0.0, r, 0.0]),
                t0,
                t1: t0 + theta,
            };
            match ellipse_segs(&e, self.tolerance, span, Some((a, b))) {
                Ok(segs) => piece.extend(segs),
                Err(NoPiece::ZeroLength) => {}
                Err(bad) => return Err(bad),
            }
        }
        if piece.is_empty() {
            return Err(NoPiece::ZeroLength); // no vertices apart
        }
        check_points(&piece.iter().flat_map(|s| [s.a, s.b]).collect::<Vec<_>>())?;
        Ok(piece)
    }

    fn spline(&self, s: &dxf::entities::Spline, place: &Place, span: Span) -> PieceResult {
        let xf = place.xf;
        if !s.control_points.is_empty() {
            let degree = usize::try_from(s.degree_of_curve)
                .map_err(|_| format!("degree {} is negative", s.degree_of_curve))?;
            let ctrl: Vec<P3> = s.control_points.iter().map(|p| xf.point(p3(p))).collect();
            let nurbs = Nurbs::new(degree, &s.knot_values, &ctrl, &s.weight_values)?;
            if let Some(arcs) = nurbs.circular_arcs() {
                return Ok(arc_piece(&arcs, span));
            }
            if let Some(piece) = cubic_piece(&nurbs.cubics(self.tolerance)?, span) {
                return Ok(piece);
            }
            let points = flatten(&NurbsCurve::new(nurbs), self.tolerance)?;
            return points_to_piece(&points, span);
        }
        if s.fit_points.len() < 2 {
            return Err("the spline has neither control points nor two fit points".into());
        }
        let mut fit: Vec<P3> = s.fit_points.iter().map(p3).collect();
        if s.flags & 1 != 0 && fit.first() != fit.last() {
            fit.push(fit[0]);
        }
        let tangent = |p: &dxf::Point| {
            let v = p3(p);
            (norm(v) > 0.0).then_some(v)
        };
        let spline = FitSpline::new(&fit, tangent(&s.start_tangent), tangent(&s.end_tangent))?;
        // The spline is built where the drawing defines it; an affine map takes a
        // Bézier's control points to those of its image.
        let cubics: Vec<Cubic> = spline
            .cubics(self.tolerance)?
            .iter()
            .map(|c| c.map(|p| xf.point(p)))
            .collect();
        if let Some(piece) = cubic_piece(&cubics, span) {
            return Ok(piece);
        }
        points_to_piece(&flatten(&Mapped(spline, xf), self.tolerance)?, span)
    }

    fn insert(&mut self, e: &Entity, ins: &dxf::entities::Insert, place: &Place, origin: Origin) {
        let name = ins.name.to_lowercase();
        let entity = self.entity_ref(e, place, origin);
        let span = self.span(origin);
        let fail = |reason: String| DxfError::BadBlock {
            entity: entity.clone(),
            reason,
            span,
        };
        let Some(block) = self.blocks.get(&name).copied() else {
            self.errors
                .push(fail(format!("no block named {:?}", ins.name)));
            return;
        };
        if place.blocks.contains(&name) || place.blocks.len() >= MAX_NESTING {
            self.errors.push(fail(format!(
                "block {:?} inserts itself or nests too deep",
                ins.name
            )));
            return;
        }
        let (sx, sy, sz) = (ins.x_scale_factor, ins.y_scale_factor, ins.z_scale_factor);
        let numbers = [
            sx,
            sy,
            sz,
            ins.rotation,
            ins.location.x,
            ins.location.y,
            ins.location.z,
            ins.column_spacing,
            ins.row_spacing,
        ];
        if numbers.iter().any(|v| !v.is_finite()) || sx == 0.0 || sy == 0.0 || sz == 0.0 {
            self.errors.push(DxfError::BadGeometry {
                entity,
                reason: "a scale factor is zero or a value is not finite".to_string(),
                span,
            });
            return;
        }
        let Some(ocs) = Affine::ocs(v3(&ins.extrusion_direction)) else {
            self.errors.push(DxfError::BadGeometry {
                entity,
                reason: "the extrusion direction is zero or not finite".to_string(),
                span,
            });
            return;
        };
        let (cols, rows) = (
            i64::from(ins.column_count.max(1)),
            i64::from(ins.row_count.max(1)),
        );
        if cols * rows > MAX_GRID {
            self.errors.push(DxfError::BadGeometry {
                entity,
                reason: format!("a {cols} × {rows} grid is more than {MAX_GRID} copies"),
                span,
            });
            return;
        }
        // Block units: converted into the units of the place the INSERT is in.
        let block_mm = self.block_units.get(&name).copied().and_then(mm_per_unit);
        let unit_scale = match (block_mm, place.mm_per_unit) {
            (Some(b), Some(p)) => b / p,
            _ => 1.0,
        };
        let base = p3(&block.base_point);
        let (sin, cos) = libm::sincos(ins.rotation.to_radians());
        let rotation = Affine {
            cols: [[cos, sin, 0.0], [-sin, cos, 0.0], [0.0, 0.0, 1.0]],
            t: [0.0; 3],
        };
        let scaling = Affine {
            cols: [
                [sx * unit_scale, 0.0, 0.0],
                [0.0, sy * unit_scale, 0.0],
                [0.0, 0.0, sz * unit_scale],
            ],
            t: [0.0; 3],
        };
        let unbase = Affine {
            t: scale(base, -1.0),
            ..Affine::IDENTITY
        };
        let layer = effective_layer(e, place);
        // Each entity's record: the k-th entity of a type is the block's k-th record of it.
        let mut ranks: HashMap<&'static str, usize> = HashMap::new();
        let origins: Vec<Origin> = block
            .entities
            .iter()
            .map(|child| {
                let kind = type_name(&child.specific);
                let rank = ranks.entry(kind).or_default();
                let record = self.source.in_block(&name, kind, *rank);
                *rank += 1;
                Origin { record, top: false }
            })
            .collect();
        let mut blocks = place.blocks.clone();
        blocks.push(name);
        for r in 0..rows {
            for c in 0..cols {
                let grid = [
                    c as f64 * ins.column_spacing,
                    r as f64 * ins.row_spacing,
                    0.0,
                ];
                let located = Affine {
                    t: p3(&ins.location),
                    ..Affine::IDENTITY
                };
                let offset = Affine {
                    t: grid,
                    ..Affine::IDENTITY
                };
                let local = located
                    .then_after(&rotation)
                    .then_after(&offset)
                    .then_after(&scaling)
                    .then_after(&unbase);
                let inner = Place {
                    xf: place.xf.then_after(&ocs).then_after(&local),
                    layer: Some(layer.clone()),
                    mm_per_unit: block_mm.or(place.mm_per_unit),
                    blocks: blocks.clone(),
                };
                for (child, &origin) in block.entities.iter().zip(&origins) {
                    self.entity(child, &inner, origin);
                }
            }
        }
    }
}

fn effective_layer(e: &Entity, place: &Place) -> String {
    match &place.layer {
        Some(l) if e.common.layer == "0" => l.clone(),
        _ => e.common.layer.clone(),
    }
}

fn check_points(points: &[P3]) -> Result<(), String> {
    if points.iter().all(|p| p.iter().all(|v| v.is_finite())) {
        Ok(())
    } else {
        Err("a coordinate is not finite".to_string())
    }
}

/// A curve seen through an affine map (the map is applied after evaluation).
struct Mapped<C>(C, Affine);

impl<C: PieceCurve> PieceCurve for Mapped<C> {
    fn pieces(&self) -> Vec<(f64, f64)> {
        self.0.pieces()
    }

    fn eval(&self, piece: usize, t: f64) -> P3 {
        self.1.point(self.0.eval(piece, t))
    }
}

/// An ellipse's major axis, axis ratio and parameters with the ratio at most 1.
///
/// DXF requires the ratio in (0, 1]; a ratio above 1 (CAD files write 1.0000001) means the
/// minor axis `r·(n × M)` is the longer one. With `M' = r·(n × M)`, `r' = 1/r`, the new
/// minor axis is `r'·(n × M') = n × (n × M) = −M` (`n` a unit normal perpendicular to
/// `M`), so `M cos t + r (n × M) sin t = M' cos(t − π/2) + (−M) sin(t − π/2)`: the same
/// point at parameter `t − π/2`.
pub fn normalize_ellipse(n: P3, major: P3, ratio: f64, s: f64, e: f64) -> (P3, f64, f64, f64) {
    if ratio <= 1.0 {
        return (major, ratio, s, e);
    }
    let quarter = std::f64::consts::FRAC_PI_2;
    (
        scale(cross(n, major), ratio),
        1.0 / ratio,
        s - quarter,
        e - quarter,
    )
}

/// Circular arcs (start, end, centre, signed sweep) as arc segments, each starting
/// exactly where the one before ends.
fn arc_piece(arcs: &[crate::curve::CircularArc], span: Span) -> Piece {
    let mut piece: Piece = Vec::with_capacity(arcs.len());
    for &(a, b, center, sweep) in arcs {
        let a = piece.last().map_or(a, |s: &Seg| s.b);
        piece.push(Seg {
            kind: SegKind::Arc { center, sweep },
            a,
            b,
            span,
        });
    }
    piece
}

/// Cubics as Bézier segments, when every one has Z linear in its parameter (a plane
/// parallel to XY, or a ramp); `None` otherwise, for the caller to flatten.
fn cubic_piece(cubics: &[Cubic], span: Span) -> Option<Piece> {
    let mut piece = Vec::with_capacity(cubics.len());
    for c in cubics {
        let size = c.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()));
        let linear_z = (3.0 * c[1][2] - 2.0 * c[0][2] - c[3][2]).abs() <= 1e-9 * size
            && (3.0 * c[2][2] - c[0][2] - 2.0 * c[3][2]).abs() <= 1e-9 * size;
        if !linear_z || !c.iter().flatten().all(|v| v.is_finite()) {
            return None;
        }
        if c.iter().all(|p| *p == c[0]) {
            continue;
        }
        piece.push(Seg {
            kind: SegKind::Bezier {
                controls: [[c[1][0], c[1][1]], [c[2][0], c[2][1]]],
            },
            a: c[0],
            b: c[3],
            span,
        });
    }
    (!piece.is_empty()).then_some(piece)
}

fn points_to_piece(points: &[P3], span: Span) -> PieceResult {
    check_points(points)?;
    let piece: Piece = points
        .windows(2)
        .filter(|w| w[0] != w[1])
        .map(|w| Seg {
            kind: SegKind::Line,
            a: w[0],
            b: w[1],
            span,
        })
        .collect();
    if piece.is_empty() {
        return Err(NoPiece::ZeroLength); // every point the same
    }
    Ok(piece)
}

/// An elliptical arc as segments: one arc when it is a circle parallel to XY, cubic
/// Béziers when it lies in a plane parallel to XY, else chords.
///
/// `ends` replaces the computed end points (exact polyline vertices).
pub fn ellipse_segs(
    e: &EllipseArc,
    tolerance: f64,
    span: Span,
    ends: Option<(P3, P3)>,
) -> PieceResult {
    check_points(&[e.c, e.u, e.v])?;
    let (lu, lv) = (norm(e.u), norm(e.v));
    if !(lu > 0.0 && lv > 0.0 && e.t0.is_finite() && e.t1.is_finite()) {
        return Err("the curve is degenerate".into());
    }
    let sweep = e.t1 - e.t0;
    let full = sweep.abs() >= TAU * (1.0 - 1e-12);
    let (a, b) = ends.unwrap_or_else(|| {
        let a = e.at(e.t0);
        (a, if full { a } else { e.at(e.t1) })
    });
    let circular = (lu - lv).abs() <= 1e-9 * lu
        && dot(e.u, e.v).abs() <= 1e-9 * lu * lv
        && e.u[2].abs() <= 1e-12 * lu
        && e.v[2].abs() <= 1e-12 * lv;
    if circular {
        if sweep.abs() < 1e-9 || dist(a, b) == 0.0 && !full {
            return points_to_piece(&[a, b], span);
        }
        let turn = cross(e.u, e.v)[2].signum();
        return Ok(vec![Seg {
            kind: SegKind::Arc {
                center: [e.c[0], e.c[1]],
                sweep: sweep * turn,
            },
            a,
            b,
            span,
        }]);
    }
    if let Some(mut piece) = cubic_piece(&e.cubics(tolerance)?, span) {
        let last = piece.len() - 1;
        if let Some((a, b)) = ends {
            (piece[0].a, piece[last].b) = (a, b);
        } else if full {
            piece[last].b = piece[0].a;
        }
        return Ok(piece);
    }
    let mut points = flatten(e, tolerance)?;
    if let Some((a, b)) = ends {
        points[0] = a;
        let last = points.len() - 1;
        points[last] = b;
    } else if full {
        let last = points.len() - 1;
        points[last] = points[0];
    }
    points_to_piece(&points, span)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::sub;

    #[test]
    fn units_table() {
        assert_eq!(mm_per_unit(DxfUnits::Inches), Some(25.4));
        assert_eq!(mm_per_unit(DxfUnits::Unitless), None);
        assert!(is_imperial(DxfUnits::Feet) && !is_imperial(DxfUnits::Meters));
        assert!((mm_per_unit(DxfUnits::USSurveyFeet).unwrap() - 304.800_609_6).abs() < 1e-6);
    }

    #[test]
    fn mirrored_circle_in_xy_is_one_clockwise_arc() {
        let m = Affine::ocs([0.0, 0.0, -1.0]).unwrap();
        let e = EllipseArc {
            c: m.point([1.0, 0.0, 0.0]),
            u: m.vector([2.0, 0.0, 0.0]),
            v: m.vector([0.0, 2.0, 0.0]),
            t0: 0.0,
            t1: 1.0,
        };
        let segs = ellipse_segs(&e, 1e-3, Span::default(), None).unwrap();
        assert_eq!(segs.len(), 1);
        assert_eq!(
            segs[0].kind,
            SegKind::Arc {
                center: [-1.0, 0.0],
                sweep: -1.0
            }
        );
        assert_eq!(segs[0].a, [-3.0, 0.0, 0.0]);
        let skew = EllipseArc {
            u: [2.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
            ..e
        };
        // Not a circle: cubic Béziers, not an arc.
        let skewed = ellipse_segs(&skew, 1e-3, Span::default(), None).unwrap();
        assert!(skewed
            .iter()
            .all(|s| matches!(s.kind, SegKind::Bezier { .. })));
        assert!(sub(
            segs[0].b,
            [-1.0 - 2.0 * libm::cos(1.0), 2.0 * libm::sin(1.0), 0.0]
        )
        .iter()
        .all(|v| v.abs() < 1e-15));
    }
}
