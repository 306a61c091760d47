//! The difference at every instant: both programs on one time axis.
//!
//! Owns the sweep over the intervals between the knots of both programs (each program's
//! piece is one cubic there, so their difference is one cubic, bounded exactly by its
//! control points and searched by halving): the largest difference and its instant, the
//! first instant it exceeds the tolerance, the time ranges where it does (which
//! `along` then reads along the path) and, when asked, the largest difference per bin of
//! a profile against time. It must not look along the path: that is `along`.

use super::cubic::{first_above, largest, Local};
use super::track::Track;
use super::Spot;

/// What the sweep finds.
pub(super) struct Aligned {
    /// The largest difference, with its instant and lines.
    pub largest: Spot,
    /// The first instant the difference exceeds the tolerance.
    pub first: Option<Spot>,
    /// The time ranges where it does, merged, in order.
    pub failing: Vec<(f64, f64)>,
    /// The largest difference in each of the profile's bins.
    pub profile: Vec<f64>,
}

/// The sweep's state between intervals.
struct Sweep {
    tolerance: f64,
    precision: f64,
    bin: f64,
    found: Aligned,
}

impl Sweep {
    /// Takes the interval `[t, t + h]` whose difference is `diff` (in local time).
    fn interval(&mut self, t: f64, h: f64, diff: &Local, lines: [u32; 2]) {
        let bez = &diff.bez(h);
        let upper = bez.upper();
        let found = &mut self.found;
        if upper > found.largest.value {
            if let Some((value, u)) = largest(bez, found.largest.value, self.precision) {
                found.largest = Spot {
                    value,
                    time: t + u * h,
                    lines,
                };
            }
        }
        if upper > self.tolerance {
            if let Some(u) = first_above(bez, self.tolerance) {
                if found.first.is_none() {
                    let value = crate::vector::norm(&diff.at(u * h)[..diff.dim]);
                    found.first = Some(Spot {
                        value,
                        time: t + u * h,
                        lines,
                    });
                }
                match found.failing.last_mut() {
                    Some(last) if last.1 >= t => last.1 = t + h,
                    _ => found.failing.push((t, t + h)),
                }
            }
        }
        if !found.profile.is_empty() && upper > 0.0 {
            let precision = self.precision.max(0.05 * upper);
            let value = largest(bez, 0.0, precision).map_or(0.0, |(v, _)| v);
            let bins = found.profile.len();
            let first = ((t / self.bin) as usize).min(bins - 1);
            let last = (((t + h) / self.bin) as usize).min(bins - 1);
            for slot in &mut found.profile[first..=last] {
                *slot = slot.max(value);
            }
        }
    }
}

/// Sweeps both programs in time: `bins` is the profile's size (0: none).
pub(super) fn sweep(a: &Track<'_>, b: &Track<'_>, tolerance: f64, bins: usize) -> Aligned {
    let end = a.total.max(b.total);
    let mut sweep = Sweep {
        tolerance,
        precision: tolerance * 1e-3,
        bin: if end > 0.0 {
            end / bins.max(1) as f64
        } else {
            1.0
        },
        found: Aligned {
            // Below any difference, so the first interval places it.
            largest: Spot {
                value: -1.0,
                ..Spot::default()
            },
            first: None,
            failing: Vec::new(),
            profile: vec![0.0; bins],
        },
    };
    let (rest_a, rest_b) = (a.final_rest(), b.final_rest());
    let last_line = |t: &Track<'_>| t.spans.last().map_or(0, |s| s.line);
    let (mut i, mut j, mut t) = (0, 0, 0.0f64);
    while i < a.spans.len() || j < b.spans.len() {
        let end_a = a.spans.get(i).map_or(f64::INFINITY, |s| s.end());
        let end_b = b.spans.get(j).map_or(f64::INFINITY, |s| s.end());
        let next = end_a.min(end_b);
        if next > t {
            let (ca, la) = match a.spans.get(i) {
                Some(s) => (a.cubic(i).shifted(t - s.start), s.line),
                None => (rest_a, last_line(a)),
            };
            let (cb, lb) = match b.spans.get(j) {
                Some(s) => (b.cubic(j).shifted(t - s.start), s.line),
                None => (rest_b, last_line(b)),
            };
            let h = next - t;
            sweep.interval(t, h, &ca.minus(&cb), [la, lb]);
            t = next;
        }
        i += usize::from(end_a <= next);
        j += usize::from(end_b <= next);
    }
    sweep.found.largest.value = sweep.found.largest.value.max(0.0);
    sweep.found
}
