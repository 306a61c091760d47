//! A tree of boxes over a set of source elements, so the path check does not scan them all.
//!
//! Owns two queries over elements given by their axis-aligned boxes: every element whose
//! box is within a reach of a query box (the same per-axis test as a plain scan, so the
//! same set), and the least distance from a point to the elements (branch and bound: a
//! subtree is skipped only when its box is farther than the best distance found, with a
//! margin for rounding, so the same least value as a plain scan). Building is
//! `O(n log n)`; a query visits the subtrees whose boxes pass its test. It must not know
//! element geometry: the distance to an element is the caller's closure.

/// Elements per leaf.
const LEAF: usize = 8;

/// Relative margin by which a box must be farther than the best distance to be skipped:
/// the rounding of an element's computed distance against its box's, nothing more.
pub(super) const ROUNDING: f64 = 1e-9;

/// One node: its box, the range of `items` below it and, unless a leaf, its children.
struct Node {
    lo: Vec<f64>,
    hi: Vec<f64>,
    range: std::ops::Range<usize>,
    children: Option<(usize, usize)>,
}

/// The tree over a set of element indices.
pub(super) struct BoxTree {
    nodes: Vec<Node>,
    items: Vec<usize>,
}

impl BoxTree {
    /// Builds the tree over `items`, whose boxes `bounds[i]` are `(lo, hi)` per axis.
    pub fn new(mut items: Vec<usize>, bounds: &[(Vec<f64>, Vec<f64>)]) -> BoxTree {
        let mut nodes = Vec::with_capacity(2 * items.len() / LEAF + 1);
        if !items.is_empty() {
            build(&mut nodes, &mut items, 0, bounds);
        }
        BoxTree { nodes, items }
    }

    /// Appends to `out` every item whose box meets `lo..hi` widened by `reach` on every axis.
    pub fn within(
        &self,
        bounds: &[(Vec<f64>, Vec<f64>)],
        lo: &[f64],
        hi: &[f64],
        reach: f64,
        out: &mut Vec<usize>,
    ) {
        let meets = |elo: &[f64], ehi: &[f64]| {
            (0..lo.len()).all(|k| elo[k] <= hi[k] + reach && lo[k] <= ehi[k] + reach)
        };
        let mut stack: Vec<usize> = Vec::new();
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if !meets(&node.lo, &node.hi) {
                continue;
            }
            match node.children {
                Some((a, b)) => stack.extend([b, a]),
                None => out.extend(
                    self.items[node.range.clone()]
                        .iter()
                        .copied()
                        .filter(|&i| meets(&bounds[i].0, &bounds[i].1)),
                ),
            }
        }
    }

    /// The least `distance(i)` over the items, skipping subtrees whose box is farther from
    /// `point` than the best found; infinity for an empty tree.
    pub fn nearest(&self, point: &[f64], mut distance: impl FnMut(usize) -> f64) -> f64 {
        let mut best = f64::INFINITY;
        let mut stack: Vec<usize> = Vec::new();
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        let scale = 1.0 + point.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if box_distance(&node.lo, &node.hi, point) - ROUNDING * (scale + best) > best {
                continue;
            }
            match node.children {
                Some((a, b)) => {
                    // Visit the nearer child first, so the farther one is more often skipped.
                    let (da, db) = (
                        box_distance(&self.nodes[a].lo, &self.nodes[a].hi, point),
                        box_distance(&self.nodes[b].lo, &self.nodes[b].hi, point),
                    );
                    stack.extend(if da <= db { [b, a] } else { [a, b] });
                }
                None => {
                    for &i in &self.items[node.range.clone()] {
                        best = best.min(distance(i));
                    }
                }
            }
        }
        best
    }
}

/// Builds the subtree over `items` (which start at `offset` in the whole list), returning
/// its node index: split at the median of the box centres along the widest axis.
fn build(
    nodes: &mut Vec<Node>,
    items: &mut [usize],
    offset: usize,
    bounds: &[(Vec<f64>, Vec<f64>)],
) -> usize {
    let dim = bounds[items[0]].0.len();
    let (mut lo, mut hi) = (vec![f64::INFINITY; dim], vec![f64::NEG_INFINITY; dim]);
    for &i in items.iter() {
        for k in 0..dim {
            lo[k] = lo[k].min(bounds[i].0[k]);
            hi[k] = hi[k].max(bounds[i].1[k]);
        }
    }
    let at = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        range: offset..offset + items.len(),
        children: None,
    });
    if items.len() <= LEAF {
        return at;
    }
    let node = &nodes[at];
    let axis = (0..dim)
        .max_by(|&a, &b| (node.hi[a] - node.lo[a]).total_cmp(&(node.hi[b] - node.lo[b])))
        .unwrap_or(0);
    let centre = |i: usize| bounds[i].0[axis] + bounds[i].1[axis];
    let middle = items.len() / 2;
    items.select_nth_unstable_by(middle, |&a, &b| centre(a).total_cmp(&centre(b)));
    let (left, right) = items.split_at_mut(middle);
    let a = build(nodes, left, offset, bounds);
    let b = build(nodes, right, offset + middle, bounds);
    nodes[at].children = Some((a, b));
    at
}

/// Euclidean distance from `point` to the box `lo..hi` (0 inside it).
pub(super) fn box_distance(lo: &[f64], hi: &[f64], point: &[f64]) -> f64 {
    let sum: f64 = (0..point.len())
        .map(|k| {
            let gap = (lo[k] - point[k]).max(point[k] - hi[k]).max(0.0);
            gap * gap
        })
        .sum();
    sum.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boxes of unit squares on a noisy diagonal, and some far away.
    fn boxes(n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
        (0..n)
            .map(|i| {
                let x = (i * 7919 % 101) as f64 * 0.37;
                let y = (i * 104_729 % 89) as f64 * 0.41;
                (vec![x, y], vec![x + 1.0, y + 0.5])
            })
            .collect()
    }

    #[test]
    fn within_finds_what_a_scan_finds() {
        let bounds = boxes(500);
        let tree = BoxTree::new((0..500).collect(), &bounds);
        for (lo, hi, reach) in [
            ([3.0, 4.0], [5.0, 6.0], 0.0),
            ([10.0, -3.0], [10.5, 1.0], 2.5),
            ([-50.0, -50.0], [-49.0, -49.0], 1.0),
        ] {
            let mut found = Vec::new();
            tree.within(&bounds, &lo, &hi, reach, &mut found);
            found.sort_unstable();
            let scanned: Vec<usize> = (0..500)
                .filter(|&i| {
                    let (elo, ehi) = &bounds[i];
                    (0..2).all(|k| elo[k] <= hi[k] + reach && lo[k] <= ehi[k] + reach)
                })
                .collect();
            assert_eq!(found, scanned);
        }
    }

    #[test]
    fn nearest_is_the_least_of_a_scan() {
        let bounds = boxes(700);
        let tree = BoxTree::new((0..700).collect(), &bounds);
        // Each element's distance: to its box's centre, which lies in its box.
        let to_centre = |i: usize, p: &[f64]| {
            let (lo, hi) = &bounds[i];
            let c = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
            ((c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2)).sqrt()
        };
        for p in [[0.0, 0.0], [17.3, 22.1], [-40.0, 90.0], [100.0, 3.0]] {
            let scanned = (0..700)
                .map(|i| to_centre(i, &p))
                .fold(f64::INFINITY, f64::min);
            let mut calls = 0;
            let found = tree.nearest(&p, |i| {
                calls += 1;
                to_centre(i, &p)
            });
            assert_eq!(found, scanned);
            assert!(calls < 700, "{calls} distances for one point");
        }
        assert_eq!(
            BoxTree::new(Vec::new(), &bounds).nearest(&[0.0, 0.0], |_| 0.0),
            f64::INFINITY
        );
    }
}
