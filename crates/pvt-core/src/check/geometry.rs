//! The source geometry a program should follow: true lines, arcs and Béziers, not chords.
//!
//! Owns the distance from a point (on the program's axes) to a toolpath element and the
//! lookup of a piece's source elements and feed by source line. A line's distance is
//! closed form (projection clamped to the segment). An arc's nearest point is found from
//! candidates (its two ends and every turn of the point's polar angle about the centre,
//! which is exact for a flat circle) refined by golden-section search over the arc
//! parameter within ±0.2 rad, which finds it on helices and spirals too. A Bézier's
//! nearest point is found among 65 equal parameter steps, each one nearer than its
//! neighbours refined by golden-section search over the intervals beside it
//! ([`crate::bezier::Bezier::distance`]). The elements a piece may follow are found through a [`BoxTree`] per source line, so a line of many
//! elements (a 4,000-vertex polyline, a loop's body) costs a piece a walk down a tree,
//! not a scan. It must not evaluate the motion.

use std::cell::OnceCell;
use std::collections::BTreeMap;

use super::boxes::{box_distance, BoxTree, ROUNDING};

use crate::axis::Axis;
use crate::axis::AXIS_COUNT;
use crate::toolpath::{Arc, ArcSweep, Element, ElementKind, Toolpath};
use crate::vector::distance;

/// The toolpath's elements, indexed by source line, on the program's axes.
pub(super) struct Source<'a> {
    elements: Vec<&'a Element>,
    /// Each element's box on the program columns (an arc's: its whole circle).
    bounds: Vec<(Vec<f64>, Vec<f64>)>,
    by_line: BTreeMap<u32, Vec<usize>>,
    /// Per source line, the tree over the elements a piece from it should follow.
    trees: BTreeMap<u32, BoxTree>,
    /// The tree over every element, for a piece whose line has none.
    all: OnceCell<BoxTree>,
    /// Axis index (into a `Position`) of every program column.
    columns: Vec<usize>,
}

impl<'a> Source<'a> {
    /// Indexes a toolpath for a program on `axes`.
    pub fn new(toolpath: &'a Toolpath, axes: &[Axis]) -> Source<'a> {
        let elements: Vec<&Element> = toolpath.contours.iter().flat_map(|c| &c.elements).collect();
        let mut by_line: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for (i, e) in elements.iter().enumerate() {
            by_line.entry(e.span.line).or_default().push(i);
        }
        let columns: Vec<usize> = axes.iter().map(|a| a.index()).collect();
        let bounds: Vec<(Vec<f64>, Vec<f64>)> = elements
            .iter()
            .map(|e| element_bounds(e, &columns))
            .collect();
        let trees = by_line
            .iter()
            .map(|(&line, on_line)| {
                (
                    line,
                    BoxTree::new(followed(on_line, elements.len()), &bounds),
                )
            })
            .collect();
        Source {
            elements,
            bounds,
            by_line,
            trees,
            all: OnceCell::new(),
            columns,
        }
    }

    /// The programmed feed of the first element on `line`, if known and positive.
    pub fn feed(&self, line: u32) -> Option<f64> {
        let e = self.elements[*self.by_line.get(&line)?.first()?];
        (e.feed > 0.0).then_some(e.feed)
    }

    /// Of the elements a piece from `line` should follow (those on the line and their
    /// neighbours, since a blend or a corner reaches into the next element; every element
    /// if none is on it), those that can hold the nearest element to any point of the box
    /// `lo..hi`: `start` is a point in the box; an element farther from the box than
    /// `start` is from its nearest element plus the box's diagonal cannot be nearest.
    pub fn near(&self, line: u32, start: &[f64], lo: &[f64], hi: &[f64]) -> Vec<usize> {
        let tree = self.trees.get(&line).unwrap_or_else(|| {
            self.all
                .get_or_init(|| BoxTree::new((0..self.elements.len()).collect(), &self.bounds))
        });
        let nearest = tree.nearest(start, |i| self.element_distance(self.elements[i], start));
        let reach = nearest + distance(lo, hi);
        let mut out = Vec::new();
        tree.within(&self.bounds, lo, hi, reach, &mut out);
        out
    }

    /// Distance from `point` (program columns) to the nearest of the given elements. An
    /// element whose box is farther than the nearest found (with a margin for rounding)
    /// cannot be nearer, and is not measured: the least value is the same.
    pub fn distance(&self, candidates: &[usize], point: &[f64]) -> f64 {
        let scale = 1.0 + point.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        candidates.iter().fold(f64::INFINITY, |best, &i| {
            let (lo, hi) = &self.bounds[i];
            if box_distance(lo, hi, point) - ROUNDING * (scale + best) > best {
                return best;
            }
            best.min(self.element_distance(self.elements[i], point))
        })
    }

    fn element_distance(&self, e: &Element, point: &[f64]) -> f64 {
        match &e.kind {
            ElementKind::Line => self.line_distance(e, point),
            ElementKind::Arc(arc) => self.arc_distance(e, arc, point),
            ElementKind::Bezier(bezier) => bezier.distance(&e.start, &e.end, &self.columns, point),
        }
    }

    fn line_distance(&self, e: &Element, point: &[f64]) -> f64 {
        let n = self.columns.len();
        let (mut a, mut b) = ([0.0; AXIS_COUNT], [0.0; AXIS_COUNT]);
        for (k, &c) in self.columns.iter().enumerate() {
            (a[k], b[k]) = (e.start[c], e.end[c]);
        }
        let (mut num, mut den) = (0.0, 0.0);
        for k in 0..n {
            num += (point[k] - a[k]) * (b[k] - a[k]);
            den += (b[k] - a[k]) * (b[k] - a[k]);
        }
        let f = if den > 0.0 {
            (num / den).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut foot = [0.0; AXIS_COUNT];
        for k in 0..n {
            foot[k] = a[k] + (b[k] - a[k]) * f;
        }
        distance(&foot[..n], point)
    }

    /// The point of an arc of sweep `sw` at parameter `f` in [0, 1], as discretization
    /// places it, written into `out` (program columns).
    fn arc_point(&self, e: &Element, arc: &Arc, sw: &ArcSweep, f: f64, out: &mut [f64]) {
        let (first, second, _) = arc.plane.axes();
        let angle = sw.start_angle + sw.sweep * f;
        let r = sw.start_radius + (sw.end_radius - sw.start_radius) * f;
        let (s, c) = libm::sincos(angle);
        for (slot, &col) in out.iter_mut().zip(&self.columns) {
            *slot = match col {
                x if x == first.index() => arc.center[0] + r * c,
                x if x == second.index() => arc.center[1] + r * s,
                x => e.start[x] + (e.end[x] - e.start[x]) * f,
            };
        }
    }

    fn arc_distance(&self, e: &Element, arc: &Arc, point: &[f64]) -> f64 {
        let sw = arc.sweep(&e.start, &e.end);
        let (first, second, _) = arc.plane.axes();
        let mut on_arc = [0.0; AXIS_COUNT];
        let n = self.columns.len();
        let mut at = |f: f64| {
            self.arc_point(e, arc, &sw, f, &mut on_arc[..n]);
            distance(&on_arc[..n], point)
        };
        let mut starts = vec![0.0, 1.0];
        let col = |a: Axis| self.columns.iter().position(|&c| c == a.index());
        if let (Some(i), Some(j)) = (col(first), col(second)) {
            let theta = libm::atan2(point[j] - arc.center[1], point[i] - arc.center[0]);
            let tau = 2.0 * std::f64::consts::PI;
            let turns = (sw.sweep.abs() / tau).ceil() as i64 + 1;
            for m in -turns..=turns {
                let f = (theta + tau * m as f64 - sw.start_angle) / sw.sweep;
                if (0.0..=1.0).contains(&f) {
                    starts.push(f);
                }
            }
        }
        let best = starts
            .into_iter()
            .map(|f| (at(f), f))
            .fold((f64::INFINITY, 0.0), |m, x| if x.0 < m.0 { x } else { m });
        let reach = 0.2 / sw.sweep.abs();
        let (lo, hi) = ((best.1 - reach).max(0.0), (best.1 + reach).min(1.0));
        let f = golden(lo, hi, |f| -at(f));
        at(f).min(best.0)
    }
}

/// The argument in `[lo, hi]` that maximizes a unimodal `g`, by golden-section search.
pub(super) fn golden(mut lo: f64, mut hi: f64, mut g: impl FnMut(f64) -> f64) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..60 {
        if g1 < g2 {
            lo = x1;
            x1 = x2;
            g1 = g2;
            x2 = lo + r * (hi - lo);
            g2 = g(x2);
        } else {
            hi = x2;
            x2 = x1;
            g2 = g1;
            x1 = hi - r * (hi - lo);
            g1 = g(x1);
        }
    }
    if g1 > g2 {
        x1
    } else {
        x2
    }
}

/// The elements a piece from a line of elements `on_line` should follow: each of them and
/// its neighbours, once each.
fn followed(on_line: &[usize], count: usize) -> Vec<usize> {
    let mut out: Vec<usize> = on_line
        .iter()
        .flat_map(|&i| [i.wrapping_sub(1), i, i + 1])
        .filter(|&j| j < count)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// An element's box on `columns`: its ends, for an arc the square around its circle, for
/// a Bézier its control points.
fn element_bounds(e: &Element, columns: &[usize]) -> (Vec<f64>, Vec<f64>) {
    let mut lo: Vec<f64> = columns.iter().map(|&c| e.start[c].min(e.end[c])).collect();
    let mut hi: Vec<f64> = columns.iter().map(|&c| e.start[c].max(e.end[c])).collect();
    if let ElementKind::Arc(arc) = &e.kind {
        let sw = arc.sweep(&e.start, &e.end);
        let r = sw.start_radius.max(sw.end_radius);
        let (first, second, _) = arc.plane.axes();
        for (axis, centre) in [(first, arc.center[0]), (second, arc.center[1])] {
            if let Some(k) = columns.iter().position(|&c| c == axis.index()) {
                lo[k] = lo[k].min(centre - r);
                hi[k] = hi[k].max(centre + r);
            }
        }
    }
    if let ElementKind::Bezier(bezier) = &e.kind {
        // The curve lies in the convex hull of its control points.
        let (first, second, _) = bezier.plane.axes();
        for (j, axis) in [first, second].into_iter().enumerate() {
            if let Some(k) = columns.iter().position(|&c| c == axis.index()) {
                for p in bezier.controls {
                    lo[k] = lo[k].min(p[j]);
                    hi[k] = hi[k].max(p[j]);
                }
            }
        }
    }
    (lo, hi)
}
