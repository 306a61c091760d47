//! Controller rules: what each format's controller accepts, in one table, and the check
//! of every piece against it before a back end writes it.
//!
//! Owns [`Caps`] (time quantum, shortest and longest piece, position and velocity units,
//! relative or absolute positions, buffer depth, whether the controller verifies the
//! trajectory before running it) and [`RuleCheck`], which [`crate::Checked`] runs on
//! every piece: the piece time against the format's shortest piece and its quantum,
//! every axis' cubic against the machine's travel limits (for every format: a relative
//! format such as the XPS trajectory leaves them to the host), and, for a controller that
//! verifies the whole trajectory (Newport XPS), the velocity (−68) and acceleration (−69)
//! limits and rest at the end of each contour (−70). Each refusal has its own code and
//! names the contour, the piece and the source line. It must not repair a piece: the
//! planner and quantizer satisfy the rules ([`Caps::default_quantum`] is `--quantize`'s
//! default), this only proves they did.

use crate::triggers::TriggerSupport;
use crate::validate::InvalidProgram;
use pvt_core::{Axis, HermiteSegment, SegmentRef};
use std::collections::BTreeMap;

/// Whether positions are where the axes go or how far they go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Positions {
    /// Absolute positions.
    Absolute,
    /// Displacements from the previous point.
    Relative,
}

/// What a format's controller accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Caps {
    /// The controller, in words.
    pub controller: &'static str,
    /// The grid the controller's piece times are on, seconds.
    pub time_quantum: Option<f64>,
    /// A time off the grid is refused (else the controller rounds it: PMAC's `TA`).
    pub quantum_required: bool,
    /// `--quantize`'s default for the format, seconds.
    pub default_quantum: Option<f64>,
    /// The shortest piece time the controller takes, seconds (0: any positive time).
    pub min_piece_seconds: f64,
    /// The longest piece time the format can express, seconds.
    pub max_piece_seconds: Option<f64>,
    /// Absolute positions or displacements.
    pub positions: Positions,
    /// Unit of written positions.
    pub position_unit: &'static str,
    /// Unit of written velocities.
    pub velocity_unit: &'static str,
    /// Positions are written in counts or microsteps: every axis needs counts per unit.
    pub scaled: bool,
    /// Pieces the controller buffers per axis (the host streams the rest).
    pub buffer_depth: Option<usize>,
    /// The controller verifies the whole trajectory before running it (XPS
    /// `MultipleAxesPVTVerification`): velocity, acceleration and rest at the end are
    /// checked here with its error codes.
    pub verifies: bool,
    /// Whether the program can hold trigger events (`--trigger-every`).
    pub triggers: TriggerSupport,
    /// A format written in counts: written velocity units per count/s (Galil 1, Zaber's
    /// native units 1.6384), so a velocity is whole at this times counts per unit.
    pub velocity_per_count: f64,
}

impl Caps {
    /// A format that takes any positive finite piece time in program units.
    pub const FREE: Caps = Caps {
        controller: "any",
        time_quantum: None,
        quantum_required: false,
        default_quantum: None,
        min_piece_seconds: 0.0,
        max_piece_seconds: None,
        positions: Positions::Absolute,
        position_unit: "program units",
        velocity_unit: "program units/s",
        scaled: false,
        buffer_depth: None,
        verifies: false,
        triggers: TriggerSupport::Written,
        velocity_per_count: 1.0,
    };

    /// The most whole counts change a piece of `seconds` on an axis at `counts_per_unit`:
    /// (velocity, acceleration), program units. The displacement is the difference of
    /// two positions each rounded by up to half a count (1 count), the end velocities are
    /// rounded by half a count/s each; in the cubic's acceleration at its ends,
    /// `6·Δd/T² + (4·Δv₀ + 2·Δv₁)/T`, that is `6/(c·T²) + 3/(c·T)`, and in its velocity
    /// (a displacement adds at most `1.5·Δd/T`, the end velocities at most their own)
    /// `1.5/(c·T) + 1/(2c)`. Zero for a format not written in counts.
    pub fn rounding_room(&self, counts_per_unit: f64, seconds: f64) -> (f64, f64) {
        if !self.scaled {
            return (0.0, 0.0);
        }
        let (c, t) = (counts_per_unit, seconds);
        (1.5 / (c * t) + 0.5 / c, 6.0 / (c * t * t) + 3.0 / (c * t))
    }

    /// The shortest whole number of `quantum`s at which whole counts change a piece's
    /// acceleration by at most `share` of `max_acceleration` (see [`Caps::rounding_room`]):
    /// `6x² + 3x ≤ share·a·c` with `x = 1/T`.
    pub fn counts_grid(
        &self,
        quantum: f64,
        counts_per_unit: f64,
        max_acceleration: f64,
        share: f64,
    ) -> f64 {
        let k = share * max_acceleration * counts_per_unit;
        let x = (-3.0 + (9.0 + 24.0 * k).sqrt()) / 12.0;
        let t = if x > 0.0 { 1.0 / x } else { f64::INFINITY };
        libm::ceil(t / quantum * (1.0 - 1e-12)).max(1.0) * quantum
    }
}

/// What the machine says about one axis: travel, the limits a verifying controller
/// checks, and counts per program unit for formats written in counts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisSetup {
    /// Lowest position the axis may reach, program units.
    pub min_position: Option<f64>,
    /// Highest position the axis may reach, program units.
    pub max_position: Option<f64>,
    /// Largest |velocity|, program units/s.
    pub max_velocity: Option<f64>,
    /// Largest |acceleration|, program units/s².
    pub max_acceleration: Option<f64>,
    /// Counts (Galil) or microsteps (Zaber) per program unit.
    pub counts_per_unit: Option<f64>,
}

/// Relative slack of every comparison: rounding of the planner's arithmetic, not room.
const SLACK: f64 = 1e-9;

/// The check of every piece of a program against its format's rules.
#[derive(Debug, Clone)]
pub struct RuleCheck {
    caps: Caps,
    axes: Vec<(Axis, AxisSetup)>,
    /// Position and velocity at the end of the last piece, per axis.
    at: Vec<(f64, f64)>,
    /// Source line of the last piece, and whether the open contour has one.
    last_line: u32,
    open: bool,
    /// Some axis has a rule a piece's cubic can break: travel limits, or counts or
    /// dynamics the format checks. Without one, a piece's time is all there is to check,
    /// and `at` is not needed.
    per_axis: bool,
}

impl RuleCheck {
    /// The check of `caps` on `axes`, with what `setup` says about each.
    pub fn new(caps: Caps, axes: &[Axis], setup: &BTreeMap<Axis, AxisSetup>) -> RuleCheck {
        let axes: Vec<(Axis, AxisSetup)> = axes
            .iter()
            .map(|a| (*a, setup.get(a).copied().unwrap_or_default()))
            .collect();
        let per_axis = caps.scaled || caps.verifies || axes.iter().any(|(_, s)| travel_limited(s));
        RuleCheck {
            caps,
            at: vec![(0.0, 0.0); axes.len()],
            axes,
            last_line: 0,
            open: false,
            per_axis,
        }
    }

    /// The first axis written in counts without counts per unit.
    pub fn missing_scale(&self) -> Option<Axis> {
        let scaled = self.caps.scaled;
        self.axes
            .iter()
            .find(|(_, s)| scaled && s.counts_per_unit.is_none())
            .map(|(a, _)| *a)
    }

    /// A contour starts at rest at `start`; the one before must have ended at rest.
    pub fn contour(&mut self, start: &[f64], contour: usize) -> Result<(), InvalidProgram> {
        self.close(contour.saturating_sub(1))?;
        for (at, p) in self.at.iter_mut().zip(start) {
            *at = (*p, 0.0);
        }
        for (i, p) in start.iter().enumerate() {
            self.travel(i, *p, contour, 0, self.last_line)?;
        }
        Ok(())
    }

    /// Ends the program: the last contour must end at rest.
    pub fn finish(&mut self, contour: usize) -> Result<(), InvalidProgram> {
        self.close(contour)
    }

    /// Checks one piece (`segment` of `contour`, 1-based).
    #[inline]
    pub fn piece(
        &mut self,
        seg: &SegmentRef<'_>,
        contour: usize,
        segment: usize,
    ) -> Result<(), InvalidProgram> {
        self.open = true;
        self.last_line = seg.line;
        let caps = &self.caps;
        // The usual piece (long enough, no grid asked for, nothing per axis) is answered
        // here; any other goes through every rule.
        let short = seg.duration < caps.min_piece_seconds * (1.0 - SLACK);
        if short || caps.quantum_required || self.per_axis {
            return self.piece_rules(seg, contour, segment);
        }
        Ok(())
    }

    /// [`RuleCheck::piece`]'s rules in full: the piece's time, then each axis.
    fn piece_rules(
        &mut self,
        seg: &SegmentRef<'_>,
        contour: usize,
        segment: usize,
    ) -> Result<(), InvalidProgram> {
        self.piece_time(seg, contour, segment)?;
        if !self.per_axis {
            return Ok(());
        }
        let (scaled, verifies) = (self.caps.scaled, self.caps.verifies);
        for i in 0..self.axes.len() {
            let (p0, v0) = self.at[i];
            let limited = travel_limited(&self.axes[i].1);
            if scaled {
                self.counts(i, (p0, v0), seg, (contour, segment))?;
            }
            if !(limited || verifies) {
                // No travel to keep and no dynamics to verify: nothing to compute.
                self.at[i] = (seg.end[i], seg.velocity[i]);
                continue;
            }
            let cubic = HermiteSegment::new(p0, v0, seg.end[i], seg.velocity[i], seg.duration);
            for p in position_extremes(&cubic) {
                self.travel(i, p, contour, segment, seg.line)?;
            }
            if verifies {
                self.dynamics(i, &cubic, contour, segment, seg.line)?;
            }
            self.at[i] = (seg.end[i], seg.velocity[i]);
        }
        Ok(())
    }

    /// The piece's time against the format's shortest piece and its grid.
    fn piece_time(
        &self,
        seg: &SegmentRef<'_>,
        contour: usize,
        segment: usize,
    ) -> Result<(), InvalidProgram> {
        let fail = |code, what| Err(refusal(code, what, contour, segment, seg.line));
        let caps = &self.caps;
        if seg.duration < caps.min_piece_seconds * (1.0 - SLACK) {
            return fail(
                "pvtc::emit::piece_too_short",
                format!(
                    "piece time {} s, under the {}'s shortest piece, {} s; pass --quantize \
                     (a grid of at least that) to merge short pieces into whole quanta",
                    seg.duration, caps.controller, caps.min_piece_seconds
                ),
            );
        }
        if let (Some(q), true) = (caps.time_quantum, caps.quantum_required) {
            let quanta = seg.duration / q;
            if (quanta - libm::round(quanta)).abs() > 1e-6 {
                return fail(
                    "pvtc::emit::piece_time_off_grid",
                    format!(
                        "piece time {} s, not a whole number of the {}'s {} s; leave out \
                         --quantize or give a multiple of it",
                        seg.duration, caps.controller, q
                    ),
                );
            }
        }
        Ok(())
    }

    /// The piece as the controller runs it, from whole counts: its velocity and
    /// acceleration against the machine's limits (`pvtc::emit::counts_over_limit`).
    fn counts(
        &self,
        i: usize,
        (p0, v0): (f64, f64),
        seg: &SegmentRef<'_>,
        (contour, segment): (usize, usize),
    ) -> Result<(), InvalidProgram> {
        let (axis, s) = &self.axes[i];
        let (Some(c), true) = (
            s.counts_per_unit,
            s.max_velocity.is_some() || s.max_acceleration.is_some(),
        ) else {
            return Ok(());
        };
        let whole = |x: f64, k: f64| libm::round(x * k) / k;
        let kv = c * self.caps.velocity_per_count;
        let cubic = HermiteSegment::new(
            whole(p0, c),
            whole(v0, kv),
            whole(seg.end[i], c),
            whole(seg.velocity[i], kv),
            seg.duration,
        );
        let (v, a) = peaks(&cubic);
        let over = |limit: Option<f64>, x: f64| limit.filter(|l| x > l * (1.0 + SLACK));
        let (what, x, l) = match (over(s.max_velocity, v), over(s.max_acceleration, a)) {
            (Some(l), _) => ("velocity", v, l),
            (_, Some(l)) => ("acceleration", a, l),
            _ => return Ok(()),
        };
        Err(refusal(
            "pvtc::emit::counts_over_limit",
            format!(
                "|{what}| {x} on axis {axis} in whole counts ({c} per unit), over its max_{what} \
                 {l}; give more counts per unit or a longer --quantize"
            ),
            contour,
            segment,
            seg.line,
        ))
    }

    fn close(&mut self, contour: usize) -> Result<(), InvalidProgram> {
        if !(self.caps.verifies && self.open) {
            return Ok(());
        }
        self.open = false;
        match self.axes.iter().zip(&self.at).find(|(_, at)| at.1 != 0.0) {
            None => Ok(()),
            Some(((axis, _), (_, v))) => Err(refusal(
                "pvtc::emit::not_at_rest",
                format!(
                    "a last piece ending at {v} units/s on axis {axis}; the {} refuses it \
                     (MultipleAxesPVTVerification -70: final velocity not zero)",
                    self.caps.controller
                ),
                contour,
                0,
                self.last_line,
            )),
        }
    }

    fn travel(
        &self,
        i: usize,
        p: f64,
        contour: usize,
        segment: usize,
        line: u32,
    ) -> Result<(), InvalidProgram> {
        let (axis, s) = &self.axes[i];
        let below = s.min_position.filter(|m| p < m - SLACK * (1.0 + m.abs()));
        let above = s.max_position.filter(|m| p > m + SLACK * (1.0 + m.abs()));
        let (word, limit) = match (below, above) {
            (Some(m), _) => ("below its min_position", m),
            (_, Some(m)) => ("above its max_position", m),
            _ => return Ok(()),
        };
        Err(refusal(
            "pvtc::emit::travel_limit",
            format!("axis {axis} at {p}, {word} {limit} (machine file)"),
            contour,
            segment,
            line,
        ))
    }

    fn dynamics(
        &self,
        i: usize,
        cubic: &HermiteSegment,
        contour: usize,
        segment: usize,
        line: u32,
    ) -> Result<(), InvalidProgram> {
        let (axis, s) = &self.axes[i];
        let (v, a) = peaks(cubic);
        let over = |limit: Option<f64>, x: f64| limit.filter(|l| x > l * (1.0 + SLACK));
        if let Some(l) = over(s.max_velocity, v) {
            return Err(refusal(
                "pvtc::emit::velocity_limit",
                format!(
                    "|velocity| {v} on axis {axis}, over its max_velocity {l}; the {} refuses \
                     it (MultipleAxesPVTVerification -68: velocity too high)",
                    self.caps.controller
                ),
                contour,
                segment,
                line,
            ));
        }
        if let Some(l) = over(s.max_acceleration, a) {
            return Err(refusal(
                "pvtc::emit::acceleration_limit",
                format!(
                    "|acceleration| {a} on axis {axis}, over its max_acceleration {l}; the {} \
                     refuses it (MultipleAxesPVTVerification -69: acceleration too high)",
                    self.caps.controller
                ),
                contour,
                segment,
                line,
            ));
        }
        Ok(())
    }
}

/// The machine file limits the axis' travel.
fn travel_limited(setup: &AxisSetup) -> bool {
    setup.min_position.is_some() || setup.max_position.is_some()
}

fn refusal(
    code: &'static str,
    what: String,
    contour: usize,
    segment: usize,
    line: u32,
) -> InvalidProgram {
    InvalidProgram {
        contour,
        segment,
        line,
        what,
        internal: false,
        code,
    }
}

/// The cubic's positions at its ends and where its velocity is zero inside it: its
/// lowest and highest positions are among them.
fn position_extremes(c: &HermiteSegment) -> impl Iterator<Item = f64> + '_ {
    // v(t) = v0 + a0·t + j·t²/2.
    let (a, b, k) = (c.jerk / 2.0, c.a0, c.v0);
    let roots: [Option<f64>; 2] = if a == 0.0 {
        [(b != 0.0).then(|| -k / b), None]
    } else {
        let disc = b * b - 4.0 * a * k;
        if disc < 0.0 {
            [None, None]
        } else {
            let r = disc.sqrt();
            [Some((-b - r) / (2.0 * a)), Some((-b + r) / (2.0 * a))]
        }
    };
    let inside = roots
        .into_iter()
        .flatten()
        .filter(move |t| *t > 0.0 && *t < c.duration);
    [0.0, c.duration]
        .into_iter()
        .chain(inside)
        .map(move |t| c.at(t).position)
}

/// The cubic's largest |velocity| and |acceleration| over its time.
fn peaks(c: &HermiteSegment) -> (f64, f64) {
    let (start, end) = (c.at(0.0), c.end());
    let mut v = start.velocity.abs().max(end.velocity.abs());
    if c.jerk != 0.0 {
        let t = -c.a0 / c.jerk;
        if t > 0.0 && t < c.duration {
            v = v.max(c.at(t).velocity.abs());
        }
    }
    let a = start.acceleration.abs().max(end.acceleration.abs());
    (v, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_piece_overshooting_its_end_reaches_its_peak_between_the_knots() {
        // From rest at 0 to 1 in 1 s ending at -3 units/s: the cubic overshoots past 1.
        let c = HermiteSegment::new(0.0, 0.0, 1.0, -3.0, 1.0);
        let top = position_extremes(&c).fold(f64::MIN, f64::max);
        // Sampled independently: the highest of a fine grid is at most the closed form.
        let sampled = (0..=10_000)
            .map(|k| c.at(k as f64 / 10_000.0).position)
            .fold(f64::MIN, f64::max);
        assert!(top > 1.0 && (top - sampled).abs() < 1e-6, "{top} {sampled}");
    }
}
