//! Number formatting shared by the back ends: fixed decimals and shortest round-trip.
//!
//! Owns how a float becomes text. Both forms are deterministic on every machine, and
//! neither ever prints `-0`.

/// Powers of ten a fixed-decimal number may be scaled by.
const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];

/// Powers of ten a fixed-decimal number's integer may be split by.
const POW10_INT: [u64; 10] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
    1_000_000_000,
];

/// The two digits of every number below 100, in order.
static DIGIT_PAIRS: [u8; 200] = {
    let mut pairs = [0u8; 200];
    let mut n = 0;
    while n < 100 {
        pairs[2 * n] = b'0' + (n / 10) as u8;
        pairs[2 * n + 1] = b'0' + (n % 10) as u8;
        n += 1;
    }
    pairs
};

/// Appends `x` with exactly `DECIMALS` (at most 9) digits after the point, never as
/// negative zero.
///
/// `x` is scaled by `10^DECIMALS` in binary floating point and rounded half away from
/// zero to an integer, which is printed with the point inserted: the same bytes on every
/// machine, and many times faster than exact decimal formatting. Values whose scaled
/// magnitude reaches 2^53 (where integers stop being exact) use Rust's exact formatting.
#[inline]
pub fn push_fixed<const DECIMALS: usize>(out: &mut Vec<u8>, x: f64) {
    const EXACT_INTEGERS: f64 = 9_007_199_254_740_992.0; // 2^53
    const { assert!(DECIMALS <= 9, "at most 9 decimals") };
    let scaled = x * POW10[DECIMALS];
    if scaled.is_nan() || scaled.abs() >= EXACT_INTEGERS {
        return push_fixed_exactly(out, x, DECIMALS);
    }
    let n = round_half_away(scaled);
    let magnitude = n.unsigned_abs();
    let unit = POW10_INT[DECIMALS];
    let (int, fraction) = (magnitude / unit, magnitude % unit);
    // At most a sign, 20 digits and a point: the text is written in place in room made
    // for the longest, which is then cut back (no copy, no branch on the length).
    let start = out.len();
    out.resize(start + 32, 0);
    let text = &mut out[start..];
    let mut len = usize::from(n < 0);
    text[0] = b'-';
    len += write_integer(&mut text[len..], int);
    if DECIMALS > 0 {
        text[len] = b'.';
        write_fraction(&mut text[len + 1..len + 1 + DECIMALS], fraction as u32);
        len += 1 + DECIMALS;
    }
    out.truncate(start + len);
}

/// Writes `value` without leading zeros at the start of `slot` (which has room for 20
/// digits) and returns how many digits it took. Below 10^4 (most coordinates, speeds and
/// times) it takes no branch on the count of digits: four digits are made, and the
/// leading zeros shifted out.
#[inline(always)]
fn write_integer(slot: &mut [u8], value: u64) -> usize {
    if value >= 10_000 {
        let count = value.ilog10() as usize + 1;
        write_digits(&mut slot[..count], value);
        return count;
    }
    let (high, low) = (2 * (value / 100) as usize, 2 * (value % 100) as usize);
    let four = u32::from_le_bytes([
        DIGIT_PAIRS[high],
        DIGIT_PAIRS[high + 1],
        DIGIT_PAIRS[low],
        DIGIT_PAIRS[low + 1],
    ]);
    let count =
        1 + usize::from(value >= 10) + usize::from(value >= 100) + usize::from(value >= 1000);
    let digits = four >> (8 * (4 - count));
    slot[..4].copy_from_slice(&digits.to_le_bytes());
    count
}

/// Fills `slot` (at most 9 long) with the last `slot.len()` decimal digits of `value`,
/// zero-padded. Eight digits or more: the last eight at once ([`eight_digits`]). Fewer:
/// each pair of digits is divided out of `value` itself, so with the length known at
/// compile time the pairs are made side by side rather than one after another.
#[inline(always)]
fn write_fraction(slot: &mut [u8], value: u32) {
    // Below 10^9: every power of ten it is divided by fits in a u32.
    let pow10 = |n: usize| POW10_INT[n] as u32;
    let len = slot.len();
    if len >= 8 {
        slot[len - 8..].copy_from_slice(&eight_digits(value % pow10(8)));
        if len == 9 {
            slot[0] = b'0' + (value / pow10(8) % 10) as u8;
        }
        return;
    }
    for k in 0..len / 2 {
        let pair = 2 * (value / pow10(2 * k) % 100) as usize;
        let end = len - 2 * k;
        slot[end - 2..end].copy_from_slice(&DIGIT_PAIRS[pair..pair + 2]);
    }
    if len % 2 == 1 {
        slot[0] = b'0' + (value / pow10(len - 1) % 10) as u8;
    }
}

/// The eight decimal digits of `value` (below 10⁸, zero-padded), first digit first.
///
/// The digits are divided out side by side in the lanes of one u64 (SWAR): two lanes of
/// 32 bits hold the halves `value / 10⁴` and `value % 10⁴`, each split into hundreds in
/// 16-bit lanes and those into tens in bytes, by multiplying with a rounded-up reciprocal
/// and shifting: `⌊x·10486 / 2²⁰⌋ = ⌊x / 100⌋` for x < 10⁴ and `⌊x·103 / 2¹⁰⌋ = ⌊x / 10⌋`
/// for x < 100. No lane's product reaches the next lane's bits that the masks keep.
#[inline(always)]
fn eight_digits(value: u32) -> [u8; 8] {
    let v = u64::from(value);
    let halves = (v / 10_000) | ((v % 10_000) << 32);
    let hundreds = ((halves * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let pairs = hundreds | ((halves - hundreds * 100) << 16);
    let tens = ((pairs * 103) >> 10) & 0x000F_000F_000F_000F;
    let digits = tens | ((pairs - tens * 10) << 8);
    (digits + 0x3030_3030_3030_3030).to_le_bytes()
}

/// Fills `slot` with the last `slot.len()` decimal digits of `value`, zero-padded.
fn write_digits(slot: &mut [u8], mut value: u64) {
    let mut end = slot.len();
    while end >= 2 {
        let pair = 2 * (value % 100) as usize;
        slot[end - 2..end].copy_from_slice(&DIGIT_PAIRS[pair..pair + 2]);
        value /= 100;
        end -= 2;
    }
    if end == 1 {
        slot[0] = b'0' + (value % 10) as u8;
    }
}

/// [`push_fixed`] for values too large (or too many decimals) for the integer path.
fn push_fixed_exactly(out: &mut Vec<u8>, x: f64, decimals: usize) {
    let text = format!("{x:.decimals$}");
    let negative_zero = text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.');
    let text = if negative_zero { &text[1..] } else { &text };
    out.extend_from_slice(text.as_bytes());
}

/// True when `x` is a whole number (as `x.fract() == 0.0`, without the call into libm
/// that `trunc` is on baseline x86-64).
pub(crate) fn is_whole(x: f64) -> bool {
    const ALL_WHOLE: f64 = 4_503_599_627_370_496.0; // 2^52: every f64 beyond is whole
    if x.abs() >= ALL_WHOLE {
        return x.is_finite();
    }
    // |x| < 2^52 (NaN compares false above and fails here): truncation is exact.
    x == (x as i64) as f64
}

/// True when [`push_fixed`] prints `x` with a fraction of zeros (`820.0000` for
/// 820.0000000000001): the question a reader of the text asks, not whether `x` is whole.
pub(crate) fn prints_whole<const DECIMALS: usize>(x: f64) -> bool {
    const EXACT_INTEGERS: f64 = 9_007_199_254_740_992.0; // 2^53
    let scaled = x * POW10[DECIMALS];
    if scaled.is_nan() || scaled.abs() >= EXACT_INTEGERS {
        return is_whole(x);
    }
    round_half_away(scaled)
        .unsigned_abs()
        .is_multiple_of(POW10_INT[DECIMALS])
}

/// `x` (|x| < 2^53) rounded half away from zero, as `f64::round` does, without the call
/// into libm that `round` is on baseline x86-64: the integer part by truncation, and the
/// fraction `x − t`, which is exact here.
fn round_half_away(x: f64) -> i64 {
    let t = x as i64;
    let fraction = x - t as f64;
    // Without branches: which way a coordinate rounds is a coin toss for the predictor.
    t + i64::from(fraction >= 0.5) - i64::from(fraction <= -0.5)
}

/// Appends the shortest text that reads back as exactly `x` (ryu's text), never as `-0.0`.
///
/// A value that is a decimal of at most 9 places between 10⁻⁵ and 10⁶ (a programmed
/// coordinate, a round feed) is written by [`push_short_decimal`] at fixed-point speed;
/// any other goes to ryu. Both give the same bytes (tested on random values).
pub fn push_exact(out: &mut String, x: f64) {
    let x = if x == 0.0 { 0.0 } else { x };
    if push_short_decimal(out, x) {
        return;
    }
    let mut buffer = ryu::Buffer::new();
    out.push_str(buffer.format_finite(x));
}

/// Appends `x` as ryu would and returns true when `x` is the double nearest a decimal
/// `m·10⁻⁹` with `10⁻⁵ ≤ |x| < 10⁶`; otherwise appends nothing and returns false.
///
/// Why the text is ryu's: such a decimal has at most 15 significant digits, and two
/// distinct decimals of at most 15 significant digits are never the same double, so
/// `m·10⁻⁹` without its trailing zeros is the one shortest text that reads back as `x`;
/// in this range ryu writes it without an exponent, with `.0` after a whole number.
/// Whether `x` is such a double is checked exactly: `m` and `10⁹` are exact doubles, so
/// `m / 10⁹` is correctly rounded, the double that reading `m·10⁻⁹` gives.
///
/// Most values written (speeds, times) are not short: they are turned away by
/// [`far_from_short`] before the division, which is the costly step.
fn push_short_decimal(out: &mut String, x: f64) -> bool {
    const UNIT: u64 = 1_000_000_000;
    let magnitude = x.abs();
    if !(1e-5..1e6).contains(&magnitude) {
        return false;
    }
    let scaled = magnitude * 1e9;
    // Below 2^53: the signed conversions are exact, and cheaper than the unsigned.
    let rounded = round_half_away(scaled) as f64;
    if far_from_short(scaled, rounded) || rounded / 1e9 != magnitude {
        return false;
    }
    let m = rounded as u64;
    let (int, fraction) = (m / UNIT, m % UNIT);
    let (fraction, places) = match fraction {
        0 => (0, 1),
        _ => without_trailing_zeros(fraction),
    };
    let mut text = [0u8; 32];
    let mut len = usize::from(x < 0.0);
    text[0] = b'-';
    len += write_integer(&mut text[len..], int);
    text[len] = b'.';
    write_fraction(&mut text[len + 1..len + 1 + places], fraction as u32);
    len += 1 + places;
    // Only ASCII digits, a sign and a point were written.
    out.push_str(std::str::from_utf8(&text[..len]).unwrap_or_default());
    true
}

/// A fraction of nine places (`fraction` / 10⁹, not zero) without its trailing zeros:
/// the digits left and how many places they take. At most eight zeros are stripped: all
/// eight at once, or by four, two and one, so that which way each step goes is a choice
/// between two values rather than a loop's exit.
fn without_trailing_zeros(fraction: u64) -> (u64, usize) {
    if fraction.is_multiple_of(100_000_000) {
        return (fraction / 100_000_000, 1);
    }
    let strip =
        |(value, places): (u64, usize), unit: u64, zeros: usize| match value.is_multiple_of(unit) {
            true => (value / unit, places - zeros),
            false => (value, places),
        };
    let four = strip((fraction, 9), 10_000, 4);
    let two = strip(four, 100, 2);
    strip(two, 10, 1)
}

/// True when `m / 10⁹` cannot be the double `x` whose product `scaled = x·10⁹` (rounded)
/// is given and rounds to the integer `m` (10⁴ ≤ `scaled` < 10¹⁵, `m` given as an exact
/// double): a quick refusal without the division, never wrong, for
/// [`push_short_decimal`].
///
/// If `m / 10⁹` rounds to `x`, then |m − x·10⁹| ≤ 10⁹·ulp(x)/2 ≤ x·10⁹·2⁻⁵³, and the
/// product is off by at most `scaled`·2⁻⁵³, so |`scaled` − m| ≤ `scaled`·2⁻⁵² (to first
/// order); `scaled − m` is exact (Sterbenz: m ≥ 10⁴ is within a factor 2 of `scaled`).
/// The refusal asks for four times that bound.
#[inline(always)]
fn far_from_short(scaled: f64, m: f64) -> bool {
    const MARGIN: f64 = 1.0 / (1u64 << 50) as f64; // 2^-50
    (scaled - m).abs() > scaled * MARGIN
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The states of a xorshift generator from `seed` (deterministic test values).
    fn xorshift(seed: u64) -> impl Iterator<Item = u64> {
        std::iter::successors(Some(seed), |&state| {
            let state = state ^ state << 13;
            let state = state ^ state >> 7;
            Some(state ^ state << 17)
        })
        .skip(1)
    }

    /// A generator state as a number in [-0.5, 0.5].
    fn centred(state: u64) -> f64 {
        state as f64 / u64::MAX as f64 - 0.5
    }

    fn fixed(x: f64, d: usize) -> String {
        let mut s = b"ab".to_vec();
        match d {
            0 => push_fixed::<0>(&mut s, x),
            1 => push_fixed::<1>(&mut s, x),
            2 => push_fixed::<2>(&mut s, x),
            3 => push_fixed::<3>(&mut s, x),
            4 => push_fixed::<4>(&mut s, x),
            6 => push_fixed::<6>(&mut s, x),
            9 => push_fixed::<9>(&mut s, x),
            _ => unreachable!("no test uses {d} decimals"),
        }
        assert_eq!(&s[..2], b"ab", "what was there is kept");
        String::from_utf8(s[2..].to_vec()).unwrap()
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
    fn prints_whole_asks_the_printed_text() {
        for (x, whole) in [
            (820.0000000000001, true),
            (819.99999999999, true),
            (820.00005, false),
            (820.00004, true),
            (0.00004, true),
            (-3.0, true),
            (642.1749, false),
            (f64::NAN, false),
            (1e300, true),
        ] {
            let mut text = Vec::new();
            push_fixed::<4>(&mut text, x);
            let printed = String::from_utf8(text).unwrap();
            assert_eq!(prints_whole::<4>(x), whole, "{x}");
            if x.is_finite() && x.abs() < 1e15 {
                assert_eq!(printed.ends_with(".0000"), whole, "{printed}");
            }
        }
    }

    #[test]
    fn is_whole_is_fract_zero() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -1.0,
            8.0117,
            4503599627370495.5,
            4503599627370496.0,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for state in xorshift(0x6a09_e667_f3bc_c908).take(100_000) {
            let x = centred(state) * 1e7;
            values.extend([x, x.trunc(), f64::from_bits(x.trunc().to_bits() + 1)]);
        }
        for x in values {
            assert_eq!(is_whole(x), x.fract() == 0.0, "{x}");
        }
    }

    #[test]
    fn integer_parts_of_every_length() {
        for (x, text) in [
            (0.0, "0.0000"),
            (9.99995, "10.0000"),
            (-99.5, "-99.5000"),
            (100.0, "100.0000"),
            (999.99996, "1000.0000"),
            (9999.0001, "9999.0001"),
            (-10000.0, "-10000.0000"),
            (123456789.25, "123456789.2500"),
            (900719925474.0991, "900719925474.0991"),
        ] {
            assert_eq!(fixed(x, 4), text);
        }
        assert_eq!(fixed(4503599627.370495, 6), "4503599627.370495");
        assert_eq!(fixed(7.0, 0), "7");
        assert_eq!(fixed(12345.0, 0), "12345");
    }

    #[test]
    fn round_half_away_is_f64_round() {
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
        for state in xorshift(0x9e37_79b9_7f4a_7c15).take(200_000) {
            let magnitude = [1.0, 1e3, 1e6, 1e9, 1e12, 1e15][(state % 6) as usize];
            let x = centred(state) * magnitude;
            values.extend([
                x,
                x.trunc() + 0.5,
                x.trunc() - 0.5,
                f64::from_bits(x.to_bits() + 1),
            ]);
        }
        for x in values {
            // Equal as numbers (a -0.0 from `round` prints as 0 either way).
            assert_eq!(round_half_away(x) as f64, x.round(), "{x}");
        }
    }

    #[test]
    fn fixed_matches_exact_formatting_away_from_ties() {
        for state in xorshift(0x2545_f491_4f6c_dd1d).take(100_000) {
            let x = centred(state) * 2e6;
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

    fn ryu_text(x: f64) -> String {
        ryu::Buffer::new().format_finite(x).to_string()
    }

    /// The fast path writes ryu's bytes: on random doubles of every size, on short
    /// decimals (a random integer over a power of ten, as programs and feeds are), on
    /// their neighbours one ulp away, and at the edges of its range.
    #[test]
    fn exact_is_ryu_on_random_values() {
        let mut values = vec![1e-5, 0.99999e-5, 1e6, 999_999.999_999_999, 5000.0, 0.1, 0.5];
        for state in xorshift(0x5851_f42d_4c95_7f2d).take(300_000) {
            let digits = state % 16;
            let places = (state >> 8) % 12;
            let integer = (state >> 16) % 10u64.pow(digits as u32).max(1);
            let decimal = integer as f64 / 10f64.powi(places as i32);
            let sign = if state & 1 == 0 { 1.0 } else { -1.0 };
            let scale = [1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9][(state >> 4) as usize % 6];
            let random = centred(state) * scale;
            for x in [decimal, random, random * 1e-12] {
                let x = sign * x;
                values.extend([
                    x,
                    f64::from_bits(x.to_bits() + 1),
                    f64::from_bits(x.to_bits().wrapping_sub(1)),
                ]);
            }
        }
        let mut short = 0;
        for x in values.into_iter().filter(|x| x.is_finite() && *x != 0.0) {
            assert_eq!(exact(x), ryu_text(x), "{x:e}");
            short += usize::from(push_short_decimal(&mut String::new(), x));
        }
        // The fast path is taken often: the short decimals in range.
        assert!(short > 150_000, "{short} short decimals");
    }

    /// [`push_fixed`]'s rule written out with the standard library alone: `x·10^d`
    /// rounded half away from zero by `f64::round`, its digits by `format!`, the point
    /// put in; beyond 2^53 (and NaN, infinities) the standard fixed formatting.
    fn fixed_reference(x: f64, d: usize) -> String {
        let scaled = x * format!("1e{d}").parse::<f64>().unwrap();
        let text = if scaled.is_nan() || scaled.abs() >= 2f64.powi(53) {
            format!("{x:.d$}")
        } else {
            let n = scaled.round();
            let digits = format!("{:0width$}", n.abs() as u64, width = d + 1);
            let (int, fraction) = digits.split_at(digits.len() - d);
            let sign = if n < 0.0 { "-" } else { "" };
            match d {
                0 => format!("{sign}{int}"),
                _ => format!("{sign}{int}.{fraction}"),
            }
        };
        match text.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
            _ => text,
        }
    }

    /// Doubles of every kind for the fixed formats: any bit pattern, a decimal of a few
    /// places (a programmed coordinate), a tie `(k + ½)·10^-d` and its neighbours, and
    /// values about the 2^53 edge of the integer path.
    fn fixed_inputs() -> impl proptest::strategy::Strategy<Value = f64> {
        use proptest::prelude::*;
        let bits = any::<u64>().prop_map(f64::from_bits);
        let decimal = (any::<i64>(), 0..12i32)
            .prop_map(|(n, places)| (n % 10_000_000_000_000) as f64 / 10f64.powi(places));
        let tie = (any::<i32>(), 0..10i32, -1..=1i64).prop_map(|(k, d, step)| {
            let x = (f64::from(k) + 0.5) / 10f64.powi(d);
            f64::from_bits(x.to_bits().wrapping_add_signed(step))
        });
        let edge = (0..10i32, -1e6..1e6f64)
            .prop_map(|(d, offset)| (2f64.powi(53) + offset) / 10f64.powi(d) * offset.signum());
        let wide = (-1e18..1e18f64, -30..30i32).prop_map(|(m, e)| m * 10f64.powi(e) / 1e18);
        prop_oneof![bits, decimal, tie, edge, wide]
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        /// Every fixed format writes the reference's text, and what was in the buffer
        /// before is kept.
        #[test]
        fn fixed_is_the_reference(x in fixed_inputs()) {
            for d in [0, 1, 2, 3, 4, 6, 9] {
                proptest::prop_assert_eq!(fixed(x, d), fixed_reference(x, d), "{:e} with {} decimals", x, d);
            }
        }

        /// The shortest text is ryu's.
        #[test]
        fn exact_is_ryu(x in fixed_inputs()) {
            if x.is_finite() {
                let expected = if x == 0.0 { "0.0".to_owned() } else { ryu_text(x) };
                proptest::prop_assert_eq!(exact(x), expected, "{:e}", x);
            }
        }

        /// Every decimal `m·10⁻⁹` in the fast path's range takes it: the quick refusal
        /// ([`far_from_short`]) turns none away, including those whose product `x·10⁹`
        /// is not the integer `m` again.
        #[test]
        fn short_decimals_take_the_fast_path(m in 10_000..1_000_000_000_000_000u64) {
            let x = m as f64 / 1e9;
            let mut text = String::new();
            proptest::prop_assert!(push_short_decimal(&mut text, x), "{}", m);
            proptest::prop_assert_eq!(text, ryu_text(x));
        }

        /// The trailing zeros stripped as a loop strips them, one at a time; half the
        /// cases end in a run of zeros.
        #[test]
        fn trailing_zeros_as_a_loop_strips_them(digits in 1..1_000_000_000u64, zeros in 0..9u32) {
            let fraction = match digits % 2 {
                0 => digits,
                _ => (digits % 10u64.pow(9 - zeros)).max(1) * 10u64.pow(zeros),
            };
            let (mut value, mut places) = (fraction, 9);
            while value % 10 == 0 {
                value /= 10;
                places -= 1;
            }
            proptest::prop_assert_eq!(without_trailing_zeros(fraction), (value, places));
        }

        #[test]
        fn eight_digits_are_the_zero_padded_number(value in 0..100_000_000u32) {
            proptest::prop_assert_eq!(
                eight_digits(value).to_vec(),
                format!("{value:08}").into_bytes()
            );
        }
    }

    /// The lanes of [`eight_digits`] at every carry: all of 0..10⁵, and each 10⁴-block's
    /// and 100-block's edges up to 10⁸.
    #[test]
    fn eight_digits_at_every_carry() {
        let edges = (0..10_000u32).flat_map(|k| {
            let base = k * 10_000;
            [base, base + 99, base + 100, base + 9_999, base + 9_900]
        });
        for value in (0..100_000).chain(edges).chain([99_999_999]) {
            assert_eq!(
                eight_digits(value).to_vec(),
                format!("{value:08}").into_bytes()
            );
        }
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
