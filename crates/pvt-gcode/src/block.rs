//! The block model: one line of G-code as the parser hands it to the interpreter.
//!
//! Owns the shape of a parsed block (words with values and spans); it must not know the
//! meaning of any word (that is [`crate::interpreter`]) nor how text is read
//! (that is [`crate::parser`]).

use std::ops::Range;

use crate::params::ParamRef;

/// One word: a letter and its value, with where it was written.
///
/// Small and `Copy`, so a block's words live in one reused buffer without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Word {
    /// The letter, upper-case ASCII.
    pub letter: u8,
    /// The value of the number after the letter.
    pub value: f64,
    /// Byte offset of the letter in the source.
    pub start: usize,
    /// Byte offset one past the number.
    pub end: usize,
}

impl Word {
    /// Byte range of the word in the source.
    pub fn span(&self) -> Range<usize> {
        self.start..self.end
    }

    /// The word spelled canonically, e.g. `G38.2`, `X-0.5`.
    pub fn name(&self) -> String {
        format!("{}{}", char::from(self.letter), self.value)
    }

    /// The letter as a `char`.
    pub fn letter_char(&self) -> char {
        char::from(self.letter)
    }
}

/// One line of a program: optional block delete, then words, comments dropped.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Block {
    /// Byte offset of the line's first byte.
    pub start: usize,
    /// Byte offset one past the line's last byte (line end not included).
    pub end: usize,
    /// 1-based line number in the file.
    pub line: u32,
    /// True when the line starts with `/` (block delete).
    pub block_delete: bool,
    /// The `N` word's value, if the block has one.
    pub line_number: Option<u64>,
    /// The words in the order written (the `N` word not included).
    pub words: Vec<Word>,
    /// Parameter assignments, in the order written; they take effect after the line.
    pub assignments: Vec<Assignment>,
    /// The text of a `(MSG, …)` comment, if the line has one.
    pub message: Option<String>,
}

/// One `#… = value` on a line.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Assignment {
    /// The parameter set.
    pub param: ParamRef,
    /// Its new value.
    pub value: f64,
}

impl Block {
    /// Empties the block for the next line, keeping the word buffer.
    pub fn reset(&mut self, start: usize, end: usize, line: u32) {
        self.start = start;
        self.end = end;
        self.line = line;
        self.block_delete = false;
        self.line_number = None;
        self.words.clear();
        self.assignments.clear();
        self.message = None;
    }

    /// Byte range of the whole line.
    pub fn span(&self) -> Range<usize> {
        self.start..self.end
    }
}

/// The smallest byte range that covers all the given words; `None` when there are none.
pub(crate) fn cover<'a>(words: impl IntoIterator<Item = &'a Word>) -> Option<Range<usize>> {
    words.into_iter().fold(None, |acc, w| match acc {
        None => Some(w.span()),
        Some(r) => Some(r.start.min(w.start)..r.end.max(w.end)),
    })
}
