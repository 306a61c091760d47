//! The subcommands: [`compile`] (single input; several go to [`batch`], `--format
//! toolpath` to [`toolpath`]), `check` ([`verify`]), [`plot`], [`diff`] (their HTML
//! pages: [`view`]) and the generated shell completions and manual page ([`manual`]).
//!
//! Owns what each command does with its arguments and in which order; it must not read
//! a format, plan or write output by itself (the layers below do).

pub mod batch;
pub mod compile;
pub mod diff;
pub mod manual;
pub mod plot;
pub mod toolpath;
pub mod verify;
pub mod view;
