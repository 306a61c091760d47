//! Rendering diagnostics on standard error.
//!
//! Owns how failures and warnings look: for people, miette's report with file, line,
//! column, a label under the offending text and a help line; for tools
//! (`--diagnostics json`), one JSON object per line. It must not decide what is an error.

use crate::args::{DiagnosticsArg, PipelineArgs};
use crate::pipeline::Failure;
use crate::{EXIT_INPUT_ERROR, EXIT_USAGE};
use miette::{Report, Severity};
use std::process::ExitCode;

/// Most diagnostics printed for one input; the rest are counted (a wrong file can have
/// one error per line).
pub const MAX_PRINTED: usize = 50;

/// Prints diagnostics the way the command line asked.
#[derive(Debug, Clone, Copy)]
pub struct Reporter {
    json: bool,
    deny_warnings: bool,
}

impl Reporter {
    /// A reporter for these pipeline arguments.
    pub fn new(args: &PipelineArgs) -> Reporter {
        Reporter {
            json: args.diagnostics == DiagnosticsArg::Json,
            deny_warnings: args.deny_warnings,
        }
    }

    /// Prints every diagnostic of `failure` and returns the exit status for it.
    pub fn fail(&self, failure: &Failure) -> ExitCode {
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
                self.print(&report);
            }
            Failure::Usage(message) => {
                self.print(&miette::miette!(code = "pvtc::usage", "{message}"));
                return ExitCode::from(EXIT_USAGE);
            }
            Failure::Input(reports) => {
                for report in reports.iter().take(MAX_PRINTED) {
                    self.print(report);
                }
                let n = reports.len();
                if !self.json {
                    if n > MAX_PRINTED {
                        eprintln!("… and {} more errors not shown", n - MAX_PRINTED);
                    }
                    eprintln!(
                        "error: {n} error{} in the input; nothing was written",
                        if n == 1 { "" } else { "s" }
                    );
                }
            }
        }
        ExitCode::from(EXIT_INPUT_ERROR)
    }

    /// Prints warnings; with `--deny-warnings` any warning fails the run.
    pub fn warnings(&self, reports: &[Report]) -> Result<(), ExitCode> {
        for report in reports {
            self.print(report);
        }
        let denied = reports
            .iter()
            .filter(|r| r.severity() == Some(Severity::Warning))
            .count();
        if self.deny_warnings && denied > 0 {
            if !self.json {
                eprintln!("error: {denied} warning(s) and --deny-warnings; nothing was written");
            }
            return Err(ExitCode::from(EXIT_INPUT_ERROR));
        }
        Ok(())
    }

    fn print(&self, report: &Report) {
        if self.json {
            eprintln!("{}", to_json(report));
        } else {
            eprintln!("{report:?}");
        }
    }
}

/// One diagnostic as a JSON object: code, severity, message, help, file, line, column.
pub fn to_json(report: &Report) -> serde_json::Value {
    let severity = match report.severity().unwrap_or(Severity::Error) {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Advice => "advice",
    };
    let mut value = serde_json::json!({
        "code": report.code().map(|c| c.to_string()),
        "severity": severity,
        "message": report.to_string(),
        "help": report.help().map(|h| h.to_string()),
    });
    let label = report.labels().and_then(|mut labels| labels.next());
    if let (Some(label), Some(source)) = (label, report.source_code()) {
        if let Ok(contents) = source.read_span(label.inner(), 0, 0) {
            value["file"] = serde_json::json!(contents.name());
            value["line"] = serde_json::json!(contents.line() + 1);
            value["column"] = serde_json::json!(contents.column() + 1);
            value["offset"] = serde_json::json!(label.offset());
            value["length"] = serde_json::json!(label.len());
        }
    }
    value
}

/// Installs a panic hook that keeps the default report for every panic except one raised
/// inside the `dxf` crate's parse, which pvt-dxf catches and turns into `pvtc::dxf::read`
/// (its message would only repeat that diagnostic). Which panics those are is a flag
/// pvt-dxf sets around that one call, not the panic's source path.
pub fn install_panic_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !pvt_dxf::panic_is_contained() {
            default(info);
        }
    }));
}
