//! The `pvtc` command: parses arguments and hands them to the library.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    pvtc::run(pvtc::Cli::parse())
}
