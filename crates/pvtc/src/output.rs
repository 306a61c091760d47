//! Writing outputs: standard output, or a file replaced atomically.
//!
//! Owns the guarantee that an output file is either the complete new output or untouched:
//! bytes go to a temporary file in the target's directory, which is then renamed over the
//! target. A failed compile drops the temporary file; an interrupt (Ctrl-C, SIGTERM)
//! removes every temporary file being written before the process exits, so no partial
//! file is left. Standard output redirected to a regular file is written in place from
//! its end, and cut back there by a failure or an interrupt. A stream (a pipe, a
//! terminal) gets the output whole or not at all: it is written to an unnamed temporary
//! file and copied to the stream once complete ([`write_stream`]). It must not decide
//! what to write.
//!
//! The rename is atomic but the data is not flushed to the disk first (compilers do not
//! either): what survives a power loss just after a compile is the file system's choice.
//! A failure or an interrupt never leaves a partial file.

use crate::failure::Failure;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Temporary outputs being written now, by every thread.
static IN_PROGRESS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Exit status after an interrupt (128 + SIGINT, as shells report it).
pub const INTERRUPTED: i32 = 130;

fn in_progress() -> MutexGuard<'static, Vec<PathBuf>> {
    IN_PROGRESS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Standard output redirected to a file while a compile writes it: a handle to the file
/// and where this output began in it. The lock is held around every write to it, so the
/// interrupt handler, which takes it to cut the file back, is never followed by a write.
static REDIRECTED_STDOUT: Mutex<Option<(std::fs::File, u64)>> = Mutex::new(None);

fn redirected_stdout() -> MutexGuard<'static, Option<(std::fs::File, u64)>> {
    REDIRECTED_STDOUT.lock().unwrap_or_else(|e| e.into_inner())
}

/// Makes Ctrl-C and SIGTERM remove every temporary output being written, then exit with
/// [`INTERRUPTED`]. Call once, before any output is written; a second call does nothing.
pub fn remove_partial_outputs_on_interrupt() {
    // An error means a handler is already installed (a second call): nothing to do.
    let _ = ctrlc::set_handler(|| {
        // Held until exit, so no temporary file is created or renamed after this.
        let files = in_progress();
        for file in files.iter() {
            let _ = std::fs::remove_file(file);
        }
        // Held until exit too: no write to standard output follows the cut.
        let stdout = redirected_stdout();
        if let Some((file, start)) = stdout.as_ref() {
            let _ = file.set_len(*start);
        }
        std::process::exit(INTERRUPTED);
    });
}

/// A temporary output listed in [`IN_PROGRESS`] for as long as it lives.
struct Listed(PathBuf);

impl Drop for Listed {
    fn drop(&mut self) {
        let mut files = in_progress();
        if let Some(i) = files.iter().position(|f| *f == self.0) {
            files.swap_remove(i);
        }
    }
}

/// Where a writer's bytes go: a file, which can start over, or a stream (standard output
/// to a pipe or terminal), which cannot.
pub enum Target<'a> {
    /// A file written from byte `start` on, such as the temporary file behind an
    /// atomically replaced output.
    File {
        /// The file.
        file: &'a mut std::fs::File,
        /// Where this output begins in it.
        start: u64,
    },
    /// Standard output redirected to a regular file, written from byte `start` on: as
    /// [`Target::File`], and cut back to `start` by an interrupt.
    RedirectedStdout {
        /// The file.
        file: &'a mut std::fs::File,
        /// Where this output begins in it.
        start: u64,
    },
    /// The null device (`-o /dev/null`, `> /dev/null`): it keeps nothing, so starting
    /// over costs nothing and a compile writes into it in one pass, as into a file.
    Discard(&'a mut std::fs::File),
    /// A stream written directly, where no temporary file could be made for it (see
    /// [`write_stream`]): what is written stays written.
    Stream(&'a mut dyn Write),
}

impl Target<'_> {
    /// Whether [`Target::restart`] can discard what was written.
    pub fn can_restart(&self) -> bool {
        !matches!(self, Target::Stream(_))
    }

    /// Whether this is a file and the file at `path` is that same file (`pvtc compile
    /// p.ngc >> p.ngc`): streaming would read what it writes.
    pub fn is_file_at(&self, path: &Path) -> bool {
        let (Target::File { file, .. } | Target::RedirectedStdout { file, .. }) = self else {
            return false;
        };
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(written), Ok(read)) => same_file(&written, &read),
            _ => false,
        }
    }

    /// Discards everything written so far (a file only; a stream is left as it is).
    pub fn restart(&mut self) -> std::io::Result<()> {
        match self {
            Target::File { file, start } | Target::RedirectedStdout { file, start } => {
                file.seek(std::io::SeekFrom::Start(*start))?;
                file.set_len(*start)
            }
            Target::Discard(_) | Target::Stream(_) => Ok(()),
        }
    }
}

impl Write for Target<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Target::File { file, .. } => file.write(buf),
            Target::RedirectedStdout { file, .. } => {
                let _held = redirected_stdout();
                file.write(buf)
            }
            Target::Discard(file) => file.write(buf),
            Target::Stream(out) => out.write(buf),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        match self {
            Target::File { file, .. } => file.write_all(buf),
            Target::RedirectedStdout { file, .. } => {
                let _held = redirected_stdout();
                file.write_all(buf)
            }
            Target::Discard(file) => file.write_all(buf),
            Target::Stream(out) => out.write_all(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Target::File { file, .. } | Target::RedirectedStdout { file, .. } => file.flush(),
            Target::Discard(file) => file.flush(),
            Target::Stream(out) => out.flush(),
        }
    }
}

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
    write: impl FnOnce(&mut Target<'_>) -> Result<T, Failure>,
) -> Result<T, Failure> {
    let fail = |error| Failure::Io {
        path: path.to_path_buf(),
        action: "write",
        error,
    };
    if let Some(mut device) = special_file(path).map_err(fail)? {
        // A device or a pipe (`-o /dev/null`, a FIFO) is written in place: renaming a
        // temporary file onto it would replace it with a regular file. The null device
        // keeps nothing, so it is written as a file that can start over; anything else
        // as a stream.
        if is_null_device(&device) {
            return write(&mut Target::Discard(&mut device));
        }
        return write_stream(&mut device, path, write);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let (mut temp, _listed) = {
        let mut files = in_progress();
        let temp = tempfile::Builder::new()
            .prefix(".pvtc-")
            .suffix(".partial")
            .tempfile_in(dir)
            .map_err(fail)?;
        files.push(temp.path().to_path_buf());
        let listed = Listed(temp.path().to_path_buf());
        (temp, listed)
    };
    temp.as_file()
        .set_permissions(permissions_for(path))
        .map_err(fail)?;
    let value = write(&mut Target::File {
        file: temp.as_file_mut(),
        start: 0,
    })?;
    temp.flush().map_err(fail)?;
    let files = in_progress();
    temp.persist(path).map_err(|e| fail(e.error))?;
    drop(files);
    Ok(value)
}

/// Lets `write` fill `path` atomically, or standard output for `None` or `-`.
pub fn write_with<T>(
    path: Option<&Path>,
    write: impl FnOnce(&mut Target<'_>) -> Result<T, Failure>,
) -> Result<T, Failure> {
    match path {
        Some(p) if p != Path::new("-") => write_file_with(p, write),
        _ => {
            let stdout_failure = |error| Failure::Io {
                path: "<stdout>".into(),
                action: "write",
                error,
            };
            let mut out = std::io::stdout().lock();
            out.flush().map_err(stdout_failure)?;
            if let Some(file) = regular_file(&out) {
                return write_stdout_file(file, write);
            }
            if let Some(mut null) = null_device(&out) {
                return write(&mut Target::Discard(&mut null));
            }
            let value = write_stream(&mut out, Path::new("<stdout>"), write)?;
            out.flush().map_err(stdout_failure)?;
            Ok(value)
        }
    }
}

/// Lets `write` fill an unnamed temporary file (in the temporary directory, gone with
/// the process whatever ends it), then copies it to `stream` (named `name` in a
/// failure): a stream keeps what it is given, so it receives the output only once the
/// whole is written, and nothing when `write` fails, after the one pass a file takes.
/// Where no temporary file can be made, `write` writes into the stream itself, as a
/// [`Target::Stream`] (a compile then checks the whole program before writing).
pub fn write_stream<T>(
    stream: &mut dyn Write,
    name: &Path,
    write: impl FnOnce(&mut Target<'_>) -> Result<T, Failure>,
) -> Result<T, Failure> {
    let Ok(mut spool) = tempfile::tempfile() else {
        return write(&mut Target::Stream(stream));
    };
    let value = write(&mut Target::File {
        file: &mut spool,
        start: 0,
    })?;
    spool
        .seek(std::io::SeekFrom::Start(0))
        .and_then(|_| std::io::copy(&mut spool, stream))
        .map_err(|error| Failure::Io {
            path: name.to_path_buf(),
            action: "write",
            error,
        })?;
    Ok(value)
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    (a.dev(), a.ino()) == (b.dev(), b.ino())
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

/// Standard output as a file, when it is redirected to a regular file.
#[cfg(unix)]
fn regular_file(out: &std::io::StdoutLock<'_>) -> Option<std::fs::File> {
    use std::os::fd::AsFd;
    let file = std::fs::File::from(out.as_fd().try_clone_to_owned().ok()?);
    file.metadata().ok()?.is_file().then_some(file)
}

#[cfg(not(unix))]
fn regular_file(_: &std::io::StdoutLock<'_>) -> Option<std::fs::File> {
    None
}

/// Standard output as a file, when it is redirected to the null device.
#[cfg(unix)]
fn null_device(out: &std::io::StdoutLock<'_>) -> Option<std::fs::File> {
    use std::os::fd::AsFd;
    let file = std::fs::File::from(out.as_fd().try_clone_to_owned().ok()?);
    is_null_device(&file).then_some(file)
}

#[cfg(not(unix))]
fn null_device(_: &std::io::StdoutLock<'_>) -> Option<std::fs::File> {
    None
}

/// Whether `file` is the null device: a character device with `/dev/null`'s device
/// number, which discards every write (terminals and serial lines, also character
/// devices, are not: what they are sent stays sent).
#[cfg(unix)]
pub fn is_null_device(file: &std::fs::File) -> bool {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let (Ok(this), Ok(null)) = (file.metadata(), std::fs::metadata("/dev/null")) else {
        return false;
    };
    this.file_type().is_char_device() && this.rdev() == null.rdev()
}

#[cfg(not(unix))]
pub fn is_null_device(_: &std::fs::File) -> bool {
    false
}

/// Lets `write` write standard output redirected to a regular file: from the file's end
/// (where `>` leaves it empty and `>>` appends), and cut back to there if `write` fails,
/// so a failed compile adds nothing to the file. Writing into a file rather than a pipe
/// lets the streaming path write in one pass and start over if it must.
fn write_stdout_file<T>(
    mut file: std::fs::File,
    write: impl FnOnce(&mut Target<'_>) -> Result<T, Failure>,
) -> Result<T, Failure> {
    let fail = |error| Failure::Io {
        path: "<stdout>".into(),
        action: "write",
        error,
    };
    let start = file.seek(std::io::SeekFrom::End(0)).map_err(fail)?;
    let _registered = RegisteredStdout::new(&file, start).map_err(fail)?;
    let mut target = Target::RedirectedStdout {
        file: &mut file,
        start,
    };
    match write(&mut target) {
        Ok(value) => Ok(value),
        Err(failure) => {
            // Best effort: the failure being reported matters more than this one.
            let _ = target.restart();
            Err(failure)
        }
    }
}

/// Redirected standard output registered in [`REDIRECTED_STDOUT`] for as long as it lives.
struct RegisteredStdout;

impl RegisteredStdout {
    fn new(file: &std::fs::File, start: u64) -> std::io::Result<RegisteredStdout> {
        *redirected_stdout() = Some((file.try_clone()?, start));
        Ok(RegisteredStdout)
    }
}

impl Drop for RegisteredStdout {
    fn drop(&mut self) {
        *redirected_stdout() = None;
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

/// `path` opened for writing when it exists and is neither a regular file nor a
/// directory (a device, a FIFO); `None` otherwise.
fn special_file(path: &Path) -> std::io::Result<Option<std::fs::File>> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => {
            std::fs::OpenOptions::new().write(true).open(path).map(Some)
        }
        _ => Ok(None),
    }
}

/// Writes `bytes` to standard output for a command whose result is the text itself
/// (`check`'s table, completions, the manual page) and returns the exit status: a reader
/// that closed the pipe (`| head`) is not a failure worth a report; any other failure is
/// reported by `reporter`.
pub fn write_stdout_status(
    bytes: &[u8],
    reporter: &crate::report::Reporter,
) -> std::process::ExitCode {
    match write_stdout(bytes) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(Failure::Io { error, .. }) if error.kind() == std::io::ErrorKind::BrokenPipe => {
            std::process::ExitCode::SUCCESS
        }
        Err(failure) => reporter.fail(&failure),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stream is written once, whole, after a pass that could start over.
    #[test]
    fn a_stream_gets_the_output_whole_after_one_restartable_pass() {
        let mut stream = Vec::new();
        let value = write_stream(&mut stream, Path::new("<test>"), |out| {
            assert!(out.can_restart(), "the pass writes a file, not the stream");
            let io = |error| Failure::Io {
                path: "<test>".into(),
                action: "write",
                error,
            };
            out.write_all(b"first guess\n").map_err(io)?;
            out.restart().map_err(io)?;
            out.write_all(b"G1 X1\n").map_err(io)?;
            Ok(7)
        })
        .unwrap();
        assert_eq!(value, 7);
        assert_eq!(stream, b"G1 X1\n");
    }

    /// A failure sends the stream nothing, whatever was written before it.
    #[test]
    fn a_failed_pass_sends_the_stream_nothing() {
        let mut stream = Vec::new();
        let result: Result<(), Failure> = write_stream(&mut stream, Path::new("<test>"), |out| {
            out.write_all(&[b'x'; 100_000]).unwrap();
            Err(Failure::Usage("refused late".into()))
        });
        assert!(matches!(result, Err(Failure::Usage(_))));
        assert!(
            stream.is_empty(),
            "{} bytes reached the stream",
            stream.len()
        );
    }
}
