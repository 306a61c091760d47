//! The source geometry a program should follow: true lines and arcs, not chords.
//!
//! Owns the distance from a point (on the program's axes) to a toolpath element and the
//! lookup of a piece's source elements and feed by source line. A line's distance is
//! closed form (projection clamped to the segment). An arc's nearest point is found from
//! candidates (its two ends and every turn of the point's polar angle about the centre,
//! which is exact for a flat circle) refined by golden-section search over the arc
//! parameter within ±0.2 rad, which finds it on helices and spirals too. It must not
//! evaluate the motion.

use std::collections::BTreeMap;

use crate::axis::Axis;
use crate::toolpath::{Arc, Element, ElementKind, Toolpath};
use crate::vector::distance;

/// The toolpath's elements, indexed by source line, on the program's axes.
pub(super) struct Source<'a> {
    elements: Vec<&'a Element>,
    /// Each element's box on the program columns (an arc's: its whole circle).
    bounds: Vec<(Vec<f64>, Vec<f64>)>,
    by_line: BTreeMap<u32, Vec<usize>>,
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
        let bounds = elements
            .iter()
            .map(|e| element_bounds(e, &columns))
            .collect();
        Source {
            elements,
            bounds,
            by_line,
            columns,
        }
    }

    /// The programmed feed of the first element on `line`, if known and positive.
    pub fn feed(&self, line: u32) -> Option<f64> {
        let e = self.elements[*self.by_line.get(&line)?.first()?];
        (e.feed > 0.0).then_some(e.feed)
    }

    /// Elements a piece from `line` should follow: those on the line and their neighbours
    /// (a blend or a corner reaches into the next element); every element if none is.
    pub fn candidates(&self, line: u32) -> Vec<usize> {
        let Some(on_line) = self.by_line.get(&line) else {
            return (0..self.elements.len()).collect();
        };
        let mut out: Vec<usize> = Vec::with_capacity(on_line.len() + 2);
        for &i in on_line {
            for j in [i.wrapping_sub(1), i, i + 1] {
                if j < self.elements.len() && !out.contains(&j) {
                    out.push(j);
                }
            }
        }
        out
    }

    /// Of `candidates`, those that can hold the nearest element to any point of the box
    /// `lo..hi`: `start` is a point in the box; an element farther from the box than
    /// `start` is from its nearest candidate plus the box's diagonal cannot be nearest.
    pub fn near(&self, candidates: &[usize], start: &[f64], lo: &[f64], hi: &[f64]) -> Vec<usize> {
        let reach = self.distance(candidates, start) + distance(lo, hi);
        candidates
            .iter()
            .copied()
            .filter(|&i| {
                let (elo, ehi) = &self.bounds[i];
                (0..lo.len()).all(|k| elo[k] <= hi[k] + reach && lo[k] <= ehi[k] + reach)
            })
            .collect()
    }

    /// Distance from `point` (program columns) to the nearest of the given elements.
    pub fn distance(&self, candidates: &[usize], point: &[f64]) -> f64 {
        candidates
            .iter()
            .map(|&i| self.element_distance(self.elements[i], point))
            .fold(f64::INFINITY, f64::min)
    }

    fn element_distance(&self, e: &Element, point: &[f64]) -> f64 {
        match &e.kind {
            ElementKind::Line => self.line_distance(e, point),
            ElementKind::Arc(arc) => self.arc_distance(e, arc, point),
        }
    }

    fn line_distance(&self, e: &Element, point: &[f64]) -> f64 {
        let a: Vec<f64> = self.columns.iter().map(|&c| e.start[c]).collect();
        let b: Vec<f64> = self.columns.iter().map(|&c| e.end[c]).collect();
        let (mut num, mut den) = (0.0, 0.0);
        for k in 0..a.len() {
            num += (point[k] - a[k]) * (b[k] - a[k]);
            den += (b[k] - a[k]) * (b[k] - a[k]);
        }
        let f = if den > 0.0 {
            (num / den).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let foot: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x + (y - x) * f).collect();
        distance(&foot, point)
    }

    /// The point of an arc at parameter `f` in [0, 1], as discretization places it.
    fn arc_point(&self, e: &Element, arc: &Arc, f: f64) -> Vec<f64> {
        let sw = arc.sweep(&e.start, &e.end);
        let (first, second, _) = arc.plane.axes();
        let angle = sw.start_angle + sw.sweep * f;
        let r = sw.start_radius + (sw.end_radius - sw.start_radius) * f;
        let (s, c) = libm::sincos(angle);
        self.columns
            .iter()
            .map(|&col| match col {
                x if x == first.index() => arc.center[0] + r * c,
                x if x == second.index() => arc.center[1] + r * s,
                x => e.start[x] + (e.end[x] - e.start[x]) * f,
            })
            .collect()
    }

    fn arc_distance(&self, e: &Element, arc: &Arc, point: &[f64]) -> f64 {
        let sw = arc.sweep(&e.start, &e.end);
        let (first, second, _) = arc.plane.axes();
        let at = |f: f64| distance(&self.arc_point(e, arc, f), point);
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

/// An element's box on `columns`: its ends, and for an arc the square around its circle.
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
    (lo, hi)
}
