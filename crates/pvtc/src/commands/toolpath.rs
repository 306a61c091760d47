//! `pvtc compile --format toolpath`: the front end's reading of one input as JSON lines.
//!
//! Owns the route that stops before planning: a G-code file or standard input streams
//! through the G-code front end into [`pvt_emit::toolpath::ToolpathWriter`]; a drawing's
//! whole toolpath is replayed into the same writer. It must not plan, and, like every
//! route, a failed run (an error, or a warning under `--deny-warnings`) writes nothing: a
//! stream that cannot start over gets a first pass into nothing.

use crate::args::CompileArgs;
use crate::options::{CompileOptions, Failure, InputKind, Source};
use crate::output::{self, Target};
use crate::report::Reporter;
use pvt_emit::toolpath::{replay, ToolpathWriter};
use std::path::Path;
use std::process::ExitCode;

/// Runs `pvtc compile --format toolpath` on its one input.
pub fn run(args: &CompileArgs) -> ExitCode {
    let reporter = Reporter::new(&args.pipeline);
    if args.out_dir.is_some() || args.inputs.len() > 1 {
        let usage = "--format toolpath writes one input: give one input and no --out-dir";
        return reporter.fail(&Failure::Usage(usage.into()));
    }
    let input = &args.inputs[0];
    let options = match args.compile_options(&input.display().to_string()) {
        Ok(options) => options,
        Err(failure) => return reporter.fail(&failure),
    };
    let written = match options.input {
        InputKind::Gcode => gcode(args, input, &options),
        InputKind::Dxf => drawing(args, input, &options),
        InputKind::Csv => Err(Failure::Usage(
            "a point series has no toolpath to show: --format toolpath reads G-code or DXF".into(),
        )),
    };
    match written.map(|warnings| reporter.warnings(&warnings)) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(code)) => code,
        Err(failure) => reporter.fail(&failure),
    }
}

fn gcode(
    args: &CompileArgs,
    input: &Path,
    options: &CompileOptions,
) -> Result<Vec<miette::Report>, Failure> {
    let spooled = crate::input::spool(input)?;
    let (path, name) = (spooled.path.as_path(), spooled.name.as_str());
    let gcode = crate::front::gcode_options(options);
    let deny = args.pipeline.deny_warnings;
    let warned = |warnings| crate::report::deny(crate::route::reports(path, name, warnings), deny);
    output::write_with(args.output.as_deref(), |out| {
        if !out.can_restart() {
            // A stream keeps what it is given: errors and denied warnings come first.
            let mut nothing = crate::route::MovedAxes::default();
            warned(crate::route::compile_read(path, name, &gcode, &mut nothing)?.warnings)?;
        }
        let mut writer = ToolpathWriter::new(std::io::BufWriter::new(&mut *out));
        let summary = crate::route::compile_read(path, name, &gcode, &mut writer)?;
        let warnings = warned(summary.warnings)?;
        writer.finish(summary.units).map_err(write_failure)?;
        Ok(warnings)
    })
}

fn drawing(
    args: &CompileArgs,
    input: &Path,
    options: &CompileOptions,
) -> Result<Vec<miette::Report>, Failure> {
    let source = Source::read(input)?;
    let (read, warnings) = crate::front::read(&source, options)?;
    let toolpath = match read {
        crate::front::Input::Toolpath(toolpath) => toolpath,
        crate::front::Input::Series(_) => {
            return Err(Failure::Usage(
                "--format toolpath reads G-code or DXF".into(),
            ))
        }
    };
    let warnings = crate::report::deny(warnings, args.pipeline.deny_warnings)?;
    output::write_with(args.output.as_deref(), |out: &mut Target<'_>| {
        let mut writer = ToolpathWriter::new(std::io::BufWriter::new(out));
        replay(&toolpath, &mut writer);
        writer.finish(toolpath.units).map_err(write_failure)?;
        Ok(warnings)
    })
}

fn write_failure(error: std::io::Error) -> Failure {
    Failure::Io {
        path: "<output>".into(),
        action: "write",
        error,
    }
}
