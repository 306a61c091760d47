//! O-word control flow: subroutines (`sub`/`endsub`/`return`/`call`), conditionals
//! (`if`/`elseif`/`else`/`endif`) and loops (`while`/`endwhile`, `do`/`while`,
//! `repeat`/`endrepeat`, `break`, `continue`), run as LinuxCNC runs them.
//!
//! Owns the recognition of control lines, the bodies held in memory and the rules that
//! bound them: [`crate::MAX_CALL_DEPTH`] nested calls, [`crate::MAX_LOOP_ITERATIONS`] per
//! loop and [`crate::MAX_TOTAL_ITERATIONS`] in all, [`crate::MAX_BUFFERED_BYTES`] of held
//! text. The main program streams: only the bodies of subroutines and loops are held, a
//! conditional skips lines as they come. A call of a subroutine defined further on
//! waits for it through [`crate::subprogram`]'s search. It must not give words a
//! meaning (lines go to [`crate::Reader`]'s block path) nor read files (subroutine files
//! come through [`crate::SubroutineFiles`]).

use std::collections::HashMap;
use std::ops::Range;
use std::rc::Rc;

use crate::diagnostic::{span, GcodeDiagnostic};
use crate::params::{ParamRef, Parameters};
use crate::parser::SourceLine;
use crate::{
    Reader, MAX_BUFFERED_BYTES, MAX_CALL_DEPTH, MAX_LOOP_ITERATIONS, MAX_TOTAL_ITERATIONS,
};

/// The keyword after an O-word label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keyword {
    Sub,
    Endsub,
    Return,
    Call,
    If,
    Elseif,
    Else,
    Endif,
    While,
    Endwhile,
    Do,
    Repeat,
    Endrepeat,
    Break,
    Continue,
}

impl Keyword {
    fn parse(word: &str) -> Option<Keyword> {
        use Keyword::*;
        Some(match word.to_ascii_lowercase().as_str() {
            "sub" => Sub,
            "endsub" => Endsub,
            "return" => Return,
            "call" => Call,
            "if" => If,
            "elseif" => Elseif,
            "else" => Else,
            "endif" => Endif,
            "while" => While,
            "endwhile" => Endwhile,
            "do" => Do,
            "repeat" => Repeat,
            "endrepeat" => Endrepeat,
            "break" => Break,
            "continue" => Continue,
            _ => return None,
        })
    }
}

/// A control line: `oLABEL keyword [values]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Control {
    /// The label, normalized: a number as digits without leading zeros, a name as
    /// `<name>` lower-cased without blanks.
    pub label: String,
    pub keyword: Keyword,
    /// The O-word and keyword, absolute byte range.
    pub span: Range<usize>,
    /// Byte position in the line's text after the keyword (where values start).
    pub rest: usize,
}

/// Recognizes a control line. `None`: not one (no O-word, or a program number alone,
/// which the parser reads); `Some(Err)`: an O-word with an unknown keyword.
pub(crate) fn parse_control(text: &str, start: usize) -> Option<Result<Control, GcodeDiagnostic>> {
    let b = text.as_bytes();
    let mut i = 0;
    let skip_blanks = |i: &mut usize| {
        while matches!(b.get(*i), Some(b' ' | b'\t')) {
            *i += 1;
        }
    };
    skip_blanks(&mut i);
    if b.get(i) == Some(&b'/') {
        i += 1;
        skip_blanks(&mut i);
    }
    if matches!(b.get(i), Some(b'N' | b'n')) {
        i += 1;
        skip_blanks(&mut i);
        while matches!(b.get(i), Some(b'0'..=b'9')) {
            i += 1;
        }
        skip_blanks(&mut i);
    }
    if !matches!(b.get(i), Some(b'O' | b'o')) {
        return None;
    }
    let o = i;
    i += 1;
    skip_blanks(&mut i);
    let label = match b.get(i) {
        Some(b'<') => {
            let close = text[i..].find('>')? + i;
            let name = crate::params::normalize(&text[i + 1..close]).into_owned();
            i = close + 1;
            format!("<{name}>")
        }
        Some(b'0'..=b'9') => {
            let first = i;
            while matches!(b.get(i), Some(b'0'..=b'9')) {
                i += 1;
            }
            let digits = text[first..i].trim_start_matches('0');
            if digits.is_empty() { "0" } else { digits }.to_owned()
        }
        _ => return None,
    };
    skip_blanks(&mut i);
    let word_start = i;
    while b.get(i).is_some_and(u8::is_ascii_alphabetic) {
        i += 1;
    }
    let word = &text[word_start..i];
    if word.is_empty() {
        // `O1000` alone, or followed by a comment: a program number.
        return None;
    }
    let span = start + o..start + i;
    Some(match Keyword::parse(word) {
        Some(keyword) => Ok(Control {
            label,
            keyword,
            span,
            rest: i,
        }),
        None => Err(GcodeDiagnostic::Oword {
            detail: format!("`{word}` is not an O-word keyword"),
            span: crate::diagnostic::span(span),
        }),
    })
}

/// A line held in memory: a subroutine's or a loop's.
#[derive(Debug, Clone)]
pub(crate) struct StoredLine {
    pub text: Box<str>,
    pub start: usize,
    pub number: u32,
    pub control: Option<Control>,
}

impl StoredLine {
    /// Holds `line`, its control word read once.
    fn new(line: SourceLine<'_>) -> Result<StoredLine, GcodeDiagnostic> {
        let control = parse_control(line.text, line.start).transpose()?;
        Ok(StoredLine {
            text: line.text.into(),
            start: line.start,
            number: line.number,
            control,
        })
    }

    /// Holds `line` as it is; a control word that cannot be read is left for the
    /// block path to report.
    pub(crate) fn held(line: SourceLine<'_>) -> StoredLine {
        StoredLine::new(line).unwrap_or_else(|_| StoredLine {
            text: line.text.into(),
            start: line.start,
            number: line.number,
            control: None,
        })
    }

    pub(crate) fn source(&self) -> SourceLine<'_> {
        SourceLine {
            text: &self.text,
            start: self.start,
            number: self.number,
        }
    }
}

/// The file a body was read from, for diagnostics.
#[derive(Debug)]
pub(crate) struct FileText {
    pub name: String,
    pub text: String,
}

/// Held lines: a subroutine's body, or a loop of the main program with its O-words.
#[derive(Debug, Clone)]
pub(crate) struct Body {
    pub lines: Rc<[StoredLine]>,
    /// `None` for the program's own file.
    pub file: Option<Rc<FileText>>,
}

/// Where a subroutine file's diagnostics are shown in the main program.
#[derive(Debug, Clone)]
pub(crate) struct Origin {
    pub file: Rc<FileText>,
    /// The outermost call in the main program, and its line.
    pub call: Range<usize>,
    pub call_line: u32,
}

impl Origin {
    /// `diagnostic` (spans in the subroutine file) shown at the call.
    pub fn wrap(&self, diagnostic: GcodeDiagnostic) -> GcodeDiagnostic {
        let at = pvt_core::text::SourceLocation::of(&self.file.text, diagnostic.span());
        GcodeDiagnostic::InSubroutineFile {
            file: self.file.name.clone(),
            line: at.line as usize,
            column: at.column as usize,
            inner_code: diagnostic.code(),
            inner: Box::new(diagnostic),
            span: span(self.call.clone()),
        }
    }
}

/// Where a conditional of the main program stands.
#[derive(Debug, Clone, PartialEq)]
enum Skip {
    /// Lines run.
    No,
    /// A false condition: skip to this label's `elseif`, `else` or `endif`.
    Branch(String),
    /// A branch ran: skip to this label's `endif`.
    ToEnd(String),
}

impl Skip {
    /// True when `control` ends the skip state's stretch of lines.
    fn stops_at(&self, control: &Control) -> bool {
        use Keyword::*;
        match self {
            Skip::No => true,
            Skip::Branch(label) => {
                *label == control.label && matches!(control.keyword, Elseif | Else | Endif)
            }
            Skip::ToEnd(label) => *label == control.label && control.keyword == Endif,
        }
    }
}

/// What a stretch of lines ended with.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Signal {
    /// It ran through.
    Next,
    Break(String),
    Continue(String),
    /// `return` or `endsub`, with the value given.
    Return(Option<f64>),
    /// The program ended (M2/M30).
    End,
}

/// A construct of the main program being held until its end.
#[derive(Debug)]
struct Recording {
    opening: Control,
    /// The keyword that ends it.
    close: Keyword,
    lines: Vec<StoredLine>,
    /// The body went past the limit (reported): its lines are skipped to its end.
    overflow: bool,
}

/// The control-flow state of a program run.
#[derive(Debug)]
pub(crate) struct Flow {
    subs: HashMap<String, Body>,
    recording: Option<Recording>,
    skip: Skip,
    /// Bytes of text held (definitions and recordings), against the limit.
    held: usize,
    depth: usize,
    /// Loop iterations of the run so far.
    iterations: u64,
    /// Files that could not be found, reported once each.
    missing: Vec<String>,
}

impl Flow {
    /// True when no body is being recorded or skipped: a line that is not an O-word
    /// line runs as it is.
    pub fn is_idle(&self) -> bool {
        self.recording.is_none() && self.skip == Skip::No
    }
}

impl Default for Flow {
    fn default() -> Self {
        Flow {
            subs: HashMap::new(),
            recording: None,
            skip: Skip::No,
            held: 0,
            depth: 0,
            iterations: 0,
            missing: Vec::new(),
        }
    }
}

/// What the keyword that opens a construct needs to end it.
fn closing(keyword: Keyword) -> Option<Keyword> {
    match keyword {
        Keyword::Sub => Some(Keyword::Endsub),
        Keyword::While => Some(Keyword::Endwhile),
        Keyword::Do => Some(Keyword::While),
        Keyword::Repeat => Some(Keyword::Endrepeat),
        _ => None,
    }
}

impl<'a> Reader<'a> {
    /// The main program's next line through the control flow; `None` when it is an
    /// ordinary line for the block path. Returns as [`Reader::line`].
    pub(crate) fn flow_line(&mut self, line: SourceLine<'_>) -> Option<bool> {
        if self.flow.recording.is_some() {
            return Some(self.record(line));
        }
        let control = match parse_control(line.text, line.start) {
            None if self.flow.skip == Skip::No => return None,
            None => return Some(true),
            Some(Err(diagnostic)) => {
                if self.flow.skip == Skip::No {
                    self.report(diagnostic);
                }
                return Some(true);
            }
            Some(Ok(control)) => control,
        };
        if !self.flow.skip.stops_at(&control) {
            return Some(true);
        }
        if let Some(close) = closing(control.keyword) {
            self.flow.recording = Some(Recording {
                opening: control,
                close,
                lines: Vec::new(),
                overflow: false,
            });
            return Some(self.record(line));
        }
        let mut skip = std::mem::replace(&mut self.flow.skip, Skip::No);
        let signal = self.control(&control, line, &mut skip);
        self.flow.skip = skip;
        Some(match signal {
            Signal::End | Signal::Next => true,
            Signal::Break(_) | Signal::Continue(_) | Signal::Return(_) => {
                let what = match signal {
                    Signal::Return(_) => "`return` or `endsub` outside a subroutine",
                    _ => "`break` or `continue` outside a loop",
                };
                self.report(GcodeDiagnostic::Oword {
                    detail: what.to_owned(),
                    span: span(control.span.clone()),
                });
                true
            }
        })
    }

    /// At the end of the input: a construct still being held never got its end.
    /// True while a construct of the main program is being held.
    pub(crate) fn flow_recording(&self) -> bool {
        self.flow.recording.is_some()
    }

    pub(crate) fn flow_finish(&mut self) {
        if let Some(recording) = self.flow.recording.take() {
            let close = recording.close;
            self.report(unclosed(&recording.opening, close));
        }
    }

    /// Holds a line of the construct being recorded; runs or defines it at its end.
    fn record(&mut self, line: SourceLine<'_>) -> bool {
        let stored = match StoredLine::new(line) {
            Ok(stored) => stored,
            Err(diagnostic) => {
                self.report(diagnostic);
                StoredLine {
                    text: line.text.into(),
                    start: line.start,
                    number: line.number,
                    control: None,
                }
            }
        };
        let Some(recording) = self.flow.recording.as_mut() else {
            return true;
        };
        let ends =
            stored.control.as_ref().is_some_and(|c| {
                c.label == recording.opening.label && c.keyword == recording.close
            }) && (!recording.lines.is_empty() || recording.overflow);
        if recording.overflow {
            if ends {
                self.flow.recording = None;
            }
            return true;
        }
        self.flow.held += stored.text.len();
        if self.flow.held > MAX_BUFFERED_BYTES {
            let held: usize = recording.lines.iter().map(|l| l.text.len()).sum();
            recording.lines = Vec::new();
            recording.overflow = true;
            let opening = recording.opening.span.clone();
            self.flow.held -= held + stored.text.len();
            self.report(GcodeDiagnostic::BodyTooLarge {
                limit: MAX_BUFFERED_BYTES,
                span: span(opening),
            });
            return true;
        }
        recording.lines.push(stored);
        if !ends {
            return true;
        }
        let Some(recording) = self.flow.recording.take() else {
            return true;
        };
        let lines: Rc<[StoredLine]> = recording.lines.into();
        let body = Body { lines, file: None };
        let end = body.lines.len();
        match recording.opening.keyword {
            Keyword::Sub => {
                // The body keeps its `endsub` line, which may return a value.
                let label = recording.opening.label;
                self.flow.subs.insert(
                    label.clone(),
                    Body {
                        lines: body.lines[1..end].to_vec().into(),
                        file: None,
                    },
                );
                if self.subprograms.wants_oword(&label) {
                    return self.found();
                }
                true
            }
            _ => {
                // Loops are not held after they ran.
                self.flow.held = self
                    .flow
                    .held
                    .saturating_sub(body.lines.iter().map(|l| l.text.len()).sum::<usize>());
                let signal = self.run_loop(&body, 0, end - 1);
                match signal {
                    Signal::End | Signal::Next => true,
                    _ => {
                        self.report(GcodeDiagnostic::Oword {
                            detail: "`break`, `continue` or `return` outside its construct"
                                .to_owned(),
                            span: span(recording.opening.span),
                        });
                        true
                    }
                }
            }
        }
    }

    /// Runs lines `range` of `body`; a diagnostic a line gave on an earlier run is not
    /// given again.
    fn run_body(&mut self, body: &Body, range: Range<usize>) -> Signal {
        let once = std::mem::replace(&mut self.interpreter.once, true);
        self.subprograms.in_body += 1;
        let signal = self.run_lines(body, range);
        self.subprograms.in_body -= 1;
        self.interpreter.once = once;
        signal
    }

    /// How many calls are in progress.
    pub(crate) fn flow_depth(&self) -> usize {
        self.flow.depth
    }

    /// Runs a subprogram (M98): a call without arguments or locals of its own, ended by
    /// its `M99`; false when the program ended in it.
    pub(crate) fn run_called(&mut self, body: &Body) -> bool {
        self.flow.depth += 1;
        let signal = self.run_body(body, 0..body.lines.len());
        self.flow.depth -= 1;
        signal != Signal::End
    }

    fn run_lines(&mut self, body: &Body, range: Range<usize>) -> Signal {
        let mut skip = Skip::No;
        let mut pc = range.start;
        while pc < range.end {
            let Some(line) = body.lines.get(pc) else {
                break;
            };
            pc += 1;
            let Some(control) = &line.control else {
                if skip == Skip::No {
                    if !self.run_line(line.source()) {
                        return Signal::End;
                    }
                    if std::mem::take(&mut self.subprograms.returned) {
                        return Signal::Return(None);
                    }
                }
                continue;
            };
            if !skip.stops_at(control) {
                continue;
            }
            if let Some(close) = closing(control.keyword) {
                let Some(end) = find(body, pc..range.end, &control.label, close) else {
                    self.report(unclosed(control, close));
                    return Signal::Next;
                };
                if control.keyword == Keyword::Sub {
                    self.define(&control.label, body, pc..end + 1);
                } else {
                    match self.run_loop(body, pc - 1, end) {
                        Signal::Next => {}
                        other => return other,
                    }
                }
                pc = end + 1;
                continue;
            }
            match self.control(control, line.source(), &mut skip) {
                Signal::Next => {}
                other => return other,
            }
        }
        Signal::Next
    }

    /// Defines the subroutine `label` as lines `range` of `body`.
    fn define(&mut self, label: &str, body: &Body, range: Range<usize>) {
        let lines: Rc<[StoredLine]> = body.lines[range].to_vec().into();
        self.flow.held += lines.iter().map(|l| l.text.len()).sum::<usize>();
        self.flow.subs.insert(
            label.to_owned(),
            Body {
                lines,
                file: body.file.clone(),
            },
        );
    }

    /// Runs the loop whose opening O-word is line `open` of `body` and closing one line
    /// `close`.
    fn run_loop(&mut self, body: &Body, open: usize, close: usize) -> Signal {
        let (Some(opening), Some(closing_line)) = (body.lines.get(open), body.lines.get(close))
        else {
            return Signal::Next;
        };
        let Some(control) = opening.control.clone() else {
            return Signal::Next;
        };
        let mut times = None;
        if control.keyword == Keyword::Repeat {
            match self.values(opening.source(), &control, 1, 1) {
                Ok(v) => times = Some(v[0].max(0.0).round() as u64),
                Err(d) => {
                    self.report(d);
                    return Signal::Next;
                }
            }
        }
        let mut count: u64 = 0;
        loop {
            match control.keyword {
                Keyword::While => match self.condition(opening.source(), &control) {
                    Ok(true) => {}
                    Ok(false) => break,
                    Err(()) => return Signal::Next,
                },
                Keyword::Repeat if Some(count) >= times => break,
                _ => {}
            }
            count += 1;
            self.flow.iterations += 1;
            let all = self.flow.iterations > MAX_TOTAL_ITERATIONS;
            if all && self.flow.iterations > MAX_TOTAL_ITERATIONS + 1 {
                // Reported once, by the loop that went past it; every loop stops now.
                return Signal::Next;
            }
            if count > MAX_LOOP_ITERATIONS || all {
                self.report(GcodeDiagnostic::LoopLimit {
                    limit: if all {
                        MAX_TOTAL_ITERATIONS
                    } else {
                        MAX_LOOP_ITERATIONS
                    },
                    all,
                    span: span(control.span.clone()),
                });
                return Signal::Next;
            }
            match self.run_body(body, open + 1..close) {
                Signal::Next => {}
                Signal::Continue(label) if label == control.label => {}
                Signal::Break(label) if label == control.label => break,
                other => return other,
            }
            if control.keyword == Keyword::Do {
                let Some(end) = closing_line.control.clone() else {
                    break;
                };
                match self.condition(closing_line.source(), &end) {
                    Ok(true) => {}
                    Ok(false) => break,
                    Err(()) => return Signal::Next,
                }
            }
        }
        Signal::Next
    }

    /// A control line other than a construct's opening: conditionals, calls, returns,
    /// `break`, `continue`, stray ends; `skip` is the conditional state of the lines it
    /// is among.
    fn control(&mut self, control: &Control, line: SourceLine<'_>, skip: &mut Skip) -> Signal {
        match control.keyword {
            Keyword::If | Keyword::Elseif => {
                if control.keyword == Keyword::Elseif && *skip == Skip::No {
                    *skip = Skip::ToEnd(control.label.clone());
                    return Signal::Next;
                }
                match self.condition(line, control) {
                    Ok(true) => *skip = Skip::No,
                    Ok(false) => *skip = Skip::Branch(control.label.clone()),
                    Err(()) => *skip = Skip::ToEnd(control.label.clone()),
                }
                Signal::Next
            }
            Keyword::Else => {
                *skip = match skip {
                    Skip::Branch(_) => Skip::No,
                    _ => Skip::ToEnd(control.label.clone()),
                };
                Signal::Next
            }
            Keyword::Endif => {
                *skip = Skip::No;
                Signal::Next
            }
            Keyword::Call => self.call(control, line),
            Keyword::Return | Keyword::Endsub => match self.values(line, control, 0, 1) {
                Ok(v) => Signal::Return(v.first().copied()),
                Err(d) => {
                    self.report(d);
                    Signal::Return(None)
                }
            },
            Keyword::Break => Signal::Break(control.label.clone()),
            Keyword::Continue => Signal::Continue(control.label.clone()),
            Keyword::Endwhile | Keyword::Endrepeat | Keyword::While => {
                self.report(GcodeDiagnostic::Oword {
                    detail: format!("o{} ends a loop that was not started", control.label),
                    span: span(control.span.clone()),
                });
                Signal::Next
            }
            Keyword::Sub | Keyword::Do | Keyword::Repeat => Signal::Next,
        }
    }

    /// `oLABEL call [a] [b] …`.
    fn call(&mut self, control: &Control, line: SourceLine<'_>) -> Signal {
        let args = match self.values(line, control, 0, crate::params::CALL_ARGUMENTS) {
            Ok(args) => args,
            Err(d) => {
                self.report(d);
                return Signal::Next;
            }
        };
        self.invoke(&control.label, args, control.span.clone(), line.number)
    }

    /// Calls the subroutine `label` with `args` from the call at `at` (on line
    /// `line_number`). An unknown one called from the main program is searched for in
    /// the rest of the file, as rs274 does.
    pub(crate) fn invoke(
        &mut self,
        label: &str,
        args: Vec<f64>,
        at: Range<usize>,
        line_number: u32,
    ) -> Signal {
        if self.flow.depth >= MAX_CALL_DEPTH {
            self.report(GcodeDiagnostic::RecursionLimit {
                limit: MAX_CALL_DEPTH,
                span: span(at),
            });
            return Signal::End;
        }
        let body = match self.subroutine(label, &at) {
            Ok(body) => body,
            Err(None) => return Signal::Next,
            Err(Some(searched)) => {
                if self.flow.depth == 0 && self.subprograms.can_search() {
                    self.subprograms
                        .search_oword(label, args, at, line_number, searched);
                } else {
                    self.unknown_subroutine(label, searched, at);
                }
                return Signal::Next;
            }
        };
        let saved_origin = self.interpreter.origin.clone();
        let call_at = at.clone();
        match &body.file {
            Some(file) => {
                let (call, call_line) = match &saved_origin {
                    Some(outer) => (outer.call.clone(), outer.call_line),
                    None => (at, line_number),
                };
                self.interpreter.origin = Some(Origin {
                    file: file.clone(),
                    call,
                    call_line,
                });
            }
            // A subroutine of the program's own file: its lines' spans are the program's.
            None => self.interpreter.origin = None,
        }
        self.flow.depth += 1;
        self.params.enter_call(&args);
        self.interpreter.enter_call();
        let signal = self.run_body(&body, 0..body.lines.len());
        self.interpreter.origin = saved_origin;
        if !matches!(signal, Signal::End) {
            // M73's state comes back as the subroutine returns (at its call).
            self.interpreter.leave_call(call_at, line_number);
        }
        self.params.leave_call();
        self.flow.depth -= 1;
        let value = match signal {
            Signal::End => return Signal::End,
            Signal::Return(value) => value,
            _ => None,
        };
        self.params
            .set(&ParamRef::Named("_value".to_owned()), value.unwrap_or(0.0));
        self.params.set(
            &ParamRef::Named("_value_returned".to_owned()),
            if value.is_some() { 1.0 } else { 0.0 },
        );
        Signal::Next
    }

    /// Reports the subroutine `label` as unknown (once per label).
    pub(crate) fn unknown_subroutine(&mut self, label: &str, searched: String, at: Range<usize>) {
        if !self.flow.missing.iter().any(|m| m == label) {
            self.flow.missing.push(label.to_owned());
            self.report(GcodeDiagnostic::UnknownSubroutine {
                name: label.to_owned(),
                searched,
                span: span(at),
            });
        }
    }

    /// The body of the subroutine `label`: defined before, or read from a file. `Err`
    /// holds what was searched, or `None` when a file was found but is wrong (reported).
    fn subroutine(&mut self, label: &str, at: &Range<usize>) -> Result<Body, Option<String>> {
        if let Some(body) = self.flow.subs.get(label) {
            return Ok(body.clone());
        }
        let name = label.strip_prefix('<').and_then(|n| n.strip_suffix('>'));
        let searched = match (name, self.options.subroutines.0.as_deref()) {
            (Some(name), Some(files)) => match files.read(name) {
                Ok(Some(file)) => return self.load(label, at, name, file).ok_or(None),
                Ok(None) => format!("no {name}.ngc in {}", files.describe()),
                Err(error) => error,
            },
            (Some(name), None) => {
                format!("no subroutine path is given to look for {name}.ngc")
            }
            (None, _) => String::new(),
        };
        Err(Some(searched))
    }

    /// Reads the definition of `name` from a subroutine file.
    fn load(
        &mut self,
        called: &str,
        at: &Range<usize>,
        name: &str,
        file: SubroutineFile,
    ) -> Option<Body> {
        let label = format!("<{}>", crate::params::normalize(name));
        let file = Rc::new(FileText {
            name: file.name,
            text: file.text,
        });
        let mut lines = Vec::new();
        let mut inside = false;
        let mut found = false;
        for line in crate::parser::SourceLines::new(&file.text) {
            let control_here = parse_control(line.text, line.start).and_then(Result::ok);
            let is = |k: Keyword| {
                control_here
                    .as_ref()
                    .is_some_and(|c| c.label == label && c.keyword == k)
            };
            if !inside {
                inside = is(Keyword::Sub);
                continue;
            }
            if is(Keyword::Endsub) {
                // The `endsub` line itself may return a value.
                if let Ok(stored) = StoredLine::new(line) {
                    lines.push(stored);
                }
                found = true;
                break;
            }
            self.flow.held += line.text.len();
            if self.flow.held > MAX_BUFFERED_BYTES {
                self.report(GcodeDiagnostic::BodyTooLarge {
                    limit: MAX_BUFFERED_BYTES,
                    span: span(at.clone()),
                });
                return None;
            }
            match StoredLine::new(line) {
                Ok(stored) => lines.push(stored),
                Err(_) => lines.push(StoredLine {
                    text: line.text.into(),
                    start: line.start,
                    number: line.number,
                    control: None,
                }),
            }
        }
        if !found {
            self.report(GcodeDiagnostic::UnknownSubroutine {
                name: called.to_owned(),
                searched: format!("{} has no o{label} sub … o{label} endsub", file.name),
                span: span(at.clone()),
            });
            return None;
        }
        let body = Body {
            lines: lines.into(),
            file: Some(file),
        };
        self.flow.subs.insert(called.to_owned(), body.clone());
        Some(body)
    }

    /// A condition: the one value after the keyword, true when not 0.
    fn condition(&mut self, line: SourceLine<'_>, control: &Control) -> Result<bool, ()> {
        match self.values(line, control, 1, 1) {
            Ok(v) => Ok(v[0] != 0.0),
            Err(d) => {
                self.report(d);
                Err(())
            }
        }
    }

    /// The values after a control line's keyword, `min..=max` of them, each a
    /// bracketed expression, a number or a parameter; only comments may follow.
    fn values(
        &mut self,
        line: SourceLine<'_>,
        control: &Control,
        min: usize,
        max: usize,
    ) -> Result<Vec<f64>, GcodeDiagnostic> {
        self.refresh_view(line.number);
        let params: &Parameters = &self.params;
        let mut reader = crate::value::Reader::new(line.text, line.start, control.rest, params);
        let mut values = Vec::new();
        loop {
            reader.skip_blanks();
            let rest = reader.rest();
            if rest.is_empty() || rest.starts_with(';') {
                break;
            }
            if rest.starts_with('(') {
                match rest.find(')') {
                    Some(close) => {
                        reader.pos += close + 1;
                        continue;
                    }
                    None => break,
                }
            }
            if values.len() == max {
                let at = reader.absolute(reader.pos);
                return Err(GcodeDiagnostic::Oword {
                    detail: format!(
                        "o{} {:?} takes at most {max} values",
                        control.label, control.keyword
                    )
                    .to_lowercase(),
                    span: span(at..at + crate::tokens::token_len(rest)),
                });
            }
            values.push(reader.real_value()?);
        }
        if values.len() < min {
            return Err(GcodeDiagnostic::Oword {
                detail: format!(
                    "o{} {} needs a condition or count, e.g. [#1 LT 10]",
                    control.label,
                    format!("{:?}", control.keyword).to_lowercase()
                ),
                span: span(control.span.clone()),
            });
        }
        Ok(values)
    }
}

/// The line in `range` of `body` that closes the construct `label` with `close`.
fn find(body: &Body, range: Range<usize>, label: &str, close: Keyword) -> Option<usize> {
    range.into_iter().find(|&i| {
        body.lines[i]
            .control
            .as_ref()
            .is_some_and(|c| c.label == label && c.keyword == close)
    })
}

fn unclosed(control: &Control, close: Keyword) -> GcodeDiagnostic {
    GcodeDiagnostic::Oword {
        detail: format!(
            "o{} {} has no o{} {}",
            control.label,
            format!("{:?}", control.keyword).to_lowercase(),
            control.label,
            format!("{close:?}").to_lowercase()
        ),
        span: span(control.span.clone()),
    }
}

/// A subroutine file's text and the name to show for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SubroutineFile {
    /// The path as shown in diagnostics.
    pub name: String,
    /// Its text.
    pub text: String,
}

/// Where named subroutines `o<name> call` not defined in the program come from: the CLI
/// reads `name.ngc` from the folders of `--subroutine-path`.
pub trait SubroutineFiles {
    /// The file for subroutine `name` (as written between `<` and `>`), `Ok(None)` when
    /// there is none, or why it could not be read.
    fn read(&self, name: &str) -> Result<Option<SubroutineFile>, String>;
    /// What is searched, for the diagnostic when nothing is found (e.g. the folders).
    fn describe(&self) -> String;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_lines_are_recognized() {
        let c = parse_control("  N10 O0100 While [#1 LT 3]", 5)
            .unwrap()
            .unwrap();
        assert_eq!(c.label, "100");
        assert_eq!(c.keyword, Keyword::While);
        assert_eq!(c.span, 5 + 6..5 + 17);
        let c = parse_control("o< My Sub >call [1]", 0).unwrap().unwrap();
        assert_eq!(c.label, "<mysub>");
        assert_eq!(c.keyword, Keyword::Call);
        assert!(parse_control("O1000", 0).is_none());
        assert!(parse_control("O1000 (program)", 0).is_none());
        assert!(parse_control("G1 X1", 0).is_none());
        assert!(parse_control("o100 jump", 0).unwrap().is_err());
    }
}
