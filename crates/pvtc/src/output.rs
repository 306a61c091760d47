//! Writing outputs: standard output, or a file replaced atomically.
//!
//! Owns the guarantee that an output file is either the complete new output or untouched:
//! bytes go to a temporary file in the target's directory, which is then renamed over the
//! target. It must not decide what to write.

use crate::pipeline::Failure;
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically, or to standard output for `None` or `-`.
pub fn write(path: Option<&Path>, bytes: &[u8]) -> Result<(), Failure> {
    match path {
        None => write_stdout(bytes),
        Some(p) if p == Path::new("-") => write_stdout(bytes),
        Some(p) => write_file(p, bytes),
    }
}

fn write_stdout(bytes: &[u8]) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|error| Failure::Io {
            path: "<stdout>".into(),
            action: "write",
            error,
        })
}

/// Writes `bytes` to a temporary file beside `path`, then renames it onto `path`.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    let fail = |error| Failure::Io {
        path: path.to_path_buf(),
        action: "write",
        error,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut temp = tempfile::Builder::new()
        .prefix(".pvtc-")
        .suffix(".partial")
        .tempfile_in(dir)
        .map_err(fail)?;
    temp.as_file()
        .set_permissions(permissions_for(path))
        .map_err(fail)?;
    temp.write_all(bytes)
        .and_then(|()| temp.as_file().sync_all())
        .map_err(fail)?;
    temp.persist(path).map_err(|e| fail(e.error))?;
    Ok(())
}

/// The permissions the output gets: those of the file it replaces, or else `rw-r--r--`
/// (a temporary file is created private, which an output must not stay).
fn permissions_for(path: &Path) -> std::fs::Permissions {
    if let Ok(meta) = std::fs::metadata(path) {
        return meta.permissions();
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::Permissions::from_mode(0o644)
    }
    #[cfg(not(unix))]
    {
        let mut p = std::fs::metadata(Path::new("."))
            .map(|m| m.permissions())
            .expect("the working directory exists");
        p.set_readonly(false);
        p
    }
}
