//! Batch compilation: many inputs into one directory, in parallel.
//!
//! Owns expanding inputs (files, directories, globs) into jobs, naming outputs (a
//! directory's tree is mirrored under the output directory), running
//! the jobs on a rayon pool with a progress bar (drawn only on a terminal), each file's
//! diagnostics (errors, warnings and notes, under the file's name, in input order) and the
//! summary. Every job is the single-file route unchanged, so a batch output is
//! byte-identical to compiling that file alone; a failing file never stops the others and
//! never leaves a partial output. It must not compile anything itself.

use crate::args::CompileArgs;
use crate::failure::Failure;
use crate::output;
use crate::report::EXIT_INPUT_ERROR;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// File extensions a directory is searched for (lower case).
pub const EXTENSIONS: [&str; 7] = ["ngc", "nc", "gcode", "tap", "cnc", "dxf", "csv"];

/// One input and where its output goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// The input file.
    pub input: PathBuf,
    /// The output file.
    pub output: PathBuf,
}

/// How one job ended.
#[derive(Debug)]
pub struct Outcome {
    /// The job.
    pub job: Job,
    /// `None` on success, else the first diagnostic in one line and their count.
    pub failure: Option<(String, usize)>,
    /// Every diagnostic of the file: its errors when it failed, else its warnings and
    /// notes.
    pub diagnostics: Vec<miette::Report>,
}

/// Runs `pvtc compile` with several inputs or `--out-dir`.
pub fn run(args: &CompileArgs) -> ExitCode {
    let reporter = crate::report::Reporter::new(&args.pipeline);
    let Some(out_dir) = args.out_dir.as_deref() else {
        return reporter.fail(&Failure::Usage(
            "several inputs need --out-dir DIR (one output per input)".into(),
        ));
    };
    let jobs = match plan_jobs(&args.inputs, out_dir, args.format.into()) {
        Ok(jobs) => jobs,
        Err(message) => return reporter.fail(&Failure::Usage(message)),
    };
    let created = match create_output_dirs(out_dir, &jobs) {
        Ok(created) => created,
        Err(failure) => return reporter.fail(&failure),
    };
    let outcomes = match args.jobs {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n.get()).build() {
            Ok(pool) => pool.install(|| run_jobs(&jobs, args)),
            Err(e) => {
                return reporter.fail(&Failure::Usage(format!("cannot start {n} threads: {e}")))
            }
        },
        None => run_jobs(&jobs, args),
    };
    remove_empty_dirs(&created);
    for outcome in &outcomes {
        reporter.print_for_input(&outcome.job.input, &outcome.diagnostics);
    }
    summarize(&outcomes, &reporter)
}

/// Creates `out_dir` and every folder a job writes into, so the input tree is mirrored
/// under it (`in/sub/b.ngc` writes `OUT/sub/b.pmac`), and returns the folders it created
/// (those that did not exist), parents first.
fn create_output_dirs(out_dir: &Path, jobs: &[Job]) -> Result<Vec<PathBuf>, Failure> {
    let mut wanted = std::collections::BTreeSet::new();
    for dir in jobs
        .iter()
        .filter_map(|job| job.output.parent())
        .chain(std::iter::once(out_dir))
    {
        wanted.extend(dir.ancestors().filter(|a| !a.as_os_str().is_empty()));
    }
    let mut created = Vec::new();
    for dir in wanted {
        if dir.is_dir() {
            continue;
        }
        std::fs::create_dir(dir).map_err(|error| Failure::Io {
            path: dir.to_path_buf(),
            action: "create",
            error,
        })?;
        created.push(dir.to_path_buf());
    }
    Ok(created)
}

/// Removes the folders of `created` that no output went into (every file written there
/// failed), deepest first, so a failed file leaves no folder behind.
fn remove_empty_dirs(created: &[PathBuf]) {
    for dir in created.iter().rev() {
        // Only an empty folder is removed; one holding an output stays.
        let _ = std::fs::remove_dir(dir);
    }
}

/// Compiles every job in parallel, in input order in the result.
pub fn run_jobs(jobs: &[Job], args: &CompileArgs) -> Vec<Outcome> {
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} files {elapsed_precise} {wide_msg}")
            .expect("a valid template"),
    );
    let outcomes = jobs
        .par_iter()
        .map(|job| {
            let outcome = run_job(job, args);
            bar.inc(1);
            outcome
        })
        .collect();
    bar.finish_and_clear();
    outcomes
}

fn run_job(job: &Job, args: &CompileArgs) -> Outcome {
    let name = job.input.display().to_string();
    let result = args.compile_options(&name).and_then(|options| {
        output::write_file_with(&job.output, |out| {
            let deny = args.pipeline.deny_warnings;
            crate::route::compile_to(&job.input, &options, deny, out)
        })
    });
    outcome(job, result)
}

/// The outcome of `job` from its result: the warnings written, or the failure.
fn outcome(job: &Job, result: Result<Vec<miette::Report>, Failure>) -> Outcome {
    match result {
        Ok(diagnostics) => Outcome {
            job: job.clone(),
            failure: None,
            diagnostics,
        },
        Err(failure) => Outcome {
            job: job.clone(),
            failure: Some(first_diagnostic(&failure)),
            diagnostics: failure_reports(failure),
        },
    }
}

/// A failure's diagnostics as reports (an I/O or usage failure is one report).
fn failure_reports(failure: Failure) -> Vec<miette::Report> {
    match failure {
        Failure::Input(reports) => reports,
        Failure::Io {
            path,
            action,
            error,
        } => vec![miette::miette!(
            code = "pvtc::io",
            "cannot {action} {}: {error}",
            path.display()
        )],
        Failure::Usage(message) => vec![miette::miette!(code = "pvtc::usage", "{message}")],
    }
}

/// The first diagnostic of a failure in one line, and how many there are.
fn first_diagnostic(failure: &Failure) -> (String, usize) {
    match failure {
        Failure::Io {
            path,
            action,
            error,
        } => (
            format!("pvtc::io: cannot {action} {}: {error}", path.display()),
            1,
        ),
        Failure::Usage(message) => (format!("pvtc::usage: {message}"), 1),
        Failure::Input(reports) => {
            let first = reports.first().map(|r| {
                let code = r.code().map(|c| c.to_string()).unwrap_or_default();
                let line = r
                    .labels()
                    .and_then(|mut labels| labels.next())
                    .and_then(|label| r.source_code().map(|s| (label, s)))
                    .and_then(|(label, s)| {
                        s.read_span(label.inner(), 0, 0).ok().map(|c| c.line() + 1)
                    });
                match line {
                    Some(line) => format!("{code} (line {line}): {r}"),
                    None => format!("{code}: {r}"),
                }
            });
            (first.unwrap_or_default(), reports.len())
        }
    }
}

fn summarize(outcomes: &[Outcome], reporter: &crate::report::Reporter) -> ExitCode {
    let mut failed = 0;
    for o in outcomes {
        if let Some((first, count)) = &o.failure {
            reporter.batch_failed(&o.job.input, first, *count);
            failed += 1;
        }
    }
    let warnings = outcomes
        .iter()
        .filter(|o| o.failure.is_none())
        .flat_map(|o| &o.diagnostics)
        .filter(|r| r.severity() == Some(miette::Severity::Warning))
        .count();
    reporter.batch_summary(outcomes.len() - failed, failed, warnings);
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_INPUT_ERROR)
    }
}

/// Expands inputs into jobs with outputs under `out_dir`, sorted by input path.
///
/// A file keeps its name; files found under a directory keep their path relative to it.
/// The extension becomes the format's. Two inputs that would write the same output are
/// an error, as are inputs that match nothing.
pub fn plan_jobs(
    inputs: &[PathBuf],
    out_dir: &Path,
    format: pvt_emit::Format,
) -> Result<Vec<Job>, String> {
    let mut by_output: BTreeMap<PathBuf, PathBuf> = BTreeMap::new();
    for input in inputs {
        for (file, relative) in expand(input)? {
            let output = out_dir.join(relative.with_extension(format.extension()));
            if let Some(other) = by_output.insert(output.clone(), file.clone()) {
                if other != file {
                    return Err(format!(
                        "{} and {} would both write {}",
                        other.display(),
                        file.display(),
                        output.display()
                    ));
                }
            }
        }
    }
    let mut jobs: Vec<Job> = by_output
        .into_iter()
        .map(|(output, input)| Job { input, output })
        .collect();
    jobs.sort_by(|a, b| a.input.cmp(&b.input));
    Ok(jobs)
}

/// The files an input names, each with the path its output keeps.
fn expand(input: &Path) -> Result<Vec<(PathBuf, PathBuf)>, String> {
    if input == Path::new("-") {
        return Err("standard input cannot be part of a batch".into());
    }
    if input.is_dir() {
        let mut files = Vec::new();
        walk(input, &mut files).map_err(|e| format!("{}: {e}", input.display()))?;
        files.sort();
        let found: Vec<_> = files
            .into_iter()
            .map(|f| {
                let relative = f.strip_prefix(input).unwrap_or(&f).to_path_buf();
                (f, relative)
            })
            .collect();
        if found.is_empty() {
            return Err(format!(
                "{} holds no {} file",
                input.display(),
                EXTENSIONS.join("/")
            ));
        }
        return Ok(found);
    }
    if input.exists() {
        let name = input
            .file_name()
            .map(PathBuf::from)
            .unwrap_or_else(|| input.to_path_buf());
        return Ok(vec![(input.to_path_buf(), name)]);
    }
    let pattern = input.to_string_lossy();
    let matches: Vec<PathBuf> = glob::glob(&pattern)
        .map_err(|e| format!("{pattern}: {e}"))?
        .filter_map(Result::ok)
        .filter(|p| p.is_file())
        .collect();
    if matches.is_empty() {
        return Err(format!(
            "{pattern}: no such file, directory or matching files"
        ));
    }
    Ok(matches
        .into_iter()
        .map(|m| {
            let name = m
                .file_name()
                .map(PathBuf::from)
                .unwrap_or_else(|| m.clone());
            (m, name)
        })
        .collect())
}

fn walk(dir: &Path, files: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            walk(&path, files)?;
        } else if has_known_extension(&path) {
            files.push(path);
        }
    }
    Ok(())
}

fn has_known_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}
