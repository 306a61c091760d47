//! Diagnostics of the CSV front end: what is wrong, where, and its stable code.
//!
//! Owns the error kinds (`pvtc::csv::<name>`), their wording and help lines, and the
//! 1-based line and column of every diagnostic. It must not decide when one applies (the
//! reader does) nor render anything (the CLI does, through miette).

use std::fmt;
use std::ops::Range;

use miette::{LabeledSpan, SourceSpan};

/// What is wrong with a point-time CSV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CsvErrorKind {
    /// No header row before the data (or an empty file).
    MissingHeader,
    /// A header name that is neither `t`, `dt`, an axis nor `v<axis>`.
    UnknownColumn,
    /// A column named twice, or both `t` and `dt`.
    DuplicateColumn,
    /// Neither `t` nor `dt` in the header.
    NoTimeColumn,
    /// No axis column in the header.
    NoAxisColumn,
    /// A velocity column for an axis that has no position column, or velocities for only
    /// some axes.
    IncompleteVelocities,
    /// A row with more or fewer fields than the header.
    WrongFieldCount,
    /// A field that is not a number.
    NotANumber,
    /// A field that is NaN or infinite.
    NotFinite,
    /// A time not after the previous row's (or a `dt` that is not positive).
    NonIncreasingTime,
    /// A header but no data row.
    NoRows,
    /// A `trigger` field that is neither 0 nor 1.
    BadTrigger,
}

impl CsvErrorKind {
    /// The stable code, e.g. `pvtc::csv::not_a_number`.
    pub fn code(self) -> &'static str {
        use CsvErrorKind as K;
        match self {
            K::MissingHeader => "pvtc::csv::missing_header",
            K::UnknownColumn => "pvtc::csv::unknown_column",
            K::DuplicateColumn => "pvtc::csv::duplicate_column",
            K::NoTimeColumn => "pvtc::csv::no_time_column",
            K::NoAxisColumn => "pvtc::csv::no_axis_column",
            K::IncompleteVelocities => "pvtc::csv::incomplete_velocities",
            K::WrongFieldCount => "pvtc::csv::wrong_field_count",
            K::NotANumber => "pvtc::csv::not_a_number",
            K::NotFinite => "pvtc::csv::not_finite",
            K::NonIncreasingTime => "pvtc::csv::non_increasing_time",
            K::NoRows => "pvtc::csv::no_rows",
            K::BadTrigger => "pvtc::csv::bad_trigger",
        }
    }

    /// How to fix it, in one line.
    pub fn help(self) -> &'static str {
        use CsvErrorKind as K;
        match self {
            K::MissingHeader => {
                "start the file with a header such as `t,x,y` (comment lines start with #)"
            }
            K::UnknownColumn => {
                "columns are t or dt, axis names X Y Z A B C, and velocities vx, vy, ..., and trigger"
            }
            K::DuplicateColumn => {
                "give each column once, and either t (absolute time) or dt (piece time)"
            }
            K::NoTimeColumn => "add a t column (absolute time, s) or a dt column (piece time, s)",
            K::NoAxisColumn => "add at least one axis column: X, Y, Z, A, B or C",
            K::IncompleteVelocities => "give a v<axis> column for every axis column, or none",
            K::WrongFieldCount => "give every row one value per header column",
            K::NotANumber => "write a decimal number such as 5000 or -0.25",
            K::NotFinite => "write a finite number",
            K::NonIncreasingTime => "times must increase from row to row (dt must be positive)",
            K::NoRows => "add at least one data row below the header",
            K::BadTrigger => "write 1 on a row where a trigger fires and 0 elsewhere",
        }
    }
}

/// One error in a point-time CSV file, labelled under the offending text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct CsvDiagnostic {
    /// What kind of error.
    pub kind: CsvErrorKind,
    /// What is wrong, quoting the text.
    pub message: String,
    /// 1-based line of the offending text.
    pub line: u32,
    /// 1-based column (in characters) of the offending text.
    pub column: u32,
    /// Byte range of the offending text.
    pub span: Range<usize>,
}

impl CsvDiagnostic {
    /// The stable code, e.g. `pvtc::csv::wrong_field_count`.
    pub fn code(&self) -> &'static str {
        self.kind.code()
    }
}

impl miette::Diagnostic for CsvDiagnostic {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.kind.code()))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.kind.help()))
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let span = SourceSpan::from(self.span.start..self.span.end);
        Some(Box::new(std::iter::once(LabeledSpan::new_with_span(
            Some(self.message.clone()),
            span,
        ))))
    }
}

/// Every error of one file, in source order; the CLI renders them all.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, miette::Diagnostic)]
#[error("the point-time file has {} error(s)", .diagnostics.len())]
#[diagnostic(code(pvtc::csv::errors))]
pub struct CsvErrors {
    /// The errors, sorted by source position.
    #[related]
    pub diagnostics: Vec<CsvDiagnostic>,
}
