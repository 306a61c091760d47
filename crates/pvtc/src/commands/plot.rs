//! `pvtc plot`: compiles (or reads) a program and writes its plot, SVG, PNG or an
//! interactive HTML page.
//!
//! Owns loading the program, choosing the format from the output's name (`.svg` or `-`:
//! SVG; `.png`: PNG; `.html`: the page of [`crate::commands::view`]) and writing the
//! file; the drawing is pvt-emit's `plot` and `view` back ends. It must not draw
//! anything itself.

use crate::args::PlotArgs;
use crate::commands::verify::Loaded;
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
    let written = match format {
        PlotFormat::Html => page(args, loaded),
        PlotFormat::Svg | PlotFormat::Png => image(args, loaded, format),
    };
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => reporter.fail(&failure),
    }
}

/// Draws and writes the SVG or PNG image of a loaded program.
fn image(args: &PlotArgs, loaded: Loaded, format: PlotFormat) -> Result<(), Failure> {
    let program = loaded.program;
    let machine = loaded.options.machine.as_ref();
    let limits = crate::settings::machine_limits(machine, program.units, &program.axes)?;
    let options = pvt_emit::plot::PlotOptions {
        title: format!(
            "{} ({})",
            args.input.display(),
            loaded.options.planner.name()
        ),
        limits,
        geometry: loaded.toolpath,
        ..Default::default()
    };
    let drawn = match format {
        PlotFormat::Png => pvt_emit::plot::plot_png(&program, &options),
        _ => pvt_emit::plot::plot_svg(&program, &options).map(String::into_bytes),
    };
    let bytes = drawn.map_err(|e| {
        Failure::Input(vec![miette::miette!(
            code = "pvtc::plot::draw",
            "cannot plot: {e}"
        )])
    })?;
    output::write(Some(&args.output), &bytes)
}

/// The HTML page of a loaded program: the text its lines name is the input's (a JSON
/// program's segments named by their own lines), with what `check` finds in it.
fn page(args: &PlotArgs, mut loaded: Loaded) -> Result<(), Failure> {
    let source = crate::options::Source::read(&args.input)?;
    let text = String::from_utf8_lossy(&source.bytes).into_owned();
    if loaded.toolpath.is_none() && source.name.to_ascii_lowercase().ends_with(".json") {
        crate::commands::diff::json_lines(&mut loaded.program, &text);
    }
    let options = crate::settings::check_options(
        loaded.options.machine.as_ref(),
        &loaded.program,
        Default::default(),
        None,
    )?;
    let report = pvt_core::check_program(&loaded.program, loaded.toolpath.as_ref(), &options);
    crate::commands::view::write_plot(&args.output, &loaded, &text, &source.name, &report)
}

/// The image formats `pvtc plot` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PlotFormat {
    /// SVG text.
    Svg,
    /// A PNG image.
    Png,
    /// An interactive HTML page.
    Html,
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
    } else if crate::commands::view::is_html(output) {
        Ok(PlotFormat::Html)
    } else {
        Err(Failure::Usage(format!(
            "plot writes SVG, PNG or HTML: name the output FILE.svg, FILE.png or FILE.html \
             (or - for SVG on standard output), not {}",
            output.display()
        )))
    }
}
