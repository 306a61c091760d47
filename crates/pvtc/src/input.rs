//! The input as a file to read: a path given, or standard input spooled into a temporary
//! file, so every route reads a file (and can read it twice).
//!
//! Owns spooling standard input and the name diagnostics give the input. It must not
//! parse, plan or report anything.

use crate::failure::Failure;

/// A G-code input as a file to read from: the file itself, or for `-` standard input
/// copied into a temporary file (removed when dropped), with the name diagnostics use.
pub struct Spooled {
    _copy: Option<tempfile::NamedTempFile>,
    /// Where to read.
    pub path: std::path::PathBuf,
    /// The path as given, or `<stdin>`.
    pub name: String,
}

/// `input` as a file to read from, spooling standard input for `-`.
pub fn spool(input: &std::path::Path) -> Result<Spooled, Failure> {
    if input != std::path::Path::new("-") {
        return Ok(Spooled {
            _copy: None,
            path: input.to_path_buf(),
            name: input.display().to_string(),
        });
    }
    let failure = |error| Failure::Io {
        path: "<stdin>".into(),
        action: "read",
        error,
    };
    let mut file = tempfile::NamedTempFile::new().map_err(failure)?;
    std::io::copy(&mut std::io::stdin().lock(), file.as_file_mut()).map_err(failure)?;
    Ok(Spooled {
        path: file.path().to_path_buf(),
        _copy: Some(file),
        name: "<stdin>".into(),
    })
}
