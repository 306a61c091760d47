//! What crosses the boundary when something goes wrong: the exceptions (`CompileError`
//! with its diagnostics, `InternalError` for a Rust panic), the warning categories, and
//! the conversion of pvtc's [`Failure`] and warnings into them.
//!
//! Owns the mapping from pvtc's outcomes to Python's: an input's errors raise
//! `CompileError` with the diagnostics `--diagnostics json` prints; a usage error
//! raises `ValueError` naming the keyword; a file that cannot be read raises `OSError`;
//! a warning goes through `warnings.warn` (notes never do: they are kept on the
//! program, as `--deny-warnings` never fails on one); a panic raises `InternalError`
//! ([`guard`]). It must not decide what is an error: pvtc's library does.

use pvtc::Failure;
use pyo3::exceptions::{PyException, PyOSError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pyo3::create_exception!(
    pvtc,
    PvtcError,
    PyException,
    "The base of pvtc's exceptions."
);
pyo3::create_exception!(
    pvtc,
    CompileError,
    PvtcError,
    "An input pvtc refuses. `.diagnostics` lists every error (a `Diagnostic` each, with \
     the CLI's stable code and the line and column); `str()` is the first."
);
pyo3::create_exception!(
    pvtc,
    InternalError,
    PvtcError,
    "A bug in pvtc: a Rust panic caught at the boundary. Please report it with the input."
);
pyo3::create_exception!(
    pvtc,
    PvtcWarning,
    PyUserWarning,
    "A warning of pvtc's; `.diagnostic` is its `Diagnostic`. `-W error` (or \
     `warnings.simplefilter('error', pvtc.PvtcWarning)`) makes it fail, as \
     `--deny-warnings` does."
);
pyo3::create_exception!(
    pvtc,
    InputWarning,
    PvtcWarning,
    "A warning about the input (G-code, DXF or CSV front end: `pvtc::gcode::…`)."
);
pyo3::create_exception!(
    pvtc,
    PlanWarning,
    PvtcWarning,
    "A warning about planning (`pvtc::plan::…`)."
);
pyo3::create_exception!(
    pvtc,
    OutputWarning,
    PvtcWarning,
    "A warning about the output format (`pvtc::emit::…`, `pvtc::pmac::…`)."
);

/// One diagnostic as Python sees it: the fields of `--diagnostics json`.
#[pyclass(module = "pvtc", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Diagnostic {
    /// The stable code, e.g. `pvtc::gcode::unknown_word`.
    pub code: Option<String>,
    /// `error`, `warning` or `advice` (a note).
    pub severity: String,
    /// What is wrong.
    pub message: String,
    /// The input's name, where the diagnostic points into it.
    pub path: Option<String>,
    /// 1-based line, where known.
    pub line: Option<u32>,
    /// 1-based column, where known.
    pub column: Option<u32>,
    /// How to fix it, where pvtc knows.
    pub help: Option<String>,
    /// How many times it occurs (repeats of one code are one diagnostic).
    pub count: usize,
}

#[pymethods]
impl Diagnostic {
    fn __repr__(&self) -> String {
        format!(
            "Diagnostic(code={:?}, severity={:?}, message={:?}, path={:?}, line={:?}, column={:?})",
            self.code.as_deref().unwrap_or(""),
            self.severity,
            self.message,
            self.path.as_deref().unwrap_or(""),
            self.line,
            self.column
        )
    }

    fn __str__(&self) -> String {
        let at = match (&self.path, self.line) {
            (Some(p), Some(l)) => format!("{p}:{l}: "),
            _ => String::new(),
        };
        let code = self.code.as_deref().unwrap_or("pvtc");
        format!("{at}{} [{code}]", self.message)
    }
}

impl Diagnostic {
    /// A diagnostic from one object of `--diagnostics json`.
    pub fn from_json(value: &serde_json::Value) -> Diagnostic {
        let text = |key: &str| value.get(key).and_then(|v| v.as_str()).map(str::to_owned);
        let number = |key: &str| {
            value
                .get(key)
                .and_then(serde_json::Value::as_u64)
                .and_then(|n| u32::try_from(n).ok())
        };
        Diagnostic {
            code: text("code"),
            severity: text("severity").unwrap_or_else(|| "error".into()),
            message: text("message").unwrap_or_default(),
            path: text("file"),
            line: number("line"),
            column: number("column"),
            help: text("help"),
            count: value
                .get("count")
                .and_then(serde_json::Value::as_u64)
                .map_or(1, |n| n as usize),
        }
    }

    /// The diagnostics of `reports`, repeats grouped, as the CLI prints them.
    pub fn all(reports: &[miette::Report]) -> Vec<Diagnostic> {
        pvtc::embed::diagnostics(reports)
            .iter()
            .map(Diagnostic::from_json)
            .collect()
    }
}

/// Replaces each `--flag-name` of a CLI message by the keyword `flag_name`.
pub fn keyword_words(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let len = after
            .find(|c: char| !(c.is_ascii_lowercase() || c == '-'))
            .unwrap_or(after.len());
        if len == 0 {
            out.push_str("--");
        } else {
            out.push_str(&crate::options::keyword_of(&after[..len]));
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    out
}

/// `failure` as the exception Python raises for it.
pub fn raise(py: Python<'_>, failure: Failure) -> PyErr {
    match failure {
        Failure::Usage(message) => PyValueError::new_err(keyword_words(&message)),
        Failure::Io {
            path,
            action,
            error,
        } => {
            let text = format!("cannot {action} {}: {error}", path.display());
            let errno = error.raw_os_error().unwrap_or(0);
            let args = (errno, text, path.display().to_string());
            match error.kind() {
                std::io::ErrorKind::NotFound => {
                    pyo3::exceptions::PyFileNotFoundError::new_err(args)
                }
                std::io::ErrorKind::PermissionDenied => {
                    pyo3::exceptions::PyPermissionError::new_err(args)
                }
                _ => PyOSError::new_err(args),
            }
        }
        Failure::Input(reports) => compile_error(py, Diagnostic::all(&reports)),
    }
}

/// A `CompileError` holding `diagnostics`; its message is the first's.
pub fn compile_error(py: Python<'_>, diagnostics: Vec<Diagnostic>) -> PyErr {
    let message = match diagnostics.as_slice() {
        [] => "the input was refused".to_string(),
        [one] => one.__str__(),
        [first, rest @ ..] => format!("{} (and {} more)", first.__str__(), rest.len()),
    };
    let err = CompileError::new_err(message);
    let list = diagnostics
        .into_iter()
        .map(|d| Py::new(py, d))
        .collect::<PyResult<Vec<_>>>()
        .and_then(|items| PyList::new(py, items));
    match list.and_then(|list| err.value(py).setattr("diagnostics", list)) {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// The warning category of a code: input, plan or output, else pvtc's own.
fn category<'py>(py: Python<'py>, code: &str) -> Bound<'py, pyo3::types::PyType> {
    let area = code.split("::").nth(1).unwrap_or("");
    match area {
        "gcode" | "dxf" | "csv" | "input" => py.get_type::<InputWarning>(),
        "plan" => py.get_type::<PlanWarning>(),
        "emit" | "pmac" => py.get_type::<OutputWarning>(),
        _ => py.get_type::<PvtcWarning>(),
    }
}

/// Issues every warning among `diagnostics` through Python's `warnings` (each repeated
/// one once, with its count in the message), at the caller's line; notes are not
/// issued.
pub fn warn_all(py: Python<'_>, diagnostics: &[Diagnostic]) -> PyResult<()> {
    let warnings = py.import("warnings")?;
    for d in diagnostics.iter().filter(|d| d.severity == "warning") {
        let code = d.code.clone().unwrap_or_default();
        let instance = category(py, &code).call1((d.__str__(),))?;
        instance.setattr("diagnostic", Py::new(py, d.clone())?)?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("stacklevel", 1)?;
        warnings.call_method("warn", (instance,), Some(&kwargs))?;
    }
    Ok(())
}

/// Runs `work`, turning a Rust panic into `InternalError` (nothing panics across the
/// boundary).
pub fn guard<T>(work: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
        Ok(result) => result,
        Err(payload) => Err(internal(payload.as_ref())),
    }
}

/// `InternalError` for a panic's payload.
pub fn internal(payload: &(dyn std::any::Any + Send)) -> PyErr {
    let message = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".into());
    InternalError::new_err(format!(
        "pvtc hit a bug ({message}); please report it with the input and options"
    ))
}
