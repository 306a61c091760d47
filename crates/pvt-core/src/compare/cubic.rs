//! A vector cubic over a time interval and the bounds the comparison needs on it.
//!
//! Owns a cubic on up to six axes in power form in local time (`Local`: `c₀ + c₁s + c₂s² +
//! c₃s³` per axis, shifted and rescaled exactly) and in Bézier form on its interval
//! (`Bez`: four control points, de Casteljau halves). A cubic lies in the convex hull of
//! its control points, so `max |Pᵢ|` bounds its length from above and the distance from a
//! point to the control points' box bounds its distance from below; the searches here
//! halve until the bound and a value at a point agree. It must not know programs or
//! time lines: `track` builds the cubics, `aligned` and `along` ask.

use crate::axis::AXIS_COUNT;

/// A vector cubic in power form in local time `s`: `c[k] = [c₀, c₁, c₂, c₃]` of axis `k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Local {
    /// Axes in use.
    pub dim: usize,
    /// Coefficients per axis.
    pub c: [[f64; 4]; AXIS_COUNT],
}

impl Local {
    /// The zero cubic on `dim` axes.
    pub fn zero(dim: usize) -> Local {
        Local {
            dim,
            c: [[0.0; 4]; AXIS_COUNT],
        }
    }

    /// The same cubic with local time starting `u` later: `p(u + s)` in `s`.
    pub fn shifted(&self, u: f64) -> Local {
        let mut out = *self;
        for (o, &[a, b, c, d]) in out.c.iter_mut().zip(&self.c).take(self.dim) {
            *o = [
                a + u * (b + u * (c + u * d)),
                b + u * (2.0 * c + 3.0 * d * u),
                c + 3.0 * d * u,
                d,
            ];
        }
        out
    }

    /// The same cubic run at `rate` times its speed: `p(rate·s)` in `s`.
    pub fn scaled(&self, rate: f64) -> Local {
        let mut out = *self;
        for o in out.c.iter_mut().take(self.dim) {
            o[1] *= rate;
            o[2] *= rate * rate;
            o[3] *= rate * rate * rate;
        }
        out
    }

    /// `self − other`, axis by axis.
    pub fn minus(&self, other: &Local) -> Local {
        let mut out = *self;
        for (o, b) in out.c.iter_mut().zip(&other.c).take(self.dim) {
            for (x, y) in o.iter_mut().zip(b) {
                *x -= y;
            }
        }
        out
    }

    /// The point at local time `s`.
    pub fn at(&self, s: f64) -> [f64; AXIS_COUNT] {
        let mut p = [0.0; AXIS_COUNT];
        for (x, &[a, b, c, d]) in p.iter_mut().zip(&self.c).take(self.dim) {
            *x = a + s * (b + s * (c + s * d));
        }
        p
    }

    /// The Bézier form of the cubic over local times `[0, h]`.
    pub fn bez(&self, h: f64) -> Bez {
        let mut p = [[0.0; AXIS_COUNT]; 4];
        for (k, &[a, b, c, d]) in self.c.iter().enumerate().take(self.dim) {
            let (b, c, d) = (b * h, c * h * h, d * h * h * h);
            p[0][k] = a;
            p[1][k] = a + b / 3.0;
            p[2][k] = a + (2.0 * b + c) / 3.0;
            p[3][k] = a + b + c + d;
        }
        Bez { dim: self.dim, p }
    }
}

/// A vector cubic in Bézier form over a parameter interval `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Bez {
    dim: usize,
    /// Control points `p[i][k]`.
    p: [[f64; AXIS_COUNT]; 4],
}

fn length(p: &[f64; AXIS_COUNT], dim: usize) -> f64 {
    crate::vector::norm(&p[..dim])
}

fn gap(a: &[f64; AXIS_COUNT], b: &[f64; AXIS_COUNT], dim: usize) -> f64 {
    crate::vector::distance(&a[..dim], &b[..dim])
}

fn mid(a: &[f64; AXIS_COUNT], b: &[f64; AXIS_COUNT]) -> [f64; AXIS_COUNT] {
    std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
}

/// Deepest halving of a search: an interval of 2⁻⁴⁰ of the one searched.
const DEPTH: u32 = 40;

impl Bez {
    /// The two halves, by de Casteljau.
    pub fn halves(&self) -> (Bez, Bez) {
        let [p0, p1, p2, p3] = self.p;
        let (a, b, c) = (mid(&p0, &p1), mid(&p1, &p2), mid(&p2, &p3));
        let (d, e) = (mid(&a, &b), mid(&b, &c));
        let m = mid(&d, &e);
        let half = |p| Bez { dim: self.dim, p };
        (half([p0, a, d, m]), half([m, e, c, p3]))
    }

    /// The point at parameter 1/2.
    pub fn middle(&self) -> [f64; AXIS_COUNT] {
        let [p0, p1, p2, p3] = self.p;
        std::array::from_fn(|k| (p0[k] + 3.0 * (p1[k] + p2[k]) + p3[k]) / 8.0)
    }

    /// An upper bound of the cubic's length `|B(u)|` over the interval.
    pub fn upper(&self) -> f64 {
        self.p
            .iter()
            .map(|p| length(p, self.dim))
            .fold(0.0, f64::max)
    }

    /// The largest length at the ends and the middle, and the parameter where it is.
    fn lower(&self) -> (f64, f64) {
        [
            (length(&self.p[0], self.dim), 0.0),
            (length(&self.middle(), self.dim), 0.5),
            (length(&self.p[3], self.dim), 1.0),
        ]
        .into_iter()
        .fold((-1.0, 0.0), |best, x| if x.0 > best.0 { x } else { best })
    }

    /// The length of the control polygon: at least the length of the curve.
    pub fn polygon(&self) -> f64 {
        (0..3)
            .map(|i| gap(&self.p[i], &self.p[i + 1], self.dim))
            .sum()
    }

    /// A lower bound of the distance from `point` to the curve: its distance to the
    /// control points' box.
    fn box_distance(&self, point: &[f64; AXIS_COUNT]) -> f64 {
        let mut sum = 0.0;
        for (k, &x) in point.iter().enumerate().take(self.dim) {
            let lo = self.p.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
            let hi = self
                .p
                .iter()
                .map(|p| p[k])
                .fold(f64::NEG_INFINITY, f64::max);
            let d = (lo - x).max(x - hi).max(0.0);
            sum += d * d;
        }
        sum.sqrt()
    }
}

/// What a search does with a part of the curve.
enum Step {
    /// Halve it and look at both halves, the earlier first.
    Halve,
    /// Leave it.
    Skip,
    /// End the search.
    Stop,
}

/// Walks the halves of `bez` depth first, earlier parameters first: `visit` is given each
/// part, its parameter interval and its depth, and says what to do with it (a part
/// [`DEPTH`] halvings deep is not halved again).
fn walk(bez: &Bez, mut visit: impl FnMut(&Bez, (f64, f64), u32) -> Step) {
    let mut stack = vec![(*bez, 0.0, 1.0, 0)];
    while let Some((b, u0, u1, depth)) = stack.pop() {
        match visit(&b, (u0, u1), depth) {
            Step::Halve if depth < DEPTH => {
                let (l, r) = b.halves();
                let um = 0.5 * (u0 + u1);
                stack.push((r, um, u1, depth + 1));
                stack.push((l, u0, um, depth + 1));
            }
            Step::Stop => return,
            _ => {}
        }
    }
}

/// The largest length `|B(u)|` of a cubic, when it may exceed `floor`: the value (within
/// `precision`, never above the true largest) and its parameter; `None` when the cubic
/// stays within `floor`.
pub(super) fn largest(bez: &Bez, floor: f64, precision: f64) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    walk(bez, |b, (u0, u1), _| {
        let bar = best.map_or(floor, |(v, _)| v.max(floor));
        let upper = b.upper();
        if upper <= bar {
            return Step::Skip;
        }
        let (value, at) = b.lower();
        if best.is_none_or(|(v, _)| value > v) && value > floor {
            best = Some((value, u0 + at * (u1 - u0)));
        }
        if upper - value <= precision {
            Step::Skip
        } else {
            Step::Halve
        }
    });
    best
}

/// The earliest parameter at which the cubic's length exceeds `level` (to within
/// 2⁻⁴⁰ of the interval), if it does.
pub(super) fn first_above(bez: &Bez, level: f64) -> Option<f64> {
    let mut found = None;
    walk(bez, |b, (u0, u1), depth| {
        if b.upper() <= level {
            return Step::Skip;
        }
        if length(&b.p[0], b.dim) > level {
            found = Some(u0);
            return Step::Stop;
        }
        if depth >= DEPTH {
            let (value, at) = b.lower();
            if value > level {
                found = Some(u0 + at * (u1 - u0));
                return Step::Stop;
            }
        }
        Step::Halve
    });
    found
}

/// The nearest point of the curve to `point`, when nearer than `below`: its distance
/// (within `precision`) and parameter.
pub(super) fn nearest(
    bez: &Bez,
    point: &[f64; AXIS_COUNT],
    below: f64,
    precision: f64,
) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    walk(bez, |b, (u0, u1), _| {
        let bar = best.map_or(below, |(d, _)| d);
        let lower = b.box_distance(point);
        if lower >= bar {
            return Step::Skip;
        }
        let dim = b.dim;
        let (d, at) = [
            (gap(&b.p[0], point, dim), 0.0),
            (gap(&b.middle(), point, dim), 0.5),
            (gap(&b.p[3], point, dim), 1.0),
        ]
        .into_iter()
        .fold((f64::INFINITY, 0.0), |m, x| if x.0 < m.0 { x } else { m });
        if d < bar {
            best = Some((d, u0 + at * (u1 - u0)));
        }
        if d - lower <= precision {
            Step::Skip
        } else {
            Step::Halve
        }
    });
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(dim: usize, from: [f64; 2], to: [f64; 2]) -> Local {
        let mut l = Local::zero(dim);
        for k in 0..dim {
            l.c[k] = [from[k], to[k] - from[k], 0.0, 0.0];
        }
        l
    }

    #[test]
    fn shifting_and_scaling_keep_the_curve() {
        let mut l = Local::zero(2);
        l.c[0] = [1.0, -2.0, 0.5, 3.0];
        l.c[1] = [0.0, 1.0, -4.0, 0.25];
        let (u, r) = (0.37, 1.9);
        let moved = l.shifted(u).scaled(r);
        for s in [0.0, 0.1, 0.45] {
            let (a, b) = (l.at(u + r * s), moved.at(s));
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
        }
    }

    #[test]
    fn the_bezier_form_is_the_same_curve() {
        let mut l = Local::zero(1);
        l.c[0] = [1.0, -2.0, 0.5, 3.0];
        let h = 0.8;
        let b = l.bez(h);
        assert!((b.middle()[0] - l.at(0.4)[0]).abs() < 1e-12);
        assert!((b.p[3][0] - l.at(h)[0]).abs() < 1e-12);
        let (left, _) = b.halves();
        assert!((left.middle()[0] - l.at(0.2)[0]).abs() < 1e-12);
    }

    #[test]
    fn the_largest_length_is_found_inside() {
        // x(s) = s(1 − s): the largest 1/4 at s = 1/2, zero at both ends.
        let mut l = Local::zero(1);
        l.c[0] = [0.0, 1.0, -1.0, 0.0];
        let (v, u) = largest(&l.bez(1.0), 0.0, 1e-12).unwrap();
        assert!((v - 0.25).abs() < 1e-9 && (u - 0.5).abs() < 1e-3, "{v} {u}");
        assert!(largest(&l.bez(1.0), 0.3, 1e-12).is_none());
        // Above 0.2 first where s(1 − s) = 0.2: s = (1 − √0.2)/2.
        let first = first_above(&l.bez(1.0), 0.2).unwrap();
        assert!(
            (first - (1.0 - 0.2f64.sqrt()) / 2.0).abs() < 1e-9,
            "{first}"
        );
    }

    #[test]
    fn the_nearest_point_of_a_line() {
        let l = line(2, [0.0, 0.0], [10.0, 0.0]);
        let (d, u) = nearest(&l.bez(1.0), &[3.0, 2.0, 0.0, 0.0, 0.0, 0.0], 5.0, 1e-12).unwrap();
        assert!((d - 2.0).abs() < 1e-9 && (u - 0.3).abs() < 1e-6, "{d} {u}");
        assert!(nearest(&l.bez(1.0), &[3.0, 6.0, 0.0, 0.0, 0.0, 0.0], 5.0, 1e-12).is_none());
    }
}
