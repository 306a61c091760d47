//! Rendering diagnostics on standard error.
//!
//! Owns how failures, warnings and notes look: for people, miette's report with file,
//! line, column, a label under the offending text and a help line; for tools
//! (`--diagnostics json`), one JSON object per line. Repeats of one code in one input are
//! one diagnostic ([`group`]): the count, the lines of every place, labels on the first
//! [`SHOWN_PLACES`]. It also holds the one `--deny-warnings` policy: [`deny`] before
//! anything is written, [`Reporter::warnings`] after, counting warnings the same way.
//! It must not decide what is an error.

use crate::args::{DiagnosticsArg, PipelineArgs};
use crate::failure::Failure;
use miette::{Diagnostic, LabeledSpan, Report, ReportHandler, Severity, SourceCode, SourceSpan};
use pvt_core::text::SourceLocation;
use std::fmt;
use std::process::ExitCode;

/// Exit status of a run whose input had errors (or whose check found a limit exceeded).
pub const EXIT_INPUT_ERROR: u8 = 1;
/// Exit status of a run whose command line asks for something impossible.
pub const EXIT_USAGE: u8 = 2;

/// Most diagnostics printed for one input; the rest are counted (a wrong file can have
/// one error per line).
pub const MAX_PRINTED: usize = 50;

/// Places of a repeated diagnostic that are labelled in its rendering; the lines of the
/// rest are listed in its help.
pub const SHOWN_PLACES: usize = 3;

/// Lines of a repeated diagnostic's places listed in its help; the rest are counted.
const LISTED_LINES: usize = 20;

/// One diagnostic as printed: a single report, or the repeats of one code grouped.
#[derive(Debug)]
pub enum Item<'a> {
    /// A diagnostic that occurs once.
    Single(&'a Report),
    /// Two or more diagnostics with one code and severity, in source order.
    Repeated(Repeated<'a>),
}

/// Groups repeats of one code and severity into one item at the place of the first, in
/// the order of the reports. Reports without a code or without a label stay single.
pub fn group(reports: &[Report]) -> Vec<Item<'_>> {
    let mut items: Vec<Item<'_>> = Vec::new();
    // Each groupable code and severity met, with the index of its item.
    let mut keys: Vec<(GroupKey, usize)> = Vec::new();
    for report in reports {
        if let Some(k) = group_key(report) {
            if let Some(&(_, at)) = keys.iter().find(|(key, _)| *key == k) {
                match &mut items[at] {
                    Item::Repeated(group) => group.members.push(report),
                    Item::Single(first) => {
                        items[at] = Item::Repeated(Repeated {
                            members: vec![first, report],
                        })
                    }
                }
                continue;
            }
            keys.push((k, items.len()));
        }
        items.push(Item::Single(report));
    }
    items
}

/// What repeats are grouped by: the code and the severity.
type GroupKey = (String, Option<Severity>);

/// Codes whose front end already makes one diagnostic per kind, with the count of its
/// places: each stays its own (one `unsupported` per feature, never merged under the
/// first feature's message).
const COUNTED_BY_THE_FRONT_END: [&str; 1] = ["pvtc::gcode::unsupported"];

/// The key of a report that can be grouped: one with a code, a label and a source.
fn group_key(r: &Report) -> Option<GroupKey> {
    let labelled = r.labels().is_some_and(|mut l| l.next().is_some());
    if !labelled || r.source_code().is_none() {
        return None;
    }
    let code = r.code()?.to_string();
    if COUNTED_BY_THE_FRONT_END.contains(&code.as_str()) {
        return None;
    }
    Some((code, r.severity()))
}

/// Repeats of one diagnostic code in one input, rendered as one diagnostic.
#[derive(Debug)]
pub struct Repeated<'a> {
    members: Vec<&'a Report>,
}

impl Repeated<'_> {
    /// How many times the diagnostic occurs.
    pub fn count(&self) -> usize {
        self.members.len()
    }

    /// 1-based line of each place, in order (0 where it cannot be read).
    pub fn lines(&self) -> Vec<usize> {
        self.members
            .iter()
            .map(|r| place(r).map_or(0, |p| p.at.line as usize))
            .collect()
    }
}

impl fmt::Display for Repeated<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (first, n) = (self.members[0], self.count());
        let same = self
            .members
            .iter()
            .all(|r| r.to_string() == first.to_string());
        let shown = if n > SHOWN_PLACES {
            format!("; the first {SHOWN_PLACES} shown")
        } else {
            String::new()
        };
        if same {
            write!(f, "{first} ({n} times{shown})")
        } else {
            write!(f, "{first} (and {} more like it{shown})", n - 1)
        }
    }
}

impl std::error::Error for Repeated<'_> {}

impl Diagnostic for Repeated<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.members[0].code()
    }

    fn severity(&self) -> Option<Severity> {
        self.members[0].severity()
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        let lines = self.lines();
        let mut listed: Vec<String> = lines
            .iter()
            .take(LISTED_LINES)
            .map(|l| l.to_string())
            .collect();
        if lines.len() > LISTED_LINES {
            listed.push(format!("and {} more", lines.len() - LISTED_LINES));
        }
        let at = format!("at lines {}", listed.join(", "));
        Some(Box::new(match self.members[0].help() {
            Some(help) => format!("{help}\n{at}"),
            None => at,
        }))
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        Some(self)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        Some(Box::new(
            self.members
                .iter()
                .take(SHOWN_PLACES)
                .filter_map(|r| r.labels().and_then(|mut l| l.next())),
        ))
    }
}

/// The group's places come from each member's own source (a streamed file's excerpts hold
/// only the lines around their own diagnostic): a span is read from the first member whose
/// source holds all of it.
impl SourceCode for Repeated<'_> {
    fn read_span<'b>(
        &'b self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn miette::SpanContents<'b> + 'b>, miette::MietteError> {
        let end = span.offset() + span.len();
        for source in self.members.iter().filter_map(|r| r.source_code()) {
            if let Ok(contents) = source.read_span(span, before, after) {
                let got = contents.span();
                if got.offset() <= span.offset() && got.offset() + got.len() >= end {
                    return Ok(contents);
                }
            }
        }
        Err(miette::MietteError::OutOfBounds)
    }
}

/// Where a report's first label is: its file and [`SourceLocation`] (1-based line and
/// column, offset and length), as its source code (the text, or a streamed file's
/// excerpt) answers.
struct Place {
    file: Option<String>,
    at: SourceLocation,
}

fn place(report: &Report) -> Option<Place> {
    let label = report.labels()?.next()?;
    let contents = report.source_code()?.read_span(label.inner(), 0, 0).ok()?;
    let number = |n: usize| u32::try_from(n + 1).unwrap_or(u32::MAX);
    Some(Place {
        file: contents.name().map(str::to_owned),
        at: SourceLocation {
            line: number(contents.line()),
            column: number(contents.column()),
            offset: label.offset(),
            length: label.len(),
        },
    })
}

/// Renders a diagnostic as miette's default handler renders a [`Report`].
struct Rendered<'a>(&'a dyn Diagnostic);

impl fmt::Display for Rendered<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        miette::MietteHandler::default().debug(self.0, f)
    }
}

/// The warnings, or, when any is a warning and `deny_warnings`, a failure holding them
/// (sources and labels kept) and one error saying nothing was written.
pub fn deny(warnings: Vec<Report>, deny_warnings: bool) -> Result<Vec<Report>, Failure> {
    let count = warning_count(&warnings);
    if !deny_warnings || count == 0 {
        return Ok(warnings);
    }
    let mut reports: Vec<Report> = warnings.into_iter().filter(is_warning).collect();
    reports.push(miette::miette!(
        code = "pvtc::deny_warnings",
        "{count} warning(s) and --deny-warnings; nothing was written"
    ));
    Err(Failure::Input(reports))
}

/// True for a warning (not an error or a note): what `--deny-warnings` fails on.
fn is_warning(report: &Report) -> bool {
    report.severity() == Some(Severity::Warning)
}

/// How many of `reports` are warnings.
fn warning_count(reports: &[Report]) -> usize {
    reports.iter().filter(|r| is_warning(r)).count()
}

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

    /// A reporter for people, for the commands without diagnostics options
    /// (`completions`, `man`).
    pub fn human() -> Reporter {
        Reporter {
            json: false,
            deny_warnings: false,
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
                self.print_all(reports);
                let n = reports.len();
                let items = group(reports).len();
                if !self.json {
                    if items > MAX_PRINTED {
                        eprintln!("… and {} more diagnostics not shown", items - MAX_PRINTED);
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

    /// Prints one diagnostic that fails a run whose output is already written (`check`'s
    /// verdict), without the "nothing was written" line of [`Reporter::fail`].
    pub fn error(&self, report: &Report) {
        self.print(report);
    }

    /// Prints warnings; with `--deny-warnings` any warning fails the run.
    pub fn warnings(&self, reports: &[Report]) -> Result<(), ExitCode> {
        self.print_all(reports);
        let denied = warning_count(reports);
        if self.deny_warnings && denied > 0 {
            if !self.json {
                eprintln!("error: {denied} warning(s) and --deny-warnings; nothing was written");
            }
            return Err(ExitCode::from(EXIT_INPUT_ERROR));
        }
        Ok(())
    }

    /// Prints `reports` with repeats grouped, at most [`MAX_PRINTED`] diagnostics.
    pub fn print_all(&self, reports: &[Report]) {
        self.print_items(reports, None);
    }

    /// A batch: prints one input's diagnostics under its name (JSON: each object has
    /// `input`); nothing for an input without any.
    pub fn print_for_input(&self, input: &std::path::Path, reports: &[Report]) {
        if reports.is_empty() {
            return;
        }
        let name = input.display().to_string();
        if !self.json {
            let errors = reports
                .iter()
                .filter(|r| r.severity().unwrap_or(Severity::Error) == Severity::Error)
                .count();
            let warnings = reports
                .iter()
                .filter(|r| r.severity() == Some(Severity::Warning))
                .count();
            eprintln!("── {name}: {}", counts(errors, warnings));
        }
        self.print_items(reports, Some(&name));
        if !self.json {
            let items = group(reports).len();
            if items > MAX_PRINTED {
                eprintln!("… and {} more diagnostics not shown", items - MAX_PRINTED);
            }
        }
    }

    /// A batch's failed file in one line: its first diagnostic and how many more it has
    /// (JSON: `pvtc::batch::failed` with `input`, `first` and `count`).
    pub fn batch_failed(&self, input: &std::path::Path, first: &str, count: usize) {
        let more = if count > 1 {
            format!(" (and {} more)", count - 1)
        } else {
            String::new()
        };
        let text = format!("failed: {}: {first}{more}", input.display());
        if self.json {
            eprintln!(
                "{}",
                serde_json::json!({
                    "code": "pvtc::batch::failed",
                    "severity": "error",
                    "message": text,
                    "input": input.display().to_string(),
                    "first": first,
                    "count": count,
                })
            );
        } else {
            eprintln!("{text}");
        }
    }

    /// The end of a batch: files compiled, failed, and the warnings of those compiled.
    pub fn batch_summary(&self, compiled: usize, failed: usize, warnings: usize) {
        let text = format!(
            "{compiled} files compiled, {failed} failed, {warnings} warning{}",
            if warnings == 1 { "" } else { "s" }
        );
        if self.json {
            eprintln!(
                "{}",
                serde_json::json!({
                    "code": "pvtc::batch::summary",
                    "severity": "advice",
                    "message": text,
                    "compiled": compiled,
                    "failed": failed,
                    "warnings": warnings,
                })
            );
        } else {
            eprintln!("{text}");
        }
    }

    fn print_items(&self, reports: &[Report], input: Option<&str>) {
        for item in group(reports).iter().take(MAX_PRINTED) {
            if self.json {
                let mut value = item_json(item);
                if let Some(input) = input {
                    value["input"] = serde_json::json!(input);
                }
                eprintln!("{value}");
                continue;
            }
            match item {
                Item::Single(report) => self.print(report),
                Item::Repeated(repeated) => eprintln!("{}", Rendered(repeated)),
            }
        }
    }

    fn print(&self, report: &Report) {
        if self.json {
            eprintln!("{}", to_json(report));
        } else {
            eprintln!("{report:?}");
        }
    }
}

/// "1 error", "2 warnings", "1 error, 3 warnings", "notes only".
fn counts(errors: usize, warnings: usize) -> String {
    let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    match (errors, warnings) {
        (0, 0) => "notes only".into(),
        (0, w) => plural(w, "warning"),
        (e, 0) => plural(e, "error"),
        (e, w) => format!("{}, {}", plural(e, "error"), plural(w, "warning")),
    }
}

/// One printed diagnostic as a JSON object: [`to_json`] or [`repeated_json`].
pub fn item_json(item: &Item<'_>) -> serde_json::Value {
    match item {
        Item::Single(report) => to_json(report),
        Item::Repeated(repeated) => repeated_json(repeated),
    }
}

/// Every diagnostic of `reports` as `--diagnostics json` prints them (repeats grouped,
/// none left out), for a program that embeds pvtc ([`crate::embed`]).
pub fn json_items(reports: &[Report]) -> Vec<serde_json::Value> {
    group(reports).iter().map(item_json).collect()
}

/// A repeated diagnostic as one JSON object: the first's fields (message and help as
/// the first place has them), `count`, and `places` with file, line, column, offset and
/// length of every place.
pub fn repeated_json(repeated: &Repeated<'_>) -> serde_json::Value {
    let mut value = to_json(repeated.members[0]);
    value["count"] = serde_json::json!(repeated.count());
    let places: Vec<serde_json::Value> = repeated
        .members
        .iter()
        .filter_map(|r| place(r))
        .map(|p| {
            serde_json::json!({
                "file": p.file,
                "line": p.at.line,
                "column": p.at.column,
                "offset": p.at.offset,
                "length": p.at.length,
            })
        })
        .collect();
    value["places"] = serde_json::json!(places);
    value
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
    if let Some(Place { file, at }) = place(report) {
        value["file"] = serde_json::json!(file);
        value["line"] = serde_json::json!(at.line);
        value["column"] = serde_json::json!(at.column);
        value["offset"] = serde_json::json!(at.offset);
        value["length"] = serde_json::json!(at.length);
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
