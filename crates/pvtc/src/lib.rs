//! pvtc: the command line, a small layer on top of the pipeline crates.
//!
//! Owns arguments ([`args`]), the data a compile shares ([`options`]), reading inputs
//! and choosing a front end ([`front`], [`pipeline`]), batch runs ([`batch`]), writing outputs atomically ([`output`]), the
//! check and plot commands' rendering ([`check`], [`plot`]) and diagnostics ([`report`]).
//! Architecture invariant: no geometry, planning or formatting happens here; a failed run
//! never creates or changes an output file.

pub mod args;
pub mod batch;
pub mod check;
pub mod excerpt;
pub mod front;
pub mod machine;
pub mod options;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod report;
pub mod stream;

pub use args::{Cli, Command, CompileArgs};
pub use pipeline::{compile, plan, CompileOptions, DrawingOptions, Failure, InputKind, Source};

use report::Reporter;
use std::process::ExitCode;

/// Exit status of a run whose input had errors (or whose check found a limit exceeded).
pub const EXIT_INPUT_ERROR: u8 = 1;
/// Exit status of a run whose command line asks for something impossible.
pub const EXIT_USAGE: u8 = 2;

/// Runs a parsed command line and returns the process exit status.
pub fn run(cli: Cli) -> ExitCode {
    report::install_panic_hook();
    output::remove_partial_outputs_on_interrupt();
    match cli.command {
        Command::Compile(mut args) => match args.pipeline.read_files() {
            Ok(()) => compile_command(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Check(mut args) => match args.pipeline.read_files() {
            Ok(()) => check::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Plot(mut args) => match args.pipeline.read_files() {
            Ok(()) => plot::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
    }
}

/// G-code, from a file or standard input, streams: standard input is first copied to a
/// temporary file, so every route runs in the same bounded memory.
fn compile_gcode(
    args: &CompileArgs,
    input: &std::path::Path,
    options: &CompileOptions,
    reporter: &Reporter,
) -> ExitCode {
    let spooled = match stdin_file(input) {
        Ok(spooled) => spooled,
        Err(failure) => return reporter.fail(&failure),
    };
    let (path, name) = match &spooled {
        Some(file) => (file.path(), "<stdin>".to_string()),
        None => (input, input.display().to_string()),
    };
    let deny = args.pipeline.deny_warnings;
    let result = output::write_with(args.output.as_deref(), |out| {
        stream::compile_streaming(path, &name, options, deny, out)
    });
    match result.map(|warnings| reporter.warnings(&warnings)) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(code)) => code,
        Err(failure) => reporter.fail(&failure),
    }
}

/// For `-`, standard input copied into a temporary file (removed when dropped).
fn stdin_file(input: &std::path::Path) -> Result<Option<tempfile::NamedTempFile>, Failure> {
    if input != std::path::Path::new("-") {
        return Ok(None);
    }
    let failure = |error| Failure::Io {
        path: "<stdin>".into(),
        action: "read",
        error,
    };
    let mut file = tempfile::NamedTempFile::new().map_err(failure)?;
    std::io::copy(&mut std::io::stdin().lock(), file.as_file_mut()).map_err(failure)?;
    Ok(Some(file))
}

fn compile_command(args: &CompileArgs) -> ExitCode {
    if args.out_dir.is_some() || args.inputs.len() > 1 {
        return batch::run(args);
    }
    let reporter = Reporter::new(&args.pipeline);
    let input = &args.inputs[0];
    if let Ok(options) = args.compile_options(&input.display().to_string()) {
        if options.input == InputKind::Gcode {
            return compile_gcode(args, input, &options, &reporter);
        }
    }
    let source = match Source::read(input) {
        Ok(source) => source,
        Err(failure) => return reporter.fail(&failure),
    };
    let options = match args.compile_options(&source.name) {
        Ok(options) => options,
        Err(failure) => return reporter.fail(&failure),
    };
    let compiled = match compile(&source, &options) {
        Ok(compiled) => compiled,
        Err(failure) => return reporter.fail(&failure),
    };
    if let Err(code) = reporter.warnings(&compiled.warnings) {
        return code;
    }
    match output::write(args.output.as_deref(), &compiled.bytes) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => reporter.fail(&failure),
    }
}
