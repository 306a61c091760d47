//! pvtc: the command line, a small layer on top of the pipeline crates.
//!
//! Owns arguments ([`args`]), the data a compile shares ([`options`]), reading inputs
//! and choosing a front end ([`front`], [`pipeline`]), batch runs ([`batch`]), the
//! unplanned toolpath route ([`toolpath`]), writing outputs atomically ([`output`]), the
//! check and plot commands' rendering ([`check`], [`plot`]), diagnostics ([`report`]),
//! and the shell completions and manual page (`pvtc completions`, `pvtc man`, from the
//! argument definitions by clap_complete and clap_mangen).
//! Architecture invariant: no geometry, planning or formatting happens here; a failed run
//! never creates or changes an output file. This root holds `mod` lines, the public
//! re-exports and the dispatch ([`run`]); no module imports anything from it
//! (`tests/tidy.rs`).

pub mod args;
pub mod commands;
pub mod excerpt;
pub mod failure;
pub mod front;
pub mod input;
pub mod machine;
pub mod options;
pub mod output;
pub mod report;
pub mod route;
pub mod settings;
pub mod subroutines;

pub use args::{Cli, Command, CompileArgs};
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
            Ok(()) => compile_command(&args),
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
        Command::Completions { shell } => completions(shell),
        Command::Man => man_page(),
    }
}

/// `pvtc completions SHELL`: the completion script on standard output.
fn completions(shell: clap_complete::Shell) -> ExitCode {
    let mut command = <Cli as clap::CommandFactory>::command();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut command, "pvtc", &mut script);
    output::write_stdout_status(&script, &Reporter::human())
}

/// The manual page of pvtc (roff), one page: name, synopsis, description, options, the
/// list of subcommands (each pointing to its section below, as there are no
/// `pvtc-compile(1)` pages), version, then for each subcommand (`pvtc compile`, …) its
/// synopsis and options.
pub fn man_page_text() -> Vec<u8> {
    let command = <Cli as clap::CommandFactory>::command();
    let mut page = Vec::new();
    // Rendering into memory cannot fail: the results are io::Results of a Vec's writes.
    let man = clap_mangen::Man::new(command.clone());
    let _ = man.render_title(&mut page);
    let _ = man.render_name_section(&mut page);
    let _ = man.render_synopsis_section(&mut page);
    let _ = man.render_description_section(&mut page);
    let _ = man.render_options_section(&mut page);
    page.extend_from_slice(b".SH SUBCOMMANDS\n");
    for sub in command.get_subcommands() {
        let name = format!("pvtc {}", sub.get_name());
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        let item = format!(
            ".TP\n\\fB{}\\fR\n{} (see {} below)\n",
            name,
            roff_text(&about),
            name.to_uppercase()
        );
        page.extend_from_slice(item.as_bytes());
    }
    let _ = man.render_version_section(&mut page);
    for sub in command.get_subcommands() {
        let name = format!("pvtc {}", sub.get_name());
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        let heading = format!(".SH \"{}\"\n{}\n", name.to_uppercase(), roff_text(&about));
        page.extend_from_slice(heading.as_bytes());
        let man = clap_mangen::Man::new(sub.clone().bin_name(name));
        let _ = man.render_synopsis_section(&mut page);
        let _ = man.render_options_section(&mut page);
    }
    page
}

/// Plain text as a roff text line: a leading `.` or `'` would read as a request.
fn roff_text(text: &str) -> String {
    let text = text.replace('\\', "\\e");
    if text.starts_with(['.', '\'']) {
        format!("\\&{text}")
    } else {
        text
    }
}

/// `pvtc man`: the manual page on standard output.
fn man_page() -> ExitCode {
    output::write_stdout_status(&man_page_text(), &Reporter::human())
}

fn compile_command(args: &CompileArgs) -> ExitCode {
    if args.format == args::FormatArg::Toolpath {
        return commands::toolpath::run(args);
    }
    if args.out_dir.is_some() || args.inputs.len() > 1 {
        return commands::batch::run(args);
    }
    let reporter = Reporter::new(&args.pipeline);
    let input = &args.inputs[0];
    let options = match args.compile_options(&input.display().to_string()) {
        Ok(options) => options,
        Err(failure) => return reporter.fail(&failure),
    };
    let deny = args.pipeline.deny_warnings;
    let result = output::write_with(args.output.as_deref(), |out| {
        route::compile_to(input, &options, deny, out)
    });
    match result.map(|warnings| reporter.warnings(&warnings)) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(code)) => code,
        Err(failure) => reporter.fail(&failure),
    }
}
