//! Why a run failed: a file that could not be read or written, the input's diagnostics,
//! or a command line that asks for something impossible.
//!
//! Owns [`Failure`], the one error type of the command line, at the bottom of pvtc's
//! modules: it imports none of them, so every module can name it without a cycle. It
//! must not print (that is `report`'s) or decide exit statuses.

use miette::Report;
use std::path::PathBuf;

/// Why a run failed.
#[derive(Debug)]
pub enum Failure {
    /// A file could not be read or written.
    Io {
        /// The file.
        path: PathBuf,
        /// `read` or `write`.
        action: &'static str,
        /// What the system said.
        error: std::io::Error,
    },
    /// The input has errors; every one of them, ready to print.
    Input(Vec<Report>),
    /// The command line asks for something impossible (exit status 2).
    Usage(String),
}

impl Failure {
    /// The stable codes of the diagnostics, in order (for tests and tools).
    pub fn codes(&self) -> Vec<String> {
        match self {
            Failure::Io { .. } => vec!["pvtc::io".into()],
            Failure::Usage(_) => vec!["pvtc::usage".into()],
            Failure::Input(reports) => reports
                .iter()
                .map(|r| r.code().map(|c| c.to_string()).unwrap_or_default())
                .collect(),
        }
    }
}
