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
    const EXACT_INTEGERS: f64 = 9_007_199_254_740_992.0; // 2^53
    let scaled = x * POW10[decimals.min(9)];
    let rounded = if scaled.abs() < EXACT_INTEGERS {
        round_half_away(scaled)
    } else {
        scaled
    };
    if decimals > 9 || rounded.abs() >= EXACT_INTEGERS {
        let start = out.len();
        write!(out, "{x:.decimals$}").expect("writing to a String cannot fail");
        if out.as_bytes()[start] == b'-' && out[start + 1..].bytes().all(|b| b == b'0' || b == b'.')
        {
            out.remove(start);
        }
        return;
    }
    let n = rounded as i64;
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

/// `x` (|x| < 2^53) rounded half away from zero, as `f64::round` does, without the call
/// into libm that `round` is on baseline x86-64: the integer part by truncation, and the
/// fraction `x − t`, which is exact here.
fn round_half_away(x: f64) -> f64 {
    let t = x as i64;
    let fraction = x - t as f64;
    let n = if fraction >= 0.5 {
        t + 1
    } else if fraction <= -0.5 {
        t - 1
    } else {
        t
    };
    n as f64
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
    fn round_half_away_is_f64_round() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut values = vec![
            0.5,
            -0.5,
            1.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        values.extend([
            4503599627370495.5,
            -4503599627370495.5,
            9007199254740991.0,
            1e-300,
        ]);
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let magnitude = [1.0, 1e3, 1e6, 1e9, 1e12, 1e15][(state % 6) as usize];
            let x = (state as f64 / u64::MAX as f64 - 0.5) * magnitude;
            values.extend([
                x,
                x.trunc() + 0.5,
                x.trunc() - 0.5,
                f64::from_bits(x.to_bits() + 1),
            ]);
        }
        for x in values {
            // Equal as numbers (a -0.0 from `round` prints as 0 either way).
            assert_eq!(round_half_away(x), x.round(), "{x}");
        }
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
