//! The one way pvtc's integration tests start the `pvtc` binary: from the workspace
//! root, without colour, with given bytes on standard input.
//!
//! Owns the process spawn shared by the CLI tests, and the command line's option names
//! from its clap definitions; it must not judge a run (each test asserts on the
//! [`Output`] itself).
#![allow(dead_code)] // each test binary uses its own part

pub mod chromium;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// The workspace root, where tests run pvtc so that `samples/…` paths resolve.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `pvtc ARGS` as a command from the workspace root, without colour.
pub fn command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_pvtc"));
    command.args(args).current_dir(root()).env("NO_COLOR", "1");
    command
}

/// Runs `pvtc ARGS` with `stdin` on standard input and collects its output. A run that
/// fails before reading its input closes the pipe; that is not an error here.
pub fn pvtc_bytes(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = command(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("pvtc runs");
    let mut pipe = child.stdin.take().expect("a piped stdin");
    let _ = pipe.write_all(stdin);
    drop(pipe);
    child.wait_with_output().expect("pvtc finishes")
}

/// [`pvtc_bytes`] with text (or nothing) on standard input.
pub fn pvtc(args: &[&str], stdin: Option<&str>) -> Output {
    pvtc_bytes(args, stdin.unwrap_or("").as_bytes())
}

/// Runs pvtc with standard output redirected to `file` (as `>` or `>>` does).
pub fn pvtc_into(args: &[&str], file: std::fs::File) -> Output {
    command(args)
        .stdin(Stdio::null())
        .stdout(Stdio::from(file))
        .stderr(Stdio::piped())
        .output()
        .expect("pvtc runs")
}

/// Runs `pvtc ARGS` with nothing on standard input.
pub fn run(args: &[&str]) -> Output {
    command(args)
        .stdin(Stdio::null())
        .output()
        .expect("pvtc runs")
}

/// Output bytes as text (invalid UTF-8 replaced).
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Every subcommand's name with its long options, from the clap definitions `--help`
/// prints.
pub fn long_options() -> Vec<(String, Vec<String>)> {
    use clap::CommandFactory;
    pvtc::Cli::command()
        .get_subcommands()
        .map(|sub| {
            let longs = sub
                .get_arguments()
                .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
                .collect();
            (sub.get_name().to_string(), longs)
        })
        .collect()
}
