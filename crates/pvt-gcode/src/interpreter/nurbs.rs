//! G5.2/G5.3: LinuxCNC's NURBS block in the XY plane.
//!
//! Owns the gathering of a NURBS block (the current position is the first control point;
//! `G5.2 P- L-` without X Y sets its weight; every `X- Y- P-` line adds a control point
//! of weight P; L, on the opening line, is the order, 3 when absent; G5.3 closes the
//! block), LinuxCNC's knot vector (uniform and clamped: `order` zeros, then 1, 2, …,
//! then `order` copies of `points − order + 1`) and its refusals (X without Y, a missing
//! or non-positive P after the first line, fewer points than the order, G5.3 without
//! G5.2). The block becomes cubic Bézier elements by
//! [`pvt_core::rational::nurbs_cubics`]: a non-rational block (every weight equal) of
//! order 2 to 4 exactly, its knot spans' Béziers; any other within [`NURBS_FIT_SHARE`]
//! of the tolerance. It must not plan or flatten the curve (pvt-core does) and refuses
//! what LinuxCNC's XY-only NURBS cannot be here: a plane other than G17, Z/A/B/C words
//! and inverse time feed.

use super::Interpreter;
use crate::block::Block;
use crate::codes::FeedMode;
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;
use crate::NURBS_FIT_SHARE;
use miette::SourceSpan;
use pvt_core::rational::{nurbs_cubics, FitError};
use pvt_core::{Bezier, Element, ElementKind, Motion, Plane, Position, Units};

/// A G5.2 block being gathered.
#[derive(Debug, Clone)]
pub(super) struct NurbsBlock {
    /// Where the curve starts (the first control point), machine frame.
    start: Position,
    /// Control points (machine XY, output units), the start first.
    points: Vec<[f64; 2]>,
    weights: Vec<f64>,
    /// L: one more than the degree.
    order: usize,
    /// The G5.2 word that opened the block.
    opened_at: SourceSpan,
}

/// LinuxCNC's knot vector for `points` control points of `order` (uniform, clamped).
pub fn knot_vector(points: usize, order: usize) -> Vec<f64> {
    let last = (points - order + 1) as f64;
    (0..points + order)
        .map(|i| {
            if i < order {
                0.0
            } else if i < points {
                (i - order + 1) as f64
            } else {
                last
            }
        })
        .collect()
}

impl Interpreter<'_> {
    /// A block in G5.2 mode: opens the NURBS block or adds a control point to it.
    pub(super) fn nurbs_point(&mut self, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let opening = request.motion.map(|(_, word)| word);
        let at = span(super::motion::move_span(request, block));
        if self.nurbs.is_none() {
            let Some(word) = opening else { return };
            if let Some(refusal) = self.nurbs_refusal(request, span(word.span())) {
                return self.push(refusal);
            }
            let order = match request.l {
                None => 3,
                Some(l) if l.value.fract() == 0.0 && (2.0..=64.0).contains(&l.value) => {
                    l.value as usize
                }
                Some(l) => return self.push(bad_value(l, "the order L is a whole number from 2")),
            };
            let start = self.position;
            self.nurbs = Some(NurbsBlock {
                start,
                points: vec![[start[0], start[1]]],
                weights: vec![1.0],
                order,
                opened_at: span(word.span()),
            });
            if !request.has_axis_words() {
                if let Some(p) = request.p {
                    if !(p.value > 0.0 && p.value.is_finite()) {
                        self.nurbs = None;
                        return self.push(bad_value(p, "a weight P is positive"));
                    }
                    if let Some(nurbs) = self.nurbs.as_mut() {
                        nurbs.weights[0] = p.value;
                    }
                }
                return;
            }
        } else if let Some(refusal) = self.nurbs_refusal(request, at) {
            self.nurbs = None;
            return self.push(refusal);
        }
        self.nurbs_control(request, at, opening.is_some());
    }

    /// Adds the block's X Y P as a control point.
    fn nurbs_control(&mut self, request: &Request, at: SourceSpan, first: bool) {
        if request.axes[0].is_none() || request.axes[1].is_none() {
            self.nurbs = None;
            return self.push(missing("G5.2", "both X and Y for a control point", at));
        }
        let weight = match request.p {
            Some(p) if p.value > 0.0 && p.value.is_finite() => p.value,
            Some(p) => {
                self.nurbs = None;
                return self.push(bad_value(p, "a weight P is positive"));
            }
            None if first => 1.0,
            None => {
                self.nurbs = None;
                return self.push(missing(
                    "G5.2",
                    "a positive weight P on every control point",
                    at,
                ));
            }
        };
        let point = match self.target(request) {
            Ok(point) => point,
            Err(diagnostic) => {
                self.nurbs = None;
                return self.push(diagnostic);
            }
        };
        self.position = point;
        if let Some(nurbs) = self.nurbs.as_mut() {
            nurbs.points.push([point[0], point[1]]);
            nurbs.weights.push(weight);
        }
    }

    /// What LinuxCNC or pvtc refuses on a G5.2 line.
    fn nurbs_refusal(&self, request: &Request, at: SourceSpan) -> Option<GcodeDiagnostic> {
        let feature = if self.modal.plane != Plane::XY {
            "NURBS outside the XY plane (G17 only)"
        } else if request.axes[2..].iter().any(Option::is_some) {
            "NURBS moving Z, A, B or C"
        } else if self.modal.feed_mode == FeedMode::InverseTime {
            "NURBS in inverse time (G93)"
        } else {
            return None;
        };
        Some(GcodeDiagnostic::Unsupported {
            code: "G5.2".to_string(),
            feature,
            places: 1,
            span: at,
        })
    }

    /// G5.3: the gathered block becomes cubic Bézier elements.
    pub(super) fn nurbs_close(&mut self, request: &Request, block: &Block) {
        let at = span(super::motion::move_span(request, block));
        let Some(nurbs) = self.nurbs.take() else {
            return self.push(missing("G5.3", "an open G5.2 block before it", at));
        };
        if nurbs.points.len() < nurbs.order {
            let needs = "at least L control points (the start counts as one)";
            return self.push(missing("G5.3", needs, at));
        }
        let knots = knot_vector(nurbs.points.len(), nurbs.order);
        let ctrl: Vec<[f64; 4]> = (nurbs.points.iter().zip(&nurbs.weights))
            .map(|(p, &w)| [p[0] * w, p[1] * w, 0.0, w])
            .collect();
        let units = self.output_units.unwrap_or(Units::Millimetre);
        let tolerance = pvt_core::defaults::tolerance(self.options.tolerance, units);
        let fitted = nurbs_cubics(nurbs.order - 1, &knots, &ctrl, tolerance * NURBS_FIT_SHARE);
        let cubics = match fitted {
            Ok(cubics) => cubics,
            Err(e) => return self.push(nurbs_unsupported(fit_refusal(&e), at)),
        };
        let mut beziers: Vec<([[f64; 2]; 4], Position, Position)> = cubics
            .iter()
            .map(|c| {
                let p = c.map(|q| [q[0], q[1]]);
                let (mut start, mut end) = (nurbs.start, nurbs.start);
                start[..2].copy_from_slice(&p[0]);
                end[..2].copy_from_slice(&p[3]);
                (p, start, end)
            })
            .collect();
        // The ends are the control points themselves, not their homogeneous round trip.
        if let Some(first) = beziers.first_mut() {
            first.0[0] = nurbs.points[0];
            first.1 = nurbs.start;
        }
        if let Some(last) = beziers.last_mut() {
            last.0[3] = nurbs.points[nurbs.points.len() - 1];
            last.2[..2].copy_from_slice(&last.0[3]);
        }
        let curve = |p: &[[f64; 2]; 4]| Bezier {
            plane: Plane::XY,
            controls: [p[1], p[2]],
        };
        let length = || beziers.iter().map(|(p, s, e)| curve(p).length(s, e)).sum();
        let Some(feed) = self.feed_rate(request, block, length) else {
            return;
        };
        for (p, start, end) in &beziers {
            let element = Element {
                kind: ElementKind::Bezier(curve(p)),
                start: *start,
                end: *end,
                feed,
                span: super::motion::element_span(block),
            };
            self.route(Motion::Feed, element);
        }
    }

    /// A NURBS block still open where other motion or the program's end comes.
    pub(super) fn nurbs_unclosed(&mut self) {
        if let Some(nurbs) = self.nurbs.take() {
            let needs = "a G5.3 closing its block before other motion or the end";
            self.push(missing("G5.2", needs, nurbs.opened_at));
        }
    }
}

fn missing(code: &str, needs: &'static str, at: SourceSpan) -> GcodeDiagnostic {
    GcodeDiagnostic::MissingWord {
        code: code.to_string(),
        needs,
        span: at,
    }
}

fn bad_value(word: crate::block::Word, expected: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::BadValue {
        word: word.name(),
        expected,
        span: span(word.span()),
    }
}

/// The refusal for a block the cubics cannot follow.
fn fit_refusal(error: &FitError) -> &'static str {
    match error {
        FitError::Spline(_) => "NURBS blocks whose knots make no curve",
        FitError::NotFinite => "NURBS blocks with no finite point",
        FitError::Tolerance | FitError::TooMany => {
            "NURBS blocks no cubics follow at this tolerance"
        }
    }
}

fn nurbs_unsupported(feature: &'static str, at: SourceSpan) -> GcodeDiagnostic {
    GcodeDiagnostic::Unsupported {
        code: "G5.2".to_string(),
        feature,
        places: 1,
        span: at,
    }
}
