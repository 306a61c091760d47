//! G6.2: LinuxCNC 2.10's NURBS block, with its own knots and weights.
//!
//! Owns the gathering of a G6.2 block as LinuxCNC 2.10 writes it (its `nc_files/nurbs/G6`
//! programs, and the canon's `NURBS_G6_FEED`, which takes the knot vector as the K of
//! every line in order and the control points as every line but the last P):
//!
//! ```text
//! G6.2 X- Y- R- K- P- [Q-]   (opening line: first control point, weight R, knot K, order P)
//!      X- Y- R- K-           (a control point, its weight and its knot)
//! G6.2 K-                    (a closing knot; P of them end the block)
//! ```
//!
//! The control point words are the selected plane's (G17: X Y, G18: Z X, G19: Y Z), read
//! against where the block starts (which stays the current position until the block
//! ends, as G5.2's do); R (weight) and K (knot) are on every control point line; the
//! knots never decrease; the block ends at its P-th closing knot, and the curve is
//! `Σ N(i,P)(u)·Rᵢ·Pᵢ / Σ N(i,P)(u)·Rᵢ` over `u` from the first knot to the last. Q
//! (LinuxCNC's feed interpolation choice) changes no geometry and is read and left. The
//! curve starts at its first control point; where that is not the current position a
//! straight feed goes there first, as LinuxCNC's canon feeds to the curve's first point.
//! Refused at their lines: a missing or non-whole P below 2 or above 64, a missing or
//! non-positive R, a missing K, a decreasing K, a control point after a closing knot,
//! fewer control points than P, an axis off the plane, inverse time feed, a block left
//! open, and (pvtc) knots that are not clamped (the first P equal, the last P equal): the
//! curve of an unclamped vector does not start and end at its end control points. The
//! elements are [`Interpreter::nurbs_curve`]'s. It must not plan or flatten the curve.

use super::nurbs::{bad_value, missing, nurbs_unsupported, Curve, NurbsBlock};
use super::Interpreter;
use crate::block::Block;
use crate::codes::FeedMode;
use crate::diagnostic::span;
use crate::request::Request;
use miette::SourceSpan;
use pvt_core::{Element, ElementKind, Motion, Units};

impl Interpreter<'_> {
    /// A block in G6.2 mode: opens the block, adds a control point or a closing knot.
    pub(super) fn nurbs_knot_line(&mut self, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let at = span(super::motion::move_span(request, block));
        let control = request.has_axis_words() || request.radius.is_some();
        if let Some(refusal) = self.knot_line_refusal(request, at) {
            self.nurbs = None;
            return self.push(refusal);
        }
        if self.nurbs.is_none() {
            if !control && request.offsets[2].is_none() {
                return;
            }
            let Some((_, word)) = request.motion else {
                let needs = "a G6.2 word with P opening a new block";
                return self.push(missing("G6.2", needs, at));
            };
            let order = match request.p {
                Some(p) if p.value.fract() == 0.0 && (2.0..=64.0).contains(&p.value) => {
                    p.value as usize
                }
                Some(p) => return self.push(bad_value(p, "the order P is a whole number 2 to 64")),
                None => return self.push(missing("G6.2", "the order P on its opening line", at)),
            };
            self.nurbs = Some(NurbsBlock {
                start: self.position,
                points: Vec::new(),
                weights: Vec::new(),
                order,
                opened_at: span(word.span()),
                knots: Some((Vec::new(), self.modal.plane)),
                words: None,
            });
        } else if let Some(p) = request.p {
            self.nurbs = None;
            return self.push(bad_value(
                p,
                "the order P goes on the opening G6.2 line only",
            ));
        }
        if control {
            self.knot_control_point(request, at);
        } else if let Some(k) = request.offsets[2] {
            self.closing_knot(k, request, block, at);
        }
    }

    /// What LinuxCNC or pvtc refuses on any G6.2 line.
    fn knot_line_refusal(
        &self,
        request: &Request,
        at: SourceSpan,
    ) -> Option<crate::diagnostic::GcodeDiagnostic> {
        let plane = match &self.nurbs {
            Some(NurbsBlock {
                knots: Some((_, plane)),
                ..
            }) => *plane,
            _ => self.modal.plane,
        };
        let (first, second, _) = plane.axes();
        let off_plane = (request.axes.iter().enumerate())
            .any(|(i, w)| w.is_some() && i != first.index() && i != second.index());
        let feature = if off_plane {
            "NURBS moving an axis off the plane"
        } else if self.modal.feed_mode == FeedMode::InverseTime {
            "NURBS in inverse time (G93)"
        } else {
            return None;
        };
        Some(nurbs_unsupported("G6.2", feature, at))
    }

    /// Adds the line's point (in the block's plane), weight R and knot K.
    fn knot_control_point(&mut self, request: &Request, at: SourceSpan) {
        let (Some(r), Some(k)) = (request.radius, request.offsets[2]) else {
            self.nurbs = None;
            let needs = "a weight R and a knot K on every control point";
            return self.push(missing("G6.2", needs, at));
        };
        if !(r.value > 0.0 && r.value.is_finite()) {
            self.nurbs = None;
            return self.push(bad_value(r, "a weight R is positive"));
        }
        let point = match self.target(request) {
            Ok(point) => point,
            Err(diagnostic) => {
                self.nurbs = None;
                return self.push(diagnostic);
            }
        };
        let Some(nurbs) = self.nurbs.as_mut() else {
            return;
        };
        let Some((knots, plane)) = nurbs.knots.as_mut() else {
            return;
        };
        if knots.len() > nurbs.points.len() {
            self.nurbs = None;
            let needs = "its control points before the closing knots";
            return self.push(missing("G6.2", needs, at));
        }
        if !(k.value.is_finite() && knots.last().is_none_or(|&last| k.value >= last)) {
            self.nurbs = None;
            return self.push(bad_value(k, "the knots K never decrease"));
        }
        knots.push(k.value);
        nurbs.points.push(plane.project(&point));
        nurbs.weights.push(r.value);
    }

    /// A closing knot; the P-th ends the block and makes the curve.
    fn closing_knot(
        &mut self,
        k: crate::block::Word,
        request: &Request,
        block: &Block,
        at: SourceSpan,
    ) {
        let Some(nurbs) = self.nurbs.as_mut() else {
            return;
        };
        let Some((knots, _)) = nurbs.knots.as_mut() else {
            return;
        };
        if !(k.value.is_finite() && knots.last().is_none_or(|&last| k.value >= last)) {
            self.nurbs = None;
            return self.push(bad_value(k, "the knots K never decrease"));
        }
        knots.push(k.value);
        if knots.len() < nurbs.points.len() + nurbs.order {
            return;
        }
        let Some(nurbs) = self.nurbs.take() else {
            return;
        };
        self.knot_curve(&nurbs, request, block, at);
    }

    /// The gathered block as elements: a straight feed to its first control point where
    /// the tool is elsewhere, then the curve.
    fn knot_curve(&mut self, nurbs: &NurbsBlock, request: &Request, block: &Block, at: SourceSpan) {
        let Some((knots, plane)) = &nurbs.knots else {
            return;
        };
        if nurbs.points.len() < nurbs.order {
            let needs = "at least P control points";
            return self.push(missing("G6.2", needs, nurbs.opened_at));
        }
        let p = nurbs.order;
        let n = knots.len();
        let clamped = knots[..p].iter().all(|&k| k == knots[0])
            && knots[n - p..].iter().all(|&k| k == knots[n - 1]);
        if !clamped {
            let feature = "NURBS whose first P and last P knots are not equal (unclamped)";
            return self.push(nurbs_unsupported("G6.2", feature, at));
        }
        let mut start = self.position;
        let (first, second, _) = plane.axes();
        start[first.index()] = nurbs.points[0][0];
        start[second.index()] = nurbs.points[0][1];
        if start != self.position {
            self.feed_to_curve(start, request, block);
        }
        let curve = Curve {
            plane: *plane,
            points: &nurbs.points,
            weights: &nurbs.weights,
            degree: p - 1,
            knots,
        };
        self.nurbs_curve(&curve, start, "G6.2", request, block, at);
    }

    /// The straight feed from the tool to a curve's first point.
    fn feed_to_curve(&mut self, to: pvt_core::Position, request: &Request, block: &Block) {
        let from = self.position;
        let length = || pvt_core::vector::distance(&from, &to);
        let Some(feed) = self.feed_rate(request, block, length) else {
            return;
        };
        let element = Element {
            kind: ElementKind::Line,
            start: from,
            end: to,
            feed,
            span: super::motion::element_span(block),
        };
        self.route(Motion::Feed, element);
        self.position = to;
    }
}
