//! `pvtc plot`: compiles (or reads) a program and writes its plot, SVG or PNG.
//!
//! Owns loading the program, choosing the format from the output's name (`.svg` or `-`:
//! SVG; `.png`: PNG) and writing the file; the drawing is pvt-emit's `plot` back end. It
//! must not draw anything itself.

use crate::args::PlotArgs;
use crate::options::Failure;
use crate::output;
use crate::report::Reporter;
use std::path::Path;
use std::process::ExitCode;

/// Runs `pvtc plot`.
pub fn run(args: &PlotArgs) -> ExitCode {
    let reporter = Reporter::new(&args.pipeline);
    let format = match format_of(&args.output) {
        Ok(format) => format,
        Err(failure) => return reporter.fail(&failure),
    };
    let loaded = match crate::commands::verify::load(&args.input, &args.pipeline, &reporter) {
        Ok(loaded) => loaded,
        Err(code) => return code,
    };
    let program = loaded.program;
    let geometry = loaded.toolpath;
    let machine = loaded.options.machine.as_ref();
    let limits = match crate::settings::machine_limits(machine, program.units, &program.axes) {
        Ok(limits) => limits,
        Err(failure) => return reporter.fail(&failure),
    };
    let options = pvt_emit::plot::PlotOptions {
        title: format!(
            "{} ({})",
            args.input.display(),
            loaded.options.planner.name()
        ),
        limits,
        geometry,
        ..Default::default()
    };
    let drawn = match format {
        PlotFormat::Svg => pvt_emit::plot::plot_svg(&program, &options).map(String::into_bytes),
        PlotFormat::Png => pvt_emit::plot::plot_png(&program, &options),
    };
    let bytes = match drawn {
        Ok(bytes) => bytes,
        Err(e) => {
            let report = miette::miette!(code = "pvtc::plot::draw", "cannot plot: {e}");
            return reporter.fail(&Failure::Input(vec![report]));
        }
    };
    match output::write(Some(&args.output), &bytes) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => reporter.fail(&failure),
    }
}

/// The image formats `pvtc plot` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PlotFormat {
    /// SVG text.
    Svg,
    /// A PNG image.
    Png,
}

/// The format the output's name asks for: `.svg` (or `-`, standard output) is SVG,
/// `.png` is PNG; any other name is a usage error rather than a file of the wrong kind.
fn format_of(output: &Path) -> Result<PlotFormat, Failure> {
    if output == Path::new("-") {
        return Ok(PlotFormat::Svg);
    }
    let extension = output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if extension.eq_ignore_ascii_case("svg") {
        Ok(PlotFormat::Svg)
    } else if extension.eq_ignore_ascii_case("png") {
        Ok(PlotFormat::Png)
    } else {
        Err(Failure::Usage(format!(
            "plot writes SVG or PNG: name the output FILE.svg or FILE.png (or - for SVG on \
             standard output), not {}",
            output.display()
        )))
    }
}
