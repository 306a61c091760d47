//! Vector arithmetic on axis slices of any length.
//!
//! Owns the handful of operations the planners need on points of `dim` axes stored in
//! flat buffers; it must not allocate.

/// Dot product of two equally long slices.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Euclidean length of a slice, without overflow or underflow in between: when the plain
/// sum of squares overflows (components beyond ~1e154) or underflows, the components are
/// scaled by the largest one first.
pub fn norm(a: &[f64]) -> f64 {
    let plain = dot(a, a);
    if plain.is_finite() && plain > 1e-290 {
        return plain.sqrt();
    }
    let m = max_abs(a);
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * a.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
}

/// Writes `a - b` into `out`.
pub fn sub_into(a: &[f64], b: &[f64], out: &mut [f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x - y;
    }
}

/// Euclidean distance between two points (as [`norm`] of their difference).
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    let plain: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    if plain.is_finite() && plain > 1e-290 {
        return plain.sqrt();
    }
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    norm(&d)
}

/// Largest absolute coordinate of a slice (0 for an empty one).
pub fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn norm_survives_huge_and_tiny_components() {
        assert_eq!(norm(&[3.0, 4.0]), 5.0);
        assert!((norm(&[3e200, 4e200]) / 5e200 - 1.0).abs() < 1e-15);
        assert!((norm(&[3e-200, 4e-200]) / 5e-200 - 1.0).abs() < 1e-15);
        assert!((distance(&[1e211, 0.0], &[0.0, 0.0]) / 1e211 - 1.0).abs() < 1e-15);
        assert_eq!(norm(&[0.0, 0.0]), 0.0);
        assert_eq!(norm(&[f64::INFINITY, 1.0]), f64::INFINITY);
    }
}
