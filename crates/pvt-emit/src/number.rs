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

/// Largest magnitude, scaled, that the integer path writes: integers are exact below it.
const EXACT_INTEGERS: f64 = 9_007_199_254_740_992.0; // 2^53

/// Bytes [`write_fixed`] may write: a sign, 8 integer digits, a point and 9 decimals, and
/// scratch past them. (An integer part of more than 8 digits is written only with fewer
/// decimals: below 2^53 the whole takes at most 16 digits.)
pub(crate) const FIXED_SLOT: usize = 19;

/// Appends `x` with exactly `DECIMALS` (at most 9) digits after the point, never as
/// negative zero.
///
/// `x` is scaled by `10^DECIMALS` in binary floating point and rounded half away from
/// zero to an integer, which is printed with the point inserted: the same bytes on every
/// machine, and many times faster than exact decimal formatting. Values whose scaled
/// magnitude reaches 2^53 (where integers stop being exact) use Rust's exact formatting.
#[inline]
pub fn push_fixed<const DECIMALS: usize>(out: &mut Vec<u8>, x: f64) {
    if !fits_fixed::<DECIMALS>(x) {
        return push_fixed_exactly(out, x, DECIMALS);
    }
    // The text is written in place in room made for the longest, which is then cut back
    // (no copy, no branch on the length).
    let start = out.len();
    out.resize(start + FIXED_SLOT, 0);
    let len = write_fixed::<DECIMALS>(&mut out[start..], x);
    out.truncate(start + len);
}

/// True when [`push_fixed`] writes `x` on its integer path ([`write_fixed`]): `x` scaled
/// by `10^DECIMALS` is a number of magnitude below 2^53.
#[inline(always)]
pub(crate) fn fits_fixed<const DECIMALS: usize>(x: f64) -> bool {
    const { assert!(DECIMALS <= 9, "at most 9 decimals") };
    // NaN compares false.
    (x * POW10[DECIMALS]).abs() < EXACT_INTEGERS
}

/// Writes `x` ([`fits_fixed`]) as [`push_fixed`] does at the start of `slot` (at least
/// [`FIXED_SLOT`] long) and returns the length of its text; up to [`FIXED_SLOT`] bytes
/// are written, those after the text being scratch that the next text overwrites or the
/// caller cuts off.
#[inline(always)]
pub(crate) fn write_fixed<const DECIMALS: usize>(slot: &mut [u8], x: f64) -> usize {
    match write_usual_fixed::<DECIMALS>(slot, x) {
        (len, true) => len,
        _ => write_wide_fixed::<DECIMALS>(slot, x),
    }
}

/// Writes `x` as [`write_fixed`] does and returns the length of its text and true, when
/// `x` is a usual value: its magnitude scaled by `10^DECIMALS` below both 2^52 and
/// 10^(8 + `DECIMALS`) − 1 (every position and velocity of 9 decimals below 4.5·10⁶, every
/// piece time below a day). For any other `x` (NaN too) it returns false, having written
/// at most [`FIXED_SLOT`] bytes of no meaning, and never panics: a caller may write a
/// whole line and check once.
///
/// The scaled magnitude is rounded to an integer without a conversion ([`rounded`]),
/// and split at the point. The integer part (below 10⁸) is made into its eight
/// zero-padded digits at once ([`eight_digit_values`]), held in a u64 with the first
/// digit in its lowest byte; its leading zeros are the u64's trailing zero bytes, shifted
/// out (all but the units digit), and the eight bytes stored whole. The fraction's
/// digits are made the same way and stored after the point. The one branch that depends
/// on the value is on the integer part's size: one below 10⁴ (with 9 decimals: below
/// 1000), as a program's coordinates, speeds and piece times in ms mostly are, takes
/// four digits at once ([`four_digit_values`]), at about half the cost.
#[inline(always)]
pub(crate) fn write_usual_fixed<const DECIMALS: usize>(slot: &mut [u8], x: f64) -> (usize, bool) {
    const { assert!(DECIMALS <= 9, "at most 9 decimals") };
    const ASCII_ZEROS: u64 = u64::from_le_bytes([b'0'; 8]);
    // Below both, exactly: 10^(8 + DECIMALS) − 1 is a double for DECIMALS ≤ 7, and 2^52
    // is the smaller for 8 and 9.
    let usual_below = (POW10[DECIMALS] * 1e8 - 1.0).min(STEP_ONE);
    let slot = &mut slot[..FIXED_SLOT];
    let scaled = x * POW10[DECIMALS];
    let magnitude = scaled.abs();
    let usual = magnitude < usual_below;
    let m = rounded(magnitude);
    let sign = usize::from(scaled < 0.0 && m != 0);
    slot[0] = b'-';
    if DECIMALS == 9 {
        return (sign + write_nine_decimals(&mut slot[sign..], m).0, usual);
    }
    let unit = POW10_INT[DECIMALS];
    let (int, fraction) = (m / unit, m % unit);
    let point = if int < 10_000 {
        let values = four_digit_values(int as u32);
        // At most three leading zeros: the units digit stays (a bit set in its byte
        // stops the count there).
        let zeros = ((values | 1 << 24).trailing_zeros() / 8) as usize;
        let digits = (values | ASCII_ZEROS as u32) >> (8 * zeros);
        slot[sign..sign + 4].copy_from_slice(&digits.to_le_bytes());
        sign + 4 - zeros
    } else {
        // Below 10⁸ when usual; any other gives digits of no meaning.
        let values = eight_digit_values(int as u32);
        // At most seven leading zeros, as above.
        let zeros = ((values | 1 << 56).trailing_zeros() / 8) as usize;
        let digits = (values | ASCII_ZEROS) >> (8 * zeros);
        slot[sign..sign + 8].copy_from_slice(&digits.to_le_bytes());
        sign + 8 - zeros
    };
    if DECIMALS == 0 {
        return (point, usual);
    }
    slot[point] = b'.';
    write_fraction::<DECIMALS>(&mut slot[point + 1..point + 1 + 9], fraction as u32);
    (point + 1 + DECIMALS, usual)
}

/// [`write_usual_fixed`]'s digits for 9 decimals: `m` / 10⁹ (the magnitude rounded,
/// below 4.5·10¹⁵) written at the start of `slot` (18 long); returns the length, and the
/// values of the fraction's last eight digits ([`eight_digit_values`]).
///
/// Split in two halves of eight digits instead of at the point: the high half is the
/// integer part (at most 7 digits) and the fraction's first digit, the low half its other
/// eight. The high half's bytes are stored with the leading zeros shifted out, then the
/// point and the fraction's first digit over its last; a high half below 10⁴ (an
/// integer part below 1000) as four digits ([`four_digit_values`]).
#[inline(always)]
fn write_nine_decimals(slot: &mut [u8], m: u64) -> (usize, u64) {
    const ASCII_ZEROS: u64 = u64::from_le_bytes([b'0'; 8]);
    let slot = &mut slot[..18];
    let (high, low) = (m / 100_000_000, m % 100_000_000);
    let point = if high < 10_000 {
        let values = four_digit_values(high as u32);
        // At most two leading zeros: the units digit stays (a bit set in its byte stops
        // the count there).
        let zeros = ((values | 1 << 16).trailing_zeros() / 8) as usize;
        let digits = (values | ASCII_ZEROS as u32) >> (8 * zeros);
        slot[..4].copy_from_slice(&digits.to_le_bytes());
        let point = 3 - zeros;
        slot[point] = b'.';
        slot[point + 1] = (values >> 24) as u8 | b'0';
        point
    } else {
        // Below 4.5·10⁷ when usual; any other gives digits of no meaning.
        let values = eight_digit_values(high as u32);
        // At most six leading zeros, as above.
        let zeros = ((values | 1 << 48).trailing_zeros() / 8) as usize;
        let digits = (values | ASCII_ZEROS) >> (8 * zeros);
        slot[..8].copy_from_slice(&digits.to_le_bytes());
        let point = 7 - zeros;
        slot[point] = b'.';
        slot[point + 1] = (values >> 56) as u8 | b'0';
        point
    };
    let last_eight = eight_digit_values(low as u32);
    slot[point + 2..point + 10].copy_from_slice(&(last_eight | ASCII_ZEROS).to_le_bytes());
    (point + 10, last_eight)
}

/// Writes the `DECIMALS` (1 to 9) zero-padded digits of `fraction` (below 10^`DECIMALS`)
/// at the start of `slot` (9 long), the rest of which is scratch.
#[inline(always)]
fn write_fraction<const DECIMALS: usize>(slot: &mut [u8], fraction: u32) {
    const ASCII_ZEROS: u64 = u64::from_le_bytes([b'0'; 8]);
    let slot = &mut slot[..9];
    if DECIMALS == 9 {
        slot[0] = (fraction / 100_000_000) as u8 | b'0';
        let last_eight = eight_digit_values(fraction % 100_000_000) | ASCII_ZEROS;
        slot[1..9].copy_from_slice(&last_eight.to_le_bytes());
    } else if DECIMALS <= 4 {
        // Four digits of which the first 4 − DECIMALS are zeros, shifted out.
        let digits = (four_digit_values(fraction) | ASCII_ZEROS as u32) >> (8 * (4 - DECIMALS));
        slot[..4].copy_from_slice(&digits.to_le_bytes());
    } else {
        // Eight digits of which the first 8 − DECIMALS are zeros, shifted out.
        let digits = (eight_digit_values(fraction) | ASCII_ZEROS) >> (8 * (8 - DECIMALS));
        slot[..8].copy_from_slice(&digits.to_le_bytes());
    }
}

/// [`write_fixed`] for a value ([`fits_fixed`]) that is not usual
/// ([`write_usual_fixed`]): its scaled magnitude below 2^53, so the text takes at most a
/// sign, 16 digits and a point. Out of the way of the usual values, digit by digit.
#[cold]
fn write_wide_fixed<const DECIMALS: usize>(slot: &mut [u8], x: f64) -> usize {
    let n = round_half_away(x * POW10[DECIMALS]);
    let magnitude = n.unsigned_abs();
    let unit = POW10_INT[DECIMALS];
    let (int, fraction) = (magnitude / unit, magnitude % unit);
    let mut text = [0u8; 32];
    let sign = usize::from(n < 0);
    text[0] = b'-';
    let count = int.checked_ilog10().unwrap_or(0) as usize + 1;
    let mut value = int;
    for digit in text[sign..sign + count].iter_mut().rev() {
        *digit = b'0' + (value % 10) as u8;
        value /= 10;
    }
    let mut len = sign + count;
    if DECIMALS > 0 {
        text[len] = b'.';
        write_fraction::<DECIMALS>(&mut text[len + 1..len + 1 + 9], fraction as u32);
        len += 1 + DECIMALS;
    }
    slot[..len].copy_from_slice(&text[..len]);
    len
}

/// The eight decimal digits of `value` (below 10⁸, zero-padded), first digit first.
#[cfg(test)]
fn eight_digits(value: u32) -> [u8; 8] {
    (eight_digit_values(value) | 0x3030_3030_3030_3030).to_le_bytes()
}

/// The four decimal digits of `value` (below 10⁴, zero-padded) as the bytes of a u32,
/// first digit in its lowest byte, each digit's value (0–9): [`eight_digit_values`]'
/// last two steps on one half. A value of 10⁴ or more gives digits of no meaning.
#[inline(always)]
fn four_digit_values(value: u32) -> u32 {
    // ⌊x·5243 / 2¹⁹⌋ = ⌊x / 100⌋ for x < 10⁴ (up to 43 699).
    let hundreds = value.wrapping_mul(5_243) >> 19;
    let pairs = (value << 16).wrapping_sub(hundreds.wrapping_mul((100 << 16) - 1));
    let tens = (pairs.wrapping_mul(103) >> 10) & 0x000F_000F;
    (pairs << 8).wrapping_sub(tens.wrapping_mul((10 << 8) - 1))
}

/// The eight decimal digits of `value` (below 10⁸, zero-padded) as the bytes of a u64,
/// first digit in its lowest byte, each digit's value (0–9) rather than its character.
///
/// The digits are divided out side by side in the lanes of one u64 (SWAR): two lanes of
/// 32 bits hold the halves `value / 10⁴` and `value % 10⁴`, each split into hundreds in
/// 16-bit lanes and those into tens in bytes, by multiplying with a rounded-up reciprocal
/// and shifting: `⌊x·10486 / 2²⁰⌋ = ⌊x / 100⌋` for x < 10⁴ and `⌊x·103 / 2¹⁰⌋ = ⌊x / 10⌋`
/// for x < 100. No lane's product reaches the next lane's bits that the masks keep, and
/// no lane's difference borrows from the next.
#[inline(always)]
fn eight_digit_values(value: u32) -> u64 {
    let v = u64::from(value);
    // Each step `(x << k) − q·((d << k) − 1)` is `q | (x − q·d) << k` lane by lane. The
    // operations wrap: a value of 10⁸ or more (which no caller prints) gives digits of no
    // meaning rather than a panic.
    let high = v / 10_000;
    let halves = (v << 32).wrapping_sub(high.wrapping_mul((10_000 << 32) - 1));
    let hundreds = (halves.wrapping_mul(10_486) >> 20) & 0x0000_007F_0000_007F;
    let pairs = (halves << 16).wrapping_sub(hundreds.wrapping_mul((100 << 16) - 1));
    let tens = (pairs.wrapping_mul(103) >> 10) & 0x000F_000F_000F_000F;
    (pairs << 8).wrapping_sub(tens.wrapping_mul((10 << 8) - 1))
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
#[inline]
pub(crate) fn prints_whole<const DECIMALS: usize>(x: f64) -> bool {
    let magnitude = (x * POW10[DECIMALS]).abs();
    if magnitude < STEP_ONE {
        return rounded(magnitude).is_multiple_of(POW10_INT[DECIMALS]);
    }
    if !fits_fixed::<DECIMALS>(x) {
        return is_whole(x);
    }
    round_half_away(x * POW10[DECIMALS])
        .unsigned_abs()
        .is_multiple_of(POW10_INT[DECIMALS])
}

/// 2^52: from here up the doubles' step is 1.
const STEP_ONE: f64 = 4_503_599_627_370_496.0;

/// `magnitude` (0 ≤ `magnitude` < 2^52) rounded half away from zero, as `f64::round`
/// does: by adding 2^52, where the doubles' step is 1, so the sum is `magnitude` rounded
/// to nearest, ties to even, and its bits count the integers from 2^52; a tie that went
/// down to even (`magnitude` − rounded = ½, exact) goes up. Any other `magnitude` (NaN
/// too) gives an integer of no meaning, without a panic.
#[inline(always)]
fn rounded(magnitude: f64) -> u64 {
    let sum = magnitude + STEP_ONE;
    let nearest = sum - STEP_ONE;
    let tie_down = magnitude - nearest == 0.5;
    sum.to_bits().wrapping_sub(STEP_ONE.to_bits()) + u64::from(tie_down)
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

/// Appends the shortest text that reads back as exactly `x` (ryu's text), never as `-0.0`
/// ([`write_exact`]).
pub fn push_exact(out: &mut String, x: f64) {
    let mut slot = [0u8; EXACT_SLOT];
    let len = write_exact(&mut slot, x);
    // Only ASCII digits, a sign, a point and an exponent were written.
    out.push_str(std::str::from_utf8(&slot[..len]).unwrap_or_default());
}

/// Bytes [`write_exact`] may write: the longest shortest text of a double is 24 bytes
/// (`-2.2250738585072014e-308`), and the fixed-point path writes [`FIXED_SLOT`] bytes.
pub(crate) const EXACT_SLOT: usize = 32;

/// Writes the shortest text that reads back as exactly `x` (ryu's text), never as
/// `-0.0`, at the start of `slot` (at least [`EXACT_SLOT`] long) and returns its length;
/// the bytes after it are scratch.
///
/// A value that is a decimal of at most 9 places between 10⁻⁵ and 10⁶ (a programmed
/// coordinate, a round feed) is written by [`write_short_decimal`] at fixed-point speed;
/// any other below 10¹⁶ by żmij, which finds the same shortest digits as ryu about twice
/// as fast and writes them in ryu's form below 10¹⁶ (from there it writes `e+16` where
/// ryu writes `e16`); the rest by ryu. All give ryu's bytes (tested on random values).
#[inline]
pub(crate) fn write_exact(slot: &mut [u8], x: f64) -> usize {
    let slot = &mut slot[..EXACT_SLOT];
    let x = if x == 0.0 { 0.0 } else { x };
    if let Some(len) = write_short_decimal(slot, x) {
        return len;
    }
    if x.abs() < 1e16 {
        let mut buffer = zmij::Buffer::new();
        return copy_short(slot, buffer.format_finite(x).as_bytes());
    }
    let mut buffer = ryu::Buffer::new();
    copy_short(slot, buffer.format_finite(x).as_bytes())
}

/// Copies `text` (at most 32 bytes) to the start of `slot` (32 long) by two overlapping
/// copies of a fixed size, without a call into `memcpy`; returns its length.
#[inline(always)]
pub(crate) fn copy_short(slot: &mut [u8], text: &[u8]) -> usize {
    let slot = &mut slot[..EXACT_SLOT];
    let n = text.len().min(EXACT_SLOT);
    if n >= 16 {
        slot[..16].copy_from_slice(&text[..16]);
        slot[n - 16..n].copy_from_slice(&text[n - 16..n]);
    } else if n >= 8 {
        slot[..8].copy_from_slice(&text[..8]);
        slot[n - 8..n].copy_from_slice(&text[n - 8..n]);
    } else if n >= 4 {
        slot[..4].copy_from_slice(&text[..4]);
        slot[n - 4..n].copy_from_slice(&text[n - 4..n]);
    } else if n >= 2 {
        slot[..2].copy_from_slice(&text[..2]);
        slot[n - 2..n].copy_from_slice(&text[n - 2..n]);
    } else if n == 1 {
        slot[0] = text[0];
    }
    n
}

/// Writes `x` as ryu would at the start of `slot` ([`EXACT_SLOT`] long) and returns its
/// length when `x` is the double nearest a decimal `m·10⁻⁹` with `10⁻⁵ ≤ |x| < 10⁶`;
/// otherwise `None`, `slot` then holding scratch.
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
#[inline(always)]
fn write_short_decimal(slot: &mut [u8], x: f64) -> Option<usize> {
    let magnitude = x.abs();
    if !(1e-5..1e6).contains(&magnitude) {
        return None;
    }
    let scaled = magnitude * 1e9;
    // Below 2^53: the signed conversions are exact, and cheaper than the unsigned.
    let m = round_half_away(scaled);
    let rounded = m as f64;
    if far_from_short(scaled, rounded) || rounded / 1e9 != magnitude {
        return None;
    }
    // As write_fixed::<9> writes it (a usual value, `m` its magnitude rounded, never
    // zero), then cut after the fraction's last digit that is not zero (the first stays).
    let slot = &mut slot[..EXACT_SLOT];
    let sign = usize::from(x < 0.0);
    slot[0] = b'-';
    let (len, last_eight) = write_nine_decimals(&mut slot[sign..], m.unsigned_abs());
    // The fraction's trailing zeros but its first digit: the last eight digits' zeros.
    let zeros = (last_eight.leading_zeros() / 8) as usize;
    Some(sign + len - zeros)
}

/// True when `m / 10⁹` cannot be the double `x` whose product `scaled = x·10⁹` (rounded)
/// is given and rounds to the integer `m` (10⁴ ≤ `scaled` < 10¹⁵, `m` given as an exact
/// double): a quick refusal without the division, never wrong, for
/// [`write_short_decimal`].
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

    fn usual(x: f64, d: usize, slot: &mut [u8]) -> (usize, bool) {
        match d {
            0 => write_usual_fixed::<0>(slot, x),
            1 => write_usual_fixed::<1>(slot, x),
            4 => write_usual_fixed::<4>(slot, x),
            7 => write_usual_fixed::<7>(slot, x),
            8 => write_usual_fixed::<8>(slot, x),
            9 => write_usual_fixed::<9>(slot, x),
            _ => unreachable!("no test uses {d} decimals"),
        }
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
            if x.abs() < STEP_ONE {
                assert_eq!(rounded(x.abs()) as f64, x.abs().round(), "{x}");
            }
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
            short += usize::from(write_short_decimal(&mut [0; EXACT_SLOT], x).is_some());
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
    /// values about the 2^53 edge of the integer path and the edge of the usual values.
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
        let usual_edge = (0..10i32, -4.0..4.0f64).prop_map(|(d, offset)| {
            let bound = (10f64.powi(8 + d) - 1.0).min(2f64.powi(52));
            (bound + offset) / 10f64.powi(d) * offset.signum()
        });
        prop_oneof![bits, decimal, tie, edge, wide, usual_edge]
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

        /// Away from a tie (where the product `x·10^d` may round either way), every
        /// fixed format writes what Rust's exact formatting writes, but `-0`.
        #[test]
        fn fixed_is_std_formatting_away_from_ties(x in fixed_inputs()) {
            for d in [0usize, 4, 6, 9] {
                let scaled = (x * 10f64.powi(d as i32)).abs();
                let ulp = f64::from_bits(scaled.to_bits() + 1) - scaled;
                if !scaled.is_finite() || ((scaled.fract() - 0.5).abs() <= 2.0 * ulp) {
                    continue;
                }
                let exact = format!("{x:.d$}");
                let exact = match exact.strip_prefix('-') {
                    Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
                    _ => exact,
                };
                proptest::prop_assert_eq!(fixed(x, d), exact, "{:e} with {} decimals", x, d);
            }
        }

        /// A usual value is one below the documented bound, and its text is the
        /// reference's; any other (NaN, infinities, beyond 2^53) is refused without a
        /// panic and without writing past the slot.
        #[test]
        fn usual_values_are_the_reference_and_others_refused(x in fixed_inputs()) {
            for d in [0usize, 1, 4, 7, 8, 9] {
                let mut slot = [b'#'; FIXED_SLOT + 1];
                let (len, usual) = usual(x, d, &mut slot);
                let scaled = (x * 10f64.powi(d as i32)).abs();
                let bound = (10f64.powi(8 + d as i32) - 1.0).min(2f64.powi(52));
                proptest::prop_assert_eq!(usual, scaled < bound, "{:e} with {} decimals", x, d);
                proptest::prop_assert!(len <= FIXED_SLOT && slot[FIXED_SLOT] == b'#');
                if usual {
                    let text = std::str::from_utf8(&slot[..len]).unwrap();
                    proptest::prop_assert_eq!(text, fixed_reference(x, d), "{:e} with {} decimals", x, d);
                }
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
            let mut slot = [0; EXACT_SLOT];
            let len = write_short_decimal(&mut slot, x);
            proptest::prop_assert!(len.is_some(), "{}", m);
            let text = std::str::from_utf8(&slot[..len.unwrap_or(0)]).unwrap();
            proptest::prop_assert_eq!(text, ryu_text(x));
        }

        #[test]
        fn eight_digits_are_the_zero_padded_number(value in 0..100_000_000u32) {
            proptest::prop_assert_eq!(
                eight_digits(value).to_vec(),
                format!("{value:08}").into_bytes()
            );
        }
    }

    /// [`four_digit_values`] on every value it takes.
    #[test]
    fn four_digits_are_the_zero_padded_number() {
        for value in 0..10_000u32 {
            let digits = (four_digit_values(value) | 0x3030_3030).to_le_bytes();
            assert_eq!(digits.to_vec(), format!("{value:04}").into_bytes());
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

    /// Every path of [`write_exact`] writes ryu's bytes at its edges: the short decimals'
    /// range, żmij's (ryu writes `1e16`, żmij `1e+16`), subnormals and the extremes.
    #[test]
    fn exact_is_ryu_at_the_edges_of_each_path() {
        let mut values = vec![
            1e16,
            9_999_999_999_999_998.0,
            1e15,
            1.2345e20,
            1e300,
            f64::MAX,
            f64::MIN_POSITIVE,
            2.2250738585072014e-308,
            5e-324,
            1e-5,
            9.999999999999999e-6,
            1e6,
            999_999.999_999_999_9,
            1e-7,
            0.1,
            3.0,
        ];
        for k in -320..=308 {
            let x = 10f64.powi(k);
            values.extend([
                x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits().saturating_sub(1)),
            ]);
        }
        for x in values.clone() {
            values.push(-x);
        }
        for x in values.into_iter().filter(|x| x.is_finite() && *x != 0.0) {
            assert_eq!(exact(x), ryu_text(x), "{x:e}");
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
