//! pvtc from Python: the extension module `pvtc` (PyO3, an abi3 wheel built by maturin
//! from `pyproject.toml`).
//!
//! Owns the Python names: `plan`, `from_points`, `check` ([`report`]), `stream`
//! ([`chunks`]), `Program` ([`program`]), `Text`, the keyword options ([`options`]) and
//! the exceptions and warnings ([`errors`]). Every call goes through the same library
//! code as the `pvtc` command ([`pvtc::embed`], the route, the settings, the CLI's own
//! option parser); this crate must not parse a format, plan, check or write by itself.
//! Nothing panics across the boundary ([`errors::guard`]).

mod chunks;
mod errors;
mod options;
mod program;
mod report;

use errors::{guard, raise, warn_all, Diagnostic};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use options::{Request, Scope};
use program::{Origin, Plan, Program};
use pvtc::Source;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;

/// Source text held in memory: `kind` is `"gcode"`, `"dxf"` or `"csv"`; `name` is what
/// diagnostics and output headers call it.
#[pyclass(module = "pvtc", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Text {
    /// The text.
    pub text: String,
    /// `"gcode"`, `"dxf"` or `"csv"`.
    pub kind: String,
    /// The name diagnostics and headers use.
    pub name: String,
}

#[pymethods]
impl Text {
    #[new]
    #[pyo3(signature = (text, kind="gcode", name="<text>"))]
    fn new(text: String, kind: &str, name: &str) -> PyResult<Text> {
        if !matches!(kind, "gcode" | "dxf" | "csv") {
            return Err(PyValueError::new_err(format!(
                "kind must be \"gcode\", \"dxf\" or \"csv\", not {kind:?}"
            )));
        }
        Ok(Text {
            text,
            kind: kind.into(),
            name: name.into(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Text(<{} characters>, kind={:?}, name={:?})",
            self.text.len(),
            self.kind,
            self.name
        )
    }
}

/// A source as given: a file, or text held.
pub enum Input {
    /// A file, with the name it is given by.
    File {
        /// Where it is.
        path: PathBuf,
        /// As given.
        name: String,
    },
    /// Text in memory.
    Held(Source),
}

impl Input {
    /// The source `value` (a path, or a `Text` whose kind is added to `request`).
    pub fn of(value: &Bound<'_, PyAny>, request: &mut Request) -> PyResult<Input> {
        if let Ok(text) = value.cast::<Text>() {
            let text = text.get();
            if !request
                .words
                .iter()
                .any(|w| w.starts_with("--input-format="))
            {
                request.words.push(format!("--input-format={}", text.kind));
            }
            return Ok(Input::Held(Source::from_text(&text.name, &text.text)));
        }
        if value.is_instance_of::<PyString>() || value.hasattr("__fspath__")? {
            let name = options::path("source", value)?;
            return Ok(Input::File {
                path: PathBuf::from(&name),
                name,
            });
        }
        Err(PyTypeError::new_err(
            "source must be a path (str or os.PathLike) or pvtc.Text(text, kind)",
        ))
    }

    /// The name diagnostics and headers use.
    pub fn name(&self) -> &str {
        match self {
            Input::File { name, .. } => name,
            Input::Held(source) => &source.name,
        }
    }

    /// How a program of this input is planned under `request`, resolved as `options`.
    fn plan(&self, request: Request, options: pvtc::CompileOptions) -> Plan {
        Plan {
            format: options.format.name().to_string(),
            name: self.name().to_string(),
            origin: match self {
                Input::File { path, .. } => Origin::File(path.clone()),
                Input::Held(source) => Origin::Held(source.clone()),
            },
            options,
            request,
        }
    }
}

/// Plans `input` with `request`: the pieces, warnings issued, as a `Program`.
fn plan_input(py: Python<'_>, input: Input, request: Request) -> PyResult<Program> {
    let options = request.compile_options(py, input.name())?;
    let planned = py.detach(|| match &input {
        Input::File { path, name } if pvtc::embed::streams(&options) => {
            pvtc::embed::plan_file(path, name, &options)
        }
        Input::File { path, .. } => {
            Source::read(path).and_then(|source| pvtc::embed::plan_source(&source, &options))
        }
        Input::Held(source) => pvtc::embed::plan_source(source, &options),
    });
    let (pieces, warnings) = planned.map_err(|f| raise(py, f))?;
    let diagnostics = Diagnostic::all(&warnings);
    warn_all(py, &diagnostics)?;
    Program::new(py, pieces, input.plan(request, options), diagnostics)
}

/// Plans `source` (a path, str or `os.PathLike`, or `pvtc.Text(text, kind)`) into a
/// `Program`, as `pvtc compile` plans it. `options` are the CLI's options with the same
/// names (`_` for `-`) and defaults: `planner`, `machine` (a path, or a dict shaped as
/// the TOML file), `tolerance`, `quantize` (seconds, or `None` for off), `feed`,
/// `rapid`, `units`, `offsets`, `tool_table`, `layers`, `format` (the output format
/// planned for, default `"pmac"`: its piece-time grid and checks), ... A G-code file
/// streams: memory is the arrays and the CLI's streaming bound.
#[pyfunction]
#[pyo3(signature = (source, **options))]
fn plan(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Program> {
    guard(|| {
        let mut request = Request::default();
        request.add(options, Scope::Plan)?;
        let input = Input::of(source, &mut request)?;
        plan_input(py, input, request)
    })
}

/// A float64 array of `value` with `columns` columns (a 1-D array for one column is
/// taken as such), and its rows.
fn columns(value: &Bound<'_, PyAny>, key: &str, columns: usize) -> PyResult<(Vec<f64>, usize)> {
    let np = value.py().import("numpy")?;
    let array = np
        .call_method1("ascontiguousarray", (value, "float64"))
        .map_err(|e| PyTypeError::new_err(format!("{key} must be an array of numbers: {e}")))?;
    let array = array.cast::<PyArrayDyn<f64>>()?;
    let shape = array.shape().to_vec();
    let rows = match shape.as_slice() {
        [n] if columns == 1 => *n,
        [n, c] if *c == columns => *n,
        _ => {
            return Err(PyValueError::new_err(format!(
                "{key} must have shape (N, {columns}), not {shape:?}"
            )))
        }
    };
    let values = array.readonly().as_slice()?.to_vec();
    Ok((values, rows))
}

/// The CSV the point-time front end reads, of these columns.
fn series_csv(
    axes: &[String],
    times: &[f64],
    positions: &[f64],
    velocities: Option<&[f64]>,
) -> String {
    let dim = axes.len();
    let mut header = vec!["t".to_string()];
    header.extend(axes.iter().cloned());
    if velocities.is_some() {
        header.extend(axes.iter().map(|a| format!("v{}", a.to_ascii_lowercase())));
    }
    let mut csv = header.join(",") + "\n";
    for (i, t) in times.iter().enumerate() {
        let mut row = vec![format!("{t}")];
        row.extend(
            positions[i * dim..(i + 1) * dim]
                .iter()
                .map(|x| format!("{x}")),
        );
        if let Some(v) = velocities {
            row.extend(v[i * dim..(i + 1) * dim].iter().map(|x| format!("{x}")));
        }
        csv.push_str(&row.join(","));
        csv.push('\n');
    }
    csv
}

/// Plans a point-time series from numpy arrays, as `pvtc compile` plans the same
/// points in a CSV file (the fly-scan case): `positions` (N, axes), `times` (N,)
/// absolute seconds, `velocities` (N, axes) or `None`. Diagnostics name point i as
/// line i + 2 of that CSV (its header is line 1).
#[pyfunction]
#[pyo3(signature = (positions, times, velocities=None, *, axes=vec!["X".to_string(), "Y".to_string()], planner="spline", **options))]
fn from_points(
    py: Python<'_>,
    positions: &Bound<'_, PyAny>,
    times: &Bound<'_, PyAny>,
    velocities: Option<&Bound<'_, PyAny>>,
    axes: Vec<String>,
    planner: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Program> {
    guard(|| {
        for axis in &axes {
            let one = axis.len() == 1 && "XYZABCxyzabc".contains(axis.as_str());
            if !one {
                return Err(PyValueError::new_err(format!(
                    "axes must name X, Y, Z, A, B or C, not {axis:?}"
                )));
            }
        }
        let dim = axes.len();
        let (p, n) = columns(positions, "positions", dim)?;
        let (t, m) = columns(times, "times", 1)?;
        if m != n {
            return Err(PyValueError::new_err(format!(
                "times has {m} values for {n} positions"
            )));
        }
        let v = match velocities {
            Some(v) => {
                let (v, k) = columns(v, "velocities", dim)?;
                if k != n {
                    return Err(PyValueError::new_err(format!(
                        "velocities has {k} rows for {n} positions"
                    )));
                }
                Some(v)
            }
            None => None,
        };
        let csv = series_csv(&axes, &t, &p, v.as_deref());
        let mut request = Request::default();
        let given = PyDict::new(py);
        given.set_item("planner", planner)?;
        request.add(Some(&given), Scope::Plan)?;
        request.add(options, Scope::Plan)?;
        request.words.push("--input-format=csv".into());
        plan_input(
            py,
            Input::Held(Source::from_text("<points>", &csv)),
            request,
        )
    })
}

/// Plans `source` in chunks of at most `chunk` pieces, yielded as `Program`s while
/// planning goes on (a G-code file in constant memory; at most two chunks are held),
/// each starting where the last ended. `source` is a path, a `pvtc.Text` (planned with
/// `options`, as `plan` plans) or a `Program` (cut into chunks). A failure raises from
/// the iteration, after the chunks before it.
#[pyfunction]
#[pyo3(signature = (source, chunk=4000, **options))]
fn stream(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    chunk: i64,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<chunks::Chunks> {
    guard(|| {
        let chunk = chunks::chunk_size(chunk)?;
        if let Ok(program) = source.cast::<Program>() {
            if options.is_some_and(|o| !o.is_empty()) {
                return Err(PyTypeError::new_err(
                    "a Program is planned already: planning options go to pvtc.plan",
                ));
            }
            let program = program.get();
            let pieces = program.with_view(py, owned)?;
            return Ok(chunks::Chunks::start(program.plan.clone(), move |sink| {
                pvtc::embed::chunk_pieces(pieces.view(), chunk, Box::new(sink));
                Ok(Vec::new())
            }));
        }
        let mut request = Request::default();
        request.add(options, Scope::Plan)?;
        let input = Input::of(source, &mut request)?;
        let options = request.compile_options(py, input.name())?;
        let plan = input.plan(request, options.clone());
        Ok(chunks::Chunks::start(plan, move |sink| match &input {
            Input::File { path, name } if pvtc::embed::streams(&options) => {
                pvtc::embed::stream_file(path, name, &options, chunk, Box::new(sink))
            }
            Input::File { path, .. } => {
                let source = Source::read(path)?;
                let (pieces, warnings) = pvtc::embed::plan_source(&source, &options)?;
                pvtc::embed::chunk_pieces(pieces.view(), chunk, Box::new(sink));
                Ok(warnings)
            }
            Input::Held(source) => {
                let (pieces, warnings) = pvtc::embed::plan_source(source, &options)?;
                pvtc::embed::chunk_pieces(pieces.view(), chunk, Box::new(sink));
                Ok(warnings)
            }
        }))
    })
}

/// Borrowed pieces, owned.
fn owned(view: pvtc::embed::PiecesView<'_>) -> pvtc::embed::Pieces {
    pvtc::embed::Pieces {
        durations: view.durations.to_vec(),
        ends: view.ends.to_vec(),
        velocities: view.velocities.to_vec(),
        lines: view.lines.to_vec(),
        contour_of: Vec::new(),
        outline: view.outline.clone(),
    }
}

/// Panics inside the boundary, for the test that proves a panic raises
/// `pvtc.InternalError` (not part of the API).
#[pyfunction]
fn _panic_inside(message: &str) -> PyResult<()> {
    guard(|| panic!("{message}"))
}

/// pvtc from Python: plan G-code, DXF drawings and point-time series into PVT motion as
/// numpy arrays (`plan`, `from_points`, `stream`), check it (`check`) and write it in
/// any controller's format (`Program.write`), with the `pvtc` command's own library.
#[pymodule(name = "pvtc")]
fn pvtc_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(from_points, m)?)?;
    m.add_function(wrap_pyfunction!(report::check, m)?)?;
    m.add_function(wrap_pyfunction!(stream, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_inside, m)?)?;
    m.add_class::<Text>()?;
    m.add_class::<Program>()?;
    m.add_class::<Diagnostic>()?;
    m.add_class::<report::Report>()?;
    m.add_class::<report::Peak>()?;
    m.add_class::<report::Violation>()?;
    m.add_class::<chunks::Chunks>()?;
    m.add("PvtcError", py.get_type::<errors::PvtcError>())?;
    m.add("CompileError", py.get_type::<errors::CompileError>())?;
    m.add("InternalError", py.get_type::<errors::InternalError>())?;
    m.add("PvtcWarning", py.get_type::<errors::PvtcWarning>())?;
    m.add("InputWarning", py.get_type::<errors::InputWarning>())?;
    m.add("PlanWarning", py.get_type::<errors::PlanWarning>())?;
    m.add("OutputWarning", py.get_type::<errors::OutputWarning>())?;
    Ok(())
}
