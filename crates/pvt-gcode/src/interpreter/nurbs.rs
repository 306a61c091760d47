//! G5.2/G5.3: LinuxCNC's NURBS block, and the curve of every NURBS block as elements.
//!
//! Owns the gathering of a G5.2 block as `rs274` (LinuxCNC 2.9) reads it: the current
//! position is the first control point; `G5.2 P- L-` without X Y sets its weight; every
//! `X- Y- P-` line adds a control point of weight P, its X Y read against the block's
//! start (under G91 every point is an offset from where the block starts, as rs274's
//! position stays there until G5.3); L, on any line of the block, sets the order when it
//! is above 3, else the order is 3; G5.3 closes the block and the tool is at the last
//! control point. Points in X Y words make a curve in XY whatever the plane (G17, G18 or
//! G19: rs274 2.9 reads X and Y and leaves Z where it is); in G18/G19 the plane's own
//! words (Z X, Y Z: LinuxCNC 2.10's `nc_files/nurbs/G5` programs) make it in that plane,
//! the block's first point deciding. A line with no axis word, P or L adds no point (a
//! comment or F, as rs274 moves only on axis words). LinuxCNC's knot vector is uniform and clamped:
//! `order` zeros, then 1, 2, …, then `order` copies of `points − order + 1`. Its
//! refusals: X without Y, a missing or non-positive P after the first line, fewer points
//! than the order, G5.3 without G5.2.
//!
//! Every block, G5.2's and G6.2's ([`super::nurbs_g6`]), becomes cubic Bézier elements
//! by [`pvt_core::rational::nurbs_cubics`] ([`Interpreter::nurbs_curve`]): a
//! non-rational block (every weight equal) of order 2 to 4 exactly, its knot spans'
//! Béziers; any other within [`NURBS_FIT_SHARE`] of the tolerance, each such cubic
//! carrying that share as its `fit`, so that the path planner keeps the motion within
//! the rest of the tolerance of it. It must not plan or flatten the curve (pvt-core
//! does) and refuses what pvtc cannot follow: A/B/C words or Z off the block's plane on
//! a G5.2 line, and inverse time feed.

use super::Interpreter;
use crate::block::Block;
use crate::codes::FeedMode;
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;
use crate::NURBS_FIT_SHARE;
use miette::SourceSpan;
use pvt_core::rational::{nurbs_cubics_marked, FitError};
use pvt_core::{Axis, Bezier, Element, ElementKind, Motion, Plane, Position, Units};

/// A NURBS block being gathered (G5.2 until its G5.3, G6.2 until its last knot).
#[derive(Debug, Clone)]
pub(super) struct NurbsBlock {
    /// Where the block starts, machine frame.
    pub start: Position,
    /// Control points in the curve's plane (output units).
    pub points: Vec<[f64; 2]>,
    pub weights: Vec<f64>,
    /// One more than the degree.
    pub order: usize,
    /// The word that opened the block.
    pub opened_at: SourceSpan,
    /// G6.2's knots (one per control point, then the closing ones), with its plane.
    pub knots: Option<(Vec<f64>, Plane)>,
    /// G5.2: the plane its control points are read in, set by the first one that has
    /// axis words (see [`Interpreter::nurbs_words`]).
    pub words: Option<Plane>,
}

/// A gathered curve: its plane, control points, weights, degree and knots.
pub(super) struct Curve<'a> {
    pub plane: Plane,
    pub points: &'a [[f64; 2]],
    pub weights: &'a [f64],
    pub degree: usize,
    pub knots: &'a [f64],
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
            let start = self.position;
            self.nurbs = Some(NurbsBlock {
                start,
                points: vec![[start[0], start[1]]],
                weights: vec![1.0],
                order: 3,
                opened_at: span(word.span()),
                knots: None,
                words: None,
            });
            if !self.nurbs_order(request) {
                return;
            }
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
        } else if opening.is_none()
            && !request.has_axis_words()
            && request.p.is_none()
            && request.l.is_none()
            && request.stop.is_none()
        {
            // rs274 moves only on a line with axis words (`enhance_block`), so a blank,
            // comment-only or F-only line inside the block is no control point (an M2
            // there still ends the program with the block open: refused below).
            return;
        } else if !self.nurbs_order(request) {
            return;
        }
        self.nurbs_control(request, at, opening.is_some());
    }

    /// L on a G5.2 line: the order when above 3 (rs274 keeps 3 for L1 to L3). False
    /// (the block dropped) for an L that is not a whole number up to 64.
    fn nurbs_order(&mut self, request: &Request) -> bool {
        let Some(l) = request.l else { return true };
        if l.value.fract() != 0.0 || !(l.value >= 0.0 && l.value <= 64.0) {
            self.nurbs = None;
            self.push(bad_value(l, "the order L is a whole number up to 64"));
            return false;
        }
        if let Some(nurbs) = self.nurbs.as_mut() {
            if l.value > 3.0 {
                nurbs.order = l.value as usize;
            }
        }
        true
    }

    /// The plane a G5.2 control point's words are in: X Y (LinuxCNC 2.9's reading, in
    /// every plane), or in G18/G19 the plane's own pair (Z X, Y Z) as LinuxCNC 2.10's
    /// `nc_files/nurbs/G5` programs write them; `None` for neither, or for a line whose
    /// reading differs from the block's first point's.
    fn nurbs_words(&self, request: &Request) -> Option<Plane> {
        let has = |a: Axis| request.axes[a.index()].is_some();
        let only = |plane: Plane| {
            let (first, second, normal) = plane.axes();
            (has(first) && has(second) && !has(normal)).then_some(plane)
        };
        let words = only(Plane::XY).or_else(|| match self.modal.plane {
            Plane::XY => None,
            plane => only(plane),
        })?;
        match self.nurbs.as_ref().and_then(|n| n.words) {
            Some(block) if block != words => None,
            _ => Some(words),
        }
    }

    /// Adds the block's point and P as a control point (against the block's start, which
    /// stays the current position until G5.3, as in rs274).
    fn nurbs_control(&mut self, request: &Request, at: SourceSpan, first: bool) {
        let Some(words) = self.nurbs_words(request) else {
            self.nurbs = None;
            let needs = "both words of one plane for a control point (X Y, or the G18/G19 plane's), as the block's first";
            return self.push(missing("G5.2", needs, at));
        };
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
        if let Some(nurbs) = self.nurbs.as_mut() {
            if nurbs.words.is_none() {
                nurbs.words = Some(words);
                nurbs.points[0] = words.project(&nurbs.start);
            }
            nurbs.points.push(words.project(&point));
            nurbs.weights.push(weight);
        }
    }

    /// What pvtc refuses on a G5.2 line.
    fn nurbs_refusal(&self, request: &Request, at: SourceSpan) -> Option<GcodeDiagnostic> {
        let z_off_plane = request.axes[Axis::Z.index()].is_some()
            && (self.modal.plane == Plane::XY
                || request.axes[Axis::X.index()..=Axis::Y.index()]
                    .iter()
                    .all(Option::is_some));
        let feature = if z_off_plane || request.axes[3..].iter().any(Option::is_some) {
            "NURBS moving Z, A, B or C off its plane"
        } else if self.modal.feed_mode == FeedMode::InverseTime {
            "NURBS in inverse time (G93)"
        } else {
            return None;
        };
        Some(nurbs_unsupported("G5.2", feature, at))
    }

    /// G5.3: the gathered block becomes cubic Bézier elements.
    pub(super) fn nurbs_close(&mut self, request: &Request, block: &Block) {
        let at = span(super::motion::move_span(request, block));
        let nurbs = match self.nurbs.take() {
            Some(nurbs) if nurbs.knots.is_none() => nurbs,
            _ => return self.push(missing("G5.3", "an open G5.2 block before it", at)),
        };
        if nurbs.points.len() < nurbs.order {
            let needs = "at least L control points (the start counts as one)";
            return self.push(missing("G5.3", needs, at));
        }
        let knots = knot_vector(nurbs.points.len(), nurbs.order);
        let curve = Curve {
            plane: nurbs.words.unwrap_or(Plane::XY),
            points: &nurbs.points,
            weights: &nurbs.weights,
            degree: nurbs.order - 1,
            knots: &knots,
        };
        self.nurbs_curve(&curve, nurbs.start, "G5.2", request, block, at);
    }

    /// The elements of `curve`, from `start` (whose in-plane coordinates are the first
    /// control point's; the other axes stay); the tool ends at the curve's end.
    pub(super) fn nurbs_curve(
        &mut self,
        curve: &Curve,
        start: Position,
        code: &str,
        request: &Request,
        block: &Block,
        at: SourceSpan,
    ) {
        let ctrl: Vec<[f64; 4]> = (curve.points.iter().zip(curve.weights))
            .map(|(p, &w)| [p[0] * w, p[1] * w, 0.0, w])
            .collect();
        let units = self.output_units.unwrap_or(Units::Millimetre);
        // A G64 P tighter than the tolerance is the one the planner keeps.
        let tolerance = pvt_core::defaults::tolerance(self.options.tolerance, units)
            .min(self.path_tolerance.unwrap_or(f64::INFINITY));
        let share = tolerance * NURBS_FIT_SHARE;
        let fitted = nurbs_cubics_marked(curve.degree, curve.knots, &ctrl, share);
        let cubics = match fitted {
            Ok(cubics) => cubics,
            Err(e) => return self.push(nurbs_unsupported(code, fit_refusal(&e), at)),
        };
        let (first, second, _) = curve.plane.axes();
        let place = |p: [f64; 2]| {
            let mut q = start;
            q[first.index()] = p[0];
            q[second.index()] = p[1];
            q
        };
        let last = curve.points[curve.points.len() - 1];
        let n = cubics.len();
        // The ends are the control points themselves, not their homogeneous round trip.
        let beziers: Vec<([[f64; 2]; 4], f64)> = (cubics.iter().enumerate())
            .map(|(i, (c, exact))| {
                let mut p = c.map(|q| [q[0], q[1]]);
                if i == 0 {
                    p[0] = curve.points[0];
                }
                if i + 1 == n {
                    p[3] = last;
                }
                (p, if *exact { 0.0 } else { share })
            })
            .collect();
        let bezier = |p: &[[f64; 2]; 4], fit: f64| Bezier {
            plane: curve.plane,
            controls: [p[1], p[2]],
            fit,
        };
        let length = || {
            (beziers.iter())
                .map(|(p, fit)| bezier(p, *fit).length(&place(p[0]), &place(p[3])))
                .sum()
        };
        let Some(feed) = self.feed_rate(request, block, length) else {
            return;
        };
        for (p, fit) in &beziers {
            let element = Element {
                kind: ElementKind::Bezier(bezier(p, *fit)),
                start: place(p[0]),
                end: place(p[3]),
                feed,
                span: super::motion::element_span(block),
            };
            self.route(Motion::Feed, element);
        }
        self.position = place(last);
    }

    /// A NURBS block still open where other motion or the program's end comes.
    pub(super) fn nurbs_unclosed(&mut self) {
        if let Some(nurbs) = self.nurbs.take() {
            let (code, needs) = match nurbs.knots {
                None => (
                    "G5.2",
                    "a G5.3 closing its block before other motion or the end",
                ),
                Some(_) => (
                    "G6.2",
                    "P closing knots (K lines) before other motion or the end",
                ),
            };
            self.push(missing(code, needs, nurbs.opened_at));
        }
    }
}

pub(super) fn missing(code: &str, needs: &'static str, at: SourceSpan) -> GcodeDiagnostic {
    GcodeDiagnostic::MissingWord {
        code: code.to_string(),
        needs,
        span: at,
    }
}

pub(super) fn bad_value(word: crate::block::Word, expected: &'static str) -> GcodeDiagnostic {
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

pub(super) fn nurbs_unsupported(
    code: &str,
    feature: &'static str,
    at: SourceSpan,
) -> GcodeDiagnostic {
    GcodeDiagnostic::Unsupported {
        code: code.to_string(),
        feature,
        places: 1,
        span: at,
    }
}
