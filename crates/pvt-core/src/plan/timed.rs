//! Point-time series: points with given segment times, and how a polyline becomes them.
//!
//! Owns [`TimedPoints`], its validation, and the cutting of a [`Polyline`] into runs of
//! timed points (repeated points dropped, times from the feed or a time slice, a run
//! ending at every exact stop). It must not choose velocities: the planners do.

use super::{PlanError, Timing};
use crate::polyline::Polyline;
use crate::program::PvtContour;
use crate::toolpath::Motion;
use crate::vector::{distance, max_abs};

/// Relative size below which a chord counts as a repeated point (as the contour planner).
const REPEAT_TOLERANCE: f64 = 1e-12;

/// Points of `dim` axes with the time of every segment and, optionally, given velocities.
///
/// Segment `i` runs from point `i` to point `i + 1` in `durations[i]` seconds. The first
/// point is where the motion starts, at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPoints {
    /// Number of axes per point.
    pub dim: usize,
    /// Point `i` is `coords[i * dim..(i + 1) * dim]`.
    pub coords: Vec<f64>,
    /// Time of each segment, seconds.
    pub durations: Vec<f64>,
    /// Velocity at every point (flat like `coords`), used as given by the PVT velocity methods.
    pub velocities: Option<Vec<f64>>,
    /// Source line of each segment (of the point it reaches).
    pub lines: Vec<u32>,
}

impl TimedPoints {
    /// A series holding only its start point.
    pub fn start_at(start: &[f64]) -> TimedPoints {
        TimedPoints {
            dim: start.len(),
            coords: start.to_vec(),
            durations: Vec::new(),
            velocities: None,
            lines: Vec::new(),
        }
    }

    /// Appends a point reached after `duration` seconds by a segment from source `line`.
    pub fn push(&mut self, point: &[f64], duration: f64, line: u32) {
        self.coords.extend_from_slice(point);
        self.durations.push(duration);
        self.lines.push(line);
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.coords.len().checked_div(self.dim).unwrap_or(0)
    }

    /// True when the series holds no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `i`.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dim..(i + 1) * self.dim]
    }

    /// Source line of the point `i` (the first point shares its segment's line).
    pub fn line_of_point(&self, i: usize) -> u32 {
        let k = i.saturating_sub(1).min(self.lines.len().saturating_sub(1));
        self.lines.get(k).copied().unwrap_or(0)
    }

    /// Checks shapes, finiteness, positive times and rest at both ends of given velocities.
    pub fn validate(&self) -> Result<(), PlanError> {
        let n = self.len();
        let shape_ok = self.dim > 0
            && n >= 1
            && self.coords.len() == n * self.dim
            && self.durations.len() + 1 == n
            && self.lines.len() + 1 == n
            && self
                .velocities
                .as_ref()
                .is_none_or(|v| v.len() == n * self.dim);
        if !shape_ok {
            return Err(PlanError::BadShape);
        }
        for i in 0..n {
            if self.point(i).iter().any(|x| !x.is_finite()) {
                return Err(PlanError::NonFinitePoint {
                    line: self.line_of_point(i),
                });
            }
        }
        for (&duration, &line) in self.durations.iter().zip(&self.lines) {
            if !(duration.is_finite() && duration > 0.0) {
                return Err(PlanError::BadDuration { line, duration });
            }
        }
        self.validate_velocities()
    }

    fn validate_velocities(&self) -> Result<(), PlanError> {
        let Some(v) = &self.velocities else {
            return Ok(());
        };
        let n = self.len();
        for i in 0..n {
            let vi = &v[i * self.dim..(i + 1) * self.dim];
            if vi.iter().any(|x| !x.is_finite()) {
                return Err(PlanError::NonFinitePoint {
                    line: self.line_of_point(i),
                });
            }
            if (i == 0 || i + 1 == n) && vi.iter().any(|&x| x != 0.0) {
                return Err(PlanError::NotAtRest {
                    line: self.line_of_point(i),
                });
            }
        }
        Ok(())
    }
}

/// Cuts a polyline into runs of timed points; each run starts and ends at rest.
///
/// Repeated points are dropped (as the contour planner does). A segment's time is
/// `chord length / feed` or the time slice. An interior point with target speed 0 (an
/// exact stop) ends one run and starts the next.
pub(super) fn runs_from_polyline(
    poly: &Polyline,
    timing: Timing,
) -> Result<Vec<TimedPoints>, PlanError> {
    if let Timing::TimeSlice(s) = timing {
        if !(s.is_finite() && s > 0.0) {
            return Err(PlanError::BadTimeSlice { seconds: s });
        }
    }
    check_polyline(poly)?;
    let n = poly.len();
    let mut runs = Vec::new();
    let mut run = TimedPoints::start_at(poly.point(0));
    let mut last = 0;
    for i in 1..n {
        let (a, b) = (poly.point(last), poly.point(i));
        let chord = distance(a, b);
        if chord > REPEAT_TOLERANCE * max_abs(a).max(max_abs(b)) {
            let duration = match timing {
                Timing::FromFeed => chord / poly.feeds[i - 1],
                Timing::TimeSlice(s) => s,
            };
            run.push(b, duration, poly.lines[i - 1]);
            last = i;
        }
        if poly.is_rest(i) && i + 1 < n && run.len() > 1 {
            let next = TimedPoints::start_at(poly.point(last));
            runs.push(std::mem::replace(&mut run, next));
        }
    }
    if run.len() > 1 {
        runs.push(run);
    }
    Ok(runs)
}

/// Finite points and finite, positive feeds, or the error naming the first bad line.
fn check_polyline(poly: &Polyline) -> Result<(), PlanError> {
    for i in 0..poly.len() {
        if poly.point(i).iter().any(|x| !x.is_finite()) {
            let line = if i == 0 {
                poly.lines.first()
            } else {
                poly.lines.get(i - 1)
            };
            return Err(PlanError::NonFinitePoint {
                line: line.copied().unwrap_or(0),
            });
        }
    }
    for (&feed, &line) in poly.feeds.iter().zip(&poly.lines) {
        if !(feed.is_finite() && feed > 0.0) {
            return Err(PlanError::BadFeed { line, feed });
        }
    }
    Ok(())
}

/// The PVT contour through a run's points with the velocity at every point given.
pub(super) fn contour_from_velocities(
    run: &TimedPoints,
    velocities: &[f64],
    motion: Motion,
) -> PvtContour {
    let dim = run.dim;
    let mut out = PvtContour::new(motion, run.point(0).to_vec());
    for i in 1..run.len() {
        out.push(
            run.point(i),
            &velocities[i * dim..(i + 1) * dim],
            run.durations[i - 1],
            run.lines[i - 1],
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_split_at_exact_stops_and_drop_repeats() {
        let mut p = Polyline::start_at(&[0.0, 0.0]);
        p.push(&[3.0, 4.0], 10.0, 1);
        p.push(&[3.0, 4.0], 10.0, 2);
        p.rest_at_last();
        p.push(&[3.0, 0.0], 2.0, 3);
        let runs = runs_from_polyline(&p, Timing::FromFeed).unwrap();
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].durations, vec![0.5]);
        assert_eq!(runs[1].coords, vec![3.0, 4.0, 3.0, 0.0]);
        assert_eq!(
            (runs[1].durations.clone(), runs[1].lines.clone()),
            (vec![2.0], vec![3])
        );
        let sliced = runs_from_polyline(&p, Timing::TimeSlice(0.01)).unwrap();
        assert_eq!(sliced[1].durations, vec![0.01]);
        assert!(runs_from_polyline(&p, Timing::TimeSlice(0.0)).is_err());
    }

    #[test]
    fn validation_names_the_line() {
        let mut t = TimedPoints::start_at(&[0.0]);
        t.push(&[1.0], 0.5, 4);
        t.push(&[2.0], 0.0, 5);
        assert_eq!(
            t.validate(),
            Err(PlanError::BadDuration {
                line: 5,
                duration: 0.0
            })
        );
        t.durations[1] = 1.0;
        t.velocities = Some(vec![0.0, 1.0, 1.0]);
        assert_eq!(t.validate(), Err(PlanError::NotAtRest { line: 5 }));
        t.velocities = Some(vec![0.0, 1.0]);
        assert_eq!(t.validate(), Err(PlanError::BadShape));
    }
}
