//! G5 and G5.1: cubic and quadratic splines in the XY plane, as LinuxCNC defines them.
//!
//! Owns the reading of a spline block (I J from the start to the first control point,
//! P Q from the end to the second; G5.1's I J to its one control point, raised to a
//! cubic exactly) into a [`Bezier`] element, LinuxCNC's refusals (a plane other than
//! G17, motion in Z/A/B/C, I without J, P without Q) and the continuation rule: a G5
//! without I and J starts along the direction the previous G5 ended in (its I J are the
//! previous P Q negated). It must not plan or flatten the curve: pvt-core does.

use super::Interpreter;
use crate::block::{Block, Word};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;
use miette::SourceSpan;
use pvt_core::{Bezier, Element, ElementKind, Motion, Plane, Units};

impl Interpreter<'_> {
    /// A G5 (`quadratic` false) or G5.1 block with axis words.
    pub(super) fn spline_move(&mut self, quadratic: bool, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let code = if quadratic { "G5.1" } else { "G5" };
        let at = span(super::motion::move_span(request, block));
        if let Some(refusal) = self.spline_refusal(code, request, at) {
            return self.push(refusal);
        }
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => return self.push(diagnostic),
        };
        let start = self.position;
        let controls = match self.spline_controls(
            quadratic,
            request,
            [start[0], start[1]],
            [end[0], end[1]],
        ) {
            Ok(controls) => controls,
            Err(needs) => {
                return self.push(GcodeDiagnostic::MissingWord {
                    code: code.to_string(),
                    needs,
                    span: at,
                })
            }
        };
        self.position = end;
        let bezier = Bezier {
            plane: Plane::XY,
            controls,
            fit: 0.0,
        };
        let length = || bezier.length(&start, &end);
        let Some(feed) = self.feed_rate(request, block, length) else {
            return;
        };
        let element = Element {
            kind: ElementKind::Bezier(bezier),
            start,
            end,
            feed,
            span: super::motion::element_span(block),
        };
        self.route(Motion::Feed, element);
    }

    /// What LinuxCNC refuses before it reads a spline's words: a plane other than G17,
    /// and motion in Z, A, B or C.
    fn spline_refusal(
        &self,
        code: &str,
        request: &Request,
        at: SourceSpan,
    ) -> Option<GcodeDiagnostic> {
        let feature = if self.modal.plane != Plane::XY {
            "splines outside the XY plane (LinuxCNC: G17 only)"
        } else if request.axes[2..].iter().any(Option::is_some) {
            "splines moving Z, A, B or C (LinuxCNC refuses them)"
        } else {
            return None;
        };
        Some(GcodeDiagnostic::Unsupported {
            code: code.to_string(),
            feature,
            places: 1,
            span: at,
        })
    }

    /// The two inner control points of the block's cubic from `start` to `end` (machine
    /// XY), or what the block lacks. Records a G5's P Q for the next one.
    fn spline_controls(
        &mut self,
        quadratic: bool,
        request: &Request,
        start: [f64; 2],
        end: [f64; 2],
    ) -> Result<[[f64; 2]; 2], &'static str> {
        let pair = |a: Option<Word>, b: Option<Word>| match (a, b) {
            (Some(a), Some(b)) => Ok(Some([a.value, b.value])),
            (None, None) => Ok(None),
            _ => Err(()),
        };
        let scale = self.scale();
        let vector = |v: [f64; 2]| self.rotate_xy([v[0] * scale, v[1] * scale]);
        let ij = pair(request.offsets[0], request.offsets[1]);
        if quadratic {
            let Ok(Some(ij)) = ij else {
                return Err("both I and J");
            };
            let q = vector(ij);
            let q = [start[0] + q[0], start[1] + q[1]];
            return Ok(Bezier::from_quadratic(Plane::XY, start, q, end).controls);
        }
        let Ok(ij) = ij else {
            return Err("both I and J, or neither");
        };
        let Ok(Some(pq)) = pair(request.p, request.q) else {
            return Err("both P and Q");
        };
        let pq = vector(pq);
        let first = match (ij, self.last_spline) {
            (Some(ij), _) => vector(ij),
            (None, Some(previous)) => [-previous[0], -previous[1]],
            (None, None) => {
                return Err(
                    "I and J on the first G5 of a series (later ones continue its direction)",
                )
            }
        };
        self.last_spline = Some(pq);
        Ok([
            [start[0] + first[0], start[1] + first[1]],
            [end[0] + pq[0], end[1] + pq[1]],
        ])
    }
}
