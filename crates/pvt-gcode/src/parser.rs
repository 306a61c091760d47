//! The grammar: source text to lines, a line to a [`Block`] (see `grammars/gcode.ebnf`).
//!
//! Owns the lexical rules (letters, numbers, comments, `%` lines, block delete, line
//! numbers, line ends, BOM), written as nom parsers, one per EBNF production. It must not
//! give words a meaning: a well-formed `E5` is the interpreter's to reject. A malformed
//! line yields one diagnostic and no block; the caller carries on with the next line.

use nom::bytes::complete::{take_till, take_while};
use nom::character::complete::{char, digit1, one_of, satisfy};
use nom::combinator::rest;
use nom::sequence::{delimited, preceded};
use nom::{IResult, Parser};

use crate::block::{Assignment, Block, Word};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::messages::{active, Active};
use crate::params::{normalize, ParamRef, Parameters};
use crate::tokens::{number, number_value, plain_number, plain_number_at, token_len, HINT_NUMBER};
use crate::value::Reader;

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
    /// The text, its line end (`\n` and every `\r` before it) removed.
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
        let (text, after) = match memchr::memchr(b'\n', self.rest.as_bytes()) {
            Some(end) => (&self.rest[..end], &self.rest[end + 1..]),
            None => (self.rest, ""),
        };
        let line = SourceLine {
            text: text.trim_end_matches('\r'),
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

/// `newline = { "\r" } , "\n"`. [`SourceLines`] and the streaming reader split lines with
/// `memchr` instead; this production is what the grammar test holds them to.
#[cfg(test)]
pub(crate) fn newline(i: &str) -> IResult<&str, &str> {
    use nom::combinator::recognize;
    recognize((take_while(|c| c == '\r'), char('\n'))).parse(i)
}

/// `blank = " " | "\t"` (any number of them).
pub(crate) fn blanks(i: &str) -> IResult<&str, &str> {
    take_while(|c| c == ' ' || c == '\t').parse(i)
}

/// `letter`: an ASCII letter, either case.
pub(crate) fn letter(i: &str) -> IResult<&str, char> {
    satisfy(|c| c.is_ascii_alphabetic()).parse(i)
}

/// `word = letter , { blank } , number`.
pub(crate) fn word(i: &str) -> IResult<&str, (char, &str)> {
    (letter, preceded(blanks, number)).parse(i)
}

/// `checksum = "*" , { blank } , digit , { digit }`.
pub(crate) fn checksum(i: &str) -> IResult<&str, &str> {
    preceded((char('*'), blanks), digit1).parse(i)
}

/// The text of a `(MSG, …)` comment's message, if `comment` (its inside) is one.
pub(crate) fn message(comment: &str) -> Option<&str> {
    let c = comment.trim_start();
    let head = c.get(..4)?;
    head.eq_ignore_ascii_case("msg,").then(|| c[4..].trim())
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

/// Parses one line into `block` (reset first), reading parameters from `params`.
///
/// A malformed line gives its first error; `block` then holds the words that could be
/// read around the bad text, so the interpreter can keep its state close to the intent.
pub(crate) fn parse_line(
    line: SourceLine<'_>,
    block: &mut Block,
    params: &Parameters,
) -> Result<LineKind, GcodeDiagnostic> {
    parse(line, block, params, true)
}

/// [`parse_line`]; `words_alone` reads a line of words alone ([`plain_words`]) without
/// the general loop, which gives the same block (tests turn it off to compare).
fn parse(
    line: SourceLine<'_>,
    block: &mut Block,
    params: &Parameters,
    words_alone: bool,
) -> Result<LineKind, GcodeDiagnostic> {
    let text = line.text;
    block.reset(line.start, line.start + text.len(), line.number);
    // A line that starts with a letter other than N (most lines) has no `%`, block
    // delete or line number: the head productions need not run.
    let plain = matches!(text.as_bytes().first(), Some(c) if c.is_ascii_alphabetic() && !matches!(c, b'N' | b'n'));
    if !plain && percent_line(text).is_ok() {
        return Ok(LineKind::Percent);
    }
    if words_alone && plain && plain_words(text, line.start, block) {
        return Ok(LineKind::Block);
    }
    let (i, mut first_error) = if plain {
        (text, None)
    } else {
        line_head(text, line.start, block)
    };
    let mut reader = Reader::new(text, line.start, text.len() - i.len(), params);
    loop {
        reader.skip_blanks();
        let at = reader.pos;
        let rest = &text[at..];
        let result = match rest.as_bytes().first() {
            None => break,
            Some(b';') if end_comment(rest).is_ok() => break,
            Some(b'(') => read_comment(&mut reader, block),
            Some(b'#') => read_assignment(&mut reader, block),
            Some(b'*') => read_checksum(&mut reader, text),
            Some(b'O' | b'o') => read_o_word(&mut reader, block),
            Some(c) if c.is_ascii_alphabetic() || matches!(c, b'$' | b'@' | b'^') => {
                read_word(&mut reader, block)
            }
            Some(_) => Err(bad_item(rest, line.start + at)),
        };
        if let Err(diagnostic) = result {
            // Carry on after the bad text, and at least one character further.
            let first_char = rest.chars().next().map_or(0, char::len_utf8);
            let mut skip = (diagnostic.span().end.saturating_sub(line.start))
                .max(reader.pos)
                .max(at + first_char)
                .min(text.len());
            while !text.is_char_boundary(skip) {
                skip += 1;
            }
            reader.pos = skip;
            first_error.get_or_insert(diagnostic);
        }
    }
    match first_error {
        Some(diagnostic) => Err(diagnostic),
        None => Ok(LineKind::Block),
    }
}

/// Reads a line of words alone (letters other than N and O, each with a number
/// [`plain_number_at`] reads, and blanks) straight into `block`, as the general loop of
/// [`parse_line`] reads them; returns false, `block.words` emptied, for any other line.
fn plain_words(text: &str, start: usize, block: &mut Block) -> bool {
    let b = text.as_bytes();
    let mut at = 0;
    while at < b.len() {
        let letter = b[at].to_ascii_uppercase();
        let (true, false) = (letter.is_ascii_alphabetic(), matches!(letter, b'N' | b'O')) else {
            block.words.clear();
            return false;
        };
        let Some((end, value)) = plain_number_at(b, skip_blanks(b, at + 1)) else {
            block.words.clear();
            return false;
        };
        block.words.push(Word {
            letter,
            value,
            start: start + at,
            end: start + end,
        });
        at = skip_blanks(b, end);
    }
    true
}

#[inline(always)]
fn skip_blanks(b: &[u8], mut at: usize) -> usize {
    while matches!(b.get(at), Some(b' ' | b'\t')) {
        at += 1;
    }
    at
}

/// A `( … )` comment at the reader; a `(MSG, …)`, `(DEBUG, …)` or `(PRINT, …)` one sets
/// the block's message.
fn read_comment(reader: &mut Reader<'_>, block: &mut Block) -> Result<(), GcodeDiagnostic> {
    let rest = reader.rest();
    match comment(rest) {
        Ok((after, inside)) => {
            if let Some(text) = message(inside) {
                block.message = Some(text.to_owned());
            } else if let Some(Active::Message(text)) = active(inside, reader.params()) {
                block.message = Some(text);
            }
            reader.pos += rest.len() - after.len();
            Ok(())
        }
        Err(_) => {
            let at = reader.absolute(reader.pos);
            Err(syntax(
                at..at + rest.len(),
                "comment is not closed: `(` needs a `)` on the same line".to_owned(),
                "close the comment with `)` before the line ends",
            ))
        }
    }
}

/// `#param = value` at the reader.
fn read_assignment(reader: &mut Reader<'_>, block: &mut Block) -> Result<(), GcodeDiagnostic> {
    let hash = reader.pos;
    reader.pos += 1;
    reader.skip_blanks();
    let param = if reader.rest().starts_with('<') {
        let (_, name) = reader.name()?;
        ParamRef::Named(normalize(name).into_owned())
    } else {
        ParamRef::Numbered(reader.index()?)
    };
    let target_end = reader.pos;
    reader.skip_blanks();
    if !reader.rest().starts_with('=') {
        let written = reader.text_between(hash, target_end);
        let detail = format!(
            "`{written}` alone: a parameter on a line must be assigned (`{written} = value`)"
        );
        let range = reader.absolute(hash)..reader.absolute(target_end);
        return Err(syntax(range, detail, HINT_ASSIGNMENT));
    }
    reader.pos += 1;
    let value = reader.real_value()?;
    if let ParamRef::Named(name) = &param {
        if crate::params::is_read_only(name) {
            return Err(GcodeDiagnostic::BadValue {
                word: reader.text_between(hash, target_end).to_owned(),
                expected: "a predefined parameter is read-only (the interpreter sets it)",
                span: span(reader.absolute(hash)..reader.absolute(target_end)),
            });
        }
    }
    block.assignments.push(Assignment { param, value });
    Ok(())
}

/// `*nn` at the reader: the XOR of every byte of the line before the `*`.
fn read_checksum(reader: &mut Reader<'_>, text: &str) -> Result<(), GcodeDiagnostic> {
    let star = reader.pos;
    let rest = reader.rest();
    let Ok((after, digits)) = checksum(rest) else {
        let at = reader.absolute(star);
        return Err(syntax(
            at..at + 1,
            "`*` must be followed by a checksum (a whole number)".to_owned(),
            HINT_CHECKSUM,
        ));
    };
    reader.pos += rest.len() - after.len();
    let computed = text.as_bytes()[..star].iter().fold(0u8, |acc, b| acc ^ b);
    let written: u64 = digits.parse().unwrap_or(u64::MAX);
    if written != u64::from(computed) {
        return Err(GcodeDiagnostic::ChecksumMismatch {
            written,
            computed: computed.into(),
            span: span(reader.absolute(star)..reader.absolute(reader.pos)),
        });
    }
    Ok(())
}

/// An `O` word: a program number alone on its line (Fanuc style) is kept as a word that
/// names the program; an O-word with a keyword reaches the parser only when it does
/// not start its line ([`crate::oword`] reads control lines), which is an error.
fn read_o_word(reader: &mut Reader<'_>, block: &mut Block) -> Result<(), GcodeDiagnostic> {
    let at = reader.pos;
    let rest = reader.rest();
    if let Ok((after, (_, n))) = word(rest) {
        let tail = after.trim_start_matches([' ', '\t']);
        if block.words.is_empty() && (tail.is_empty() || tail.starts_with(['(', ';'])) {
            reader.pos += rest.len() - after.len();
            block.words.push(Word {
                letter: b'O',
                value: number_value(n),
                start: reader.absolute(at),
                end: reader.absolute(reader.pos),
            });
            return Ok(());
        }
    }
    let len = rest.trim_end().len().max(1);
    reader.pos += len;
    let shown: String = rest.trim_end().chars().take(40).collect();
    Err(GcodeDiagnostic::Oword {
        detail: format!(
            "`{shown}`: an O-word is a line of its own, `oN keyword [values]`, or a program number alone"
        ),
        span: span(reader.absolute(at)..reader.absolute(at + len)),
    })
}

/// A letter (or `$`) and its value: a number, parameter, expression or function.
fn read_word(reader: &mut Reader<'_>, block: &mut Block) -> Result<(), GcodeDiagnostic> {
    let at = reader.pos;
    let rest = reader.rest();
    let letter = rest.as_bytes()[0].to_ascii_uppercase();
    reader.pos += 1;
    reader.skip_blanks();
    let value = match plain_number(reader.rest().as_bytes()) {
        Some((len, value)) => {
            reader.pos += len;
            value
        }
        None => {
            if !starts_value(reader.rest()) {
                return Err(bad_number(rest, reader.absolute(at)));
            }
            reader.word_start = Some(at);
            let value = reader.real_value();
            reader.word_start = None;
            value?
        }
    };
    let word = Word {
        letter,
        value,
        start: reader.absolute(at),
        end: reader.absolute(reader.pos),
    };
    if letter == b'N' {
        let detail = format!(
            "line number `{}` must start the block",
            reader.text_between(at, reader.pos)
        );
        return Err(syntax(word.span(), detail, HINT_LINE_NUMBER));
    }
    block.words.push(word);
    Ok(())
}

/// True when `i` starts a value: a number, `[`, `#`, or a function name and `[`.
fn starts_value(i: &str) -> bool {
    match i.as_bytes().first() {
        Some(b'0'..=b'9' | b'.' | b'+' | b'-' | b'[' | b'#') => true,
        Some(c) if c.is_ascii_alphabetic() => {
            let name = i.bytes().take_while(u8::is_ascii_alphabetic).count();
            i[name..].trim_start_matches([' ', '\t']).starts_with('[')
        }
        _ => false,
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

const HINT_LINE_NUMBER: &str =
    "a line number is N and a whole number at the start of the block, e.g. N10";
const HINT_ASSIGNMENT: &str = "assign a parameter as #1 = 2.5 or #<name> = [#1 * 2]";
const HINT_CHECKSUM: &str =
    "a checksum is `*` and the XOR of every byte of the line before it, e.g. N1 G1 X1*96";

fn syntax(range: std::ops::Range<usize>, detail: String, hint: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::Syntax {
        detail,
        hint,
        span: span(range),
    }
}

/// The diagnostic for text at `i` that is neither a word nor a comment.
fn bad_item(i: &str, at: usize) -> GcodeDiagnostic {
    let Some(c) = i.chars().next() else {
        return syntax(at..at, "unexpected end of line".to_owned(), HINT_NUMBER);
    };
    let one = at..at + c.len_utf8();
    match c {
        ')' => syntax(
            one,
            "`)` without an opening `(`".to_owned(),
            "comments are written (like this)",
        ),
        '[' => syntax(
            at..at + token_len(i),
            "an expression must be the value of a word, e.g. X[1+2]".to_owned(),
            HINT_NUMBER,
        ),
        '0'..='9' | '+' | '-' | '.' => {
            let len = number(i).map_or(c.len_utf8(), |(r, _)| i.len() - r.len());
            syntax(
                at..at + len,
                format!("number `{}` has no letter", &i[..len]),
                HINT_NUMBER,
            )
        }
        c => GcodeDiagnostic::UnknownWord {
            word: c.escape_debug().to_string(),
            meaning: "not a G-code letter",
            span: span(one),
        },
    }
}

/// A letter not followed by a value.
fn bad_number(i: &str, at: usize) -> GcodeDiagnostic {
    let len = token_len(i);
    let letter = &i[..1];
    syntax(
        at..at + len,
        format!("`{}`: {letter} must be followed by a number", &i[..len]),
        HINT_NUMBER,
    )
}

#[cfg(test)]
mod tests;
