//! `pvtc compile`: one input through the route into its output, written atomically;
//! several inputs or `--out-dir` go to [`super::batch`], `--format toolpath` to
//! [`super::toolpath`].
//!
//! Owns the order of a single compile (options, route, warnings). It must not plan or
//! format.

use crate::args::CompileArgs;
use crate::report::Reporter;
use std::process::ExitCode;

/// Runs `pvtc compile`: `--format toolpath`, a batch, or one input through the route.
pub fn run(args: &CompileArgs) -> ExitCode {
    if args.format == crate::args::FormatArg::Toolpath {
        return super::toolpath::run(args);
    }
    if args.out_dir.is_some() || args.inputs.len() > 1 {
        return super::batch::run(args);
    }
    let reporter = Reporter::new(&args.pipeline);
    let input = &args.inputs[0];
    let options = match args.compile_options(&input.display().to_string()) {
        Ok(options) => options,
        Err(failure) => return reporter.fail(&failure),
    };
    let deny = args.pipeline.deny_warnings;
    let result = crate::output::write_with(args.output.as_deref(), |out| {
        crate::route::compile_to(input, &options, deny, out)
    });
    match result.map(|warnings| reporter.warnings(&warnings)) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(code)) => code,
        Err(failure) => reporter.fail(&failure),
    }
}
