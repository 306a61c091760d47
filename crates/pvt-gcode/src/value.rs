//! Values: numbers, parameter reads and bracketed expressions, evaluated as they are read.
//!
//! Owns the RS274NGC expression language: `[ … ]` with `**`, `* / MOD`, `+ -`,
//! `EQ NE GT GE LT LE`, `AND OR XOR` (that precedence, highest first, left to right in a
//! level), the functions ABS ACOS ASIN ATAN[a]/[b] COS EXP FIX FUP ROUND LN SIN SQRT TAN
//! EXISTS (angles in degrees), and `#` reads (`#1`, `#[expr]`, `##1`, `#<name>`). It must
//! not know what a word means nor change parameters (assignments are the parser's to
//! collect and [`crate::compile_into`]'s to apply). It never recurses without bound.

use crate::diagnostic::{span, GcodeDiagnostic};
use crate::params::{normalize, Parameters, ReadProblem, MAX_NUMBERED};
use crate::tokens;

/// How deep brackets and `#` indirections may nest.
const MAX_DEPTH: u32 = 32;

/// Equality tolerance of EQ and NE, as LinuxCNC uses.
const EQUAL_TOLERANCE: f64 = 0.0001;

type Result<T> = std::result::Result<T, GcodeDiagnostic>;

/// Reads values from one line of text.
pub(crate) struct Reader<'a> {
    text: &'a str,
    /// Byte offset of `text` in the source.
    base: usize,
    /// Current byte position in `text`.
    pub pos: usize,
    params: &'a Parameters,
    depth: u32,
    /// Where the word being read starts: errors in its top-level value span the word.
    pub word_start: Option<usize>,
}

/// A binary operator and its precedence level (1 binds tightest).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Pow,
    Mul,
    Div,
    Mod,
    Add,
    Sub,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
}

impl Op {
    fn level(self) -> u8 {
        use Op::*;
        match self {
            Pow => 1,
            Mul | Div | Mod => 2,
            Add | Sub => 3,
            Eq | Ne | Gt | Ge | Lt | Le => 4,
            And | Or | Xor => 5,
        }
    }
}

const TOP_LEVEL: u8 = 5;

impl<'a> Reader<'a> {
    /// A reader of `text` (at byte `base` of the source) starting at byte `pos`.
    pub fn new(text: &'a str, base: usize, pos: usize, params: &'a Parameters) -> Self {
        Reader {
            text,
            base,
            pos,
            params,
            depth: 0,
            word_start: None,
        }
    }

    /// The text from the current position.
    pub fn rest(&self) -> &'a str {
        self.text.get(self.pos..).unwrap_or("")
    }

    /// The source offset of byte `pos` of the line.
    pub fn absolute(&self, pos: usize) -> usize {
        self.base + pos
    }

    /// The line's text between two byte positions.
    pub fn text_between(&self, start: usize, end: usize) -> &'a str {
        self.text.get(start..end).unwrap_or("")
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    /// Skips blanks.
    pub fn skip_blanks(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.pos += 1;
        }
    }

    /// Absolute byte range for `start..end` of the line.
    fn range(&self, start: usize, end: usize) -> std::ops::Range<usize> {
        self.base + start..self.base + end.max(start)
    }

    fn syntax_here(&self, detail: String) -> GcodeDiagnostic {
        let len = tokens::token_len(self.rest());
        GcodeDiagnostic::Syntax {
            detail,
            hint: HINT_EXPRESSION,
            span: span(self.range(self.pos, self.pos + len)),
        }
    }

    /// The parameters values are read from.
    pub fn params(&self) -> &'a Parameters {
        self.params
    }

    /// A real value: `[sign] (number | [expr] | #param | FUNCTION[expr])`.
    pub fn real_value(&mut self) -> Result<f64> {
        self.skip_blanks();
        // A sign before a number is the number's; before anything else it negates.
        let sign = match self.peek() {
            Some(sign @ (b'-' | b'+')) if !self.number_follows(1) => {
                self.pos += 1;
                Some(sign)
            }
            _ => None,
        };
        self.skip_blanks();
        let value = match self.peek() {
            Some(b'[') => self.bracketed()?,
            Some(b'#') => self.parameter()?,
            Some(c) if c.is_ascii_alphabetic() => self.function()?,
            _ if sign.is_some() => {
                let start = self.top_start(self.pos - 1);
                let len = tokens::token_len(self.rest());
                return Err(GcodeDiagnostic::Syntax {
                    detail: "a sign must be followed by a value".to_owned(),
                    hint: HINT_EXPRESSION,
                    span: span(self.range(start, self.pos + len)),
                });
            }
            _ => self.number()?,
        };
        Ok(if sign == Some(b'-') { -value } else { value })
    }

    /// True when a digit or `.` follows `skip` bytes and any blanks.
    fn number_follows(&self, skip: usize) -> bool {
        let rest = self.rest().get(skip..).unwrap_or("");
        rest.trim_start_matches([' ', '\t'])
            .starts_with(|c: char| c.is_ascii_digit() || c == '.')
    }

    /// A plain number (blanks allowed between its digits); no exponent may follow.
    pub fn number(&mut self) -> Result<f64> {
        let rest = self.rest();
        let Ok((after, text)) = tokens::number(rest) else {
            let detail = match rest.chars().next() {
                Some(c) => format!("expected a number, found `{}`", c.escape_debug()),
                None => "expected a number at the end of the line".to_owned(),
            };
            let start = self.top_start(self.pos);
            let end = self.pos + tokens::token_len(rest);
            return Err(GcodeDiagnostic::Syntax {
                detail,
                hint: tokens::HINT_NUMBER,
                span: span(self.range(start, end)),
            });
        };
        let start = self.pos;
        self.pos += rest.len() - after.len();
        if tokens::starts_exponent(after) {
            let len = tokens::token_len(after);
            let detail = format!("exponent `{}` is not G-code", &after[..len]);
            return Err(GcodeDiagnostic::Syntax {
                detail,
                hint: tokens::HINT_NUMBER,
                span: span(self.range(self.pos, self.pos + len)),
            });
        }
        let value = tokens::number_value(text);
        if !value.is_finite() {
            let shown: String = text.chars().take(24).collect();
            let more = if text.len() > 24 { "…" } else { "" };
            return Err(GcodeDiagnostic::Syntax {
                detail: format!("number `{shown}{more}` is too large"),
                hint: "numbers must be below about 1.8e308",
                span: span(self.range(self.top_start(start), self.pos)),
            });
        }
        Ok(value)
    }

    /// `start`, or the word's start for a value outside any brackets.
    fn top_start(&self, start: usize) -> usize {
        match self.word_start {
            Some(word) if self.depth == 0 => word.min(start),
            _ => start,
        }
    }

    fn enter(&mut self) -> Result<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.syntax_here(format!("expression nested more than {MAX_DEPTH} deep")));
        }
        Ok(())
    }

    /// `[ expression ]`, at a `[`.
    fn bracketed(&mut self) -> Result<f64> {
        self.enter()?;
        let start = self.pos;
        self.pos += 1;
        let value = self.binary(TOP_LEVEL)?;
        self.skip_blanks();
        if self.peek() != Some(b']') {
            return Err(match self.peek() {
                None => GcodeDiagnostic::Syntax {
                    detail: "expression is not closed: `[` needs a `]`".to_owned(),
                    hint: HINT_EXPRESSION,
                    span: span(self.range(start, self.pos)),
                },
                Some(_) => self.syntax_here(format!(
                    "expected an operator or `]`, found `{}`",
                    &self.rest()[..tokens::token_len(self.rest())]
                )),
            });
        }
        self.pos += 1;
        self.depth -= 1;
        Ok(value)
    }

    /// Operators of `level` and tighter, left to right.
    fn binary(&mut self, level: u8) -> Result<f64> {
        if level == 0 {
            return self.real_value();
        }
        let mut lhs = self.binary(level - 1)?;
        loop {
            let op_start = self.pos;
            let Some((op, len)) = self.peek_op() else {
                return Ok(lhs);
            };
            if op.level() != level {
                self.pos = op_start;
                return Ok(lhs);
            }
            let at = self.pos;
            self.pos += len;
            let rhs = self.binary(level - 1)?;
            lhs = self.apply(op, lhs, rhs, at..at + len)?;
        }
    }

    /// The binary operator after any blanks (position left after the blanks).
    fn peek_op(&mut self) -> Option<(Op, usize)> {
        self.skip_blanks();
        let b = self.text.as_bytes();
        let at = |i: usize| b.get(self.pos + i).map(u8::to_ascii_uppercase);
        Some(match (at(0)?, at(1), at(2)) {
            (b'*', Some(b'*'), _) => (Op::Pow, 2),
            (b'*', ..) => (Op::Mul, 1),
            (b'/', ..) => (Op::Div, 1),
            (b'+', ..) => (Op::Add, 1),
            (b'-', ..) => (Op::Sub, 1),
            (b'M', Some(b'O'), Some(b'D')) => (Op::Mod, 3),
            (b'A', Some(b'N'), Some(b'D')) => (Op::And, 3),
            (b'X', Some(b'O'), Some(b'R')) => (Op::Xor, 3),
            (b'O', Some(b'R'), _) => (Op::Or, 2),
            (b'E', Some(b'Q'), _) => (Op::Eq, 2),
            (b'N', Some(b'E'), _) => (Op::Ne, 2),
            (b'G', Some(b'T'), _) => (Op::Gt, 2),
            (b'G', Some(b'E'), _) => (Op::Ge, 2),
            (b'L', Some(b'T'), _) => (Op::Lt, 2),
            (b'L', Some(b'E'), _) => (Op::Le, 2),
            _ => return None,
        })
    }

    fn apply(&self, op: Op, a: f64, b: f64, at: std::ops::Range<usize>) -> Result<f64> {
        let truth = |t: bool| if t { 1.0 } else { 0.0 };
        let value = match op {
            Op::Pow => libm::pow(a, b),
            Op::Mul => a * b,
            Op::Div if b == 0.0 => return Err(self.math(at, "division by zero".to_owned())),
            Op::Div => a / b,
            Op::Mod if b == 0.0 => return Err(self.math(at, "MOD by zero".to_owned())),
            Op::Mod => {
                let r = libm::fmod(a, b);
                if r < 0.0 {
                    r + b.abs()
                } else {
                    r
                }
            }
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Eq => truth((a - b).abs() < EQUAL_TOLERANCE),
            Op::Ne => truth((a - b).abs() >= EQUAL_TOLERANCE),
            Op::Gt => truth(a > b),
            Op::Ge => truth(a >= b),
            Op::Lt => truth(a < b),
            Op::Le => truth(a <= b),
            Op::And => truth(a != 0.0 && b != 0.0),
            Op::Or => truth(a != 0.0 || b != 0.0),
            Op::Xor => truth((a != 0.0) != (b != 0.0)),
        };
        if !value.is_finite() {
            let detail = format!("{} {op:?} {} has no finite value", show(a), show(b));
            return Err(self.math(at, detail));
        }
        Ok(value)
    }

    fn math(&self, at: std::ops::Range<usize>, detail: String) -> GcodeDiagnostic {
        GcodeDiagnostic::MathError {
            detail,
            span: span(self.range(at.start, at.end)),
        }
    }

    /// A function call at a letter: `NAME[expr]`, `ATAN[a]/[b]`, `EXISTS[#<name>]`.
    fn function(&mut self) -> Result<f64> {
        let start = self.pos;
        let rest = self.rest();
        let len = rest.bytes().take_while(u8::is_ascii_alphabetic).count();
        let name = rest[..len].to_ascii_uppercase();
        self.pos += len;
        self.skip_blanks();
        if self.peek() != Some(b'[') {
            self.pos = start;
            return Err(self.syntax_here(format!(
                "`{}` is not a number, parameter, expression or function",
                &rest[..len.max(1)]
            )));
        }
        if name == "EXISTS" {
            return self.exists();
        }
        let arg = self.bracketed()?;
        let at = start..self.pos;
        if name == "ATAN" {
            return self.atan(arg, at);
        }
        let value = self.unary(&name, arg, at.clone())?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.math(at, format!("{name}[{}] has no finite value", show(arg))))
        }
    }

    fn unary(&self, name: &str, x: f64, at: std::ops::Range<usize>) -> Result<f64> {
        let domain = |ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(self.math(at.clone(), format!("{name}[{}] is undefined", show(x))))
            }
        };
        Ok(match name {
            "ABS" => x.abs(),
            "ACOS" => {
                domain((-1.0..=1.0).contains(&x))?;
                libm::acos(x).to_degrees()
            }
            "ASIN" => {
                domain((-1.0..=1.0).contains(&x))?;
                libm::asin(x).to_degrees()
            }
            "COS" => libm::cos(x.to_radians()),
            "SIN" => libm::sin(x.to_radians()),
            "TAN" => libm::tan(x.to_radians()),
            "EXP" => libm::exp(x),
            "LN" => {
                domain(x > 0.0)?;
                libm::log(x)
            }
            "SQRT" => {
                domain(x >= 0.0)?;
                x.sqrt()
            }
            "FIX" => x.floor(),
            "FUP" => x.ceil(),
            "ROUND" => x.round(),
            _ => {
                return Err(GcodeDiagnostic::Syntax {
                    detail: format!("`{name}` is not an RS274NGC function"),
                    hint: HINT_FUNCTIONS,
                    span: span(self.range(at.start, at.start + name.len())),
                })
            }
        })
    }

    /// `ATAN[a]/[b]`: the angle of (b, a) in degrees; the `[a]` is read already.
    fn atan(&mut self, a: f64, at: std::ops::Range<usize>) -> Result<f64> {
        self.skip_blanks();
        if self.peek() != Some(b'/') {
            return Err(self.syntax_here("ATAN takes two arguments: ATAN[y]/[x]".to_owned()));
        }
        self.pos += 1;
        self.skip_blanks();
        if self.peek() != Some(b'[') {
            return Err(self.syntax_here("ATAN takes two arguments: ATAN[y]/[x]".to_owned()));
        }
        let b = self.bracketed()?;
        let _ = at;
        Ok(libm::atan2(a, b).to_degrees())
    }

    /// `EXISTS[#<name>]`, at the `[`.
    fn exists(&mut self) -> Result<f64> {
        self.pos += 1;
        self.skip_blanks();
        let name = match self.peek() {
            Some(b'#') => {
                self.pos += 1;
                self.skip_blanks();
                self.name()?
            }
            _ => {
                return Err(
                    self.syntax_here("EXISTS takes a named parameter: EXISTS[#<name>]".to_owned())
                )
            }
        };
        self.skip_blanks();
        if self.peek() != Some(b']') {
            return Err(self.syntax_here("expected `]` after the parameter".to_owned()));
        }
        self.pos += 1;
        Ok(if self.params.exists(name.1) { 1.0 } else { 0.0 })
    }

    /// `<name>` at a `<`: the start offset and the name as written.
    pub fn name(&mut self) -> Result<(usize, &'a str)> {
        let start = self.pos;
        let rest = self.rest();
        if !rest.starts_with('<') {
            return Err(self.syntax_here("expected `<name>`".to_owned()));
        }
        let Some(close) = rest.find('>') else {
            return Err(GcodeDiagnostic::Syntax {
                detail: "parameter name is not closed: `<` needs a `>`".to_owned(),
                hint: HINT_EXPRESSION,
                span: span(self.range(start, self.text.len())),
            });
        };
        let name = &rest[1..close];
        if name.trim().is_empty() {
            return Err(self.syntax_here("empty parameter name".to_owned()));
        }
        self.pos += close + 1;
        Ok((start, name))
    }

    /// The index of a numbered parameter after `#` (a real value, whole, in range).
    pub fn index(&mut self) -> Result<usize> {
        let start = self.pos;
        let value = self.real_value()?;
        let rounded = value.round();
        if (value - rounded).abs() > 1e-6 || !(1.0..=MAX_NUMBERED as f64).contains(&rounded) {
            return Err(GcodeDiagnostic::OutOfRange {
                what: "parameter number (1 to 5602)",
                value,
                span: span(self.range(start.saturating_sub(1), self.pos)),
            });
        }
        Ok(rounded as usize)
    }

    /// A parameter read, at a `#`.
    fn parameter(&mut self) -> Result<f64> {
        self.enter()?;
        let hash = self.pos;
        self.pos += 1;
        self.skip_blanks();
        let result = if self.peek() == Some(b'<') {
            let (_, name) = self.name()?;
            self.params.named(name)
        } else {
            let index = self.index()?;
            self.params.numbered(index)
        };
        self.depth -= 1;
        result.map_err(|problem| self.read_problem(problem, hash))
    }

    fn read_problem(&self, problem: ReadProblem, hash: usize) -> GcodeDiagnostic {
        let written = &self.text[hash..self.pos];
        let at = span(self.range(hash, self.pos));
        match problem {
            ReadProblem::Undefined => GcodeDiagnostic::UndefinedParameter {
                name: written.to_owned(),
                span: at,
            },
            ReadProblem::MachineSpecific(feature) => GcodeDiagnostic::Unsupported {
                code: normalize(written).into_owned(),
                feature,
                places: 1,
                span: at,
            },
        }
    }
}

const HINT_EXPRESSION: &str =
    "an expression is [ value operator value … ], e.g. [#<scale>*-25.372] or [2*SIN[30]]";
const HINT_FUNCTIONS: &str =
    "functions: ABS ACOS ASIN ATAN[y]/[x] COS EXP FIX FUP ROUND LN SIN SQRT TAN EXISTS";

fn show(x: f64) -> String {
    crate::diagnostic::show(x)
}
