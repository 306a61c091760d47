//! pvtc: the command line, a small layer on top of the pipeline crates.
//!
//! Layers, each importing only those below it: [`failure`] and [`input`] at the bottom;
//! [`options`] (what the command line asked, side files read once, no defaults);
//! [`settings`] (every default, applied once); [`front`] (choosing a front end) and
//! [`route`] (the one compile path, every input kind into the same planning sink;
//! [`pipeline`] runs a streamed G-code compile's front end on a thread of its own);
//! [`output`] (atomic writes) and [`report`] (the only writer of standard error);
//! [`args`] (clap); [`commands`] (compile, batch, toolpath, check, plot, diff, manual);
//! [`embed`] (the same route for a program that embeds pvtc: pieces kept as arrays).
//! Architecture invariant: no geometry, planning or formatting happens here; a failed run
//! never creates or changes an output file. This root holds `mod` lines, the public
//! re-exports and the dispatch ([`run`]); no module imports anything from it
//! (`tests/tidy.rs`).

pub mod args;
pub mod commands;
pub mod embed;
pub mod excerpt;
pub mod failure;
pub mod front;
pub mod input;
pub mod machine;
pub mod options;
pub mod output;
pub mod pipeline;
pub mod report;
pub mod route;
pub mod settings;
pub mod subroutines;

pub use args::{Cli, Command, CompileArgs};
pub use commands::manual::man_page_text;
pub use failure::Failure;
pub use options::{Asked, CompileOptions, DrawingOptions, InputKind, Source, VelocitySource};
pub use route::{compile, plan};

use report::Reporter;
use std::process::ExitCode;

pub use report::{EXIT_INPUT_ERROR, EXIT_USAGE};

/// Runs a parsed command line and returns the process exit status.
pub fn run(cli: Cli) -> ExitCode {
    report::install_panic_hook();
    output::remove_partial_outputs_on_interrupt();
    match cli.command {
        Command::Compile(mut args) => match args.pipeline.read_files() {
            Ok(()) => commands::compile::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Check(mut args) => match args.pipeline.read_files() {
            Ok(()) => commands::verify::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Plot(mut args) => match args.pipeline.read_files() {
            Ok(()) => commands::plot::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Diff(mut args) => match args.pipeline.read_files() {
            Ok(()) => commands::diff::run(&args),
            Err(failure) => Reporter::new(&args.pipeline).fail(&failure),
        },
        Command::Completions { shell } => commands::manual::completions(shell),
        Command::Man => commands::manual::man_page(),
    }
}
