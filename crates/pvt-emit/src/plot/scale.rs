//! Scales of the plot: value ranges, the speed colour ramp, units and tick labels.
//!
//! Owns the mapping from numbers to what a reader sees (colours, padded ranges, label
//! text). It must not draw and must not sample the motion.

use super::PlotError;
use plotters::style::RGBColor;
use pvt_core::PvtProgram;

/// Colour steps of the speed scale.
pub(super) const BINS: usize = 32;

/// Anchors of the viridis colour map, slow (dark purple) to fast (yellow).
const RAMP: [(u8, u8, u8); 5] = [
    (68, 1, 84),
    (59, 82, 139),
    (33, 145, 140),
    (94, 201, 98),
    (253, 231, 37),
];

/// Colour of bin `bin` of [`BINS`].
pub(super) fn ramp(bin: usize) -> RGBColor {
    let x = bin.min(BINS - 1) as f64 / (BINS - 1) as f64 * (RAMP.len() - 1) as f64;
    let i = (x.floor() as usize).min(RAMP.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    let (a, b) = (RAMP[i], RAMP[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The bin of `value` on the scale `lo..hi`.
pub(super) fn bin(value: f64, (lo, hi): (f64, f64)) -> usize {
    if hi <= lo {
        return 0;
    }
    let x = ((value - lo) / (hi - lo)).clamp(0.0, 1.0);
    (x * (BINS - 1) as f64).round() as usize
}

/// Smallest and largest of `values`; an error when one is not finite or there is none.
pub(super) fn extent(values: impl Iterator<Item = f64>) -> Result<(f64, f64), PlotError> {
    let mut out: Option<(f64, f64)> = None;
    for v in values {
        if !v.is_finite() {
            return Err(PlotError::NotFinite);
        }
        out = Some(out.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
    }
    out.ok_or(PlotError::Empty)
}

/// `lo..hi` widened by 5 % a side (and to a non-empty range when `lo == hi`).
pub(super) fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    let span = hi - lo;
    let pad = if span > 0.0 {
        span * 0.05
    } else {
        (hi.abs() * 0.05).max(1.0)
    };
    (lo - pad, hi + pad)
}

/// Widens the ranges about their centres so one unit is as long on both axes of a
/// plotting area `pixels` (width, height) in size.
pub(super) fn equal_aspect(
    x: (f64, f64),
    y: (f64, f64),
    pixels: (u32, u32),
) -> ((f64, f64), (f64, f64)) {
    let (w, h) = (f64::from(pixels.0.max(1)), f64::from(pixels.1.max(1)));
    let per_pixel = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let about = |(lo, hi): (f64, f64), n: f64| {
        let mid = (lo + hi) / 2.0;
        (mid - per_pixel * n / 2.0, mid + per_pixel * n / 2.0)
    };
    (about(x, w), about(y, h))
}

/// A tick label: few significant digits, no trailing zeros, exponent when large.
pub(super) fn tick(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = if a >= 100.0 {
        0
    } else if a >= 1.0 {
        2
    } else {
        4
    };
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// Unit names of a program's quantities.
pub(super) struct Units {
    /// Unit of each axis column: the program's length unit, or `deg` for a rotary axis.
    pub axis: Vec<&'static str>,
    /// Unit of the vector speed's length.
    pub speed: &'static str,
}

impl Units {
    /// The units of `program`.
    pub(super) fn of(program: &PvtProgram) -> Units {
        let length = program.units.name();
        let axis: Vec<&'static str> = program
            .axes
            .iter()
            .map(|a| if a.is_rotary() { "deg" } else { length })
            .collect();
        let any_linear = program.axes.iter().any(|a| !a.is_rotary());
        let speed = if any_linear { length } else { "deg" };
        Units { axis, speed }
    }

    /// The distinct axis units joined with `suffix`, e.g. `mm/s` or `mm/s, deg/s`.
    pub(super) fn joined(&self, suffix: &str) -> String {
        let mut names: Vec<&str> = Vec::new();
        for u in &self.axis {
            if !names.contains(u) {
                names.push(u);
            }
        }
        let with: Vec<String> = names.iter().map(|u| format!("{u}{suffix}")).collect();
        with.join(", ")
    }
}
