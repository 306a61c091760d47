//! Along the path: where the other program passes the same place, and when.
//!
//! Owns the matching of one program (`from`) to the other's path (`to`) over the time
//! ranges where their difference at the same instant exceeds the tolerance: each knot of
//! `from` in a range is matched to the nearest point of `to` found walking forward from
//! the last match (a window of `to`'s path about as long as `from` travelled since, so
//! a path that passes one place twice matches the pass in step); between two matches
//! `from` is compared with `to` run on the straight time warp between them, bounded
//! exactly as `aligned` bounds a difference, and halved where that bound exceeds the
//! tolerance. A sample with no point of `to` within the tolerance is a difference in
//! position (its distance is reported); a matched one gives the time shift: the least
//! change of time that brings `to` within the tolerance, widened by the largest distance
//! between the paths, of `from`'s position (so a path moved a little is not also a time
//! shift where it slows to a stop). It must not compare instants: that is `aligned`.

use super::cubic::{first_above, nearest};
use super::track::Track;
use crate::axis::AXIS_COUNT;

/// A finding: its value, the instants in `from` and in `to`, and their lines.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Meet {
    /// The distance (or the time shift, seconds: `to`'s time less `from`'s).
    pub value: f64,
    /// The instant in `from` and the matching one in `to`.
    pub at: [f64; 2],
    /// The lines of `from` and `to` there.
    pub lines: [u32; 2],
}

/// What the matching finds.
#[derive(Debug, Clone, Default)]
pub(super) struct Along {
    /// The largest distance from a sample of `from` to `to`'s path.
    pub distance: Meet,
    /// Samples with no point of `to` within the tolerance.
    pub unmatched: usize,
    /// The matched samples: the instant in `from` and the nearest one in `to`.
    pub matches: Vec<(f64, f64)>,
}

/// Deepest halving between two matches.
const HALVINGS: u32 = 12;

struct Matcher<'t, 'a> {
    from: &'t Track<'a>,
    to: &'t Track<'a>,
    tolerance: f64,
    found: Along,
}

fn distance(a: &[f64; AXIS_COUNT], b: &[f64; AXIS_COUNT], dim: usize) -> f64 {
    crate::vector::distance(&a[..dim], &b[..dim])
}

impl Matcher<'_, '_> {
    /// The nearest point of `to` to `point`, walking forward from `to`'s time `after`
    /// over at least two spans and `budget` of path: its distance and time.
    fn nearest(&self, point: &[f64; AXIS_COUNT], after: f64, budget: f64) -> Option<(f64, f64)> {
        let to = self.to;
        let mut j = to.span_at(after)?;
        let (mut best, mut walked, mut seen) = (None::<(f64, f64)>, 0.0, 0);
        while j < to.spans.len() {
            let s = &to.spans[j];
            let offset = (after - s.start).max(0.0);
            let h = s.duration - offset;
            if h > 0.0 {
                let bez = to.cubic(j).shifted(offset).bez(h);
                let below = best.map_or(f64::INFINITY, |b| b.0);
                if let Some((d, u)) = nearest(&bez, point, below, self.tolerance * 1e-3) {
                    best = Some((d, s.start + offset + u * h));
                }
                walked += bez.polygon();
            }
            seen += 1;
            j += 1;
            if seen >= 2 && walked > budget {
                break;
            }
        }
        best.or_else(|| Some((distance(point, &to.position(after), to.dim()), after)))
    }

    /// Matches `from`'s instant `t`, searching `to` after `after` over `budget` of path:
    /// the matching time in `to` when within the tolerance.
    fn sample(&mut self, t: f64, after: f64, budget: f64) -> Option<f64> {
        let point = self.from.position(t);
        let (d, tau) = self.nearest(&point, after, budget)?;
        let lines = [self.from.line_to(t), self.to.line_to(tau)];
        if d > self.found.distance.value {
            self.found.distance = Meet {
                value: d,
                at: [t, tau],
                lines,
            };
        }
        if d > self.tolerance {
            self.found.unmatched += 1;
            return None;
        }
        self.found.matches.push((t, tau));
        Some(tau)
    }

    /// The path `from` travels between two instants: at least its length.
    fn travelled(&self, t0: f64, t1: f64) -> f64 {
        let from = self.from;
        let (mut sum, mut t) = (0.0, t0);
        while t < t1 {
            let end = match from.span_at(t) {
                Some(i) if from.spans[i].end() > t => from.spans[i].end().min(t1),
                _ => t1,
            };
            sum += from.running_at(t).0.bez(end - t).polygon();
            t = end;
        }
        sum
    }

    /// Whether `from` on `[t0, t1]` stays within the tolerance of `to` run on the
    /// straight warp from `tau0` to `tau1`; else an instant where it may not.
    fn warp_within(&self, (t0, tau0): (f64, f64), (t1, tau1): (f64, f64)) -> Result<(), f64> {
        let rate = (tau1 - tau0) / (t1 - t0);
        let mut ta = t0;
        while ta < t1 {
            let tau = tau0 + (ta - t0) * rate;
            // Where `to`'s span at `tau` ends, on `from`'s clock: the first span end past
            // `ta` (rounding may map the one at `tau` onto `ta` itself, and the walk would
            // then crawl by 10⁻¹² of the stretch).
            let spans = &self.to.spans;
            let to_end = match self.to.span_at(tau) {
                Some(j) if rate > 0.0 => spans[j..]
                    .iter()
                    .map(|s| t0 + (s.end() - tau0) / rate)
                    .find(|&end| end > ta)
                    .unwrap_or(t1),
                _ => t1,
            };
            let tb = to_end.min(t1).max(ta + (t1 - t0) * 1e-12);
            let a = self.from.running_at(ta).0;
            let b = self.to.running_at(tau).0.scaled(rate);
            let h = tb - ta;
            if let Some(u) = first_above(&a.minus(&b).bez(h), self.tolerance) {
                return Err(ta + u * h);
            }
            ta = tb;
        }
        Ok(())
    }

    /// Checks the stretch between two matched samples, halving where needed.
    fn between(&mut self, first: (f64, f64), second: (f64, f64), depth: u32) {
        let bad = match self.warp_within(first, second) {
            Ok(()) => return,
            Err(at) => at,
        };
        let budget = 2.0 * self.travelled(first.0, second.0) + 10.0 * self.tolerance;
        if depth >= HALVINGS {
            self.sample(bad, first.1, budget);
            return;
        }
        let t = 0.5 * (first.0 + second.0);
        if let Some(tau) = self.sample(t, first.1, budget) {
            self.between(first, (t, tau), depth + 1);
            self.between((t, tau), second, depth + 1);
        }
    }

    /// Matches every knot of `from` in `[r0, r1]`, and checks between them.
    fn range(&mut self, r0: f64, r1: f64) {
        let from = self.from;
        let back = self
            .to
            .span_at(r0)
            .map_or(0.0, |j| self.to.spans[j.saturating_sub(1)].start);
        let mut times = vec![r0];
        let first = from.span_at(r0).unwrap_or(0);
        times.extend(
            from.spans[first..]
                .iter()
                .map(|s| s.end())
                .skip_while(|&e| e <= r0)
                .take_while(|&e| e < r1),
        );
        times.push(r1);
        let mut last: Option<(f64, f64)> = None;
        let (mut after, mut since) = (back, r0);
        for (n, &t) in times.iter().enumerate() {
            let budget = 2.0 * self.travelled(since, t) + 10.0 * self.tolerance;
            match self.sample(t, after, budget) {
                Some(tau) => {
                    if let Some(prev) = last.filter(|_| n > 0) {
                        self.between(prev, (t, tau), 0);
                    }
                    last = Some((t, tau));
                    (after, since) = (tau, t);
                }
                None => last = None,
            }
        }
    }
}

/// The least change of time from `t` that brings `to` within `within` of `point`,
/// given that `to` is within it at `tau`.
fn least_shift(
    to: &Track<'_>,
    point: &[f64; AXIS_COUNT],
    (t, tau): (f64, f64),
    within: f64,
) -> f64 {
    let near = |x: f64| distance(point, &to.position(x), to.dim()) <= within;
    if near(t) {
        return 0.0;
    }
    let (mut inside, mut outside) = (tau, t);
    for _ in 0..60 {
        let m = 0.5 * (inside + outside);
        if near(m) {
            inside = m;
        } else {
            outside = m;
        }
    }
    inside - t
}

/// The largest time shift (by magnitude) at the matched samples: the least change of
/// time that brings `to` within `within` of `from`'s position.
pub(super) fn shift(from: &Track<'_>, to: &Track<'_>, matches: &[(f64, f64)], within: f64) -> Meet {
    let mut largest = Meet::default();
    for &(t, tau) in matches {
        let shift = least_shift(to, &from.position(t), (t, tau), within);
        if shift.abs() > largest.value.abs() {
            largest = Meet {
                value: shift,
                at: [t, t + shift],
                lines: [from.line_to(t), to.line_to(tau)],
            };
        }
    }
    largest
}

/// Matches `from` to `to`'s path over the time ranges given.
pub(super) fn along(
    from: &Track<'_>,
    to: &Track<'_>,
    ranges: &[(f64, f64)],
    tolerance: f64,
) -> Along {
    let mut matcher = Matcher {
        from,
        to,
        tolerance,
        found: Along::default(),
    };
    for &(r0, r1) in ranges {
        matcher.range(r0, r1);
    }
    matcher.found
}
