//! Chaining and ordering: entity pieces joined into contours, contours into a toolpath.
//!
//! Owns the rules that make the output independent of how the drawing was drawn: pieces
//! whose end points meet within the join tolerance are joined (reversed where needed),
//! chains that come back to their start are closed, and contours are visited
//! nearest-neighbour from the start point with rapids between them. It must not read DXF
//! records or evaluate curves.
//!
//! # Chaining
//! Pieces are taken in drawing order (model space order, block contents expanded in place).
//! Each unused piece starts a chain; the chain is extended at its end, then at its start,
//! each time with the unused piece having an end point nearest to the chain's free end
//! (3D distance, at most the join tolerance; ties go to the earlier piece, then to its
//! start point). A chain whose end comes within the join tolerance of its start is closed
//! and stops growing. Joined end points are snapped: each element starts exactly where the
//! previous one ended, and a closed chain ends exactly at its start.
//!
//! # Ordering
//! From the current position (first the start point), the next contour is the one with
//! the entry point nearest in XY: an open chain may be entered at either end (and is then
//! reversed), a closed chain at the start of any of its pieces (and is then rotated). Ties
//! go to the earlier chain, then to the earlier entry point (forward before reversed).
//!
//! # Rapids and safe Z
//! Without a safe Z, one rapid line goes from the current position to the next contour's
//! entry point (none when they coincide). With a safe Z `s`, the machine starts at
//! (start point, `s`); before each contour a rapid at Z = `s` moves over its entry point, a
//! feed contour of one line plunges from `s` to the entry point's Z, the contour is cut,
//! and a rapid retracts straight up to `s`. Zero-length moves are left out. Each generated
//! move carries the source span of the entity it travels to (the first element of the
//! next contour); a retract carries the span of the entity it leaves.

use pvt_core::{
    Arc, ArcDirection, Bezier, Contour, Element, ElementKind, Motion, Plane, Position, Span,
};
use std::collections::HashMap;

use crate::geom::{dist, P3};

/// What a piece of geometry is: a line, a circular arc in a plane parallel to XY, or a
/// cubic Bézier in a plane parallel to XY (Z moving linearly with its parameter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegKind {
    /// Straight line.
    Line,
    /// Circular arc about `center` (X, Y) sweeping `sweep` radians (signed, + = CCW).
    Arc {
        /// Centre in X, Y.
        center: [f64; 2],
        /// Signed sweep, radians, positive counter-clockwise seen from +Z.
        sweep: f64,
    },
    /// Cubic Bézier from `a` to `b` with these inner control points (X, Y).
    Bezier {
        /// `P₁` and `P₂`.
        controls: [[f64; 2]; 2],
    },
}

/// One line, arc or Bézier from `a` to `b`, with the DXF span it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seg {
    /// Line, arc or Bézier.
    pub kind: SegKind,
    /// Start point.
    pub a: P3,
    /// End point.
    pub b: P3,
    /// Source of the segment.
    pub span: Span,
}

impl Seg {
    /// The same geometry traversed the other way (an arc flips direction).
    pub fn reversed(&self) -> Seg {
        let kind = match self.kind {
            SegKind::Line => SegKind::Line,
            SegKind::Arc { center, sweep } => SegKind::Arc {
                center,
                sweep: -sweep,
            },
            SegKind::Bezier { controls } => SegKind::Bezier {
                controls: [controls[1], controls[0]],
            },
        };
        Seg {
            kind,
            a: self.b,
            b: self.a,
            span: self.span,
        }
    }
}

/// The segments of one entity (or one closed or open part of one), in order.
pub type Piece = Vec<Seg>;

/// Reverses a whole piece.
fn reverse(piece: &[Seg]) -> Piece {
    piece.iter().rev().map(Seg::reversed).collect()
}

/// A chain of segments cut without stopping.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Segments in cutting order (before snapping).
    pub segs: Vec<Seg>,
    /// Indices into `segs` where each joined piece starts.
    pub piece_starts: Vec<usize>,
    /// The chain comes back to its start.
    pub closed: bool,
}

impl Chain {
    fn start(&self) -> P3 {
        self.segs[0].a
    }

    fn end(&self) -> P3 {
        self.segs[self.segs.len() - 1].b
    }
}

struct Grid {
    cell: f64,
    map: HashMap<(i64, i64), Vec<(usize, usize)>>,
}

impl Grid {
    fn key(&self, p: P3) -> (i64, i64) {
        (
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
        )
    }

    fn near(&self, p: P3) -> Vec<(usize, usize)> {
        let (kx, ky) = self.key(p);
        let mut out = Vec::new();
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                if let Some(v) = self
                    .map
                    .get(&(kx.saturating_add(dx), ky.saturating_add(dy)))
                {
                    out.extend_from_slice(v);
                }
            }
        }
        out
    }
}

/// Joins pieces into chains (see the module docs); empty pieces are dropped.
pub fn chain_pieces(pieces: &[Piece], join: f64) -> Vec<Chain> {
    let pieces: Vec<&Piece> = pieces.iter().filter(|p| !p.is_empty()).collect();
    let ends = |i: usize| [pieces[i][0].a, pieces[i][pieces[i].len() - 1].b];
    let mut grid = Grid {
        cell: if join > 0.0 { join } else { 1.0 },
        map: HashMap::new(),
    };
    for i in 0..pieces.len() {
        for (e, p) in ends(i).into_iter().enumerate() {
            let key = grid.key(p);
            grid.map.entry(key).or_default().push((i, e));
        }
    }
    let mut used = vec![false; pieces.len()];
    // The unused piece end nearest to `p` within the join tolerance.
    let best = |used: &[bool], p: P3| -> Option<(usize, usize)> {
        let mut found: Option<(f64, usize, usize)> = None;
        for (i, e) in grid.near(p) {
            if used[i] {
                continue;
            }
            let d = dist(ends(i)[e], p);
            if d <= join {
                let better = match found {
                    None => true,
                    Some((bd, bi, be)) => d < bd || (d == bd && (i, e) < (bi, be)),
                };
                if better {
                    found = Some((d, i, e));
                }
            }
        }
        found.map(|(_, i, e)| (i, e))
    };
    let mut chains = Vec::new();
    for first in 0..pieces.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let mut parts: std::collections::VecDeque<Piece> = std::collections::VecDeque::new();
        parts.push_back(pieces[first].clone());
        let chain_start = |parts: &std::collections::VecDeque<Piece>| parts[0][0].a;
        let chain_end = |parts: &std::collections::VecDeque<Piece>| {
            let last = &parts[parts.len() - 1];
            last[last.len() - 1].b
        };
        let mut closed = dist(chain_start(&parts), chain_end(&parts)) <= join;
        while !closed {
            let Some((i, e)) = best(&used, chain_end(&parts)) else {
                break;
            };
            used[i] = true;
            parts.push_back(if e == 0 {
                pieces[i].clone()
            } else {
                reverse(pieces[i])
            });
            closed = dist(chain_start(&parts), chain_end(&parts)) <= join;
        }
        while !closed {
            let Some((i, e)) = best(&used, chain_start(&parts)) else {
                break;
            };
            used[i] = true;
            parts.push_front(if e == 1 {
                pieces[i].clone()
            } else {
                reverse(pieces[i])
            });
            closed = dist(chain_start(&parts), chain_end(&parts)) <= join;
        }
        let mut segs = Vec::new();
        let mut piece_starts = Vec::new();
        for part in parts {
            piece_starts.push(segs.len());
            segs.extend(part);
        }
        chains.push(Chain {
            segs,
            piece_starts,
            closed,
        });
    }
    chains
}

/// Orders chains nearest-neighbour from `start` (XY), reversing or rotating each as entered.
pub fn order_chains(chains: Vec<Chain>, start: [f64; 2]) -> Vec<Chain> {
    let mut left: Vec<Option<Chain>> = chains.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(left.len());
    let mut here = start;
    let xy = |p: P3, h: [f64; 2]| libm::hypot(p[0] - h[0], p[1] - h[1]);
    loop {
        // (distance, chain, entry): entry 0..n = rotate closed chain to piece k; for open
        // chains 0 = forward, 1 = reversed.
        let mut best: Option<(f64, usize, usize)> = None;
        for (ci, chain) in left.iter().enumerate() {
            let Some(chain) = chain else { continue };
            let entries: Vec<P3> = if chain.closed {
                chain
                    .piece_starts
                    .iter()
                    .map(|&k| chain.segs[k].a)
                    .collect()
            } else {
                vec![chain.start(), chain.end()]
            };
            for (k, p) in entries.into_iter().enumerate() {
                let d = xy(p, here);
                if best.is_none_or_greater(d) {
                    best = Some((d, ci, k));
                }
            }
        }
        let Some((_, ci, k)) = best else { break };
        let Some(mut chain) = left[ci].take() else {
            break;
        };
        if chain.closed {
            let at = chain.piece_starts[k];
            chain.segs.rotate_left(at);
            chain.piece_starts = chain
                .piece_starts
                .iter()
                .map(|&s| (s + chain.segs.len() - at) % chain.segs.len())
                .collect();
            chain.piece_starts.sort_unstable();
        } else if k == 1 {
            chain.segs = reverse(&chain.segs);
            let n = chain.segs.len();
            let mut starts: Vec<usize> = chain.piece_starts.iter().map(|&s| n - s).collect();
            starts.retain(|&s| s < n);
            starts.push(0);
            starts.sort_unstable();
            chain.piece_starts = starts;
        }
        let end = chain.end();
        here = [end[0], end[1]];
        out.push(chain);
    }
    out
}

trait BestSoFar {
    fn is_none_or_greater(&self, d: f64) -> bool;
}

impl BestSoFar for Option<(f64, usize, usize)> {
    fn is_none_or_greater(&self, d: f64) -> bool {
        match self {
            None => true,
            Some((bd, _, _)) => d < *bd,
        }
    }
}

/// A position from a point: X, Y, Z, rotaries at 0.
pub fn position(p: P3) -> Position {
    [p[0], p[1], p[2], 0.0, 0.0, 0.0]
}

/// The elements of a chain, snapped so that each starts where the previous one ended.
pub fn chain_elements(chain: &Chain, feed: f64) -> Vec<Element> {
    let mut out: Vec<Element> = Vec::with_capacity(chain.segs.len());
    let first = chain.start();
    let n = chain.segs.len();
    let mut at = first;
    for (i, seg) in chain.segs.iter().enumerate() {
        let end = if chain.closed && i + 1 == n {
            first
        } else {
            seg.b
        };
        let a = at;
        if a == end
            && !matches!(seg.kind, SegKind::Arc { .. } | SegKind::Bezier { .. } if seg.a == seg.b)
        {
            continue; // zero length after snapping
        }
        let kind = match seg.kind {
            SegKind::Line => ElementKind::Line,
            SegKind::Arc { center, sweep } => arc_kind(center, sweep, a, end),
            SegKind::Bezier { controls } => ElementKind::Bezier(Bezier {
                plane: Plane::XY,
                controls,
                fit: 0.0,
            }),
        };
        out.push(Element {
            kind,
            start: position(a),
            end: position(end),
            feed,
            span: seg.span,
        });
        at = end;
    }
    out
}

/// An arc element, or a line where snapping made the arc's sweep unrecognisable.
fn arc_kind(center: [f64; 2], sweep: f64, a: P3, b: P3) -> ElementKind {
    let direction = if sweep > 0.0 {
        ArcDirection::CounterClockwise
    } else {
        ArcDirection::Clockwise
    };
    let arc = Arc {
        plane: Plane::XY,
        center,
        direction,
        extra_turns: 0,
    };
    let snapped = arc.sweep(&position(a), &position(b)).sweep;
    if (snapped - sweep).abs() > 0.5 {
        return ElementKind::Line;
    }
    ElementKind::Arc(arc)
}

/// Builds the contours of the ordered chains with rapids between them.
pub fn build_contours(
    chains: &[Chain],
    start: [f64; 2],
    safe_z: Option<f64>,
    feed: f64,
    rapid: f64,
) -> Vec<Contour> {
    let mut contours = Vec::new();
    let mut here: P3 = [start[0], start[1], safe_z.unwrap_or(0.0)];
    let line = |a: P3, b: P3, feed: f64, span: Span| Element {
        kind: ElementKind::Line,
        start: position(a),
        end: position(b),
        feed,
        span,
    };
    let push_move = |contours: &mut Vec<Contour>, motion, a: P3, b: P3, span| {
        if a != b {
            let f = if motion == Motion::Rapid { rapid } else { feed };
            contours.push(Contour {
                motion,
                elements: vec![line(a, b, f, span)],
            });
        }
    };
    for chain in chains {
        let elements = chain_elements(chain, feed);
        let (Some(first), Some(last)) = (elements.first(), elements.last()) else {
            continue;
        };
        let entry = [first.start[0], first.start[1], first.start[2]];
        let exit = [last.end[0], last.end[1], last.end[2]];
        match safe_z {
            None => push_move(&mut contours, Motion::Rapid, here, entry, first.span),
            Some(s) => {
                let over = [entry[0], entry[1], s];
                push_move(&mut contours, Motion::Rapid, here, over, first.span);
                push_move(&mut contours, Motion::Feed, over, entry, first.span);
            }
        }
        let last_span = last.span;
        contours.push(Contour {
            motion: Motion::Feed,
            elements,
        });
        here = exit;
        if let Some(s) = safe_z {
            let up = [exit[0], exit[1], s];
            push_move(&mut contours, Motion::Rapid, exit, up, last_span);
            here = up;
        }
    }
    contours
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(a: [f64; 2], b: [f64; 2]) -> Piece {
        vec![Seg {
            kind: SegKind::Line,
            a: [a[0], a[1], 0.0],
            b: [b[0], b[1], 0.0],
            span: Span::default(),
        }]
    }

    #[test]
    fn square_drawn_in_any_order_and_direction_closes() {
        let pieces = vec![
            line([1.0, 1.0], [1.0, 0.0]),
            line([0.0, 0.0], [1.0, 0.0]),
            line([0.0, 1.0], [0.0, 0.0]),
            line([0.0, 1.0], [1.0, 1.0 + 1e-6]),
        ];
        let chains = chain_pieces(&pieces, 1e-3);
        assert_eq!(chains.len(), 1);
        assert!(chains[0].closed);
        let els = chain_elements(&chains[0], 1.0);
        assert_eq!(els.len(), 4);
        for w in els.windows(2) {
            assert_eq!(w[0].end, w[1].start);
        }
        assert_eq!(els[3].end, els[0].start);
    }

    #[test]
    fn reversed_arc_keeps_its_geometry() {
        let seg = Seg {
            kind: SegKind::Arc {
                center: [0.0, 0.0],
                sweep: 1.0,
            },
            a: [1.0, 0.0, 0.0],
            b: [libm::cos(1.0), libm::sin(1.0), 0.0],
            span: Span::default(),
        };
        let r = seg.reversed();
        assert_eq!(
            r.kind,
            SegKind::Arc {
                center: [0.0, 0.0],
                sweep: -1.0
            }
        );
        match arc_kind([0.0, 0.0], -1.0, r.a, r.b) {
            ElementKind::Arc(a) => assert_eq!(a.direction, ArcDirection::Clockwise),
            other => panic!("arc lost: {other:?}"),
        }
    }

    #[test]
    fn nearest_neighbour_order_reverses_open_chains_and_breaks_ties_by_index() {
        let pieces = vec![
            line([10.0, 0.0], [5.0, 0.0]),
            line([-3.0, 0.0], [-4.0, 0.0]),
            line([3.0, 0.0], [4.0, 0.0]),
        ];
        let chains = order_chains(chain_pieces(&pieces, 1e-6), [0.0, 0.0]);
        // -3 and 3 are equally near: the earlier chain (index 1) wins.
        assert_eq!(chains[0].segs[0].a, [-3.0, 0.0, 0.0]);
        assert_eq!(chains[1].segs[0].a, [3.0, 0.0, 0.0]);
        // The first line is entered at its end (5), nearer to 4.
        assert_eq!(chains[2].segs[0].a, [5.0, 0.0, 0.0]);
        let contours = build_contours(&chains, [0.0, 0.0], Some(5.0), 10.0, 100.0);
        let motions: Vec<Motion> = contours.iter().map(|c| c.motion).collect();
        use Motion::{Feed as F, Rapid as R};
        assert_eq!(motions, [R, F, F, R, R, F, F, R, R, F, F, R]);
        assert_eq!(
            contours[0].elements[0].start,
            [0.0, 0.0, 5.0, 0.0, 0.0, 0.0]
        );
    }
}
