//! pvtc: the command line, a small layer on top of the pipeline crates.
//!
//! Owns arguments ([`args`]), reading inputs and choosing a front end ([`pipeline`]),
//! writing outputs atomically ([`output`]) and rendering diagnostics ([`report`]).
//! Architecture invariant: no geometry, planning or formatting happens here; a failed run
//! never creates or changes an output file.

pub mod args;
pub mod batch;
pub mod front;
pub mod output;
pub mod pipeline;
pub mod report;

pub use args::{Cli, Command, CompileArgs};
pub use pipeline::{compile, CompileOptions, DrawingOptions, Failure, InputKind, Source};

use std::process::ExitCode;

/// Exit status of a run whose input had errors.
pub const EXIT_INPUT_ERROR: u8 = 1;
/// Exit status of a run whose command line asks for something impossible.
pub const EXIT_USAGE: u8 = 2;

/// Runs a parsed command line and returns the process exit status.
pub fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Compile(args) => compile_command(&args),
    }
}

fn compile_command(args: &CompileArgs) -> ExitCode {
    if args.out_dir.is_some() || args.inputs.len() > 1 {
        return batch::run(args);
    }
    let source = match Source::read(&args.inputs[0]) {
        Ok(source) => source,
        Err(failure) => return report::fail(&failure),
    };
    let options = args.compile_options(&source.name);
    match compile(&source, &options) {
        Ok(compiled) => {
            report::warnings(&compiled.warnings);
            match output::write(args.output.as_deref(), &compiled.bytes) {
                Ok(()) => ExitCode::SUCCESS,
                Err(failure) => report::fail(&failure),
            }
        }
        Err(failure) => report::fail(&failure),
    }
}
