//! The geometry of LinuxCNC's lathe cycles G70 (finishing), G71 and G72 (roughing, with
//! their .1 and .2 variants): a profile of lines and arcs in the ZX plane, its offsets,
//! and the passes that cut it, as LinuxCNC 2.9's `interp_g7x.cc` makes them.
//!
//! Owns the profile ([`Segment`]s as points `z + i·x`, fillets and chamfers at corners),
//! turning it so that the cut runs towards −Z and −X (LinuxCNC's flips and its quarter
//! turn for G72), offsetting it by a distance (arcs joining lines that part), and the
//! roughing passes (layers `I` apart, each cut until the profile is met, with an
//! escape of `R` back out, pockets cut as they are met); the moves come out as
//! [`Cut`]s in program coordinates. Every tolerance and decision is LinuxCNC's, so the
//! moves are its moves. It must not know words, spans or the interpreter
//! (`interpreter/lathe.rs` feeds it and runs its cuts).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// LinuxCNC's tolerance of the cycles, program units.
const TOLERANCE: f64 = 1e-6;

/// A point or vector of the ZX plane: `re` is Z, `im` is X.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Zx {
    pub re: f64,
    pub im: f64,
}

impl Zx {
    /// The point at Z `z`, X `x`.
    pub const fn new(z: f64, x: f64) -> Zx {
        Zx { re: z, im: x }
    }
    fn conj(self) -> Zx {
        Zx::new(self.re, -self.im)
    }
    fn abs(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
    /// The square of the length.
    pub fn norm(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Times `i`: a quarter turn counter-clockwise.
    fn turn(self) -> Zx {
        Zx::new(-self.im, self.re)
    }
    /// Times `k`.
    pub fn scale(self, k: f64) -> Zx {
        Zx::new(self.re * k, self.im * k)
    }
}

impl Add for Zx {
    type Output = Zx;
    fn add(self, o: Zx) -> Zx {
        Zx::new(self.re + o.re, self.im + o.im)
    }
}
impl Sub for Zx {
    type Output = Zx;
    fn sub(self, o: Zx) -> Zx {
        Zx::new(self.re - o.re, self.im - o.im)
    }
}
impl Mul for Zx {
    type Output = Zx;
    fn mul(self, o: Zx) -> Zx {
        Zx::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}
impl Div for Zx {
    type Output = Zx;
    fn div(self, o: Zx) -> Zx {
        let d = o.norm();
        Zx::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}
impl Neg for Zx {
    type Output = Zx;
    fn neg(self) -> Zx {
        Zx::new(-self.re, -self.im)
    }
}

/// What a segment of the profile is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Shape {
    Line,
    /// An arc about `center`, counter-clockwise in (Z, X) when `ccw` (G3).
    Arc {
        ccw: bool,
        center: Zx,
    },
    /// A fillet of this radius at the corner (an `A` word), made an arc by the finish.
    Fillet(f64),
    /// A chamfer of this size at the corner (a `C` word), made a line by the finish.
    Chamfer(f64),
}

/// What a map of the plane does to a turn: keeps it (a move, a quarter turn) or
/// reverses it (a mirror).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Map {
    Turn,
    Mirror,
}

/// One segment of a profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment {
    pub start: Zx,
    pub end: Zx,
    pub shape: Shape,
}

/// A move of a cycle, program coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Cut {
    Rapid(Zx),
    Feed(Zx),
    Arc { ccw: bool, center: Zx, end: Zx },
}

/// Which roughing cycle: G71 (layers along Z) or G72 (facing, layers along X), and
/// which pockets it cuts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Roughing {
    /// G72.
    pub facing: bool,
    /// 0: everything (G7x), 1: no pockets (G7x.1), 2: after the first pocket (G7x.2).
    pub pockets: u8,
}

/// The numbers of a cycle block, program units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Numbers {
    /// Where the cycle starts (its X Z, else where the tool is).
    pub start: Zx,
    /// D: the distance left to the profile (G70: the first pass's).
    pub d: f64,
    /// E: G70's last pass's distance.
    pub e: f64,
    /// I: the depth of a roughing layer.
    pub i: f64,
    /// P: G70's passes.
    pub p: f64,
    /// R: the escape of a roughing pass.
    pub r: f64,
    /// U, W: the profile moved by them (X, Z).
    pub shift: Zx,
}

/// Why LinuxCNC refuses a cycle, as its message says it.
pub(crate) type Refusal = String;

impl Segment {
    pub fn line(start: Zx, end: Zx) -> Segment {
        Segment {
            start,
            end,
            shape: Shape::Line,
        }
    }

    fn center(&self) -> Option<Zx> {
        match self.shape {
            Shape::Arc { center, .. } => Some(center),
            _ => None,
        }
    }

    /// The segment moved `distance` to its left (a line) or its radius grown by it
    /// towards its turn (an arc), as LinuxCNC offsets it.
    fn offset(&mut self, distance: f64) {
        match self.shape {
            Shape::Arc { ccw, center } => {
                let radius = (self.start - center).abs();
                let sign = if ccw { 1.0 } else { -1.0 };
                let factor = (radius + sign * distance) / radius;
                self.start = (self.start - center).scale(factor) + center;
                self.end = (self.end - center).scale(factor) + center;
            }
            _ => {
                let along = self.start - self.end;
                let d = along.turn().scale(distance / along.abs());
                self.start = self.start + d;
                self.end = self.end + d;
            }
        }
    }

    /// LinuxCNC's size of a segment: a line's length, an arc's chord or radius,
    /// whichever is shorter.
    fn size(&self) -> f64 {
        match self.shape {
            Shape::Arc { center, .. } => (self.start - self.end)
                .abs()
                .min((self.start - center).abs()),
            _ => (self.start - self.end).abs(),
        }
    }

    /// Whether the segment runs towards −Z without rising above its ends (an arc), as
    /// the cycles need.
    fn monotonic(&self) -> bool {
        match self.shape {
            Shape::Arc { ccw, center } => {
                let entry = (self.start - center).im;
                let exit = (self.end - center).im;
                let dz = (self.end - self.start).re;
                match ccw {
                    true => entry >= -1e-3 && exit >= -1e-3 && dz <= -1e-3,
                    false => entry <= 1e-3 && exit <= 1e-3 && dz <= -1e-3,
                }
            }
            Shape::Fillet(_) | Shape::Chamfer(_) => true,
            Shape::Line => (self.end - self.start).re <= 1e-3,
        }
    }

    /// Applies `f` to every point, reversing an arc's turn when `f` mirrors.
    fn map(&mut self, f: impl Fn(Zx) -> Zx, kind: Map) {
        self.start = f(self.start);
        self.end = f(self.end);
        if let Shape::Arc { ccw, center } = self.shape {
            self.shape = Shape::Arc {
                ccw: ccw ^ (kind == Map::Mirror),
                center: f(center),
            };
        }
    }

    /// Where the segment crosses `x`: the Z of each crossing, in LinuxCNC's order.
    fn crossings(&self, x: f64) -> Vec<f64> {
        match self.shape {
            Shape::Arc { ccw, center } => {
                let r = (self.start - center).abs();
                let s = -(x - r - center.im) * (x + r - center.im);
                if s < -TOLERANCE {
                    return Vec::new();
                }
                let s = s.max(0.0).sqrt();
                [Zx::new(center.re + s, x), Zx::new(center.re - s, x)]
                    .into_iter()
                    .filter(|p| self.on_arc(ccw, center, *p))
                    .map(|p| p.re)
                    .collect()
            }
            _ => {
                let (a, b) = (self.start, self.end);
                if a.im.min(b.im) > x + TOLERANCE || a.im.max(b.im) < x - TOLERANCE {
                    return Vec::new();
                }
                if (a.im - b.im).abs() < TOLERANCE {
                    return vec![a.re, b.re];
                }
                vec![(x - a.im) / (b.im - a.im) * (b.re - a.re) + a.re]
            }
        }
    }

    /// Whether `p` (on the circle) lies within the arc.
    fn on_arc(&self, ccw: bool, center: Zx, p: Zx) -> bool {
        let cross = |a: Zx| ((a - center).conj() * (p - center)).im;
        match ccw {
            true => cross(self.start) >= -TOLERANCE && cross(self.end) <= TOLERANCE,
            false => cross(self.start) <= TOLERANCE && cross(self.end) >= -TOLERANCE,
        }
    }

    /// The cut along the segment to its end.
    fn cut(&self) -> Cut {
        match self.shape {
            Shape::Arc { ccw, center } => Cut::Arc {
                ccw,
                center,
                end: self.end,
            },
            _ => Cut::Feed(self.end),
        }
    }

    /// The top of an arc (counter-clockwise, turning back up past its centre): where a
    /// climb along it stops.
    fn arc_top(&self, center: Zx) -> Zx {
        match self.end.re < center.re {
            true => Zx::new(center.re, center.im + (self.start - center).abs()),
            false => self.end,
        }
    }
}

/// The end of `prev` and the start of `next` moved to where they meet (the circle
/// and the line, the two circles, the two lines), as LinuxCNC joins them.
fn join(prev: &mut Segment, next: &mut Segment) -> Result<(), Refusal> {
    match (prev.center(), next.center()) {
        (None, None) => {
            let rot = (next.start - next.end)
                .conj()
                .scale(1.0 / (next.start - next.end).abs());
            let ps = (prev.start - next.end) * rot;
            let pe = (prev.end - next.end) * rot;
            if (ps - pe).im == 0.0 {
                return Err("Cannot intersect parallel lines".into());
            }
            let f = ps.im / (ps - pe).im;
            let at = (ps + (pe - ps).scale(f)) / rot + next.end;
            next.start = at;
            prev.end = at;
        }
        (Some(center), None) => {
            if (next.start - prev.end).abs() < TOLERANCE {
                return Ok(());
            }
            let at = line_circle(next.start, next.end, center, prev.end, next.start);
            next.start = at;
            prev.end = at;
        }
        (None, Some(center)) => {
            if (next.start - prev.end).abs() < TOLERANCE {
                return Ok(());
            }
            let at = line_circle(prev.start, prev.end, center, next.end, next.start);
            next.start = at;
            prev.end = at;
        }
        (Some(prev_center), Some(center)) => {
            let a = (next.start - center).abs();
            let b = (prev.start - prev_center).abs();
            let c = (center - prev_center).abs();
            let cos = (c * c + a * a - b * b) / 2.0 / a / c;
            let rot = Zx::new(cos, (1.0 - (cos * cos).min(1.0)).sqrt());
            let at = (rot * (prev_center - center)).scale(a / c) + center;
            prev.end = at;
            next.start = at;
        }
    }
    Ok(())
}

/// Of the points where the line through `a` and `b` meets the circle about `center`
/// through `on`, the one nearer `near`.
fn line_circle(a: Zx, b: Zx, center: Zx, on: Zx, near: Zx) -> Zx {
    let rot = (a - b).conj().scale(1.0 / (a - b).abs());
    let pe = (on - b) * rot;
    let pc = (center - b) * rot;
    let half = (pc - pe).norm() - pc.im * pc.im;
    let half = half.max(0.0).sqrt();
    let s1 = Zx::new(pc.re + half, 0.0) / rot + b;
    let s2 = Zx::new(pc.re - half, 0.0) / rot + b;
    match (near - s1).abs() < (near - s2).abs() {
        true => s1,
        false => s2,
    }
}

/// A profile as the cycles turn it, and the turns made: bit 4 a quarter turn (G72),
/// bit 2 X mirrored, bit 1 Z mirrored.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Profile {
    pub segments: Vec<Segment>,
    flips: u8,
}

impl Profile {
    /// The profile of `segments` (the first from the cycle's start to the profile).
    pub fn new(segments: Vec<Segment>) -> Profile {
        Profile { segments, flips: 0 }
    }

    fn each(&mut self, f: impl Fn(Zx) -> Zx + Copy, kind: Map) {
        for s in &mut self.segments {
            s.map(f, kind);
        }
    }

    /// A quarter turn, so that G72's layers along X are G71's along Z.
    fn rotate(&mut self) {
        self.each(|p| Zx::new(p.im, -p.re), Map::Turn);
        self.flips ^= 4;
    }

    /// Mirrors the profile so that it runs towards −Z and −X.
    fn swap(&mut self) {
        let (Some(first), Some(last)) = (self.segments.first(), self.segments.last()) else {
            return;
        };
        let direction = first.end - last.end;
        if direction.im > 0.0 {
            self.each(Zx::conj, Map::Mirror);
            self.flips ^= 2;
        }
        if direction.re < 0.0 {
            self.each(|p| -p.conj(), Map::Mirror);
            self.flips ^= 1;
        }
    }

    /// A cut back in the program's frame: the turns undone, last first.
    fn unturn(&self, cut: Cut) -> Cut {
        let (flips, point) = (self.flips, move |mut p: Zx| {
            if self.flips & 1 != 0 {
                p = -p.conj();
            }
            if self.flips & 2 != 0 {
                p = p.conj();
            }
            if self.flips & 4 != 0 {
                p = Zx::new(-p.im, p.re);
            }
            p
        });
        let mirrored = (flips & 1 != 0) ^ (flips & 2 != 0);
        match cut {
            Cut::Rapid(p) => Cut::Rapid(point(p)),
            Cut::Feed(p) => Cut::Feed(point(p)),
            Cut::Arc { ccw, center, end } => Cut::Arc {
                ccw: ccw ^ mirrored,
                center: point(center),
                end: point(end),
            },
        }
    }

    /// Each segment runs towards −Z (the approach made vertical where it runs back).
    fn check_monotonic(&mut self) -> Result<(), Refusal> {
        if let Some(first) = self.segments.first_mut() {
            if (first.end - first.start).re > 0.0 {
                first.start.re = first.end.re;
            }
        }
        match self.segments.iter().all(Segment::monotonic) {
            true => Ok(()),
            false => Err("Not monotonic".into()),
        }
    }

    /// Fillets and chamfers made arcs and lines between their neighbours; segments
    /// shorter than 0.001 dropped.
    fn finish_corners(&mut self) -> Result<(), Refusal> {
        let n = self.segments.len();
        for k in 1..n.saturating_sub(1) {
            let size = match self.segments[k].shape {
                Shape::Fillet(d) | Shape::Chamfer(d) => d,
                _ => continue,
            };
            let (left, rest) = self.segments.split_at_mut(k);
            let (middle, right) = rest.split_at_mut(1);
            corner(&mut left[k - 1], &mut middle[0], &mut right[0], size)?;
        }
        self.segments.retain(|s| s.size() >= 1e-3);
        Ok(())
    }

    /// The profile moved `distance` towards the cycle's start (its first segment, the
    /// approach, kept), in steps no larger than half the shortest segment, arcs joining
    /// what parts and what turns back dropped, as LinuxCNC offsets it.
    fn add_distance(&mut self, distance: f64) -> Result<(), Refusal> {
        if self.segments.len() < 2 {
            return Ok(());
        }
        let first = self.segments[0];
        let last = self.segments[self.segments.len() - 1];
        let angle = (first.end - first.start) / (last.start - first.start);
        let distance = if angle.im < 0.0 { -distance } else { distance };
        let approach = self.segments.remove(0);
        let mut done = 0.0;
        let mut steps = 0;
        while done != distance && !self.segments.is_empty() {
            steps += 1;
            if steps > 100_000 {
                return Err("the profile does not offset".into());
            }
            let mut step = self
                .segments
                .iter()
                .map(|s| s.size() / 2.0)
                .fold(1e9, f64::min)
                .min((distance - done).abs());
            if distance < 0.0 {
                step = -step;
            }
            self.offset_step(step, distance)?;
            done += step;
        }
        let n = self.segments.len();
        for k in 0..n.saturating_sub(1) {
            let mid = (self.segments[k].end + self.segments[k + 1].start).scale(0.5);
            self.segments[k].end = mid;
            self.segments[k + 1].start = mid;
        }
        let mut approach = approach;
        if let Some(front) = self.segments.first() {
            approach.end = front.start;
        }
        self.segments.insert(0, approach);
        Ok(())
    }

    /// One step of [`Self::add_distance`].
    fn offset_step(&mut self, step: f64, distance: f64) -> Result<(), Refusal> {
        for s in &mut self.segments {
            s.offset(step);
        }
        self.segments.retain(|s| s.size() >= 1e-3);
        let mut k = 0;
        while k + 1 < self.segments.len() {
            if (self.segments[k].end - self.segments[k + 1].start).re > 1e-2 {
                let (mut s, mut e) = (self.segments[k], self.segments[k + 1]);
                s.offset(-step);
                e.offset(-step);
                let center = (s.end + e.start).scale(0.5);
                let bridge = Segment {
                    start: self.segments[k].end,
                    end: self.segments[k + 1].start,
                    shape: Shape::Arc {
                        ccw: distance > 0.0,
                        center,
                    },
                };
                self.segments.insert(k + 1, bridge);
                k += 1;
            }
            k += 1;
        }
        self.drop_reversed_and_join()
    }

    /// Drops what turned back (the shorter of a reversed segment and the one before it)
    /// and what shrank away, and joins the rest, as LinuxCNC walks its list.
    fn drop_reversed_and_join(&mut self) -> Result<(), Refusal> {
        let mut k = 0;
        let mut restarts = 0;
        while k + 1 < self.segments.len() {
            if !self.segments[k].monotonic() {
                if k == 0 {
                    return Err("Not monotonic".into());
                }
                let drop = match self.segments[k].size() < self.segments[k - 1].size() {
                    true => k,
                    false => k - 1,
                };
                self.segments.remove(drop);
                k = 0;
                restarts += 1;
                if restarts > 10_000 || self.segments.len() < 2 {
                    return Err("Not monotonic".into());
                }
            }
            if self.segments[k].size() < 1e-3 {
                self.segments.remove(k);
                // LinuxCNC goes on from the second segment.
                k = 1;
                continue;
            }
            let (left, right) = self.segments.split_at_mut(k + 1);
            join(&mut left[k], &mut right[0])?;
            k += 1;
        }
        Ok(())
    }
}

/// A fillet (radius `size`, an arc) or chamfer (a line) at the corner between `prev`
/// and `next`: both offset by `size` and met, the finish between their feet.
fn corner(
    prev: &mut Segment,
    finish: &mut Segment,
    next: &mut Segment,
    size: f64,
) -> Result<(), Refusal> {
    let parted = |size: f64| {
        let (mut p, mut n) = (*prev, *next);
        p.offset(size);
        n.offset(size);
        ((p.end - n.start).re > 1e-2, p, n)
    };
    let (mut size, (mut apart, mut p, mut n)) = (size, parted(size));
    if apart {
        size = -size;
        (apart, p, n) = parted(size);
    }
    if apart {
        return Err(format!(
            "Corner finish failed at ({}, {})",
            prev.end.re, prev.end.im
        ));
    }
    join(&mut p, &mut n)?;
    let center = (p.end + n.start).scale(0.5);
    p.offset(-size);
    n.offset(-size);
    prev.end = p.end;
    next.start = n.start;
    finish.start = p.end;
    finish.end = n.start;
    finish.shape = match finish.shape {
        Shape::Fillet(_) => Shape::Arc {
            ccw: (finish.start - center).im > 0.0 || (finish.end - center).im > 0.0,
            center,
        },
        _ => Shape::Line,
    };
    Ok(())
}

/// G70: the profile `passes` times, from `d` to `e` away from it, each pass from the
/// cycle's start.
pub(crate) fn finishing(profile: &Profile, n: &Numbers) -> Result<Vec<Cut>, Refusal> {
    let mut profile = profile.clone();
    if let Some(first) = profile.segments.first_mut() {
        first.start = n.start;
    }
    let mut test = profile.clone();
    test.segments.remove(0);
    test.swap();
    if !test.segments.iter().all(Segment::monotonic) {
        test.rotate();
        test.swap();
    }
    test.check_monotonic()?;
    if test.flips & 4 != 0 {
        profile.rotate();
    }
    profile.swap();
    profile.finish_corners()?;
    profile.check_monotonic()?;
    let mut cuts = Vec::new();
    let passes = n.p.trunc().max(0.0) as i64;
    for pass in (1..=passes).rev() {
        let distance = (pass - 1) as f64 * (n.d - n.e) / n.p + n.e;
        let mut path = profile.clone();
        path.add_distance(distance)?;
        let Some((first, rest)) = path.segments.split_first() else {
            continue;
        };
        cuts.push(profile.unturn(Cut::Rapid(first.start)));
        cuts.push(profile.unturn(Cut::Rapid(first.end)));
        cuts.extend(rest.iter().map(|s| profile.unturn(s.cut())));
    }
    Ok(cuts)
}

/// G71/G72 (`kind`): layers `I` deep from the cycle's start until the profile, `D` away
/// from it and moved by U W, is met, each escaping by R; pockets as `kind` says.
pub(crate) fn roughing(
    profile: &Profile,
    kind: Roughing,
    n: &Numbers,
) -> Result<Vec<Cut>, Refusal> {
    let mut profile = profile.clone();
    if let Some(first) = profile.segments.first_mut() {
        first.start = n.start;
    }
    if kind.facing {
        profile.rotate();
    }
    profile.swap();
    profile.finish_corners()?;
    profile.check_monotonic()?;
    profile.add_distance(n.d)?;
    let shift = Zx::new(n.shift.re, n.shift.im);
    profile.each(|p| p + shift, Map::Turn);
    let Some(front) = profile.segments.first().copied() else {
        return Ok(Vec::new());
    };
    let mut pocket = Pockets {
        delta: n.i.max(2.0 * TOLERANCE),
        escape: Zx::new(n.r, n.r),
        starts: vec![front.start],
        cuts: vec![Cut::Rapid(front.start)],
        budget: 10_000_000,
    };
    if let Some(last) = profile.segments.last().copied() {
        if last.end.im < front.start.im {
            let up = Zx::new(last.end.re, front.start.im);
            profile.segments.push(Segment::line(last.end, up));
        }
    }
    pocket.cut(&profile.segments, kind.pockets, front.start, 0)?;
    Ok(pocket.cuts.into_iter().map(|c| profile.unturn(c)).collect())
}

/// The state of a roughing cycle's passes.
struct Pockets {
    delta: f64,
    escape: Zx,
    starts: Vec<Zx>,
    cuts: Vec<Cut>,
    /// Steps left before the cycle is refused as endless.
    budget: u64,
}

impl Pockets {
    fn spend(&mut self) -> Result<(), Refusal> {
        self.budget = self.budget.checked_sub(1).ok_or("the cycle does not end")?;
        Ok(())
    }

    /// Cuts from `at` along `segments[k..]` in layers, as LinuxCNC's `pocket`.
    fn cut(
        &mut self,
        segments: &[Segment],
        mut cycle: u8,
        mut at: Zx,
        mut k: usize,
    ) -> Result<(), Refusal> {
        let mut x = self.starts.last().map_or(at.im, |s| s.im);
        if cycle == 2 {
            while k < segments.len() {
                if self.dive(&segments[k], &mut at, -1e9, k == 0)? {
                    break;
                }
                k += 1;
            }
            cycle = 3;
        }
        while k < segments.len() {
            self.spend()?;
            while x - TOLERANCE > at.im {
                x -= self.delta;
                self.spend()?;
            }
            if self.dive(&segments[k], &mut at, x, k == 0)? {
                return self.climb_out(segments, cycle, at, k);
            }
            if (at.im - x).abs() > TOLERANCE {
                k += 1;
                continue;
            }
            self.layer(segments, &mut k, &mut x, at);
        }
        Ok(())
    }

    /// After the dive along `segments[k]` stops: along the profile up, a pocket cut
    /// where it turns down again (unless G7x.1).
    fn climb_out(
        &mut self,
        segments: &[Segment],
        cycle: u8,
        mut at: Zx,
        k: usize,
    ) -> Result<(), Refusal> {
        if cycle == 1 {
            for s in &segments[k..] {
                self.climb_only(s, &mut at);
            }
            return Ok(());
        }
        for (j, s) in segments.iter().enumerate().skip(k) {
            if self.climb(s, &mut at)? {
                if cycle == 3 {
                    let last = self.starts.last().copied().unwrap_or(at);
                    if at.im > last.im && self.starts.len() > 1 {
                        self.starts.pop();
                    }
                    if self.starts.len() == 1 {
                        self.starts.push(at);
                    }
                }
                return self.cut(segments, cycle, at, j);
            }
        }
        Ok(())
    }

    /// One layer at `at`: cut along −Z to where the profile is met, escape and return.
    fn layer(&mut self, segments: &[Segment], k: &mut usize, x: &mut f64, at: Zx) {
        for (j, segment) in segments.iter().enumerate().skip(*k) {
            let crossings = segment.crossings(at.im);
            let (Some(&first), Some(&last)) = (crossings.first(), crossings.last()) else {
                continue;
            };
            let z = if j != *k { first } else { last };
            let distance = (z - at.re).abs();
            if z - TOLERANCE > at.re {
                continue;
            }
            if distance < TOLERANCE {
                if j == *k {
                    continue;
                }
                if (at - segment.start).abs() < TOLERANCE {
                    *k = j;
                } else {
                    *x -= self.delta;
                }
                return;
            }
            let mut to = Zx::new(z, at.im);
            self.cuts.push(Cut::Feed(to));
            let scale = (distance / 2.0 / self.escape.re).min(1.0);
            let escape = self.escape.scale(scale);
            to = to + escape;
            self.cuts.push(Cut::Rapid(to));
            self.cuts.push(Cut::Rapid(at - escape.conj()));
            self.cuts.push(match *k == 0 {
                true => Cut::Rapid(at),
                false => Cut::Feed(at),
            });
            *x -= self.delta;
            return;
        }
    }

    /// Down along `s` to `x` (or its end); true when `s` does not go down from here.
    fn dive(&mut self, s: &Segment, at: &mut Zx, x: f64, fast: bool) -> Result<bool, Refusal> {
        let go = |cuts: &mut Vec<Cut>, to: Zx| match fast {
            true => cuts.push(Cut::Rapid(to)),
            false => cuts.push(Cut::Feed(to)),
        };
        let Shape::Arc { ccw, center } = s.shape else {
            if s.start.im <= s.end.im + TOLERANCE {
                return Ok(true);
            }
            if x < s.end.im {
                go(&mut self.cuts, s.end);
                *at = s.end;
                return Ok(false);
            }
            let Some(&z) = s.crossings(x).first() else {
                return Err("x too large in straight dive".into());
            };
            *at = Zx::new(z, x);
            go(&mut self.cuts, *at);
            return Ok(false);
        };
        if (*at - s.end).abs() < TOLERANCE || (*at - s.end).re <= TOLERANCE {
            *at = s.end;
            return Ok(false);
        }
        let mut crossings = s.crossings(x);
        if crossings.is_empty() {
            crossings = s.crossings(x - TOLERANCE);
        }
        let arc = |end: Zx| Cut::Arc { ccw, center, end };
        if ccw {
            if at.re - TOLERANCE > center.re {
                return Ok(true);
            }
            match crossings.last() {
                Some(&z) if z <= center.re => {
                    *at = Zx::new(z, x);
                }
                _ => *at = s.end,
            }
            self.cuts.push(arc(*at));
            return Ok(false);
        }
        if at.re <= center.re {
            return Ok(true);
        }
        match crossings.first() {
            None => *at = s.end,
            Some(&z) if z < center.re => return Ok(false),
            Some(&z) => *at = Zx::new(z, x),
        }
        self.cuts.push(arc(*at));
        Ok(false)
    }

    /// Up along `s` from its start; true where it stops climbing (a pocket follows).
    fn climb(&mut self, s: &Segment, at: &mut Zx) -> Result<bool, Refusal> {
        let Shape::Arc { ccw, center } = s.shape else {
            if s.end.im + TOLERANCE < s.start.im {
                return Ok(true);
            }
            if (*at - s.start).abs() > TOLERANCE {
                return Err("How did we get here?".into());
            }
            self.cuts.push(Cut::Feed(s.end));
            *at = s.end;
            return Ok(false);
        };
        if !ccw {
            if at.re > center.re {
                return Ok(true);
            }
            if (*at - s.end).abs() > 1e-3 {
                self.cuts.push(s.cut());
            }
            *at = s.end;
            return Ok(false);
        }
        if at.re < center.re {
            return Ok(true);
        }
        let top = s.arc_top(center);
        if (*at - top).abs() > 1e-3 {
            self.cuts.push(Cut::Arc {
                ccw,
                center,
                end: top,
            });
        }
        *at = top;
        Ok(true)
    }

    /// G7x.1's last pass: up along `s` where it climbs from the current height.
    fn climb_only(&mut self, s: &Segment, at: &mut Zx) {
        let crossings = s.crossings(at.im);
        let (Some(&first), Some(&last)) = (crossings.first(), crossings.last()) else {
            return;
        };
        let Shape::Arc { ccw, center } = s.shape else {
            if s.end.im < s.start.im {
                return;
            }
            at.re = first;
            self.cuts.push(Cut::Feed(*at));
            self.cuts.push(Cut::Feed(s.end));
            *at = s.end;
            return;
        };
        let (z, end) = match ccw {
            false if last > center.re => return,
            false => (last, s.end),
            true if first < center.re => return,
            true => (first, s.arc_top(center)),
        };
        at.re = z;
        self.cuts.push(Cut::Feed(*at));
        if (*at - end).abs() > 1e-3 {
            self.cuts.push(Cut::Arc { ccw, center, end });
        }
        *at = end;
    }
}
