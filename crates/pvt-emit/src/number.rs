//! Number formatting shared by the back ends: fixed decimals and shortest round-trip.
//!
//! Owns how a float becomes text. Both forms are deterministic on every machine, and
//! neither ever prints `-0`.

use std::fmt::Write as _;

/// Powers of ten a fixed-decimal number may be scaled by.
const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];

/// Appends `x` with exactly `decimals` digits after the point, never as negative zero.
///
/// `x` is scaled by `10^decimals` in binary floating point and rounded half away from
/// zero to an integer, which is printed with the point inserted: the same bytes on every
/// machine, and many times faster than exact decimal formatting. Values whose scaled
/// magnitude reaches 2^53 (where integers stop being exact) use Rust's exact formatting.
pub fn push_fixed(out: &mut String, x: f64, decimals: usize) {
    let scaled = (x * POW10[decimals.min(9)]).round();
    if decimals > 9 || scaled.abs() >= 9_007_199_254_740_992.0 {
        let start = out.len();
        write!(out, "{x:.decimals$}").expect("writing to a String cannot fail");
        if out.as_bytes()[start] == b'-' && out[start + 1..].bytes().all(|b| b == b'0' || b == b'.')
        {
            out.remove(start);
        }
        return;
    }
    let n = scaled as i64;
    if n < 0 {
        out.push('-');
    }
    let mut digits = itoa::Buffer::new();
    let text = digits.format(n.unsigned_abs());
    if text.len() <= decimals {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', decimals - text.len()));
        out.push_str(text);
    } else {
        let (int, frac) = text.split_at(text.len() - decimals);
        out.push_str(int);
        if decimals > 0 {
            out.push('.');
            out.push_str(frac);
        }
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
    fn fixed_matches_exact_formatting_away_from_ties() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..100_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = (state as f64 / u64::MAX as f64 - 0.5) * 2e6;
            for d in [0, 3, 4, 6] {
                let exact = format!("{x:.d$}");
                let exact = if exact.starts_with('-')
                    && exact[1..].bytes().all(|b| b == b'0' || b == b'.')
                {
                    exact[1..].to_string()
                } else {
                    exact
                };
                // Only a value within an ulp of a tie may round the other way.
                let tie = ((x * POW10[d]).abs().fract() - 0.5).abs() < 1e-6;
                if !tie {
                    assert_eq!(fixed(x, d), exact, "{x} with {d} decimals");
                }
            }
        }
        assert_eq!(fixed(0.0000005, 6), "0.000001");
        assert_eq!(fixed(1e300, 2).len(), 304);
        assert_eq!(fixed(-0.25, 0), "0");
        assert_eq!(fixed(12.5, 0), "13");
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
