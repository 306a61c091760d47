//! The polyline: the points a contour passes through and the speed wanted at each.
//!
//! Owns the flat point buffer that connects discretization to planning. It must not plan:
//! it only records points, per-point target speeds and per-segment feeds and lines.

/// Points of `dim` axes with target speeds; segment `i` runs from point `i` to `i + 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    /// Number of axes per point.
    pub dim: usize,
    /// Point `i` is `coords[i * dim..(i + 1) * dim]`.
    pub coords: Vec<f64>,
    /// Target path speed at each point, units per second; 0 means come to rest there.
    pub speeds: Vec<f64>,
    /// Programmed feed of each segment, units per second.
    pub feeds: Vec<f64>,
    /// Source line of each segment.
    pub lines: Vec<u32>,
    /// Points where the motion must stop whatever the feeds say (exact stop).
    rest: Vec<bool>,
}

impl Polyline {
    /// A polyline holding only its start point, at rest.
    pub fn start_at(start: &[f64]) -> Polyline {
        Polyline {
            dim: start.len(),
            coords: start.to_vec(),
            speeds: vec![0.0],
            feeds: Vec::new(),
            lines: Vec::new(),
            rest: vec![true],
        }
    }

    /// Builds a polyline from explicit points, speeds, feeds and lines (tests and tools).
    ///
    /// # Panics
    /// If the lengths disagree with `dim` and the number of points.
    pub fn from_parts(
        dim: usize,
        coords: Vec<f64>,
        speeds: Vec<f64>,
        feeds: Vec<f64>,
        lines: Vec<u32>,
    ) -> Polyline {
        let n = speeds.len();
        assert!(
            dim > 0 && coords.len() == n * dim,
            "coords must hold n * dim values"
        );
        assert!(
            feeds.len() + 1 == n && lines.len() + 1 == n,
            "one feed and line per segment"
        );
        let rest = speeds.iter().map(|&s| s == 0.0).collect();
        Polyline {
            dim,
            coords,
            speeds,
            feeds,
            lines,
            rest,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.speeds.len()
    }

    /// True when the polyline holds no point at all.
    pub fn is_empty(&self) -> bool {
        self.speeds.is_empty()
    }

    /// Point `i`.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dim..(i + 1) * self.dim]
    }

    /// The last point.
    pub fn last_point(&self) -> &[f64] {
        self.point(self.len() - 1)
    }

    /// Appends a point reached by a segment at `feed` (units/s) programmed on `line`.
    ///
    /// The previous last point stops being an end: its target speed becomes the lower of
    /// the feeds of its two segments (unless it is a rest point); the new point is at rest
    /// until a further point follows it.
    pub fn push(&mut self, point: &[f64], feed: f64, line: u32) {
        debug_assert_eq!(point.len(), self.dim);
        let last = self.len() - 1;
        if !self.rest[last] {
            self.speeds[last] = self.feeds[last - 1].min(feed);
        }
        self.coords.extend_from_slice(point);
        self.speeds.push(0.0);
        self.feeds.push(feed);
        self.lines.push(line);
        self.rest.push(false);
    }

    /// True when the motion must stop at point `i` whatever the feeds say.
    pub fn is_rest(&self, i: usize) -> bool {
        self.rest[i]
    }

    /// Makes the motion come to rest at the current last point (exact stop).
    pub fn rest_at_last(&mut self) {
        let last = self.len() - 1;
        self.rest[last] = true;
        self.speeds[last] = 0.0;
    }
}
