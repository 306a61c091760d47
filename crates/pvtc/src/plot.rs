//! `pvtc plot`: compiles (or reads) a program and writes its SVG plot.
//!
//! Owns loading the program and writing the file (named `.svg`, or `-`); the drawing is pvt-emit's `plot`
//! back end. It must not draw anything itself.

use crate::args::PlotArgs;
use crate::output;
use crate::pipeline::Failure;
use crate::report::Reporter;
use crate::EXIT_INPUT_ERROR;
use std::path::Path;
use std::process::ExitCode;

/// Runs `pvtc plot`.
pub fn run(args: &PlotArgs) -> ExitCode {
    let reporter = Reporter::new(&args.pipeline);
    if let Err(failure) = check_extension(&args.output) {
        return reporter.fail(&failure);
    }
    let loaded = match crate::check::load(&args.input, &args.pipeline, &reporter) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let program = loaded.program;
    let limits = match &loaded.options.machine {
        Some(m) => match m.limits_in(program.units, &program.axes) {
            Ok(limits) => limits,
            Err(e) => return reporter.fail(&crate::Failure::Input(vec![miette::Report::new(e)])),
        },
        None => Default::default(),
    };
    let options = pvt_emit::plot::PlotOptions {
        title: format!(
            "{} ({})",
            args.input.display(),
            loaded.options.planner.name()
        ),
        limits,
        ..Default::default()
    };
    let svg = match pvt_emit::plot::plot_svg(&program, &options) {
        Ok(svg) => svg,
        Err(e) => {
            eprintln!("error: cannot plot: {e}");
            return ExitCode::from(EXIT_INPUT_ERROR);
        }
    };
    match output::write(Some(&args.output), svg.as_bytes()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => reporter.fail(&failure),
    }
}

/// Refuses an output named for another format (`-o part.png` would hold SVG): the file
/// must end in `.svg`, or be `-` for standard output.
fn check_extension(output: &Path) -> Result<(), Failure> {
    let svg = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if svg || output == Path::new("-") {
        return Ok(());
    }
    Err(Failure::Usage(format!(
        "plot writes SVG only: name the output FILE.svg (or - for standard output), not {}",
        output.display()
    )))
}
