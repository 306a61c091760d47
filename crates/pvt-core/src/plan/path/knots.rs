//! Knots of a contour and the speed at each: where pieces start and end.
//!
//! Owns the initial knots (element ends, arc subdivisions by the error bound, the short
//! zones beside a junction passed at speed), the speed caps and the backward and forward
//! passes (with the S-curve distances under a jerk limit), and the repairs: splitting a
//! piece over the tolerance, slowing a piece over a limit and, under a jerk limit,
//! slowing a knot whose acceleration step is over its bound. It must not compute a
//! piece's cubic: that is [`super::pieces`] and [`super::piece`]. It reads pieces
//! ([`super::piece`]) but never builds them, so `pieces.rs` depends on it and not back.

mod local;

use super::curve::Curve;
use super::piece::Pieces;
use super::transition::Transition;
use super::{AxisBounds, Vector, NORMAL_SHARE, TANGENT_ANGLE};
use crate::program::SegmentRef;
use crate::vector::norm;

/// Share of its lines' tangential acceleration the passes let a corner blend change
/// speed at. Its cap already takes each axis' whole acceleration for the turn, so a
/// blend that also changes speed is over a limit and slowed in small steps by the
/// closed-form repair; with half, fewer are, and dense polylines (the bench's ellipse
/// of 720 chords at F60000: 1.204 → 1.027 of TOPP-RA) keep more speed. The closed-form
/// repair still keeps every limit.
const BLEND_TANGENT_SHARE: f64 = 0.5;

/// A point on an element: element index and parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Place {
    pub element: usize,
    pub param: f64,
}

/// A knot: the end of one piece and the start of the next.
#[derive(Debug, Clone, Copy)]
pub(super) struct Knot {
    /// Where the piece before ends.
    pub before: Place,
    /// Where the piece after starts (another element's start at a junction).
    pub after: Place,
    /// Index into [`Knots::junctions`] when the knot joins two elements (32 bits, as
    /// [`Knot::blend`]: a window's knots are kept in two vectors, and these two fields
    /// were a fifth of each).
    pub junction: Option<u32>,
    /// Index into [`Knots::junctions`] when the piece after this knot is a corner blend.
    pub blend: Option<u32>,
    /// The knot's own speed cap (junction, limit repairs), before the caps of its pieces.
    cap: f64,
    /// Planned path speed, units/s.
    pub speed: f64,
    /// The speed is given (a window's start, already emitted): never lowered.
    fixed: bool,
    /// This knot's index among the knots the last round's pieces were made from
    /// ([`Knots::pieces_again`]); `u32::MAX` for a knot made since.
    pub(super) last_round: u32,
}

/// Where a window of the path starts: on its first element at `param`, moving at
/// `speed` (along the junction's direction when `junction` is given), as the pieces
/// already emitted left it.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Start {
    pub param: f64,
    pub speed: f64,
    pub junction: Option<Junction>,
}

/// Two elements meeting at a knot.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Junction {
    /// Unit velocity direction at the junction: the bisector of the two tangents.
    pub direction: Vector,
    /// |direction − incoming tangent| (= |direction − outgoing tangent|).
    pub deviation: f64,
    /// Between two lines under limits: the corner is cut by one blend piece that leaves
    /// the first line this far (path length) before the corner and joins the second as
    /// far after it.
    pub blend: Option<f64>,
    /// sin(α/2) of the turning angle α.
    pub half_turn_sin: f64,
    /// How far a corner blend may be from the corner and the lines (the corner
    /// tolerance, else the path tolerance).
    pub tolerance: f64,
    /// The speed cap at the junction (or of the blend piece). (Its unit tangents are
    /// its curves' own, [`Curve::unit_tangent`] at their ends: not kept here, a junction
    /// is made for every element and moved.)
    pub cap: f64,
    /// Under a jerk limit, between a line and a tangent circle: the curvature
    /// transition that replaces a short stretch of each (see [`super::transition`]).
    /// Its knots are marked as a corner blend's are ([`Knot::blend`]). Boxed: it is
    /// large and rare, and every junction is built and moved, with one or without.
    pub transition: Option<Box<Transition>>,
}

impl Junction {
    /// Where the piece that cuts the junction (a corner blend or a curvature
    /// transition) leaves the first element, whose span is `span`; `None` for a
    /// junction passed at a knot.
    fn leaves_at(&self, span: f64) -> Option<f64> {
        match (&self.transition, self.blend) {
            (Some(t), _) => Some(t.params[0]),
            (None, Some(l)) => Some(span - l),
            (None, None) => None,
        }
    }

    /// Where that piece joins the second element.
    fn joins_at(&self) -> Option<f64> {
        match (&self.transition, self.blend) {
            (Some(t), _) => Some(t.params[1]),
            (None, blend) => blend,
        }
    }

    /// True when a curvature transition leaves `curve`, its first element, at or before
    /// parameter `param`.
    fn leaves_before(&self, param: f64, curve: &Curve) -> bool {
        self.transition.is_some() && self.leaves_at(curve.span).is_some_and(|l| l <= param)
    }

    /// The path length of that piece (0 for a junction passed at a knot).
    fn cut_length(&self) -> f64 {
        match &self.transition {
            Some(t) => t.length,
            None => 2.0 * self.blend.unwrap_or(0.0),
        }
    }
}

/// The knots of one contour, in order, with their junctions.
#[derive(Debug, Clone)]
pub(super) struct Knots {
    pub knots: Vec<Knot>,
    pub junctions: Vec<Junction>,
    /// True when limits bound the tangential acceleration (trapezoids), false when the
    /// speed may change over any piece.
    accelerates: bool,
    /// True with a jerk limit: speed changes are S-curves between knots at zero
    /// tangential acceleration (see "Jerk" in [`super`]).
    pub jerk_mode: bool,
    /// In jerk mode, the shortest cruise a line's trapezoid gets, seconds (three quanta on
    /// a time grid, else 0): a shorter one would be stretched to whole quanta, and the
    /// velocities beside it divided by that stretch.
    pub min_cruise: f64,
    /// The passes' and repairs' per-piece values, whose storage every round reuses
    /// (boxed: a window on the grid carries its knots by value).
    pub(super) scratch: Box<Scratch>,
}

/// Per-piece values the speed passes and the tolerance repair work on, kept with the
/// knots so that a round allocates none.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    ways: Vec<PieceWay>,
    /// Each piece's largest error bound, by its knot ([`Knots::split_over`]; where the
    /// tolerance is the only repair, the last round's, see [`Knots::errors_again`]).
    pub(super) errors: Vec<f64>,
    /// Beside [`Scratch::errors`] where [`Knots::errors_again`] made them: each piece's
    /// time, made with its bound, so that the settled pieces take both over
    /// ([`Knots::pieces_from_bounds`]) instead of making them again.
    pub(super) durations: Vec<f64>,
    /// Each knot's known path ahead ([`Knots::known_ahead`]).
    ahead: Vec<f64>,
    /// The speeds of the knots the last round's pieces were made from (empty: none to
    /// take over), for [`Knots::pieces_again`].
    pub(super) made_at: Vec<f64>,
    /// The trapezoid knots [`Knots::add_trapezoids`] inserts, each after its knot.
    added: Vec<Added>,
    /// A local round's knots whose speed the next may change ([`local`]).
    touched: Vec<usize>,
    /// The pieces a round splits (`split_errors`), and after a local round's split the
    /// knots it inserted ([`local`]).
    inserted: Vec<usize>,
    /// The pieces whose error bounds a local round made ([`local`]).
    changed: Vec<usize>,
}

/// A trapezoid knot to insert after knot `after`: at `param` on that knot's element, its
/// cap and speed `speed` (a third of a knot's room: the knots are moved up in place).
#[derive(Debug, Clone, Copy)]
struct Added {
    after: usize,
    param: f64,
    speed: f64,
}

/// What the speed passes know of one piece: how fast it may run and how its speed may
/// change along it.
#[derive(Debug, Clone, Copy)]
struct PieceWay {
    /// Path length.
    length: f64,
    /// The piece's own speed cap.
    cap: f64,
    /// Tangential acceleration left for changing speed.
    accel: f64,
    /// The path jerk of its S-curve (jerk mode; infinite on blends and without: the
    /// plain constant-acceleration distances).
    jerk: f64,
    /// The largest ratio of its end speeds (a jerk-limited blend's pulse).
    ratio: f64,
}

impl PieceWay {
    /// A way not made yet: what [`Knots::ways_kept`] sizes a fresh vector with.
    const UNKNOWN: PieceWay = PieceWay {
        length: f64::NAN,
        cap: f64::NAN,
        accel: f64::NAN,
        jerk: f64::NAN,
        ratio: f64::NAN,
    };

    /// The fastest speed at one end from which the other end's speed `v` is reached.
    fn reach(&self, v: f64) -> f64 {
        let reach = if self.jerk.is_finite() {
            scurve_reachable(v, self.accel, self.jerk, self.length)
        } else {
            reachable(v, self.accel, self.length)
        };
        if self.ratio.is_finite() {
            reach.min(self.ratio * v)
        } else {
            reach
        }
    }

    /// True when the way bounds no change of speed: its reach is infinite from any
    /// speed (no finite acceleration, path jerk or ratio of end speeds), so that
    /// [`PieceWay::limit`]`(speed, v)` is `speed` whatever `v` (∞ where `speed` is NaN).
    pub(super) fn is_free(&self) -> bool {
        !self.accel.is_finite() && !self.jerk.is_finite() && !self.ratio.is_finite()
    }

    /// `speed.min(self.reach(v))`, without the reach where `speed` is at most `v`: the
    /// reach is never below `v` (`v + Δ` with `Δ ≥ 0`, `√(v² + 2ad) ≥ v`, `ratio ≥ 1`),
    /// so the minimum is `speed` there, bit for bit.
    fn limit(&self, speed: f64, v: f64) -> f64 {
        if speed <= v {
            speed
        } else {
            speed.min(self.reach(v))
        }
    }
}

/// The storage of a window's knots, kept for the next window's (see [`Knots::new`]).
#[derive(Debug, Default)]
pub(super) struct KnotStorage {
    knots: Vec<Knot>,
    junctions: Vec<Junction>,
    pub(super) scratch: Box<Scratch>,
}

impl Knots {
    /// The vectors of these knots, emptied by the next [`Knots::new`] that takes them.
    pub fn into_storage(self) -> KnotStorage {
        KnotStorage {
            knots: self.knots,
            junctions: self.junctions,
            scratch: self.scratch,
        }
    }
}

impl Knots {
    /// Every knot's place, junction, blend, cap, speed and whether it is fixed, bit for
    /// bit (`{:?}` of an `f64` is its shortest round trip): what a settling decides,
    /// without [`Knot::last_round`], which only the rounds that take over the last
    /// round's values keep.
    #[cfg(test)]
    pub(super) fn settled_state(&self) -> String {
        let knot = |k: &Knot| {
            let Knot {
                before,
                after,
                junction,
                blend,
                cap,
                speed,
                fixed,
                last_round: _,
            } = k;
            format!("{before:?} {after:?} {junction:?} {blend:?} {cap:?} {speed:?} {fixed}\n")
        };
        self.knots.iter().map(knot).collect()
    }
}

impl Knot {
    /// [`Knot::junction`] as an index into [`Knots::junctions`].
    pub fn junction_index(&self) -> Option<usize> {
        self.junction.map(|j| j as usize)
    }

    /// [`Knot::blend`] as an index into [`Knots::junctions`].
    pub fn blend_index(&self) -> Option<usize> {
        self.blend.map(|j| j as usize)
    }

    fn at(place: Place, cap: f64) -> Knot {
        Knot {
            before: place,
            after: place,
            junction: None,
            blend: None,
            cap,
            speed: 0.0,
            fixed: false,
            last_round: u32::MAX,
        }
    }
}

impl Knots {
    /// Knots at every element end, along arcs by the error bound, and beside junctions;
    /// `narrow` sizes corner blends for a time grid (see `junction`).
    pub fn new(
        curves: &[Curve],
        bounds: &AxisBounds,
        tolerance: f64,
        corner: Option<f64>,
        start: &Start,
        narrow: bool,
        storage: KnotStorage,
    ) -> Knots {
        let mut first = Knot::at(
            Place {
                element: 0,
                param: start.param,
            },
            start.speed,
        );
        first.fixed = true;
        // Room for a line's blend knot and end knot, and its junction: a knot vector
        // grown one push at a time copied itself about twice per window.
        let KnotStorage {
            mut knots,
            mut junctions,
            scratch,
        } = storage;
        knots.clear();
        knots.reserve(2 * curves.len() + 1);
        // Another window's pieces: none is taken over.
        let mut scratch = scratch;
        scratch.made_at.clear();
        knots.push(first);
        junctions.clear();
        junctions.reserve(curves.len());
        let mut this = Knots {
            knots,
            junctions,
            accelerates: bounds.accelerates() || bounds.jerk_mode(),
            jerk_mode: bounds.jerk_mode(),
            min_cruise: 0.0,
            scratch,
        };
        if let Some(j) = &start.junction {
            this.knots[0].junction = Some(0);
            this.junctions.push(j.clone());
        }
        // Each junction is made as its element comes, straight into `junctions` (it is
        // large: a curvature transition rides in it); the next element needs only where
        // a cut junction joins it and its cap.
        let mut joins: Option<(f64, f64)> = None;
        let rules = JunctionRules::new(bounds, tolerance, corner, narrow);
        for (e, curve) in curves.iter().enumerate() {
            let mut after = false;
            if let Some(next) = curves.get(e + 1) {
                // A line's unit tangent is kept with it; an arc's is made here.
                let (own_in, own_out);
                let t_in = match curve.line_tangent() {
                    Some(t) => t,
                    None => {
                        own_in = curve.unit_tangent(curve.span);
                        &own_in
                    }
                };
                let t_out = match next.line_tangent() {
                    Some(t) => t,
                    None => {
                        own_out = next.unit_tangent(0.0);
                        &own_out
                    }
                };
                let make = |rules: &JunctionRules<'_>, out: &mut Vec<Junction>| {
                    junction(curve, next, [t_in, t_out], rules, out)
                };
                after = make(&rules, &mut this.junctions);
                if e == 0 && after && this.last_junction().leaves_before(start.param, curve) {
                    // A window that starts past where a transition would leave its first
                    // element (never after a cut, which is never inside one): the
                    // junction as the stretched grid makes it, without a transition.
                    this.junctions.pop();
                    let narrow = JunctionRules {
                        narrow: true,
                        ..rules
                    };
                    after = make(&narrow, &mut this.junctions);
                }
            }
            if let Some((l, cap)) = joins {
                let place = Place {
                    element: e,
                    param: l,
                };
                this.knots.push(Knot::at(place, cap));
            }
            let from = if e == 0 { start.param } else { 0.0 };
            for param in inner_params(curve, tolerance).filter(|p| *p > from) {
                this.knots
                    .push(Knot::at(Place { element: e, param }, f64::INFINITY));
            }
            joins = after.then(|| this.last_junction()).and_then(|j| {
                let cap = j.cap;
                j.joins_at().map(|l| (l, cap))
            });
            this.push_end(curves, e, after);
        }
        this
    }

    /// The junction last made (by `junction`, which pushes it).
    fn last_junction(&self) -> &Junction {
        &self.junctions[self.junctions.len() - 1]
    }

    /// The knot that ends element `e`: the contour's end, a corner blend's start, a
    /// junction passed at speed, or an exact stop.
    fn push_end(&mut self, curves: &[Curve], e: usize, junction: bool) {
        let curve = &curves[e];
        let end = Place {
            element: e,
            param: curve.span,
        };
        if e + 1 == curves.len() {
            self.knots.push(Knot::at(end, 0.0));
            return;
        }
        if !junction {
            let mut knot = Knot::at(end, 0.0);
            knot.after = Place {
                element: e + 1,
                param: 0.0,
            };
            self.knots.push(knot);
            return;
        }
        let index = self.junctions.len() - 1;
        let j = &self.junctions[index];
        if let Some(leaves) = j.leaves_at(curve.span) {
            let mut knot = Knot::at(
                Place {
                    element: e,
                    param: leaves,
                },
                j.cap,
            );
            knot.blend = Some(index as u32);
            self.knots.push(knot);
        } else {
            let mut knot = Knot::at(end, j.cap);
            knot.after = Place {
                element: e + 1,
                param: 0.0,
            };
            knot.junction = Some(index as u32);
            self.knots.push(knot);
        }
    }

    /// Speed at every knot: caps, then the backward and forward passes, then trapezoid
    /// knots on lines where the speed can rise between two knots.
    ///
    /// The pieces' ways ([`Knots::way_again`]), the knots' caps and the backward pass
    /// are one sweep from the end: once piece `k`'s way is made, knot `k + 1` has both
    /// its pieces' ways and the backward speed of the knot after it, so it is capped and
    /// limited there, in the order three sweeps would take.
    pub fn plan_speeds(&mut self, curves: &[Curve], bounds: &AxisBounds) {
        let n = self.knots.len();
        let mut ways = std::mem::take(&mut self.scratch.ways);
        let keep = self.ways_kept(&mut ways);
        for k in (0..n - 1).rev() {
            ways[k] = self.way_again(curves, bounds, k, keep, &ways);
            self.cap_and_limit(k + 1, &ways);
        }
        self.cap_and_limit(0, &ways);
        for (k, way) in ways.iter().enumerate() {
            let speed = way.limit(self.knots[k + 1].speed, self.knots[k].speed);
            self.knots[k + 1].speed = speed;
        }
        self.scratch.ways = ways;
    }

    /// Knot `j`'s speed before the forward pass: its cap, lowered to those of its
    /// pieces (whose ways are made), then the backward pass's limit from the knot after
    /// it (already set); a fixed knot keeps its cap.
    #[inline(always)]
    fn cap_and_limit(&mut self, j: usize, ways: &[PieceWay]) {
        self.knots[j].speed = self.backward_speed(j, ways);
    }

    /// [`Knots::cap_and_limit`]'s speed for knot `j`, not set.
    #[inline(always)]
    fn backward_speed(&self, j: usize, ways: &[PieceWay]) -> f64 {
        let n = self.knots.len();
        let knot = &self.knots[j];
        let mut cap = knot.cap;
        if j > 0 {
            cap = cap.min(ways[j - 1].cap);
        }
        if j < n - 1 {
            cap = cap.min(ways[j].cap);
        }
        if knot.fixed {
            knot.cap
        } else if j < n - 1 {
            ways[j].limit(cap, self.knots[j + 1].speed)
        } else {
            cap
        }
    }

    /// Sizes `ways` for these knots' pieces, made again from the end by
    /// [`Knots::way_again`]; returns how many knots the last round's ways were made from
    /// when they can be taken over ([`Knots::way_again`]), else 0.
    fn ways_kept(&self, ways: &mut Vec<PieceWay>) -> usize {
        let n = self.knots.len();
        let last = self.scratch.made_at.len();
        if last < 2 || ways.len() + 1 != last {
            ways.clear();
            ways.resize(n - 1, PieceWay::UNKNOWN);
            return 0;
        }
        ways.resize(n - 1, ways[0]);
        last
    }

    /// Piece `k`'s [`PieceWay`], with `ways` made from the end down to `k + 1` and
    /// holding, below, the last round's (`last` knots; 0: none to take over). A piece
    /// between two knots that were consecutive then keeps its way, which follows from
    /// their places and the window's curves, junctions and bounds alone (never from
    /// their speeds or caps). A way kept moves back (or stays): `ways[i]`, `i ≤ k`, is
    /// still the last round's.
    #[inline(always)]
    fn way_again(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
        last: usize,
        ways: &[PieceWay],
    ) -> PieceWay {
        let i = self.knots[k].last_round as usize;
        let kept = i <= k && i + 1 < last && self.knots[k + 1].last_round as usize == i + 1;
        if kept {
            ways[i]
        } else {
            self.piece_way(curves, bounds, k)
        }
    }

    /// Piece `k`'s length, cap and what bounds its change of speed.
    fn piece_way(&self, curves: &[Curve], bounds: &AxisBounds, k: usize) -> PieceWay {
        let mut way = PieceWay {
            length: 0.0,
            cap: f64::INFINITY,
            accel: f64::INFINITY,
            jerk: f64::INFINITY,
            ratio: f64::INFINITY,
        };
        if let Some(j) = self.knots[k].blend_index() {
            let j = &self.junctions[j];
            way.cap = j.cap;
            way.length = j.cut_length();
            if j.transition.is_some() {
                // A curvature transition runs at one speed (see `super::transition`).
                way.ratio = 1.0;
                return way;
            }
            let e = self.knots[k].after.element;
            // A blend's cap takes the whole acceleration for its turn: the passes
            // let it change speed at a share of its lines' (see the constant).
            let a = |c: &Curve| tangential_accel(c, 0.0, c.span, bounds, j.cap);
            way.accel = BLEND_TANGENT_SHARE * a(&curves[e]).min(a(&curves[e + 1]));
            if self.jerk_mode {
                // Under a jerk limit a blend is a smooth pulse at rest in
                // acceleration at both ends: an S-curve over its length.
                let least = bounds.jerk.iter().fold(f64::INFINITY, |a, &b| a.min(b));
                way.jerk = BLEND_JERK_SHARE * least;
                way.ratio = BLEND_SPEED_RATIO;
            }
            return way;
        }
        let (curve, from, to) = self.piece_span(curves, k);
        way.cap = speed_cap(curve, from, to, bounds);
        way.accel = tangential_accel(curve, from, to, bounds, way.cap);
        way.length = curve.length(from, to);
        if self.jerk_mode {
            way.jerk = path_jerk(curve, from, to, bounds);
        }
        way
    }

    /// On a line piece whose speed may rise above both ends, knots where the cruise
    /// begins and ends (with limits; without, the speed changes over whole pieces).
    /// Returns whether any knot was added: where none was, the knots are as they were.
    pub fn add_trapezoids(&mut self, curves: &[Curve], bounds: &AxisBounds) -> bool {
        if !self.accelerates {
            return false;
        }
        let mut added = std::mem::take(&mut self.scratch.added);
        added.clear();
        for k in 0..self.knots.len() - 1 {
            if self.knots[k].blend.is_some() {
                continue;
            }
            let (curve, from, to) = self.piece_span(curves, k);
            let cap = speed_cap(curve, from, to, bounds);
            let a = tangential_accel(curve, from, to, bounds, cap);
            let d = curve.length(from, to);
            let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
            let j = if self.jerk_mode {
                path_jerk(curve, from, to, bounds)
            } else {
                f64::INFINITY
            };
            if !curve.is_line() || !(a.is_finite() || j.is_finite()) {
                continue;
            }
            let (peak, rise, fall) = if j.is_finite() {
                // A rise (or fall) of a rounding error's speed is none: its S-curve's
                // length, `(va + vb)·√(Δv/j)`, is far above the rounding of the speed,
                // and a knot there (a window's fixed start at its cap) would begin a
                // piece of nanoseconds that the repairs slow to rest.
                let (peak, rise, fall) = scurve_peak(va, vb, cap, a, j, d);
                let none = |v: f64| peak - v <= 1e-9 * peak;
                (
                    peak,
                    if none(va) { 0.0 } else { rise },
                    if none(vb) { 0.0 } else { fall },
                )
            } else {
                let peak = cap.min((a * d + 0.5 * (va * va + vb * vb)).sqrt());
                let rise = (peak * peak - va * va) / (2.0 * a);
                let fall = (peak * peak - vb * vb) / (2.0 * a);
                (peak, rise, fall)
            };
            let mut add = |at: f64| {
                if at > 1e-9 * d && at < d * (1.0 - 1e-9) {
                    added.push(Added {
                        after: k,
                        param: from + at,
                        speed: peak,
                    });
                }
            };
            add(rise);
            // In jerk mode a cruise is at least 10⁻⁶ of the piece (and `min_cruise`
            // long): a cruise of a rounding error's length would be a piece whose
            // accelerations, from its written ends, are rounding noise.
            let cruise = d - fall - rise;
            let long = j.is_infinite() || cruise >= (self.min_cruise * peak).max(1e-6 * d);
            if d - fall > rise * (1.0 + 1e-9) && long {
                add(d - fall);
            }
        }
        insert_after(
            &mut self.knots,
            added.len(),
            added.iter().rev(),
            |knots, a| {
                let place = Place {
                    element: knots[a.after].after.element,
                    param: a.param,
                };
                let mut knot = Knot::at(place, a.speed);
                knot.speed = a.speed;
                (a.after, knot)
            },
        );
        let any = !added.is_empty();
        self.scratch.added = added;
        any
    }

    /// The element and parameter range of piece `k` (from knot `k` to knot `k + 1`).
    #[inline]
    pub fn piece_span<'c>(&self, curves: &'c [Curve], k: usize) -> (&'c Curve, f64, f64) {
        let a = self.knots[k].after;
        let b = self.knots[k + 1].before;
        debug_assert_eq!(a.element, b.element);
        (&curves[a.element], a.param, b.param)
    }

    /// Splits every piece whose error bound exceeds `tolerance` at its middle parameter;
    /// a corner blend over its tolerance instead gets both end speeds capped at the
    /// slower one (at equal speeds it meets it). Returns whether any changed.
    pub fn split_over(&mut self, pieces: &Pieces, tolerance: f64) -> bool {
        // The largest error of each knot's piece (of its S-curve parts in jerk mode).
        let mut errors = std::mem::take(&mut self.scratch.errors);
        errors.clear();
        errors.resize(self.knots.len() - 1, 0.0);
        for (knot, error) in pieces.knots_and_errors() {
            errors[knot] = errors[knot].max(error);
        }
        let split = self.split_errors(&errors, tolerance);
        self.scratch.errors = errors;
        split
    }

    /// [`Knots::split_over`] on the error bounds [`Knots::errors_again`] left.
    pub fn split_over_errors(&mut self, tolerance: f64) -> bool {
        let errors = std::mem::take(&mut self.scratch.errors);
        let split = self.split_errors(&errors, tolerance);
        self.scratch.errors = errors;
        split
    }

    /// True when the tolerance is the only repair that can change these knots: no
    /// limit for [`Knots::slow_over`] and no jerk limit for [`Knots::step_over`], so a
    /// round needs each piece's error bound and nothing else of it.
    pub fn tolerance_alone_repairs(&self, bounds: &AxisBounds) -> bool {
        !self.jerk_mode && no_limit(bounds)
    }

    /// [`Knots::split_over`] with each piece's largest error given: the knots are built
    /// again only where some piece is split.
    fn split_errors(&mut self, errors: &[f64], tolerance: f64) -> bool {
        let mut split = false;
        for (k, &error) in errors.iter().enumerate() {
            // Speeds do not change here: capping every blend first caps the same.
            split |= self.cap_blend_over(k, error) != [false, false];
        }
        let mut splits = std::mem::take(&mut self.scratch.inserted);
        splits.clear();
        let over = |&(k, &error): &(usize, &f64)| self.splits_at(k, error, tolerance);
        splits.extend(errors.iter().enumerate().filter(over).map(|(k, _)| k));
        self.insert_splits(&splits);
        split |= !splits.is_empty();
        self.scratch.inserted = splits;
        split
    }

    /// Splits each piece of `splits` (in order) at its middle parameter, in place.
    fn insert_splits(&mut self, splits: &[usize]) {
        let down = splits.iter().rev().copied();
        insert_after(&mut self.knots, splits.len(), down, |knots, k| {
            (k, split_knot(knots, k))
        });
    }

    /// Where piece `k` is a corner blend over its tolerance with error bound `error`,
    /// caps both its knots (but a fixed one) at the slower end speed (at equal speeds it
    /// meets it). Returns which of the two caps it lowered.
    fn cap_blend_over(&mut self, k: usize, error: f64) -> [bool; 2] {
        let mut lowered = [false; 2];
        let Some(j) = self.knots[k].blend_index() else {
            return lowered;
        };
        if error > self.junctions[j].tolerance {
            let slower = self.knots[k].speed.min(self.knots[k + 1].speed);
            for (i, lowered) in lowered.iter_mut().enumerate() {
                let knot = &mut self.knots[k + i];
                if !knot.fixed && knot.cap > slower {
                    knot.cap = slower;
                    *lowered = true;
                }
            }
        }
        lowered
    }

    /// True when piece `k`, with error bound `error`, is split at its middle: over the
    /// tolerance and no corner blend.
    fn splits_at(&self, k: usize, error: f64, tolerance: f64) -> bool {
        error > tolerance && self.knots[k].blend.is_none()
    }

    /// Lowers the speed caps at both ends of every piece whose closed-form velocity or
    /// acceleration peak exceeds a limit. Returns whether any did.
    pub fn slow_over(&mut self, pieces: &Pieces, bounds: &AxisBounds) -> bool {
        if no_limit(bounds) {
            // Every piece's factor is 1 (see `Piece::limit_factor`).
            return false;
        }
        let mut slowed = false;
        for piece in pieces {
            let k = piece.knot;
            if piece.at_rest() {
                // A line at rest at both ends: trapezoid knots will replace it.
                continue;
            }
            let factor = piece.limit_factor(bounds);
            if factor < 1.0 {
                for knot in self.knots[k..k + 2].iter_mut().filter(|k| !k.fixed) {
                    let step = if factor > 0.9999 { 1.0 - 1e-3 } else { 0.98 };
                    knot.cap = knot.cap.min(knot.speed * factor * step);
                }
                slowed = true;
            }
        }
        slowed
    }

    /// Lowers the speed caps of knots `range` (never the fixed start) to `factor` of their
    /// speeds, a little more as [`Knots::slow_over`] does: the resampled grid's repair of
    /// a piece over a limit or the tolerance.
    pub fn slow_knots(&mut self, range: std::ops::Range<usize>, factor: f64) {
        let step = if factor > 0.9999 { 1.0 - 1e-3 } else { 0.98 };
        let end = range.end.min(self.knots.len());
        for knot in self.knots[range.start.min(end)..end]
            .iter_mut()
            .filter(|k| !k.fixed)
        {
            knot.cap = knot.cap.min(knot.speed * factor * step);
        }
    }

    /// In jerk mode, lowers the speed caps where the acceleration steps by more than
    /// `bounds.step` on an axis: between two consecutive pieces (or parts of one
    /// S-curve), and by more than half of it between rest and the contour's first and last
    /// piece (two contours straight on then step within the whole), less the room the
    /// rounding of written positions needs beside the knot (`6·r/T²` for each piece of
    /// `T` seconds beside it, see [`super::PathOptions::position_resolution`]). Every such step
    /// (a corner blend, a junction passed at speed, a change of curvature, the
    /// interpolation of a curve) grows with the square of the speeds, so the knot's cap
    /// goes down by the square root of the excess; a blend beside the knot, whose
    /// acceleration depends on both its speeds, has its other knot lowered too, and an
    /// S-curve's inner step both of its knots. Returns whether any step was over.
    pub fn step_over(&mut self, pieces: &Pieces, bounds: &AxisBounds) -> bool {
        if !self.jerk_mode || pieces.is_empty() {
            return false;
        }
        let dim = pieces.dim();
        let mut over = false;
        // The acceleration at the end of the piece before the knot (rest before the
        // first), carried from piece to piece rather than kept for all of them.
        let mut end_before = Vector::zeros(dim);
        for i in 0..=pieces.len() {
            let ends = pieces.get(i).map(|p| p.end_accelerations());
            let after = ends.map_or(Vector::zeros(dim), |e| e[0]);
            let end = ends.map_or(Vector::zeros(dim), |e| e[1]);
            let before = std::mem::replace(&mut end_before, end);
            // Against rest, half: a contour that follows another straight on (no dwell
            // between) steps from that one's end to its own start, within the whole.
            let share = if i == 0 || i == pieces.len() {
                0.5
            } else {
                1.0
            };
            // Room for the rounding of the written positions beside the knot.
            let rounding: f64 = [i.checked_sub(1), (i < pieces.len()).then_some(i)]
                .into_iter()
                .flatten()
                .map(|p| {
                    // A planned piece shorter than a quantum is one on the grid.
                    let t = pieces.duration(p).max(bounds.quantum);
                    6.0 * bounds.resolution / (t * t)
                })
                .sum();
            let mut factor: f64 = 1.0;
            for a in 0..dim {
                let step = (after[a] - before[a]).abs();
                let bound = share * bounds.step[a] - rounding;
                if bound <= 0.0 {
                    // Pieces too short for the rounding: longer ones, at lower speed.
                    factor = factor.min(0.5);
                } else if step > bound * (1.0 + 1e-9) {
                    factor = factor.min((bound / step).sqrt());
                }
            }
            if factor >= 1.0 {
                continue;
            }
            over = true;
            let mut lower = Vec::with_capacity(2);
            if i == 0 {
                lower.push(pieces.knot(0) + 1);
            } else if i == pieces.len() {
                lower.push(pieces.knot(i - 1));
            } else {
                let (prev, next) = (pieces.knot(i - 1), pieces.knot(i));
                if prev == next {
                    lower.extend([next, next + 1]);
                } else {
                    lower.push(next);
                    if self.knots[prev].blend.is_some() {
                        lower.push(prev);
                    }
                    if self.knots[next].blend.is_some() {
                        lower.push(next + 1);
                    }
                }
            }
            let step = if factor > 0.9999 { 1.0 - 1e-3 } else { 0.98 };
            for k in lower {
                let knot = &mut self.knots[k];
                if !knot.fixed {
                    knot.cap = knot.cap.min(knot.speed * factor * step);
                }
            }
        }
        over
    }

    /// Distance from every knot to the start of the window's last element (0 on it):
    /// what is known to lie ahead of each knot, since the last element's end, and with
    /// it how the last element is left, depends on elements not yet read.
    /// Written into `ahead`, whose storage the window's scratch keeps.
    fn known_ahead(&self, curves: &[Curve], ahead: &mut Vec<f64>) {
        let n = self.knots.len();
        let last = &curves[curves.len() - 1];
        let unknown = last.length(0.0, last.span);
        ahead.clear();
        ahead.resize(n, 0.0);
        for k in (0..n - 1).rev() {
            ahead[k] = ahead[k + 1] + self.piece_length(curves, k);
        }
        ahead.iter_mut().for_each(|d| *d = (*d - unknown).max(0.0));
    }

    /// Caps every knot (but the fixed start) at the speed from which the least
    /// tangential acceleration `least` stops before the last element: whatever the
    /// elements after the window ask, a window cut at any knot can still meet it.
    /// (Under a jerk limit the window is cut at [`Knots::stop_horizon`] instead.)
    pub fn cap_for_window(&mut self, curves: &[Curve], least: f64) {
        if least == f64::INFINITY && !self.knots.iter().any(|k| !k.fixed && k.cap.is_nan()) {
            // Every cap is `√∞ = ∞` (or `√NaN` at `d = 0`), and `min` keeps the knot's own.
            return;
        }
        let mut ahead = std::mem::take(&mut self.scratch.ahead);
        self.known_ahead(curves, &mut ahead);
        for (knot, &d) in self.knots.iter_mut().zip(&ahead) {
            if !knot.fixed {
                knot.cap = knot.cap.min((2.0 * least * d).sqrt());
            }
        }
        self.scratch.ahead = ahead;
    }

    /// The index of the last knot that ends a piece on known path (before the window's
    /// last element, whose end depends on what follows), at least `k`.
    fn last_known(&self, curves: &[Curve], k: usize) -> usize {
        let last = curves.len() - 1;
        self.knots[k + 1..]
            .iter()
            .position(|n| n.before.element >= last && n.before.param > 0.0)
            .map_or(self.knots.len() - 1, |i| k + i)
    }

    /// The last knot `k` from which the passes bring the highest feed of the elements up
    /// to `k` to rest on known path: the backward pass from rest at the last known knot
    /// (see [`Knots::last_known`]), each piece's S-curve at its own acceleration and path
    /// jerk ([`PieceWay`], zero tangential acceleration at every knot, across any
    /// number of short elements), without caps, reaches that feed at `k`. `None` when it
    /// does at no knot. The pass costs one [`PieceWay`] per piece from the end back
    /// to `k`. Up to `k` the stop at the window's end bounds no knot's speed: where it
    /// binds after `k`, the backward pass carries the pass's own value back, which at
    /// every knot up to `k` is at least the feed there, the highest speed it can have.
    pub fn stop_horizon(&self, curves: &[Curve], bounds: &AxisBounds) -> Option<usize> {
        let known = self.last_known(curves, 0);
        // The highest feed up to each knot's element, by element.
        let element = self.knots[known].before.element;
        let mut feed = 0.0_f64;
        let fastest: Vec<f64> = curves[..=element]
            .iter()
            .map(|c| {
                feed = feed.max(c.feed);
                feed
            })
            .collect();
        let mut reach = 0.0;
        for k in (0..known).rev() {
            reach = self.piece_way(curves, bounds, k).reach(reach);
            if reach >= fastest[self.knots[k].after.element] {
                return Some(k);
            }
        }
        None
    }

    /// True when a window that starts at knot `k` with its speed fixed can settle:
    /// - the piece after `k` lasts at least `shortest` seconds at `k`'s speed (a time
    ///   grid's quantum: a shorter one between two planned knots is rounding noise in
    ///   its cubic's accelerations, which the repairs would slow the next knot for);
    /// - its first piece before trapezoid knots (up to the next knot that ends the
    ///   element or starts a corner blend) does not slow and does not end in a corner
    ///   blend (whose cap differs between the shares a grid's windows plan at), or it
    ///   lies on a line with room
    ///   for an S-curve at the line's own acceleration and path jerk from `k`'s speed to
    ///   any lower one (`scurve_stop` in [`super`]): a deceleration that fills its piece
    ///   exactly could not be met, within rounding, without slowing the fixed start;
    /// - and the passes bring `k`'s speed to rest at a knot `m` after it on known path
    ///   (see [`Knots::last_known`]) through every planned speed between: the backward
    ///   pass from rest at `m`, capped at each knot's planned speed, each piece's
    ///   S-curve at its own acceleration and path jerk under `bounds` (on a grid the
    ///   least of every share's, so that the next window meets this plan's slowdowns
    ///   at whichever share it converges) ([`PieceWay`]), reaches at least the speed
    ///   at `k`, over any number of short elements. `m` is tried at
    ///   `k + 1, k + 2, k + 4, …` (the reach grows with `m`), so the check costs
    ///   `O(L·log L)` piece limits for a stop over `L` pieces (each piece's way made
    ///   once, a knot no faster than the speed carried back to it taking none).
    pub fn room_to_slow(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        k: usize,
        shortest: f64,
    ) -> bool {
        let speed = self.knots[k].speed;
        let known = self.last_known(curves, k);
        if known <= k
            || self.piece_length(curves, k) < shortest * speed
            || !self.first_piece_settles(curves, bounds, k)
        {
            return false;
        }
        // The way of piece `k + 1 + n` at `ways[n]`, made where first needed and kept
        // for the passes from later `m`.
        let mut ways: Vec<Option<PieceWay>> = Vec::new();
        let mut span = 1;
        loop {
            let m = (k + span).min(known);
            ways.resize(m - k - 1, None);
            // A knot no faster than the speed carried back keeps its own (see
            // [`PieceWay::limit`]): its piece's way is not needed.
            let ahead = (k + 1..m).rev().fold(0.0, |v, i| {
                let planned = self.knots[i].speed;
                if planned <= v {
                    planned
                } else {
                    let way =
                        ways[i - k - 1].get_or_insert_with(|| self.piece_way(curves, bounds, i));
                    way.limit(planned, v)
                }
            });
            if ahead >= speed || self.piece_way(curves, bounds, k).reach(ahead) >= speed {
                return true;
            }
            if m == known {
                return false;
            }
            span *= 2;
        }
    }

    /// The first condition of [`Knots::room_to_slow`].
    fn first_piece_settles(&self, curves: &[Curve], bounds: &AxisBounds, k: usize) -> bool {
        let knot = &self.knots[k];
        let element = knot.after.element;
        let Some(next) = self.knots[k + 1..]
            .iter()
            .find(|n| n.blend.is_some() || n.junction.is_some() || n.before.element != element)
        else {
            return false;
        };
        if knot.blend.is_some() {
            return false;
        }
        if next.speed >= knot.speed && next.blend.is_none() {
            return true;
        }
        let curve = &curves[element];
        let end = if next.before.element == element {
            next.before.param
        } else {
            curve.span
        };
        let cap = speed_cap(curve, 0.0, curve.span, bounds);
        let a = tangential_accel(curve, 0.0, curve.span, bounds, cap);
        let j = path_jerk(curve, 0.0, curve.span, bounds);
        curve.is_line()
            && curve.length(knot.after.param, end) >= super::scurve_stop(knot.speed, a, j)
    }

    /// The last knot at which the window may be cut with at least `keep` of known path
    /// after it (see [`Knots::known_ahead`]; never a knot that starts a corner blend, never
    /// one on the last element), and never earlier than half the knots; `None` when there
    /// is none.
    pub fn cut(&mut self, curves: &[Curve], keep: f64) -> Option<usize> {
        let n = self.knots.len();
        let last = curves.len() - 1;
        let mut ahead = std::mem::take(&mut self.scratch.ahead);
        if keep > 0.0 {
            self.known_ahead(curves, &mut ahead);
        } else {
            // Every knot has at least no path after it (`known_ahead` is never below 0).
            ahead.clear();
            ahead.resize(n, 0.0);
        }
        let cut = (1..n - 1).rev().find(|&k| {
            let knot = &self.knots[k];
            let cuttable = knot.blend.is_none() && knot.after.element < last;
            cuttable && (ahead[k] >= keep || k <= n / 2)
        });
        self.scratch.ahead = ahead;
        cut
    }

    /// True when knot `k` lies inside a line, the pieces beside it on that line, at least
    /// `stop(speed)` before the line's end: a window that starts there with its speed
    /// fixed can come to rest on that line whatever its repairs ask of the knots after
    /// it, so its plan settles as the contour's start does.
    pub fn room_to_stop(&self, curves: &[Curve], k: usize, stop: &dyn Fn(f64) -> f64) -> bool {
        let knot = &self.knots[k];
        let curve = &curves[knot.after.element];
        knot.junction.is_none()
            && self.knots[k - 1].blend.is_none()
            && knot.before.element == knot.after.element
            && curve.is_line()
            && curve.length(knot.after.param, curve.span) >= stop(knot.speed)
    }

    /// Under path jerk `jerk`, a bound on the time the piece before knot `k` needs to
    /// turn the velocity from its element's tangent onto the knot's junction direction,
    /// a change of `Δ = speed·deviation` across the path (0 where the knot joins no
    /// elements). A cubic that keeps its chord and changes its velocity by `Δ` over `T`
    /// has jerk `6·Δ/T²`; an S-curve of two parts may leave the turn to one of them
    /// (`24·Δ/T²`), and the window after a cut plans the piece's speeds again, so
    /// [`TURN_MARGIN`] times that: `T = √(TURN_MARGIN·24·Δ/jerk)`. A window cut inside a
    /// piece leaves the next window at least this much of it (see [`super::grid_cut`]).
    pub fn turn_time(&self, k: usize, jerk: f64) -> f64 {
        let knot = &self.knots[k];
        match knot.junction_index() {
            Some(j) => {
                let turn = knot.speed * self.junctions[j].deviation;
                (TURN_MARGIN * 24.0 * turn / jerk).sqrt()
            }
            None => 0.0,
        }
    }

    /// True when a window may end at knot `k`: not the fixed start, not the last knot,
    /// not a corner blend's start, not on the window's last element.
    pub fn cuttable(&self, curves: &[Curve], k: usize) -> bool {
        let knot = &self.knots[k];
        k > 0 && k + 1 < self.knots.len() && knot.blend.is_none() && {
            knot.after.element + 1 < curves.len()
        }
    }

    /// Inserts a knot `u` seconds into piece `k` (not a blend, not at rest, `u` inside
    /// its time `T`), where its reference motion `φ(t) = φa + wa·t + (wb − wa)/(2T)·t²`
    /// is at `u`, with the reference's speed there: the pieces on both sides follow the
    /// same reference motion and take `u` and `T − u` (see "Streaming on a grid" in
    /// [`super`]). Returns the new knot's index, `k + 1`.
    pub fn insert_inside(&mut self, curves: &[Curve], k: usize, u: f64, t: f64) -> usize {
        let knot = inside(curves, &self.knots[k], &self.knots[k + 1], u, t);
        self.knots.insert(k + 1, knot);
        k + 1
    }

    /// As [`Knots::remove`] of knot `from` (one [`Knots::insert_inside`] put there)
    /// followed by [`Knots::insert_inside`] into piece `k` (`k < from`, indices
    /// without it), moving only the knots between: a window's cut tries one grid time
    /// after another inside the pieces before it.
    pub fn move_inside(
        &mut self,
        curves: &[Curve],
        from: usize,
        k: usize,
        u: f64,
        t: f64,
    ) -> usize {
        // Knot `k + 1` without the inserted one.
        let next = if from == k + 1 { k + 2 } else { k + 1 };
        let knot = inside(curves, &self.knots[k], &self.knots[next], u, t);
        self.knots[k + 1..=from].rotate_right(1);
        self.knots[k + 1] = knot;
        k + 1
    }

    /// Removes knot `k` (one [`Knots::insert_inside`] put there).
    pub fn remove(&mut self, k: usize) {
        self.knots.remove(k);
    }

    /// Path length of piece `k`.
    fn piece_length(&self, curves: &[Curve], k: usize) -> f64 {
        match self.knots[k].blend_index() {
            Some(j) => self.junctions[j].cut_length(),
            None => {
                let (curve, from, to) = self.piece_span(curves, k);
                curve.length(from, to)
            }
        }
    }

    /// Where a window continuing after knot `k` starts, and the element it starts on.
    pub fn start_after(&self, k: usize) -> (usize, Start) {
        let knot = &self.knots[k];
        let start = Start {
            param: knot.after.param,
            speed: knot.speed,
            junction: knot.junction_index().map(|j| self.junctions[j].clone()),
        };
        (knot.after.element, start)
    }

    /// Hands pieces `0..count` to `emit`.
    pub fn emit(
        &self,
        curves: &[Curve],
        pieces: &Pieces,
        count: usize,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) {
        for i in (0..pieces.len()).take_while(|&i| pieces.knot(i) < count) {
            let (end, velocity) = pieces.end_state(i);
            emit(&SegmentRef {
                end,
                velocity,
                duration: pieces.duration(i),
                line: curves[self.knots[pieces.knot(i)].after.element].line,
            });
        }
    }

    /// [`Knots::velocity`] as a vector of the curve's axes: along a junction's
    /// direction made in place, without a call.
    #[inline(always)]
    pub fn velocity_at(&self, k: usize, curve: &Curve, param: f64) -> Vector {
        let knot = &self.knots[k];
        match knot.junction_index() {
            Some(j) if knot.speed > 0.0 => {
                let direction = &self.junctions[j].direction;
                Vector::from_fn(direction.len(), |i| knot.speed * direction.values[i])
            }
            _ => {
                let mut out = curve.derivative_vector(param);
                let scale = knot.speed / norm(&out);
                out.iter_mut().for_each(|x| *x *= scale);
                out
            }
        }
    }

    /// The velocity of knot `k` leaving along (or arriving on) `curve` at `param`.
    pub fn velocity(&self, k: usize, curve: &Curve, param: f64, out: &mut [f64]) {
        let knot = &self.knots[k];
        match knot.junction_index() {
            Some(j) if knot.speed > 0.0 => {
                for (o, d) in out.iter_mut().zip(&self.junctions[j].direction) {
                    *o = knot.speed * d;
                }
            }
            _ => {
                curve.derivative(param, out);
                let scale = knot.speed / norm(out);
                out.iter_mut().for_each(|x| *x *= scale);
            }
        }
    }
}

/// The knot that splits piece `k` of `knots` at its middle parameter.
fn split_knot(knots: &[Knot], k: usize) -> Knot {
    let (from, to) = (knots[k].after, knots[k + 1].before);
    debug_assert_eq!(from.element, to.element);
    let place = Place {
        element: from.element,
        param: 0.5 * (from.param + to.param),
    };
    Knot::at(place, f64::INFINITY)
}

/// Inserts `count` elements into `v` in place, each after index `k` where
/// `make(v, item)` gives `(k, element)` for each of `items`, which come by descending
/// `k` (distinct, below `v.len()`). From the end: the vector grows once, and each element
/// moves up by the insertions before it (the elements between two insertions as one
/// run). `make` sees `v` with every element up to `k + 1` still in its place (every
/// element moved so far went at least one place above `k + 1`), so it reads them as
/// they were; no second vector is held.
fn insert_after<T: Copy, X>(
    v: &mut Vec<T>,
    count: usize,
    items: impl Iterator<Item = X>,
    mut make: impl FnMut(&[T], X) -> (usize, T),
) {
    let n = v.len();
    if count == 0 {
        return;
    }
    v.resize(n + count, v[n - 1]);
    let (mut end, mut run_end) = (n + count, n);
    for item in items {
        let (k, element) = make(v, item);
        let run = run_end - (k + 1);
        v.copy_within(k + 1..run_end, end - run);
        end -= run + 1;
        v[end] = element;
        run_end = k + 1;
    }
    debug_assert_eq!(end, run_end, "every element placed");
}

/// True when no axis has a velocity, acceleration or jerk limit.
fn no_limit(bounds: &AxisBounds) -> bool {
    bounds.free && bounds.jerk.iter().all(|&j| j == f64::INFINITY)
}

/// The knot `u` seconds into the piece from knot `a` to knot `b` of time `t` (see
/// [`Knots::insert_inside`]).
fn inside(curves: &[Curve], a: &Knot, b: &Knot, u: f64, t: f64) -> Knot {
    debug_assert_eq!(a.after.element, b.before.element);
    let (curve, from, to) = (&curves[a.after.element], a.after.param, b.before.param);
    let (wa, wb) = (a.speed / curve.rate(from), b.speed / curve.rate(to));
    let param = (from + wa * u + 0.5 * (wb - wa) / t * u * u).clamp(from, to);
    let w = wa + (wb - wa) * u / t;
    let place = Place {
        element: a.after.element,
        param,
    };
    let mut knot = Knot::at(place, w * curve.rate(param));
    knot.speed = knot.cap;
    knot
}

/// The fastest speed at the end of a piece of length `d` entered at `v` under `a`.
fn reachable(v: f64, a: f64, d: f64) -> f64 {
    if a.is_finite() {
        (v * v + 2.0 * a * d).sqrt()
    } else {
        f64::INFINITY
    }
}

/// The highest path speed on `[from, to]` of `curve`: the feed, each axis' velocity
/// limit and each axis' share of its acceleration limit for the centripetal part.
#[inline]
pub(super) fn speed_cap(curve: &Curve, from: f64, to: f64, bounds: &AxisBounds) -> f64 {
    let mut cap = curve.feed;
    if bounds.free {
        return cap;
    }
    for i in 0..bounds.velocity.len() {
        if bounds.velocity[i] == f64::INFINITY && bounds.acceleration[i] == f64::INFINITY {
            // No limit on the axis: every quotient below is infinite (or NaN), no cap.
            continue;
        }
        let (tangent, normal) = curve.axis_factors(from, to, i);
        if tangent > 0.0 {
            cap = cap.min(bounds.velocity[i] / tangent);
        }
        if normal > 0.0 {
            cap = cap.min((NORMAL_SHARE * bounds.acceleration[i] / normal).sqrt());
        }
    }
    cap
}

/// The tangential acceleration left on `[from, to]` at speed `speed` on the worst axis.
#[inline]
fn tangential_accel(curve: &Curve, from: f64, to: f64, bounds: &AxisBounds, speed: f64) -> f64 {
    let mut accel = f64::INFINITY;
    // Where `speed²·normal` is finite on every axis, an axis with no acceleration limit
    // leaves infinite acceleration (or NaN, which `min` passes over): it is skipped.
    let finite_normal = curve
        .normal_bound()
        .is_some_and(|n| (speed * speed * n).is_finite());
    if finite_normal && bounds.free {
        return accel;
    }
    for i in 0..bounds.acceleration.len() {
        if finite_normal && bounds.acceleration[i] == f64::INFINITY {
            continue;
        }
        let (tangent, normal) = curve.axis_factors(from, to, i);
        let left = bounds.acceleration[i] - speed * speed * normal;
        if tangent > 0.0 {
            accel = accel.min(left.max(0.0) / tangent);
        }
    }
    accel
}

/// The most pieces one arc is cut into before its error is checked.
const MAX_ARC_PIECES: f64 = 65_536.0;

/// Parameters inside `curve` where knots go at first: an arc's equal pieces by the error
/// bound at constant speed (at least two). Pieces beside a junction passed at speed are
/// split later, where their bound needs it.
fn inner_params(curve: &Curve, tolerance: f64) -> impl Iterator<Item = f64> {
    // A tolerance of zero (or one so small that no count of pieces meets it) gives no
    // finite count: the knots stop at the bound and the error check refuses the plan.
    let n = curve.arc_piece_angle(tolerance).map_or(1, |angle| {
        let pieces = (curve.span / angle - 1e-9).ceil();
        match pieces.is_finite() {
            true => pieces.clamp(2.0, MAX_ARC_PIECES) as usize,
            false => MAX_ARC_PIECES as usize,
        }
    });
    let span = curve.span;
    (1..n).map(move |i| span * i as f64 / n as f64)
}

/// What every junction of a window is made under: the bounds and tolerances, `narrow`
/// (see [`Knots::new`]), and what the bounds limit, asked once per window.
#[derive(Clone, Copy)]
struct JunctionRules<'b> {
    bounds: &'b AxisBounds,
    tolerance: f64,
    corner: Option<f64>,
    narrow: bool,
    /// [`AxisBounds::accelerates`].
    accelerates: bool,
    /// [`AxisBounds::jerk_mode`].
    jerk: bool,
    /// [`AxisBounds::limits_speed`].
    limits_speed: bool,
}

impl<'b> JunctionRules<'b> {
    fn new(bounds: &'b AxisBounds, tolerance: f64, corner: Option<f64>, narrow: bool) -> Self {
        JunctionRules {
            bounds,
            tolerance,
            corner,
            narrow,
            accelerates: bounds.accelerates(),
            jerk: bounds.jerk_mode(),
            limits_speed: bounds.limits_speed(),
        }
    }
}

/// The junction from `a` into `b`, whose unit tangents at the joint are `tangents`
/// (arriving, leaving), pushed onto `out`; false, and nothing pushed, when it must be
/// an exact stop. Beside a junction passed at speed its pieces may turn over the zones
/// of [`zone`] (for the acceleration cap). The junction is written where it lies in
/// `out` (it is large) and taken back off where it cannot be passed at any speed.
fn junction(
    a: &Curve,
    b: &Curve,
    tangents: [&Vector; 2],
    rules: &JunctionRules<'_>,
    out: &mut Vec<Junction>,
) -> bool {
    let [t_in, t_out] = tangents;
    let n = t_in.len();
    let (mut sum, mut diff) = (Vector::zeros(n), Vector::zeros(n));
    for i in 0..n {
        let (x, y) = (t_in.values[i], t_out.values[i]);
        sum.values[i] = x + y;
        diff.values[i] = x - y;
    }
    let (sum_norm, diff_norm) = (norm(&sum), norm(&diff));
    let stops =
        !rules.accelerates && rules.corner.is_none() && turns_beyond_tangent(diff_norm, sum_norm);
    if sum_norm < 1e-6 || stops {
        return false;
    }
    out.push(Junction {
        direction: Vector::zeros(n),
        deviation: 0.0,
        blend: None,
        half_turn_sin: 0.5 * diff_norm,
        tolerance: rules.corner.unwrap_or(rules.tolerance),
        cap: a.feed.min(b.feed),
        transition: None,
    });
    let last = out.len() - 1;
    // The bisector, written where the junction lies (the sum made again, not read back:
    // a vector written one value at a time and read two at a time stalls), and its
    // difference from the arriving tangent.
    let junction = &mut out[last];
    let mut off = Vector::zeros(n);
    for i in 0..n {
        let d = (t_in.values[i] + t_out.values[i]) / sum_norm;
        junction.direction.values[i] = d;
        off.values[i] = d - t_in.values[i];
    }
    junction.deviation = norm(&off);
    let passes = junction_cap([a, b], tangents, &mut out[last], rules);
    if !passes {
        out.pop();
    }
    passes
}

/// Caps `junction` (from `a` into `b` with unit tangents `tangents`, as [`junction`]
/// makes it) under `rules`: a curvature transition, a corner blend, or the zones of a
/// junction passed at speed. Returns whether it can be passed at some speed.
fn junction_cap(
    [a, b]: [&Curve; 2],
    tangents: [&Vector; 2],
    junction: &mut Junction,
    rules: &JunctionRules<'_>,
) -> bool {
    let (bounds, tolerance, narrow) = (rules.bounds, rules.tolerance, rules.narrow);
    if rules.jerk && !narrow {
        if let Some(t) = super::transition::transition(a, b, tolerance) {
            junction.cap = junction.cap.min(t.cap(bounds));
            junction.tolerance = tolerance;
            junction.transition = Some(Box::new(t));
            return junction.cap > 0.0;
        }
    }
    let blends = rules.accelerates || rules.corner.is_some();
    if a.is_line() && b.is_line() && blends && junction.deviation > 1e-12 {
        // At equal end speeds the blend passes within L·sin(α/2)/2 of the corner (see
        // `blend_error`): L is sized for that, and unequal speeds are evened out where
        // they would take it farther. On a time grid, whose stretches move the inner
        // control points, L is sized by the triangle bound L·sin(α/2), which holds for
        // any of them.
        // Under a jerk limit the blend is the smooth pulse of `pieces`, within
        // L·sin(α/2)/3 of the corner at equal speeds (see `smooth_blend_error`).
        let share = match (narrow, rules.jerk) {
            (true, _) => 1.0,
            (false, true) => 3.0 * (1.0 - 1e-9),
            (false, false) => 2.0 * (1.0 - 1e-9),
        };
        let most = if rules.jerk { SMOOTH_BLEND_SPAN } else { 0.45 };
        let l = (share * junction.tolerance / junction.half_turn_sin)
            .min(most * a.span)
            .min(most * b.span);
        junction.blend = Some(l);
        let cap = if rules.jerk {
            smooth_blend_cap(tangents, l, bounds)
        } else {
            blend_cap(tangents, l, bounds)
        };
        junction.cap = junction.cap.min(cap);
    } else if rules.limits_speed {
        let zones = [zone(a, junction, tolerance), zone(b, junction, tolerance)];
        let cap = through_cap(&junction.direction, tangents, zones, bounds);
        junction.cap = junction.cap.min(cap);
    }
    junction.cap > 0.0
}

/// True when the turning angle `2·atan2(diff, sum)` of two unit tangents (`diff` and
/// `sum` the norms of their difference and sum) is over [`TANGENT_ANGLE`].
///
/// The same answer as that comparison, with `atan2` only near the bound: the angle is
/// `2·atan(diff / sum)`, increasing in `diff / sum`, so a ratio clearly below (above)
/// tan(`TANGENT_ANGLE` / 2) answers at once. "Clearly" is 10⁻⁶ relative, which moves the
/// angle by about 2·10⁻⁸ rad, far beyond the rounding of the product and of `atan2`.
fn turns_beyond_tangent(diff: f64, sum: f64) -> bool {
    /// tan(`TANGENT_ANGLE` / 2) = tan(1°).
    const HALF_TANGENT: f64 = 0.017_455_064_928_217_585;
    if diff < sum * (HALF_TANGENT * (1.0 - 1e-6)) {
        return false;
    }
    if diff > sum * (HALF_TANGENT * (1.0 + 1e-6)) {
        return true;
    }
    2.0 * libm::atan2(diff, sum) > TANGENT_ANGLE
}

/// Length of the zone beside a junction passed at speed whose piece's error
/// 4/27·L·deviation takes half the tolerance (at most 45 % of the element).
fn zone(c: &Curve, j: &Junction, tolerance: f64) -> f64 {
    if j.deviation <= 1e-12 {
        return 0.0;
    }
    (27.0 * 0.5 * tolerance / (4.0 * j.deviation)).min(0.45 * c.length(0.0, c.span))
}

/// Speed cap of a junction passed at speed: each axis' velocity along the bisector, and
/// the lateral acceleration 4·v²·|t_i − d_i|/L of the zone pieces of length L.
fn through_cap(
    direction: &Vector,
    tangents: [&Vector; 2],
    zones: [f64; 2],
    bounds: &AxisBounds,
) -> f64 {
    let mut cap = f64::INFINITY;
    for i in 0..direction.len() {
        if bounds.velocity[i] == f64::INFINITY && bounds.acceleration[i] == f64::INFINITY {
            // No limit on the axis: every quotient below is infinite (or NaN), no cap.
            continue;
        }
        if direction[i] != 0.0 {
            cap = cap.min(bounds.velocity[i] / direction[i].abs());
        }
        for (t, l) in tangents.iter().zip(zones) {
            let lateral = (t[i] - direction[i]).abs();
            if lateral > 0.0 && l > 0.0 {
                cap = cap.min((bounds.acceleration[i] * l / (4.0 * lateral)).sqrt());
            }
        }
    }
    cap
}

/// Speed cap of a corner blend of half-length L at equal end speeds v: its
/// acceleration at either end is v²·(u₂ − u₁)/(2L) on each axis.
fn blend_cap(tangents: [&Vector; 2], l: f64, bounds: &AxisBounds) -> f64 {
    let mut cap = f64::INFINITY;
    let [arriving, leaving] = tangents;
    for (i, (t1, t2)) in arriving.iter().zip(leaving.iter()).enumerate() {
        let turn = (t2 - t1).abs();
        if turn > 0.0 {
            cap = cap.min((2.0 * l * bounds.acceleration[i] / turn).sqrt());
        }
    }
    cap
}

/// Share of each axis' jerk limit a jerk-limited corner blend's turn takes at its cap; the
/// rest is for a change of speed along it (see [`BLEND_JERK_SHARE`]). On dense chords the
/// speed changes weigh more than the cap (which goes with the cube root of this share):
/// with mill.toml splines.dxf takes 2.90 times its time without `max_jerk` at 0.75 and
/// 0.15, 2.60 at 0.5 and 0.45.
const TURN_JERK_SHARE: f64 = 0.5;

/// Share of the least jerk limit the passes let a jerk-limited corner blend change speed
/// with, as an S-curve over its length `2L` (its pulse is steeper on its shorter part,
/// and the turn takes [`TURN_JERK_SHARE`]; the closed-form check slows what is over).
pub(super) const BLEND_JERK_SHARE: f64 = 0.45;

/// The margin of [`Knots::turn_time`] over a turn at the jerk limit.
const TURN_MARGIN: f64 = 2.0;

/// Largest share of either line a jerk-limited corner blend takes (0.45 without a jerk
/// limit): its cap grows with `L^(2/3)`, and the straight piece left between two blends
/// on dense chords is at rest in acceleration at both ends whatever its length.
const SMOOTH_BLEND_SPAN: f64 = 0.49;

/// Largest ratio of a jerk-limited corner blend's end speeds the passes allow: its pulse
/// needs them within a factor of two (see `Knots::smooth_blend`).
const BLEND_SPEED_RATIO: f64 = 1.5;

/// Speed cap of a jerk-limited corner blend of half-length L at equal end speeds v (see
/// `Knots::smooth_blend`): its acceleration peaks at `v²·|u₂ − u₁|/L` and its jerk is
/// `v³·|u₂ − u₁|/L²` on each axis; the jerk takes [`TURN_JERK_SHARE`] of the limit.
fn smooth_blend_cap(tangents: [&Vector; 2], l: f64, bounds: &AxisBounds) -> f64 {
    let mut cap = f64::INFINITY;
    let [arriving, leaving] = tangents;
    for (i, (t1, t2)) in arriving.iter().zip(leaving.iter()).enumerate() {
        let turn = (t2 - t1).abs();
        if turn > 0.0 {
            cap = cap.min((l * bounds.acceleration[i] / turn).sqrt());
            cap = cap.min(libm::cbrt(TURN_JERK_SHARE * bounds.jerk[i] * l * l / turn));
        }
    }
    cap
}

/// Share of the least jerk limit per unit of tangent that a piece's S-curve on an arc
/// uses as its path jerk: on a curve the turn adds jerk of its own, and the closed-form
/// check slows what is still over. On a line there is no turn: [`LINE_JERK_SHARE`].
const JERK_SHARE: f64 = 0.9;

/// Share of the least jerk limit per unit of tangent that a piece's S-curve on a line
/// uses: the rest keeps the parts' jerk, computed from their rounded times and speeds,
/// clear of the closed-form check's margin (at the whole limit some contours slow in
/// ever smaller steps and do not settle).
const LINE_JERK_SHARE: f64 = 0.99;

/// The path jerk of the S-curves on `[from, to]` of `curve`: the least `jerk_i / |t_i|`
/// over the axes, [`LINE_JERK_SHARE`] of it on a line and [`JERK_SHARE`] on an arc
/// (infinite when no axis the piece moves has a limit).
pub(super) fn path_jerk(curve: &Curve, from: f64, to: f64, bounds: &AxisBounds) -> f64 {
    let mut jerk = f64::INFINITY;
    for i in 0..bounds.jerk.len() {
        let (tangent, _) = curve.axis_factors(from, to, i);
        if tangent > 0.0 {
            jerk = jerk.min(bounds.jerk[i] / tangent);
        }
    }
    if curve.is_line() {
        LINE_JERK_SHARE * jerk
    } else {
        JERK_SHARE * jerk
    }
}

/// The shortest path length over which the speed goes from `va` to `vb`, at zero
/// tangential acceleration at both ends, under tangential acceleration `a` and path jerk
/// `j`: `(va + vb)/2 · (Δv/a + a/j)` when `Δv ≥ a²/j` (the acceleration reaches `a`),
/// else `(va + vb)·√(Δv/j)`.
pub(super) fn scurve_distance(va: f64, vb: f64, a: f64, j: f64) -> f64 {
    let dv = (vb - va).abs();
    if dv == 0.0 {
        return 0.0;
    }
    if !a.is_finite() && !j.is_finite() {
        return 0.0;
    }
    if dv * j >= a * a {
        0.5 * (va + vb) * (dv / a + a / j)
    } else {
        (va + vb) * (dv / j).sqrt()
    }
}

/// Bisection steps of [`scurve_peak`]: a fixed count, so the result is the same on every
/// run.
const BISECTIONS: usize = 64;

/// The fastest speed at the end of a piece of length `d` entered at `v` by an S-curve
/// (see [`scurve_distance`]), in closed form. The distance grows with the speed change
/// `Δ`; while `Δ < a²/j` it is `(2v + Δ)·√(Δ/j)`, so `s = √Δ` is the one real root of
/// `s³ + 2v·s = d·√j` (Cardano, `p = 2v ≥ 0`); beyond, `(2v + Δ)/2·(Δ/a + a/j) = d`
/// is a quadratic in `Δ`.
fn scurve_reachable(v: f64, a: f64, j: f64, d: f64) -> f64 {
    if !j.is_finite() {
        return reachable(v, a, d);
    }
    if d <= 0.0 {
        return v;
    }
    let (p, q) = (2.0 * v, d * j.sqrt());
    let root = (0.25 * q * q + p * p * p / 27.0).sqrt();
    let u = libm::cbrt(0.5 * q + root);
    // u − p/(3u) loses digits when p is large against q: the same root as q/(u² + p/3 +
    // p²/(9u²)), from (u − p/(3u))·(u² + p/3 + p²/(9u²)) = u³ − p³/(27u³) = q.
    let s = q / (u * u + p / 3.0 + p * p / (9.0 * u * u));
    let delta = s * s;
    if !a.is_finite() || delta * j < a * a {
        return v + delta;
    }
    // Δ²/a + Δ·(2v/a + a/j) + 2v·a/j − 2d = 0, the positive root.
    let b = p / a + a / j;
    let c = p * a / j - 2.0 * d;
    let disc = (b * b - 4.0 * c / a).max(0.0);
    // The root (−b + √disc)·a/2 as 2·(−c)/(b + √disc), without cancellation.
    v + (-2.0 * c / (b + disc.sqrt())).max(0.0)
}

/// The highest cruise speed (at most `cap`) of a line of length `d` from `va` to `vb` by
/// two S-curves, and the lengths of the rise and the fall.
fn scurve_peak(va: f64, vb: f64, cap: f64, a: f64, j: f64, d: f64) -> (f64, f64, f64) {
    let low = va.max(vb);
    let mut hi = cap.min(low + libm::cbrt(d * d * j));
    if a.is_finite() {
        hi = hi.min((a * d + 0.5 * (va * va + vb * vb)).sqrt());
    }
    let fits = |p: f64| scurve_distance(va, p, a, j) + scurve_distance(p, vb, a, j) <= d;
    let mut lo = low;
    if hi > lo {
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }
    (
        lo,
        scurve_distance(va, lo, a, j),
        scurve_distance(lo, vb, a, j),
    )
}

#[cfg(test)]
mod tests {
    use super::{scurve_distance, scurve_reachable, turns_beyond_tangent, TANGENT_ANGLE};

    /// A window keeps its knots in one vector (a split and the trapezoids insert in
    /// place), and the junction and blend indices are 32 bits: a knot is two places, two 32-bit junction indices,
    /// its cap, speed, last round and fixed flag, no more.
    #[test]
    fn a_knot_is_72_bytes() {
        assert_eq!(std::mem::size_of::<super::Knot>(), 72);
    }

    /// The quick answer is the `atan2` comparison's on tangent pairs turning by every
    /// angle, most of them within a few ulps of the bound, and on zeros, infinities, NaN.
    #[test]
    fn turns_beyond_tangent_is_the_atan2_comparison() {
        let mut pairs = vec![
            (0.0, 0.0),
            (0.0, 2.0),
            (2.0, 0.0),
            (f64::INFINITY, 1.0),
            (1.0, f64::INFINITY),
            (f64::INFINITY, f64::INFINITY),
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for k in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = state as f64 / u64::MAX as f64;
            // Half the angles within 3·10⁻⁶ of the bound (either side of the quick
            // answers' edge, 10⁻⁶), the rest anywhere in [0, π].
            let angle = match k % 2 {
                0 => TANGENT_ANGLE * (1.0 + (unit - 0.5) * 6e-6),
                _ => unit * std::f64::consts::PI,
            };
            // Two unit tangents `angle` apart: |t_in − t_out| and |t_in + t_out|.
            let (sin, cos) = libm::sincos(angle / 2.0);
            let ulps = (state >> 60) as i64 - 8;
            let diff = f64::from_bits((2.0 * sin).to_bits().wrapping_add_signed(ulps));
            pairs.push((diff, 2.0 * cos));
        }
        for (diff, sum) in pairs {
            let atan2 = 2.0 * libm::atan2(diff, sum) > TANGENT_ANGLE;
            assert_eq!(turns_beyond_tangent(diff, sum), atan2, "{diff:e} {sum:e}");
        }
    }

    /// The closed-form inversion against the distance it inverts: a speed a little
    /// under the one reached covers at most the length and one a little over at least
    /// it (the margin, 10⁻¹² of the speed, is a few units in the last place of `v + Δ`),
    /// on both sides of the branch point `Δ = a²/j`, from rest and at speed.
    #[test]
    fn scurve_reachable_inverts_the_distance() {
        let (a, j) = (1000.0, 45000.0);
        for v in [0.0, 0.01, 1.0, 20.0, 100.0] {
            for d in [1e-6, 1e-3, 0.01, 0.1, 0.5, 2.0, 10.0, 100.0] {
                let r = scurve_reachable(v, a, j, d);
                assert!(r > v, "{v} {d}: {r}");
                let margin = 1e-12 * r;
                let under = scurve_distance(v, (r - margin).max(v), a, j);
                let over = scurve_distance(v, r + margin, a, j);
                assert!(under <= d && over >= d, "{v} {d}: {under} {over}");
            }
        }
        // Without an acceleration limit: the triangular profile only.
        let r = scurve_reachable(5.0, f64::INFINITY, j, 1.0);
        let covered = scurve_distance(5.0, r, f64::INFINITY, j);
        assert!((covered - 1.0).abs() <= 1e-9, "{covered}");
    }
}

/// The shortcuts a window without limits takes (a line's kept unit tangent, the
/// junction's bisector written in place, `AxisBounds::free`, no known path without a
/// stopping distance, no limit check), each against the full computation made afresh,
/// bit for bit, on random programs of lines and arcs (helical, both ways round).
#[cfg(test)]
mod shortcut_tests {
    use super::{KnotStorage, Knots, Start};
    use crate::axis::{Axis, AXIS_COUNT};
    use crate::plan::path::{curve::Curve, AxisBounds, PathOptions, Vector};
    use crate::toolpath::{Arc, ArcDirection, Element, ElementKind, Plane, Span};
    use crate::vector::norm;

    /// A random program of `n` elements: chords of 0.2 along a wandering heading, one in
    /// four an arc through the next point, at random feeds.
    pub(super) fn program(seed: u64, n: usize) -> Vec<Element> {
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut at = [0.0; AXIS_COUNT];
        let mut elements = Vec::new();
        let mut heading = 0.0;
        for _ in 0..n {
            let mut end = at;
            // Most chords turn by under a degree (passed at speed), one in ten sharply.
            heading += 0.03 * (next() - 0.5) + if next() < 0.1 { 2.0 } else { 0.0 };
            (end[0], end[1]) = (
                at[0] + 0.2 * libm::cos(heading),
                at[1] + 0.2 * libm::sin(heading),
            );
            end[2] = at[2] + 0.01 * (next() - 0.5);
            let kind = if next() < 0.25 {
                let (mx, my) = (0.5 * (at[0] + end[0]), 0.5 * (at[1] + end[1]));
                let side = 0.05 + next();
                let direction = if next() < 0.5 {
                    ArcDirection::Clockwise
                } else {
                    ArcDirection::CounterClockwise
                };
                let (dx, dy) = (end[0] - at[0], end[1] - at[1]);
                ElementKind::Arc(Arc {
                    plane: Plane::XY,
                    center: [mx - side * dy, my + side * dx],
                    direction,
                    extra_turns: 0,
                })
            } else {
                ElementKind::Line
            };
            let feed = 10.0 + 40.0 * next();
            elements.push(Element {
                kind,
                start: at,
                end,
                feed,
                span: Span::default(),
            });
            at = end;
        }
        elements
    }

    /// The unit tangent as [`Curve::derivative`] over its norm.
    fn fresh_tangent(curve: &Curve, phi: f64) -> Vector {
        let mut t = Vector::zeros(curve.start.len());
        curve.derivative(phi, &mut t);
        let n = norm(&t);
        Vector::from_fn(t.len(), |i| t[i] / n)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The window's caps and cut without a stopping distance: as with the known path
    /// ahead of every knot computed.
    fn assert_window_shortcuts(knots: &mut Knots, curves: &[Curve]) {
        let mut capped = knots.clone();
        capped.cap_for_window(curves, f64::INFINITY);
        let mut ahead = Vec::new();
        knots.known_ahead(curves, &mut ahead);
        for (k, (knot, &d)) in knots.knots.iter().zip(&ahead).enumerate() {
            let cap = if knot.fixed {
                knot.cap
            } else {
                knot.cap.min((2.0 * f64::INFINITY * d).sqrt())
            };
            assert_eq!(capped.knots[k].cap.to_bits(), cap.to_bits());
        }
        let n = knots.knots.len();
        let last = curves.len() - 1;
        let cut = (1..n - 1).rev().find(|&k| {
            let knot = &knots.knots[k];
            knot.blend.is_none() && knot.after.element < last && (ahead[k] >= 0.0 || k <= n / 2)
        });
        assert_eq!(knots.cut(curves, 0.0), cut);
    }

    /// X, Y and Z with no limit, at a path tolerance of 1e-3.
    pub(super) fn xyz_without_limits() -> ([Axis; 3], PathOptions) {
        let options = PathOptions {
            tolerance: 1e-3,
            corner_tolerance: None,
            limits: Default::default(),
            quantum: None,
            servo_period: crate::defaults::SERVO_PERIOD_S,
            position_resolution: 0.0,
        };
        ([Axis::X, Axis::Y, Axis::Z], options)
    }

    /// The curves of random program `seed` (40 elements) on `axes` and their knots,
    /// starting at rest, at a path tolerance of 1e-3.
    fn random_knots_at_rest(seed: u64, axes: &[Axis], bounds: &AxisBounds) -> (Vec<Curve>, Knots) {
        let mut curves = Vec::new();
        for e in &program(seed, 40) {
            Curve::push_new(e, axes, &mut curves);
        }
        let start = Start {
            param: 0.0,
            speed: 0.0,
            junction: None,
        };
        let storage = KnotStorage::default();
        let knots = Knots::new(&curves, bounds, 1e-3, None, &start, false, storage);
        (curves, knots)
    }

    /// A split in place is the rebuild it replaced: every knot copied in order into a
    /// new vector, a knot at the middle parameter of each piece over the tolerance (not
    /// a corner blend) after its first knot; on random programs with random errors,
    /// none, some and all of them over.
    #[test]
    fn knots_split_in_place_are_those_rebuilt() {
        let (axes, options) = xyz_without_limits();
        let bounds = AxisBounds::new(&axes, &options);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for seed in 1..30 {
            let (_, mut knots) = random_knots_at_rest(seed, &axes, &bounds);
            for share in [0.0, 0.3, 1.0] {
                let errors: Vec<f64> = (0..knots.knots.len() - 1)
                    .map(|_| {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
                        if unit < share {
                            2.0
                        } else {
                            0.5
                        }
                    })
                    .collect();
                let mut rebuilt = Vec::new();
                for (k, knot) in knots.knots.iter().enumerate() {
                    rebuilt.push(*knot);
                    if k < errors.len() && errors[k] > 1.0 && knot.blend.is_none() {
                        let (a, b) = (knot.after, knots.knots[k + 1].before);
                        assert_eq!(a.element, b.element);
                        let place = super::Place {
                            element: a.element,
                            param: 0.5 * (a.param + b.param),
                        };
                        rebuilt.push(super::Knot::at(place, f64::INFINITY));
                    }
                }
                let added = rebuilt.len() > knots.knots.len();
                assert_eq!(knots.split_errors(&errors, 1.0), added);
                assert_eq!(format!("{:?}", knots.knots), format!("{rebuilt:?}"));
            }
        }
    }

    /// Trapezoid knots inserted in place: the knots before, bit for bit and in order,
    /// with knots between them only inside a line piece, each on the element of the
    /// knot before, past the one before it, short of the next knot, and at its peak (its
    /// cap and speed); with and without a jerk limit, on random programs planned once.
    #[test]
    fn trapezoid_knots_are_inserted_between_the_knots() {
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let mut added = 0;
        for jerk in [None, Some(5e4)] {
            let limit = crate::limits::AxisLimits {
                velocity: Some(80.0),
                acceleration: Some(800.0),
                jerk,
            };
            let options = PathOptions {
                tolerance: 1e-3,
                corner_tolerance: None,
                limits: axes.iter().map(|&a| (a, limit)).collect(),
                quantum: None,
                servo_period: crate::defaults::SERVO_PERIOD_S,
                position_resolution: 0.0,
            };
            let bounds = AxisBounds::new(&axes, &options);
            for seed in 1..20 {
                let (curves, mut knots) = random_knots_at_rest(seed, &axes, &bounds);
                knots.plan_speeds(&curves, &bounds);
                let before = knots.knots.clone();
                let any = knots.add_trapezoids(&curves, &bounds);
                assert_eq!(any, knots.knots.len() > before.len());
                added += knots.knots.len() - before.len();
                let mut i = 0;
                let mut last_param = f64::NEG_INFINITY;
                for knot in &knots.knots {
                    if i < before.len() && format!("{knot:?}") == format!("{:?}", before[i]) {
                        last_param = knot.after.param;
                        i += 1;
                        continue;
                    }
                    let (prev, next) = (&before[i - 1], &before[i]);
                    assert!(curves[prev.after.element].is_line());
                    assert_eq!(knot.after.element, prev.after.element);
                    assert_eq!(knot.before.element, prev.after.element);
                    assert!(knot.after.param > last_param, "{knot:?}");
                    assert!(knot.after.param < next.before.param, "{knot:?}");
                    assert_eq!(next.before.element, prev.after.element);
                    assert_eq!(knot.speed.to_bits(), knot.cap.to_bits());
                    last_param = knot.after.param;
                }
                assert_eq!(i, before.len(), "every knot kept, in order");
            }
        }
        assert!(added > 100, "{added} trapezoid knots");
    }

    #[test]
    fn without_limits_the_shortcuts_are_the_full_computation() {
        let (axes, options) = xyz_without_limits();
        let bounds = AxisBounds::new(&axes, &options);
        assert!(bounds.free);
        let full = AxisBounds {
            free: false,
            ..bounds.clone()
        };
        let mut junctions = 0;
        for seed in 1..40 {
            let mut curves = Vec::new();
            for e in &program(seed, 60) {
                Curve::push_new(e, &axes, &mut curves);
            }
            for c in &curves {
                for phi in [0.0, 0.5 * c.span, c.span] {
                    assert_eq!(bits(&c.unit_tangent(phi)), bits(&fresh_tangent(c, phi)));
                }
            }
            let start = Start {
                param: 0.0,
                speed: 0.0,
                junction: None,
            };
            let storage = KnotStorage::default();
            let mut knots = Knots::new(&curves, &bounds, 1e-3, None, &start, false, storage);
            let mut pieces = crate::plan::path::piece::Pieces::default();
            assert!(crate::plan::path::settle_into(
                &mut knots,
                &curves,
                &bounds,
                1e-3,
                &mut pieces
            ));
            for knot in &knots.knots {
                let Some(j) = knot.junction_index() else {
                    continue;
                };
                let (a, b) = (&curves[knot.before.element], &curves[knot.after.element]);
                let (t_in, t_out) = (fresh_tangent(a, a.span), fresh_tangent(b, 0.0));
                let sum = Vector::from_fn(3, |i| t_in[i] + t_out[i]);
                let direction = Vector::from_fn(3, |i| sum[i] / norm(&sum));
                let off = Vector::from_fn(3, |i| direction[i] - t_in[i]);
                let junction = &knots.junctions[j];
                assert_eq!(bits(&junction.direction), bits(&direction));
                assert_eq!(junction.deviation.to_bits(), norm(&off).to_bits());
                junctions += 1;
            }
            for k in 0..knots.knots.len() - 1 {
                let (quick, slow) = (
                    knots.piece_way(&curves, &bounds, k),
                    knots.piece_way(&curves, &full, k),
                );
                assert_eq!(format!("{quick:?}"), format!("{slow:?}"));
            }
            for piece in &pieces {
                assert_eq!(piece.limit_factor(&bounds), 1.0);
            }
            assert_window_shortcuts(&mut knots, &curves);
        }
        assert!(junctions > 600, "{junctions} junctions");
    }
}
