//! Rendering diagnostics on standard error.
//!
//! Owns how failures and warnings look to a person: miette's report with file, line,
//! column, a label under the offending text and a help line. It must not decide what is
//! an error.

use crate::pipeline::Failure;
use crate::{EXIT_INPUT_ERROR, EXIT_USAGE};
use miette::Report;
use std::process::ExitCode;

/// Most diagnostics printed for one input; the rest are counted (a wrong file can have
/// one error per line).
pub const MAX_PRINTED: usize = 50;

/// Prints every diagnostic of `failure` and returns the exit status for it.
pub fn fail(failure: &Failure) -> ExitCode {
    match failure {
        Failure::Io {
            path,
            action,
            error,
        } => {
            let report = miette::miette!(
                code = "pvtc::io",
                "cannot {action} {}: {error}",
                path.display()
            );
            eprintln!("{report:?}");
        }
        Failure::Usage(message) => {
            let report = miette::miette!(code = "pvtc::usage", "{message}");
            eprintln!("{report:?}");
            return ExitCode::from(EXIT_USAGE);
        }
        Failure::Input(reports) => {
            for report in reports {
                eprintln!("{report:?}");
            }
            let n = reports.len();
            eprintln!(
                "error: {n} error{} in the input; nothing was written",
                if n == 1 { "" } else { "s" }
            );
        }
    }
    ExitCode::from(EXIT_INPUT_ERROR)
}

/// Prints warnings.
pub fn warnings(reports: &[Report]) {
    for report in reports {
        eprintln!("{report:?}");
    }
}
