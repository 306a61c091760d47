//! The motion as a servo loop sees it: positions sampled every servo period.
//!
//! Owns the sampled velocity and acceleration (first and second differences of the
//! sampled positions, `(x(k) − x(k−1))/P` and `(x(k+1) − 2x(k) + x(k−1))/P²`, each at the
//! time of sample `k`; the axes are at rest before the start and after the end, so the
//! steps into and out of motion are seen) and the vector speed against the programmed
//! feed at the same instants. Both walk the program once, in time order ([`Walk`]): the
//! memory they use does not grow with the number of samples. It must not use closed
//! forms: that is [`super::peaks`].

use super::geometry::Source;
use super::timeline::{Timeline, Walk};
use super::{Peak, SpeedReport};
use crate::toolpath::Motion;
use crate::vector::norm;

/// Per axis, the largest sampled |velocity| and |acceleration|.
pub(super) fn sampled_peaks(tl: &Timeline<'_>, period: f64) -> (Vec<Peak>, Vec<Peak>) {
    let dim = tl.program.axes.len();
    let mut vel = vec![Peak::default(); dim];
    let mut acc = vec![Peak::default(); dim];
    if tl.pieces.is_empty() {
        return (vel, acc);
    }
    let last = (tl.total / period).ceil() as i64 + 1;
    // Two walks: one reads the positions a period ahead, one finds the line running now.
    let (mut ahead, mut now) = (Walk::new(tl), Walk::new(tl));
    let (mut before, mut here, mut next) = (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
    ahead.positions_at(-period, &mut before);
    ahead.positions_at(0.0, &mut here);
    for k in 0..=last {
        let t = k as f64 * period;
        ahead.positions_at(t + period, &mut next);
        let line = now.seek(t).map_or(0, |i| tl.pieces[i].line);
        for a in 0..dim {
            let v = ((here[a] - before[a]) / period).abs();
            if v > vel[a].value {
                vel[a] = Peak {
                    value: v,
                    time: t,
                    line,
                };
            }
            let second = ((next[a] - 2.0 * here[a] + before[a]) / (period * period)).abs();
            if second > acc[a].value {
                acc[a] = Peak {
                    value: second,
                    time: t,
                    line,
                };
            }
        }
        std::mem::swap(&mut before, &mut here);
        std::mem::swap(&mut here, &mut next);
    }
    (vel, acc)
}

/// Vector speed against the programmed feed at every servo sample of feed motion.
///
/// Only pieces of feed contours whose source line has a known feed count; the speed is the
/// exact (closed-form) vector speed at the sample. `None` when no sample qualifies.
pub(super) fn speed_against_feed(
    tl: &Timeline<'_>,
    source: &Source<'_>,
    period: f64,
) -> Option<SpeedReport> {
    let dim = tl.program.axes.len();
    let mut v = vec![0.0; dim];
    let (mut min, mut max) = (
        Peak {
            value: f64::INFINITY,
            ..Peak::default()
        },
        Peak::default(),
    );
    let (mut sum_sq, mut count) = (0.0, 0usize);
    let last = (tl.total / period).floor() as usize;
    let mut walk = Walk::new(tl);
    for k in 0..=last {
        let t = k as f64 * period;
        let Some(i) = walk.seek(t) else { break };
        let p = &tl.pieces[i];
        let Some(feed) = source.feed(p.line).filter(|_| p.motion == Motion::Feed) else {
            continue;
        };
        walk.velocities(i, (t - p.start).min(p.duration), &mut v);
        let speed = norm(&v);
        if speed < min.value {
            min = Peak {
                value: speed,
                time: t,
                line: p.line,
            };
        }
        if speed > max.value {
            max = Peak {
                value: speed,
                time: t,
                line: p.line,
            };
        }
        sum_sq += (speed - feed) * (speed - feed);
        count += 1;
    }
    (count > 0).then(|| SpeedReport {
        min,
        max,
        rms_error: (sum_sq / count as f64).sqrt(),
        samples: count,
    })
}
