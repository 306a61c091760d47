//! The `--tool-table` file: LinuxCNC's `.tbl` tool table for G43 H.
//!
//! Owns reading that file and turning a format error into a coded diagnostic
//! (`pvtc::tool_table::syntax`) that names the line and labels the word. The format itself
//! is [`pvt_gcode::ToolTable::parse`]'s; it must not know how the offsets are applied.

use crate::pipeline::Failure;
use miette::{LabeledSpan, NamedSource};
use std::path::Path;

/// Reads a tool table file.
pub fn read(path: &Path) -> Result<pvt_gcode::ToolTable, Failure> {
    let text = std::fs::read_to_string(path).map_err(|error| Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    })?;
    pvt_gcode::ToolTable::parse(&text).map_err(|(range, message)| {
        let report = miette::miette!(
            code = "pvtc::tool_table::syntax",
            labels = vec![LabeledSpan::at(range, "here")],
            help = "write one tool per line, e.g. `T1 P1 Z0.5 D6 ;6 mm drill`",
            "{message}"
        )
        .with_source_code(NamedSource::new(path.display().to_string(), text.clone()));
        Failure::Input(vec![report])
    })
}
