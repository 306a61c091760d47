//! Number formatting shared by the back ends: fixed decimals and shortest round-trip.
//!
//! Owns how a float becomes text. Both forms are deterministic on every machine, and
//! neither ever prints `-0`.

use std::fmt::Write as _;

/// Appends `x` with exactly `decimals` digits after the point, never as negative zero.
pub fn push_fixed(out: &mut String, x: f64, decimals: usize) {
    let start = out.len();
    write!(out, "{x:.decimals$}").expect("writing to a String cannot fail");
    if out.as_bytes()[start] == b'-' && out[start + 1..].bytes().all(|b| b == b'0' || b == b'.') {
        out.remove(start);
    }
}

/// Appends the shortest text that reads back as exactly `x` (ryu), never as `-0.0`.
pub fn push_exact(out: &mut String, x: f64) {
    let x = if x == 0.0 { 0.0 } else { x };
    let mut buffer = ryu::Buffer::new();
    out.push_str(buffer.format_finite(x));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(x: f64, d: usize) -> String {
        let mut s = String::new();
        push_fixed(&mut s, x, d);
        s
    }

    fn exact(x: f64) -> String {
        let mut s = String::new();
        push_exact(&mut s, x);
        s
    }

    #[test]
    fn fixed_rounds_and_never_prints_negative_zero() {
        assert_eq!(fixed(1.23456789, 6), "1.234568");
        assert_eq!(fixed(-1e-12, 6), "0.000000");
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-2.5, 1), "-2.5");
        assert_eq!(fixed(5000.0, 4), "5000.0000");
    }

    #[test]
    fn exact_round_trips() {
        for x in [0.1, 1.0 / 3.0, 1e-7, 12345.678, -2.0, 1e300] {
            assert_eq!(exact(x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(exact(-0.0), "0.0");
        assert_eq!(exact(5000.0), "5000.0");
    }
}
