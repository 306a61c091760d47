//! Fanuc-style subprograms: `M98 P<n> [L<count>]` calls the block `O<n>` … `M99` of the
//! same file, as rs274 runs them (it searches the file for `O<n>`, usually after M30).
//!
//! Owns the M98/M99 words (taken out of a block before the interpreter sees it), the
//! subprogram definitions and the search: when `O<n>` is not known yet, the main
//! program's following lines are held until `O<n>` … `M99` comes by, then the call runs
//! and the held lines are read again. Held text counts against
//! [`crate::MAX_BUFFERED_BYTES`]. The same search finds an `oN sub` that comes after
//! its `oN call` in the main program. A program number that starts the file, or one met
//! when nothing is searched, names the program (rs274 runs its lines as main program
//! code). It must not give other words a meaning nor read files.

use std::collections::HashMap;
use std::ops::Range;

use crate::block::Word;
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::oword::{Body, StoredLine};
use crate::parser::SourceLine;
use crate::{Reader, MAX_BUFFERED_BYTES, MAX_CALL_DEPTH};

/// An `M98` call of a block.
#[derive(Debug, Clone)]
pub(crate) struct Call {
    number: u32,
    times: u64,
    span: Range<usize>,
}

/// A call whose subroutine comes later in the file.
#[derive(Debug)]
enum Pending {
    /// `M98 P<n>`: the block `O<n>` … `M99`.
    Fanuc(Call),
    /// `oLABEL call`: `oLABEL sub` … `oLABEL endsub`, with the call's arguments.
    Oword {
        label: String,
        args: Vec<f64>,
        span: Range<usize>,
        line: u32,
        /// What was searched before the rest of the file (subroutine files).
        searched: String,
    },
}

impl Pending {
    fn span(&self) -> Range<usize> {
        match self {
            Pending::Fanuc(call) => call.span.clone(),
            Pending::Oword { span, .. } => span.clone(),
        }
    }
}

/// A call waiting for its subprogram, and the main program lines read meanwhile.
#[derive(Debug)]
struct Search {
    call: Pending,
    held: Vec<StoredLine>,
    bytes: usize,
}

/// The subprogram state of a program run.
#[derive(Debug, Default)]
pub(crate) struct Subprograms {
    defined: HashMap<u32, Body>,
    search: Option<Search>,
    /// The subprogram whose lines are being held up to its `M99`.
    recording: Option<(u32, Vec<StoredLine>)>,
    /// An `M99` ran: the subprogram returns.
    pub returned: bool,
    /// How many bodies (loops, subroutines, subprograms) are running.
    pub in_body: u32,
    /// After the program end: a subprogram's lines are skipped without warnings.
    skipping_after_end: bool,
    /// How many searches' held lines are being read again (one inside another when a
    /// call in held lines searches in turn), and their bytes.
    replaying: u32,
    replayed_bytes: usize,
}

/// How deep searches may nest (a call in held lines whose definition is further on in
/// the held lines); deeper, the call is `unknown_subroutine`. Bounds the stack and, with
/// the bytes of every nested search counted together, the memory.
const MAX_SEARCH_DEPTH: u32 = 16;

impl Subprograms {
    /// True when no subprogram is being recorded or searched for: a line runs as it is.
    pub fn is_idle(&self) -> bool {
        self.recording.is_none() && self.search.is_none()
    }

    /// True when a search may start: none is under way, no body is running and searches
    /// do not nest too deep.
    pub fn can_search(&self) -> bool {
        self.search.is_none() && self.in_body == 0 && self.replaying < MAX_SEARCH_DEPTH
    }

    /// Starts searching the rest of the file for `oLABEL sub`.
    pub fn search_oword(
        &mut self,
        label: &str,
        args: Vec<f64>,
        span: Range<usize>,
        line: u32,
        searched: String,
    ) {
        self.search = Some(Search {
            call: Pending::Oword {
                label: label.to_owned(),
                args,
                span,
                line,
                searched,
            },
            held: Vec::new(),
            bytes: 0,
        });
    }

    /// True when the search waits for the subroutine `label`.
    pub fn wants_oword(&self, label: &str) -> bool {
        matches!(&self.search, Some(Search { call: Pending::Oword { label: l, .. }, .. }) if l == label)
    }

    /// The Fanuc subprogram number searched for, if any.
    fn wanted_number(&self) -> Option<u32> {
        match &self.search {
            Some(Search {
                call: Pending::Fanuc(call),
                ..
            }) => Some(call.number),
            _ => None,
        }
    }
}

/// `O<n>` alone on its line (a comment may follow): `n`.
fn program_number(text: &str) -> Option<u32> {
    let t = text.trim_start_matches([' ', '\t']);
    let rest = t.strip_prefix(['O', 'o'])?;
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    let tail = rest[digits..].trim_start_matches([' ', '\t']);
    if digits == 0 || !(tail.is_empty() || tail.starts_with(['(', ';'])) {
        return None;
    }
    rest[..digits].parse().ok()
}

/// True when the line's words include M99 (read lexically: comments dropped, blanks
/// and case ignored).
fn has_m99(text: &str) -> bool {
    let mut words = String::with_capacity(text.len());
    let mut depth = 0;
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            ';' if depth == 0 => break,
            ' ' | '\t' => {}
            c if depth == 0 => words.push(c.to_ascii_uppercase()),
            _ => {}
        }
    }
    let b = words.as_bytes();
    words
        .match_indices("M99")
        .any(|(at, _)| !matches!(b.get(at + 3), Some(b'0'..=b'9' | b'.')))
}

fn stored(line: SourceLine<'_>) -> StoredLine {
    StoredLine::held(line)
}

impl<'a> Reader<'a> {
    /// A main program line through the subprogram machinery; `None` when it is not
    /// its business. Returns as [`Reader::line`].
    pub(crate) fn subprogram_line(&mut self, line: SourceLine<'_>) -> Option<bool> {
        if let Some((number, lines)) = &mut self.subprograms.recording {
            lines.push(stored(line));
            if has_m99(line.text) {
                let number = *number;
                let Some((_, lines)) = self.subprograms.recording.take() else {
                    return Some(true);
                };
                self.subprograms.defined.insert(
                    number,
                    Body {
                        lines: lines.into(),
                        file: None,
                    },
                );
                if self.subprograms.wanted_number() == Some(number) {
                    return Some(self.found());
                }
            }
            return Some(true);
        }
        self.subprograms.search.as_ref()?;
        if self.flow_recording() {
            // The searched `oLABEL sub` is being defined: its lines are the flow's.
            return None;
        }
        let wanted = self.subprograms.wanted_number();
        if wanted.is_some() && program_number(line.text) == wanted {
            self.subprograms.recording = wanted.map(|n| (n, Vec::new()));
            return Some(true);
        }
        if let Some(Ok(control)) = crate::oword::parse_control(line.text, line.start) {
            if control.keyword == crate::oword::Keyword::Sub
                && self.subprograms.wants_oword(&control.label)
            {
                return None;
            }
        }
        let outer = self.subprograms.replayed_bytes;
        let search = self.subprograms.search.as_mut()?;
        search.bytes += line.text.len();
        if outer + search.bytes > MAX_BUFFERED_BYTES {
            let search = self.subprograms.search.take()?;
            self.report(GcodeDiagnostic::BodyTooLarge {
                limit: MAX_BUFFERED_BYTES,
                span: span(search.call.span()),
            });
            return Some(true);
        }
        search.held.push(stored(line));
        Some(true)
    }

    /// After the program end: true when `line` is part of a subprogram (`O<n>` …
    /// `M99`), which is not reported as a block after the end.
    pub(crate) fn subprogram_after_end(&mut self, line: SourceLine<'_>) -> bool {
        if self.subprograms.skipping_after_end {
            self.subprograms.skipping_after_end = !has_m99(line.text);
            return true;
        }
        if program_number(line.text).is_some() {
            self.subprograms.skipping_after_end = true;
            return true;
        }
        false
    }

    /// Takes M98 (with its P and L) and M99 out of the block about to run: the call to
    /// make after it, if any.
    pub(crate) fn take_subprogram_words(&mut self) -> Option<Call> {
        let is = |w: &Word, code: f64| w.letter == b'M' && (w.value - code).abs() < 1e-9;
        if self.block.words.iter().any(|w| is(w, 99.0)) {
            self.block.words.retain(|w| !is(w, 99.0));
            if self.subprograms.in_body > 0 && self.flow_depth() > 0 {
                self.subprograms.returned = true;
            } else {
                let at = self.block.span();
                self.report(GcodeDiagnostic::Oword {
                    detail: "M99 outside a subprogram (the main program does not repeat)"
                        .to_owned(),
                    span: span(at),
                });
            }
        }
        let words = &mut self.block.words;
        let m98 = words.iter().position(|w| is(w, 98.0))?;
        let call_word = words.remove(m98);
        let take = |words: &mut Vec<Word>, letter: u8| {
            let i = words.iter().position(|w| w.letter == letter)?;
            Some(words.remove(i))
        };
        let p = take(words, b'P');
        let l = take(words, b'L');
        let Some(p) = p.filter(|p| p.value >= 0.0 && p.value.fract() == 0.0) else {
            self.report(GcodeDiagnostic::MissingWord {
                code: "M98".to_owned(),
                needs: "a P word: the number of the subprogram",
                span: span(call_word.span()),
            });
            return None;
        };
        let times = l.map_or(1.0, |l| l.value.max(0.0).round());
        Some(Call {
            number: p.value as u32,
            times: times as u64,
            span: call_word.start..p.end,
        })
    }

    /// Runs an M98 call, or starts searching the rest of the file for its subprogram.
    pub(crate) fn subprogram_call(&mut self, call: Call) -> bool {
        if let Some(body) = self.subprograms.defined.get(&call.number).cloned() {
            return self.run_subprogram(&call, &body);
        }
        if !self.subprograms.can_search() {
            self.report(GcodeDiagnostic::UnknownSubroutine {
                name: format!("O{}", call.number),
                searched: "a subprogram called from a body must come before the call".to_owned(),
                span: span(call.span),
            });
            return true;
        }
        self.subprograms.search = Some(Search {
            call: Pending::Fanuc(call),
            held: Vec::new(),
            bytes: 0,
        });
        true
    }

    /// The searched subprogram or subroutine is defined: the call runs, then the held
    /// lines are read again.
    pub(crate) fn found(&mut self) -> bool {
        let Some(search) = self.subprograms.search.take() else {
            return true;
        };
        let ran = match search.call {
            Pending::Fanuc(call) => match self.subprograms.defined.get(&call.number).cloned() {
                Some(body) => self.run_subprogram(&call, &body),
                None => true,
            },
            Pending::Oword {
                label,
                args,
                span,
                line,
                ..
            } => self.invoke(&label, args, span, line) != crate::oword::Signal::End,
        };
        if !ran {
            return true;
        }
        self.subprograms.replaying += 1;
        self.subprograms.replayed_bytes += search.bytes;
        for line in &search.held {
            if !self.source_line(line.source()) {
                break;
            }
        }
        self.subprograms.replaying -= 1;
        self.subprograms.replayed_bytes -= search.bytes;
        true
    }

    fn run_subprogram(&mut self, call: &Call, body: &Body) -> bool {
        if self.flow_depth() >= MAX_CALL_DEPTH {
            self.report(GcodeDiagnostic::RecursionLimit {
                limit: MAX_CALL_DEPTH,
                span: span(call.span.clone()),
            });
            return false;
        }
        for _ in 0..call.times {
            if !self.run_called(body) {
                return false;
            }
        }
        true
    }

    /// At the end of the input: a call whose subprogram never came.
    pub(crate) fn subprograms_finish(&mut self) {
        if let Some(search) = self.subprograms.search.take() {
            match search.call {
                Pending::Fanuc(call) => self.report(GcodeDiagnostic::UnknownSubroutine {
                    name: format!("O{}", call.number),
                    searched: "no block O… ending with M99 in this file".to_owned(),
                    span: span(call.span),
                }),
                Pending::Oword {
                    label,
                    span,
                    searched,
                    ..
                } => {
                    let searched = match searched.is_empty() {
                        true => "not defined in this file".to_owned(),
                        false => format!("not defined in this file; {searched}"),
                    };
                    self.unknown_subroutine(&label, searched, span);
                }
            }
        }
        if let Some((number, lines)) = self.subprograms.recording.take() {
            let at = lines.first().map_or(0, |l| l.start);
            self.report(GcodeDiagnostic::Oword {
                detail: format!("subprogram O{number} has no M99"),
                span: span(at..at),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn program_numbers_and_m99_are_read_lexically() {
        assert_eq!(program_number("O1000"), Some(1000));
        assert_eq!(program_number(" o0042 (drill)"), Some(42));
        assert_eq!(program_number("O1000 G1"), None);
        assert_eq!(program_number("o100 sub"), None);
        assert!(has_m99("M99"));
        assert!(has_m99("G90 m 99 (back)"));
        assert!(has_m99("G90M99"));
        assert!(!has_m99("M990"));
        assert!(!has_m99("(M99)"));
        assert!(!has_m99("M199"));
    }
}
