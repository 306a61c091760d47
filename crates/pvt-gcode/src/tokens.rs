//! Tokens of a G-code line that the grammar and the value reader both scan: a number
//! as RS274NGC writes it (blanks between digits), where a token ends, an exponent after
//! a number, and the hint of a malformed number.
//!
//! Owns these lexical helpers so that `parser` (the grammar) and `value` (expressions
//! and parameters) both read them without importing each other. It must not build a
//! block or give a word a meaning.

use nom::IResult;

pub(crate) const HINT_NUMBER: &str =
    "write a word as a letter and a decimal number, e.g. X-.5, Y3., F+200";

/// `number = [ sign ] , { blank } , digits-with-blanks [ "." … ]`: RS274NGC allows blanks
/// between the digits (`1 0.5` is 10.5); trailing blanks are not part of the number.
/// Hand-written rather than nom, to stay allocation-free and fast.
pub(crate) fn number(i: &str) -> IResult<&str, &str> {
    let fail = || nom::Err::Error(nom::error::Error::new(i, nom::error::ErrorKind::Digit));
    let b = i.as_bytes();
    let mut at = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let (mut end, mut digits, mut dots) = (0, 0, 0);
    while let Some(&c) = b.get(at) {
        match c {
            b'0'..=b'9' => digits += 1,
            b'.' if dots == 0 => dots += 1,
            b' ' | b'\t' => {
                at += 1;
                continue;
            }
            _ => break,
        }
        at += 1;
        end = at;
    }
    if digits == 0 {
        return Err(fail());
    }
    Ok((&i[end..], &i[..end]))
}

/// True when `after` (the text right after a number) starts an exponent such as `e3`.
pub(crate) fn starts_exponent(after: &str) -> bool {
    let Some(next) = after.strip_prefix(['e', 'E']) else {
        return false;
    };
    let next = next.strip_prefix(['+', '-']).unwrap_or(next);
    next.starts_with(|c: char| c.is_ascii_digit())
}

/// Length of the token at the start of `i`: up to a blank, comment or line end.
pub(crate) fn token_len(i: &str) -> usize {
    i.find([' ', '\t', '(', ';'])
        .unwrap_or(i.len())
        .max(i.chars().next().map_or(0, char::len_utf8))
}

/// The value of text [`number`] accepted, correctly rounded; infinite when too large.
pub(crate) fn number_value(text: &str) -> f64 {
    if let Some(value) = short_decimal(text) {
        return value;
    }
    if !text.contains([' ', '\t']) {
        return text.parse().unwrap_or(f64::NAN);
    }
    let mut buffer = [0u8; 64];
    let mut len = 0;
    for b in text.bytes().filter(|b| *b != b' ' && *b != b'\t') {
        if len == buffer.len() {
            let joined: String = text.chars().filter(|c| *c != ' ' && *c != '\t').collect();
            return joined.parse().unwrap_or(f64::NAN);
        }
        buffer[len] = b;
        len += 1;
    }
    std::str::from_utf8(&buffer[..len])
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Powers of ten that are exact in an `f64`.
const EXACT_POWERS_OF_TEN: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// The value of a blank-free decimal of at most 15 digits (what CAM writes), or `None`.
pub(crate) fn short_decimal(text: &str) -> Option<f64> {
    plain_number(text.as_bytes())
        .filter(|(len, _)| *len == text.len())
        .map(|(_, value)| value)
}

/// A number as CAM writes it and its value: `[sign] digits [. digits]`, at most 15
/// digits, followed by nothing that could continue it (blanks then a digit or point, an
/// exponent, a second point). Returns its length; `None` sends the text to the general
/// reader ([`Reader::real_value`]), which gives the same value or the diagnostic. One
/// scan, no allocation: the hot path of a surfacing program.
///
/// Clinger's fast path: the digits as an integer below 2^53 and the power of ten are both
/// exact, so one IEEE division gives the correctly rounded value, bit for bit what
/// `str::parse` gives, without its general-case machinery.
pub(crate) fn plain_number(b: &[u8]) -> Option<(usize, f64)> {
    plain_number_at(b, 0)
}

/// [`plain_number`] of the text of `b` from byte `at`; returns where the number ends (an
/// offset in `b`). The bytes before `at` are read only to fetch the last eight bytes of a
/// line at once; they never change the result.
#[inline(always)]
pub(crate) fn plain_number_at(b: &[u8], start: usize) -> Option<(usize, f64)> {
    let first = b.get(start).copied();
    let negative = first == Some(b'-');
    let sign = start + usize::from(matches!(first, Some(b'+' | b'-')));
    let (mut mantissa, int_end) = digits(b, sign, 0);
    let (mut at, mut scale) = (int_end, 0);
    if b.get(at) == Some(&b'.') {
        let fraction_end;
        (mantissa, fraction_end) = digits(b, at + 1, mantissa);
        scale = fraction_end - (at + 1);
        at = fraction_end;
    }
    let count = int_end - sign + scale;
    let continues = match b.get(at) {
        Some(b'e' | b'E' | b'.') => true,
        Some(b' ' | b'\t') => matches!(
            b[at..].iter().find(|c| !matches!(c, b' ' | b'\t')),
            Some(b'0'..=b'9' | b'.')
        ),
        _ => false,
    };
    if count == 0 || count > 15 || continues {
        return None;
    }
    // Below 2^53 (15 digits): the signed conversion is exact, and cheaper than the unsigned.
    // A whole number (a G or M code, a feed) needs no division (x / 1 is x).
    let magnitude = match scale {
        0 => mantissa as i64 as f64,
        _ => mantissa as i64 as f64 / EXACT_POWERS_OF_TEN[scale],
    };
    Some((at, if negative { -magnitude } else { magnitude }))
}

/// Reads the run of decimal digits of `b` from `at` onto `mantissa` (wrapping: a caller
/// refuses more than 15 digits); returns the mantissa and where the run ends.
///
/// A run shorter than eight (a coordinate's integer part or fraction) is read from the
/// eight bytes at `at` at once ([`leading_digits`], [`eight_at`]), without a branch per
/// digit; a longer run goes on one digit at a time.
#[inline]
fn digits(b: &[u8], mut at: usize, mut mantissa: u64) -> (u64, usize) {
    let (count, value) = leading_digits(eight_at(b, at));
    if count < 8 {
        let scale = POW10_U64[count];
        return (mantissa.wrapping_mul(scale).wrapping_add(value), at + count);
    }
    while at < b.len() {
        let digit = b[at].wrapping_sub(b'0');
        if digit >= 10 {
            break;
        }
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(digit));
        at += 1;
    }
    (mantissa, at)
}

/// The eight bytes of `b` from `at` (the first in the low byte), those past its end read
/// as zero bytes, which are not digits. Near the end of a text of eight bytes or more,
/// its last eight bytes are read at once and shifted down.
#[inline(always)]
fn eight_at(b: &[u8], at: usize) -> u64 {
    if let Some(eight) = b.get(at..).and_then(|rest| rest.first_chunk::<8>()) {
        return u64::from_le_bytes(*eight);
    }
    let past = at.min(b.len());
    match b.last_chunk::<8>() {
        Some(last) => {
            // 1 ..= 8 bytes of the last eight lie before `past`.
            let before = past + 8 - b.len();
            match before {
                8 => 0,
                _ => u64::from_le_bytes(*last) >> (8 * before),
            }
        }
        None => b[past..]
            .iter()
            .rev()
            .fold(0, |word, &c| (word << 8) | u64::from(c)),
    }
}

/// 10⁰ … 10⁷.
const POW10_U64: [u64; 8] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000];

/// How many of the eight bytes of `word` (the first in the low byte), from the first,
/// are decimal digits, and, when fewer than eight, their value.
///
/// A byte is a digit when `byte − '0'` is below 10: subtracting `'0'` from every byte at
/// once borrows only out of a byte that is below `'0'`, which is not a digit, so the
/// first flagged byte is the first that is not a digit. The digits before it are moved
/// to the top (the lower bytes become zeros, leading zeros of the number) and combined
/// in three steps, pairs, fours, then eight (Lemire's multiply-and-shift).
#[inline(always)]
fn leading_digits(word: u64) -> (usize, u64) {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let values = word.wrapping_sub(ONES * u64::from(b'0'));
    let not_digit = (values | values.wrapping_add(ONES * 0x76)) & (ONES * 0x80);
    let count = (not_digit.trailing_zeros() / 8) as usize;
    if count == 0 || count == 8 {
        return (count, 0);
    }
    let aligned = (values << (8 * (8 - count))) & (ONES * 0x0F);
    let pairs = (aligned.wrapping_mul((10 << 8) | 1) >> 8) & 0x00FF_00FF_00FF_00FF;
    let fours = (pairs.wrapping_mul((100 << 16) | 1) >> 16) & 0x0000_FFFF_0000_FFFF;
    (count, fours.wrapping_mul((10_000 << 32) | 1) >> 32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// [`plain_number`]'s rule read one byte at a time, its value by `str::parse`.
    fn plain_reference(b: &[u8]) -> Option<(usize, f64)> {
        let run = |from: usize| b[from..].iter().take_while(|c| c.is_ascii_digit()).count();
        let sign = usize::from(matches!(b.first(), Some(b'+' | b'-')));
        let whole = run(sign);
        let mut at = sign + whole;
        let mut count = whole;
        if b.get(at) == Some(&b'.') {
            let fraction = run(at + 1);
            count += fraction;
            at += 1 + fraction;
        }
        let next_solid = b[at..].iter().find(|c| !matches!(c, b' ' | b'\t'));
        let continues = match b.get(at) {
            Some(b'e' | b'E' | b'.') => true,
            Some(b' ' | b'\t') => matches!(next_solid, Some(b'0'..=b'9' | b'.')),
            _ => false,
        };
        if count == 0 || count > 15 || continues {
            return None;
        }
        let text = std::str::from_utf8(&b[..at]).ok()?;
        Some((at, text.parse().ok()?))
    }

    /// Text a G-code number may be, or nearly: digits, signs, points, blanks, letters,
    /// and the bytes either side of the digits (`/`, `:`).
    fn near_numbers() -> impl Strategy<Value = Vec<u8>> {
        let byte = prop_oneof![
            8 => b'0'..=b'9',
            1 => prop::sample::select(b"+-. \tXEe/:".to_vec()),
            1 => any::<u8>(),
        ];
        prop::collection::vec(byte, 0..24)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// Length and value, bit for bit, as the byte-at-a-time reference reads them.
        #[test]
        fn plain_number_is_the_reference(bytes in near_numbers()) {
            let got = plain_number(&bytes).map(|(len, v)| (len, v.to_bits()));
            let expected = plain_reference(&bytes).map(|(len, v)| (len, v.to_bits()));
            prop_assert_eq!(got, expected, "{:?}", String::from_utf8_lossy(&bytes));
        }

        /// Read from an offset, a number is what it is alone (the bytes before it only
        /// serve to load the last eight bytes of the text at once).
        #[test]
        fn plain_number_at_an_offset_is_the_number_alone(
            before in near_numbers(),
            bytes in near_numbers(),
        ) {
            let text = [before.as_slice(), bytes.as_slice()].concat();
            let got = plain_number_at(&text, before.len())
                .map(|(end, v)| (end - before.len(), v.to_bits()));
            let alone = plain_reference(&bytes).map(|(len, v)| (len, v.to_bits()));
            prop_assert_eq!(got, alone, "{:?}", String::from_utf8_lossy(&text));
        }

        /// The count of leading digits of any eight bytes, and their value.
        #[test]
        fn leading_digits_of_any_word(word in any::<u64>(), digits in 0..=8usize, seed in any::<u64>()) {
            // Half the time the first `digits` bytes are made digits.
            let mut bytes = word.to_le_bytes();
            if seed % 2 == 0 {
                for (i, b) in bytes.iter_mut().take(digits).enumerate() {
                    *b = b'0' + ((seed >> (4 * i)) % 10) as u8;
                }
            }
            let count = bytes.iter().take_while(|b| b.is_ascii_digit()).count();
            let (got_count, value) = leading_digits(u64::from_le_bytes(bytes));
            prop_assert_eq!(got_count, count);
            if (1..8).contains(&count) {
                let text = std::str::from_utf8(&bytes[..count]).unwrap();
                prop_assert_eq!(value, text.parse::<u64>().unwrap());
            }
        }
    }
}
