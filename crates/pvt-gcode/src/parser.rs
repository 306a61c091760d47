//! The grammar: source text to lines, a line to a [`Block`] (see `grammars/gcode.ebnf`).
//!
//! Owns the lexical rules (letters, numbers, comments, `%` lines, block delete, line
//! numbers, line ends, BOM), written as nom parsers, one per EBNF production. It must not
//! give words a meaning: a well-formed `Q5` is the interpreter's to reject. A malformed
//! line yields one diagnostic and no block; the caller carries on with the next line.

use nom::branch::alt;
use nom::bytes::complete::{take_till, take_while};
use nom::character::complete::{char, digit1, one_of, satisfy};
use nom::combinator::{opt, recognize, rest};
use nom::sequence::{delimited, preceded};
use nom::{IResult, Parser};

use crate::block::{Block, Word};
use crate::diagnostic::{span, GcodeDiagnostic};

/// What a line turned out to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LineKind {
    /// A `%` program delimiter.
    Percent,
    /// A block (possibly empty: blank or only comments).
    Block,
}

/// One line of the source, without its line end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SourceLine<'a> {
    /// The text, `\r\n` or `\n` removed.
    pub text: &'a str,
    /// Byte offset of `text` in the source.
    pub start: usize,
    /// 1-based line number.
    pub number: u32,
}

/// The lines of a source, a leading UTF-8 BOM skipped.
pub(crate) struct SourceLines<'a> {
    rest: &'a str,
    offset: usize,
    number: u32,
}

impl<'a> SourceLines<'a> {
    /// Lines of `source`.
    pub fn new(source: &'a str) -> Self {
        let (rest, offset) = match source.strip_prefix('\u{feff}') {
            Some(rest) => (rest, '\u{feff}'.len_utf8()),
            None => (source, 0),
        };
        SourceLines {
            rest,
            offset,
            number: 0,
        }
    }
}

impl<'a> Iterator for SourceLines<'a> {
    type Item = SourceLine<'a>;

    fn next(&mut self) -> Option<SourceLine<'a>> {
        if self.rest.is_empty() {
            return None;
        }
        let (after, text) = line_text(self.rest).ok()?;
        let (after, _) = opt(newline).parse(after).ok()?;
        let line = SourceLine {
            text: text.strip_suffix('\r').unwrap_or(text),
            start: self.offset,
            number: self.number.saturating_add(1),
        };
        self.offset += self.rest.len() - after.len();
        self.rest = after;
        self.number = line.number;
        Some(line)
    }
}

// ---- productions (names as in grammars/gcode.ebnf) ----

/// `line_text`: everything up to the line end.
pub(crate) fn line_text(i: &str) -> IResult<&str, &str> {
    take_till(|c| c == '\n').parse(i)
}

/// `newline = [ "\r" ] , "\n"`.
pub(crate) fn newline(i: &str) -> IResult<&str, &str> {
    recognize((opt(char('\r')), char('\n'))).parse(i)
}

/// `blank = " " | "\t"` (any number of them).
pub(crate) fn blanks(i: &str) -> IResult<&str, &str> {
    take_while(|c| c == ' ' || c == '\t').parse(i)
}

/// `number = [ sign ] , ( digits , [ "." , [ digits ] ] | "." , digits )`; no exponent.
pub(crate) fn number(i: &str) -> IResult<&str, &str> {
    // Not nom's `digit0`: in nom 8.0.0 it returns a wrong remainder at the end of a &str.
    let digits0 = take_while(|c: char| c.is_ascii_digit());
    let digits_first = recognize((digit1, opt((char('.'), digits0))));
    let dot_first = recognize((char('.'), digit1));
    recognize((opt(one_of("+-")), alt((digits_first, dot_first)))).parse(i)
}

/// `letter`: an ASCII letter, either case.
pub(crate) fn letter(i: &str) -> IResult<&str, char> {
    satisfy(|c| c.is_ascii_alphabetic()).parse(i)
}

/// `word = letter , { blank } , number`.
pub(crate) fn word(i: &str) -> IResult<&str, (char, &str)> {
    (letter, preceded(blanks, number)).parse(i)
}

/// `comment = "(" , { any character but ")" } , ")"`.
pub(crate) fn comment(i: &str) -> IResult<&str, &str> {
    delimited(char('('), take_till(|c| c == ')'), char(')')).parse(i)
}

/// `end_comment = ";" , { any character }`.
pub(crate) fn end_comment(i: &str) -> IResult<&str, &str> {
    preceded(char(';'), rest).parse(i)
}

/// `line_number = "N" , { blank } , digits`.
pub(crate) fn line_number(i: &str) -> IResult<&str, &str> {
    preceded((one_of("Nn"), blanks), digit1).parse(i)
}

/// `block_delete = "/"`.
pub(crate) fn block_delete(i: &str) -> IResult<&str, char> {
    char('/').parse(i)
}

/// `percent_line = { blank } , "%" , { any character }`.
pub(crate) fn percent_line(i: &str) -> IResult<&str, &str> {
    preceded((blanks, char('%')), rest).parse(i)
}

// ---- a line to a block ----

/// Parses one line into `block` (reset first).
///
/// A malformed line gives its first error; `block` then holds the words that could be
/// read around the bad text, so the interpreter can keep its state close to the intent.
pub(crate) fn parse_line(
    line: SourceLine<'_>,
    block: &mut Block,
) -> Result<LineKind, GcodeDiagnostic> {
    let text = line.text;
    block.reset(line.start, line.start + text.len(), line.number);
    if percent_line(text).is_ok() {
        return Ok(LineKind::Percent);
    }
    let at = |rest: &str| line.start + text.len() - rest.len();
    let (mut i, mut first_error) = line_head(text, line.start, block);
    loop {
        i = blanks(i).map_or(i, |(r, _)| r);
        if i.is_empty() || end_comment(i).is_ok() {
            break;
        }
        if let Ok((after, _)) = comment(i) {
            i = after;
            continue;
        }
        let (result, after) = match word(i) {
            Ok((after, (l, n))) => (
                read_word(&i[..i.len() - after.len()], l, n, at(i), after),
                after,
            ),
            Err(_) => (Err(bad_item(i, at(i))), i),
        };
        i = match result {
            Ok(word) => {
                block.words.push(word);
                after
            }
            // Carry on after the bad text, and at least one character further.
            Err(diagnostic) => {
                let first_char = i.chars().next().map_or(0, char::len_utf8);
                let skip = (diagnostic.span().end.saturating_sub(at(i)))
                    .max(i.len() - after.len())
                    .max(first_char);
                first_error.get_or_insert(diagnostic);
                &i[skip.min(i.len())..]
            }
        };
    }
    match first_error {
        Some(diagnostic) => Err(diagnostic),
        None => Ok(LineKind::Block),
    }
}

/// Reads the optional block delete and line number at the start of `text` (which starts
/// at byte `start`); returns the rest and an error for a line number with a fraction.
fn line_head<'a>(
    text: &'a str,
    start: usize,
    block: &mut Block,
) -> (&'a str, Option<GcodeDiagnostic>) {
    let mut i = blanks(text).map_or(text, |(r, _)| r);
    if let Ok((after, _)) = block_delete(i) {
        block.block_delete = true;
        i = blanks(after).map_or(after, |(r, _)| r);
    }
    let Ok((after, digits)) = line_number(i) else {
        return (i, None);
    };
    if after.starts_with('.') {
        let (len, at) = (token_len(i), start + text.len() - i.len());
        let detail = format!("line number `{}` is not a whole number", &i[..len]);
        return (
            &i[len..],
            Some(syntax(at..at + len, detail, HINT_LINE_NUMBER)),
        );
    }
    block.line_number = Some(digits.parse().unwrap_or(u64::MAX));
    (after, None)
}

/// Checks a well-formed word: finite value, not an `N` word, no exponent after it.
fn read_word(
    text: &str,
    l: char,
    n: &str,
    start: usize,
    after: &str,
) -> Result<Word, GcodeDiagnostic> {
    let word = make_word(l, n, start, start + text.len())?;
    check_after_number(after, word.end)?;
    if word.letter == b'N' {
        let detail = format!("line number `{text}` must start the block");
        return Err(syntax(word.span(), detail, HINT_LINE_NUMBER));
    }
    Ok(word)
}

const HINT_NUMBER: &str = "write a word as a letter and a decimal number, e.g. X-.5, Y3., F+200";
const HINT_LINE_NUMBER: &str =
    "a line number is N and a whole number at the start of the block, e.g. N10";

fn syntax(range: std::ops::Range<usize>, detail: String, hint: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::Syntax {
        detail,
        hint,
        span: span(range),
    }
}

/// A word from its letter and number text; a number too large to be finite is an error.
fn make_word(l: char, n: &str, start: usize, end: usize) -> Result<Word, GcodeDiagnostic> {
    match n.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(Word {
            letter: l.to_ascii_uppercase() as u8,
            value,
            start,
            end,
        }),
        _ => {
            let shown: String = n.chars().take(24).collect();
            let more = if n.len() > 24 { "…" } else { "" };
            Err(syntax(
                start..end,
                format!("number `{shown}{more}` is too large"),
                "numbers must be below about 1.8e308",
            ))
        }
    }
}

/// True when `after` (the text right after a number) starts an exponent such as `e3`.
fn starts_exponent(after: &str) -> bool {
    let Some(next) = after.strip_prefix(['e', 'E']) else {
        return false;
    };
    let next = next.strip_prefix(['+', '-']).unwrap_or(next);
    next.starts_with(|c: char| c.is_ascii_digit())
}

/// Rejects an exponent (`1e3`) glued to a number.
fn check_after_number(after: &str, at: usize) -> Result<(), GcodeDiagnostic> {
    if !starts_exponent(after) {
        return Ok(());
    }
    let len = token_len(after);
    let detail = format!("exponent `{}` is not G-code", &after[..len]);
    Err(syntax(at..at + len, detail, HINT_NUMBER))
}

/// Length of the token at the start of `i`: up to a blank, comment or line end.
fn token_len(i: &str) -> usize {
    i.find([' ', '\t', '(', ';'])
        .unwrap_or(i.len())
        .max(i.chars().next().map_or(0, char::len_utf8))
}

/// The diagnostic for text at `i` that is neither a word nor a comment.
fn bad_item(i: &str, at: usize) -> GcodeDiagnostic {
    let Some(c) = i.chars().next() else {
        return syntax(at..at, "unexpected end of line".to_owned(), HINT_NUMBER);
    };
    let one = at..at + c.len_utf8();
    let token = at..at + token_len(i);
    match c {
        '(' => syntax(
            at..at + i.len(),
            "comment is not closed: `(` needs a `)` on the same line".to_owned(),
            "close the comment with `)` before the line ends",
        ),
        ')' => syntax(
            one,
            "`)` without an opening `(`".to_owned(),
            "comments are written (like this)",
        ),
        '#' => unsupported(token, "#", "parameters"),
        '[' => unsupported(token, "[", "expressions"),
        '*' => unsupported(token, "*", "checksums"),
        '<' | '>' | '=' => unsupported(token, &c.to_string(), "parameters"),
        '0'..='9' | '+' | '-' | '.' => {
            let len = number(i).map_or(c.len_utf8(), |(r, _)| i.len() - r.len());
            syntax(
                at..at + len,
                format!("number `{}` has no letter", &i[..len]),
                HINT_NUMBER,
            )
        }
        c if c.is_ascii_alphabetic() => bad_number(i, at),
        c => GcodeDiagnostic::UnknownWord {
            word: c.escape_debug().to_string(),
            meaning: "not a G-code letter",
            span: span(one),
        },
    }
}

/// A letter not followed by a number.
fn bad_number(i: &str, at: usize) -> GcodeDiagnostic {
    let after_letter = &i[1..];
    let value = blanks(after_letter).map_or(after_letter, |(r, _)| r);
    let value_at = at + i.len() - value.len();
    match value.chars().next() {
        Some('#') => unsupported(value_at..value_at + token_len(value), "#", "parameters"),
        Some('[') => unsupported(value_at..value_at + token_len(value), "[", "expressions"),
        _ => {
            let len = token_len(i);
            let letter = &i[..1];
            syntax(
                at..at + len,
                format!("`{}`: {letter} must be followed by a number", &i[..len]),
                HINT_NUMBER,
            )
        }
    }
}

fn unsupported(
    range: std::ops::Range<usize>,
    code: &str,
    feature: &'static str,
) -> GcodeDiagnostic {
    GcodeDiagnostic::Unsupported {
        code: code.to_owned(),
        feature,
        span: span(range),
    }
}

#[cfg(test)]
mod tests;
