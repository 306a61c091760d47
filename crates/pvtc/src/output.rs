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
    write_file_with(path, |out| {
        out.write_all(bytes).map_err(|error| Failure::Io {
            path: path.to_path_buf(),
            action: "write",
            error,
        })
    })
}

/// Lets `write` fill a temporary file beside `path`, then renames it onto `path`; if
/// `write` fails, the temporary file is removed and `path` is left as it was.
pub fn write_file_with<T>(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<T, Failure>,
) -> Result<T, Failure> {
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
    let value = write(&mut temp)?;
    temp.flush()
        .and_then(|()| temp.as_file().sync_all())
        .map_err(fail)?;
    temp.persist(path).map_err(|e| fail(e.error))?;
    Ok(value)
}

/// Lets `write` fill `path` atomically, or standard output for `None` or `-`.
pub fn write_with<T>(
    path: Option<&Path>,
    write: impl FnOnce(&mut dyn Write) -> Result<T, Failure>,
) -> Result<T, Failure> {
    match path {
        Some(p) if p != Path::new("-") => write_file_with(p, write),
        _ => {
            let mut out = std::io::stdout().lock();
            let value = write(&mut out)?;
            out.flush().map_err(|error| Failure::Io {
                path: "<stdout>".into(),
                action: "write",
                error,
            })?;
            Ok(value)
        }
    }
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
