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
    let negative = b.first() == Some(&b'-');
    let sign = usize::from(matches!(b.first(), Some(b'+' | b'-')));
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
    let magnitude = mantissa as i64 as f64 / EXACT_POWERS_OF_TEN[scale];
    Some((at, if negative { -magnitude } else { magnitude }))
}

/// Reads the run of decimal digits of `b` from `at` onto `mantissa` (wrapping: a caller
/// refuses more than 15 digits); returns the mantissa and where the run ends.
#[inline]
fn digits(b: &[u8], mut at: usize, mut mantissa: u64) -> (u64, usize) {
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
