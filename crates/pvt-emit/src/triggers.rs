//! Trigger events along the motion (`--trigger-every`): every N program units of path,
//! or every T seconds of motion.
//!
//! Owns where the triggers fall ([`TriggerClock`]) and the cut of a piece at them, along
//! the piece's own cubic (the same motion, [`TriggerClock::cut`]). The clock runs over
//! the written pieces, contour after contour (a dwell and the rest between contours
//! add neither time nor path); the path is the length of the linear axes' motion
//! (X, Y, Z; the rotary axes are left out), measured along the cubics by Gauss–Legendre
//! quadrature. The k-th trigger (k ≥ 1) falls where the motion time reaches k·T or the
//! path k·N. On a time grid (`--quantize`, [`Triggers::grid`]) its instant is rounded to
//! the nearest grid time inside the piece, so both parts of a cut piece keep whole quanta
//! (a distance trigger then lies within speed × grid / 2 of k·N; a time trigger whose T
//! is whole quanta falls exactly); without one, a trigger closer to a knot or to the
//! trigger before it than the format's shortest piece (at least [`SHORTEST_PART`])
//! moves onto it. Triggers that land on the same instant are one trigger.
//!
//! Each back end writes a trigger its controller's way ([`crate::ProgramWriter::trigger`]);
//! a format whose controller has no place for one in the program says why
//! ([`crate::Caps::triggers`]). It must not plan or change a piece's motion.

use pvt_core::{Axis, HermiteSegment};

/// How often a trigger fires.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TriggerEvery {
    /// Every this many seconds of motion.
    Seconds(f64),
    /// Every this much path of the linear axes, program units.
    Distance(f64),
}

/// The trigger option as a back end receives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triggers {
    /// How often.
    pub every: TriggerEvery,
    /// The time grid the pieces are on (`--quantize`), seconds.
    pub grid: Option<f64>,
}

/// Whether a format's controller takes triggers inside the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TriggerSupport {
    /// The back end writes each trigger into the program.
    Written,
    /// None: why, and what the controller offers instead.
    None(&'static str),
}

/// Off a time grid, the shortest part a cut leaves, seconds.
pub const SHORTEST_PART: f64 = 1e-7;

/// Gauss–Legendre nodes and weights on [-1, 1], five points.
const GAUSS: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Sub-intervals of a piece for the path length.
const PANELS: usize = 16;

/// Where the triggers fall, fed one piece at a time.
#[derive(Debug, Clone)]
pub struct TriggerClock {
    triggers: Triggers,
    linear: Vec<bool>,
    /// Off a grid, the shortest part a cut may leave, seconds.
    shortest: f64,
    /// Motion time and path so far.
    time: f64,
    path: f64,
    /// Triggers fired so far.
    fired: u64,
}

/// A piece cut at its triggers: the parts, each with whether a trigger fires at its
/// end; `at_start` is a trigger at the piece's first knot.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cut {
    /// A trigger at the start of the piece.
    pub at_start: bool,
    /// The parts in order: (duration, end positions, end velocities, trigger at end).
    pub parts: Vec<(f64, Vec<f64>, Vec<f64>, bool)>,
}

impl TriggerClock {
    /// A clock for a program on `axes`, written in a format whose shortest piece is
    /// `shortest` seconds.
    pub fn new(triggers: Triggers, axes: &[Axis], shortest: f64) -> TriggerClock {
        TriggerClock {
            triggers,
            linear: axes.iter().map(|a| !a.is_rotary()).collect(),
            shortest: shortest.max(SHORTEST_PART),
            time: 0.0,
            path: 0.0,
            fired: 0,
        }
    }

    /// Triggers fired so far.
    pub fn fired(&self) -> u64 {
        self.fired
    }

    /// The piece from `start` (positions, velocities) to `end` (positions, velocities)
    /// in `duration` seconds, cut at the triggers inside it.
    pub fn cut(&mut self, start: (&[f64], &[f64]), end: (&[f64], &[f64]), duration: f64) -> Cut {
        let cubics: Vec<HermiteSegment> = (0..end.0.len())
            .map(|i| HermiteSegment::new(start.0[i], start.1[i], end.0[i], end.1[i], duration))
            .collect();
        let instants = self.instants(&cubics, duration);
        let mut cut = Cut::default();
        let mut from = 0.0;
        let mut last_trigger = false;
        for t in instants {
            if t <= 0.0 {
                cut.at_start = true;
            } else if t >= duration {
                last_trigger = true;
            } else {
                let p = cubics.iter().map(|c| c.at(t).position).collect();
                let v = cubics.iter().map(|c| c.at(t).velocity).collect();
                cut.parts.push((t - from, p, v, true));
                from = t;
            }
        }
        let (p, v) = (end.0.to_vec(), end.1.to_vec());
        cut.parts.push((duration - from, p, v, last_trigger));
        cut
    }

    /// The instants of the triggers in the piece, from its start, on the grid, in order
    /// and each once; the clock moves past the piece.
    fn instants(&mut self, cubics: &[HermiteSegment], duration: f64) -> Vec<f64> {
        let mut local = Vec::new();
        match self.triggers.every {
            TriggerEvery::Seconds(every) => loop {
                let target = (self.fired + 1) as f64 * every - self.time;
                if target > duration * (1.0 + 1e-12) {
                    break;
                }
                local.push(target.max(0.0));
                self.fired += 1;
            },
            TriggerEvery::Distance(every) => {
                let total = self.length(cubics, duration);
                loop {
                    let target = (self.fired + 1) as f64 * every - self.path;
                    if target > total * (1.0 + 1e-12) {
                        break;
                    }
                    local.push(self.time_at_length(cubics, duration, target.max(0.0)));
                    self.fired += 1;
                }
                self.path += total;
            }
        }
        self.time += duration;
        let mut snapped: Vec<f64> = Vec::new();
        for t in local.into_iter().map(|t| self.snap(t, duration)) {
            // Off a grid, a trigger too close to the one before is that one.
            let close = |last: &f64| t - last < self.shortest && t < duration;
            if !snapped
                .last()
                .is_some_and(|l| *l == t || (self.triggers.grid.is_none() && close(l)))
            {
                snapped.push(t);
            }
        }
        snapped
    }

    /// `t` on the grid (or onto a knot closer than [`SHORTEST_PART`]), within the piece.
    fn snap(&self, t: f64, duration: f64) -> f64 {
        match self.triggers.grid {
            Some(q) => {
                let whole = libm::round(duration / q);
                let n = libm::round(t / q).clamp(0.0, whole);
                if n == whole {
                    duration
                } else {
                    n * q
                }
            }
            None if t < self.shortest => 0.0,
            None if duration - t < self.shortest => duration,
            None => t,
        }
    }

    /// Speed of the linear axes at `t`.
    fn speed(&self, cubics: &[HermiteSegment], t: f64) -> f64 {
        let sum: f64 = cubics
            .iter()
            .zip(&self.linear)
            .filter(|(_, linear)| **linear)
            .map(|(c, _)| c.at(t).velocity.powi(2))
            .sum();
        sum.sqrt()
    }

    /// Path of the linear axes from 0 to `t`.
    fn length(&self, cubics: &[HermiteSegment], t: f64) -> f64 {
        let h = t / PANELS as f64;
        (0..PANELS)
            .map(|k| {
                let mid = (k as f64 + 0.5) * h;
                GAUSS
                    .iter()
                    .map(|(x, w)| w * self.speed(cubics, mid + x * h / 2.0))
                    .sum::<f64>()
                    * h
                    / 2.0
            })
            .sum()
    }

    /// The time at which the path from the piece's start reaches `target` (bisection:
    /// the path grows with time).
    fn time_at_length(&self, cubics: &[HermiteSegment], duration: f64, target: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, duration);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.length(cubics, mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_at_constant_speed_triggers_every_n() {
        let triggers = Triggers {
            every: TriggerEvery::Distance(1.0),
            grid: None,
        };
        let mut clock = TriggerClock::new(triggers, &[Axis::X], 0.0);
        // 10 units in 1 s at 10 units/s.
        let cut = clock.cut((&[0.0], &[10.0]), (&[10.0], &[10.0]), 1.0);
        let ends: Vec<f64> = cut.parts.iter().map(|p| p.1[0]).collect();
        assert_eq!(cut.parts.len(), 10, "{ends:?}");
        for (k, p) in ends.iter().enumerate() {
            assert!((p - (k + 1) as f64).abs() < 1e-9, "{ends:?}");
        }
        assert!(cut.parts.iter().all(|p| p.3));
    }
}
