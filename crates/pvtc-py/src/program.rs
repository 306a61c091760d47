//! `pvtc.Program`: a planned program as numpy arrays, no Python object per piece, and
//! what can be done with it: written in any format as `pvtc compile` writes it, and
//! sampled at a servo period.
//!
//! Owns the arrays (handed over from Rust without a copy and made read-only, so that
//! the program written is the program planned) and the plan they came from (the
//! options as command-line words, the format planned for, the input to read again). It
//! must not write or plan by itself: [`pvtc::embed`] and the route do.

use crate::errors::{guard, raise, warn_all, Diagnostic};
use crate::options::{Request, Scope};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pvtc::embed::{Outline, Pieces, PiecesView};
use pvtc::{CompileOptions, Failure, Source};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;

/// Where a program's input is, to read it again (to write it planned otherwise, or for
/// the geometry `check` measures the path error from).
#[derive(Debug, Clone)]
pub enum Origin {
    /// A file.
    File(PathBuf),
    /// Text held in memory: a `pvtc.Text`, or the CSV of `from_points`.
    Held(Source),
    /// A chunk of a stream: nothing to read again.
    Chunk,
}

/// How a program was planned.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The options asked for.
    pub request: Request,
    /// The format planned for (its grid and checks).
    pub format: String,
    /// The input's name in diagnostics and headers.
    pub name: String,
    /// Where the input is.
    pub origin: Origin,
    /// The options, resolved.
    pub options: CompileOptions,
}

/// A planned program: per piece `t` (durations, s), `p` and `v` (end positions and
/// velocities, one column per axis), `line` (source line) and `contour` (contour index),
/// with `start` (where the axes are before the first piece), `axes`, `kind` (`"feed"` or
/// `"rapid"` per contour), `units` and `total_time`. The arrays are read-only numpy
/// arrays handed over without a copy.
#[pyclass(module = "pvtc", frozen)]
pub struct Program {
    t: Py<PyArray1<f64>>,
    p: Py<PyArray2<f64>>,
    v: Py<PyArray2<f64>>,
    line: Py<PyArray1<u32>>,
    contour: Py<PyArray1<u32>>,
    outline: Outline,
    total_time: f64,
    pub(crate) plan: Plan,
    diagnostics: Vec<Diagnostic>,
}

/// `array` made read-only.
fn frozen<'py, T>(array: Bound<'py, T>) -> PyResult<Py<T>> {
    let kwargs = PyDict::new(array.py());
    kwargs.set_item("write", false)?;
    array.as_any().call_method("setflags", (), Some(&kwargs))?;
    Ok(array.unbind())
}

impl Program {
    /// The program of `pieces` (their vectors become the arrays, uncopied).
    pub fn new(
        py: Python<'_>,
        pieces: Pieces,
        plan: Plan,
        diagnostics: Vec<Diagnostic>,
    ) -> PyResult<Program> {
        let dim = pieces.outline.axes.len();
        let n = pieces.durations.len();
        let total_time = pieces.durations.iter().sum();
        let matrix = |flat: Vec<f64>| {
            Array2::from_shape_vec((n, dim), flat).map_err(|e| PyValueError::new_err(e.to_string()))
        };
        Ok(Program {
            t: frozen(PyArray1::from_vec(py, pieces.durations))?,
            p: frozen(matrix(pieces.ends)?.into_pyarray(py))?,
            v: frozen(matrix(pieces.velocities)?.into_pyarray(py))?,
            line: frozen(PyArray1::from_vec(py, pieces.lines))?,
            contour: frozen(PyArray1::from_vec(py, pieces.contour_of))?,
            outline: pieces.outline,
            total_time,
            plan,
            diagnostics,
        })
    }

    /// Runs `work` on the pieces, borrowed from the arrays.
    pub fn with_view<T>(
        &self,
        py: Python<'_>,
        work: impl FnOnce(PiecesView<'_>) -> T,
    ) -> PyResult<T> {
        let (t, p, v, line) = (
            self.t.bind(py).readonly(),
            self.p.bind(py).readonly(),
            self.v.bind(py).readonly(),
            self.line.bind(py).readonly(),
        );
        let view = PiecesView {
            durations: slice(t.as_slice())?,
            ends: slice(p.as_slice())?,
            velocities: slice(v.as_slice())?,
            lines: slice(line.as_slice())?,
            outline: &self.outline,
        };
        Ok(work(view))
    }

    /// The program as pvt-core's, for checking and sampling; a `ValueError` for a chunk
    /// that starts in motion.
    pub fn whole(&self, py: Python<'_>, what: &str) -> PyResult<pvt_core::PvtProgram> {
        self.with_view(py, |view| view.program())?.ok_or_else(|| {
            PyValueError::new_err(format!(
                "this chunk starts in motion (inside contour {}): it is not a program of its \
                 own, so it cannot be {what}; feed its arrays to the controller's buffer, or \
                 {what} the whole program",
                self.outline.first_contour
            ))
        })
    }

    /// The source read again, where there is one.
    pub fn source(&self) -> Result<Option<Source>, Failure> {
        match &self.plan.origin {
            Origin::File(path) => Source::read(path).map(Some),
            Origin::Held(source) => Ok(Some(source.clone())),
            Origin::Chunk => Ok(None),
        }
    }

    /// The bytes of `options.format`, as `pvtc compile` writes them.
    fn bytes(&self, py: Python<'_>, options: &CompileOptions) -> PyResult<Vec<u8>> {
        let o = &self.outline;
        let same = pvtc::embed::same_plan(&self.plan.options, options, o.units, &o.axes)
            .map_err(|f| raise(py, f))?;
        if same {
            if o.starts_in_motion() {
                self.whole(py, "written")?;
            }
            let name = &self.plan.name;
            let written = self.with_view(py, |view| {
                py.detach(|| pvtc::embed::write_pieces(view, name, options))
            })?;
            return written.map_err(|f| raise(py, f));
        }
        let Some(source) = self.source().map_err(|f| raise(py, f))? else {
            return Err(PyValueError::new_err(format!(
                "this chunk was planned for {}, and {} plans differently (piece-time grid, \
                 longest piece or header): stream with format={:?}",
                self.plan.format,
                options.format.name(),
                options.format.name()
            )));
        };
        let compiled = py
            .detach(|| pvtc::compile(&source, options))
            .map_err(|f| raise(py, f))?;
        warn_all(py, &Diagnostic::all(&compiled.warnings))?;
        Ok(compiled.bytes)
    }
}

#[pymethods]
impl Program {
    /// Piece durations, seconds, shape (N,).
    #[getter]
    fn t(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.t.clone_ref(py)
    }

    /// End position of every piece, shape (N, axes).
    #[getter]
    fn p(&self, py: Python<'_>) -> Py<PyArray2<f64>> {
        self.p.clone_ref(py)
    }

    /// End velocity of every piece, units/s, shape (N, axes).
    #[getter]
    fn v(&self, py: Python<'_>) -> Py<PyArray2<f64>> {
        self.v.clone_ref(py)
    }

    /// Source line of every piece, shape (N,) (for `from_points`, point i is line i + 2).
    #[getter]
    fn line(&self, py: Python<'_>) -> Py<PyArray1<u32>> {
        self.line.clone_ref(py)
    }

    /// Index of every piece's contour in the whole program, shape (N,).
    #[getter]
    fn contour(&self, py: Python<'_>) -> Py<PyArray1<u32>> {
        self.contour.clone_ref(py)
    }

    /// Where the axes are before the first piece, shape (axes,).
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let dim = self.outline.axes.len();
        let start = self
            .outline
            .contours
            .first()
            .map_or_else(|| vec![0.0; dim], |c| c.start.clone());
        PyArray1::from_vec(py, start)
    }

    /// Velocities before the first piece, shape (axes,): zero, but for a chunk of a
    /// stream that starts inside a contour.
    #[getter]
    fn start_velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.outline.start_velocity.clone())
    }

    /// The axes, in X Y Z A B C order, as a tuple of names.
    #[getter]
    fn axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, self.outline.axes.iter().map(|a| a.to_string()))
    }

    /// `"feed"` or `"rapid"` for each contour of this program (contour
    /// `first_contour + i` of the whole program for `kind[i]`).
    #[getter]
    fn kind<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, self.outline.contours.iter().map(|c| c.motion.name()))
    }

    /// Index of this program's first contour in the whole program (0 but for a chunk).
    #[getter]
    fn first_contour(&self) -> usize {
        self.outline.first_contour
    }

    /// Units of the linear positions: `"mm"` or `"in"` (rotary axes: degrees).
    #[getter]
    fn units(&self) -> &'static str {
        self.outline.units.name()
    }

    /// `"pvt"` (cubic pieces through positions and velocities) or `"pt"` (straight pieces).
    #[getter]
    fn interpolation(&self) -> &'static str {
        match self.outline.interpolation {
            pvt_core::Interpolation::Pvt => "pvt",
            pvt_core::Interpolation::Pt => "pt",
        }
    }

    /// The sum of the piece durations, seconds.
    #[getter]
    fn total_time(&self) -> f64 {
        self.total_time
    }

    /// The output format the program was planned for (its piece-time grid and checks).
    #[getter]
    fn format(&self) -> &str {
        &self.plan.format
    }

    /// The input's name, as diagnostics and output headers give it.
    #[getter]
    fn source_name(&self) -> &str {
        &self.plan.name
    }

    /// The warnings and notes planning gave (the warnings also went through
    /// `warnings.warn`).
    #[getter]
    fn diagnostics(&self) -> Vec<Diagnostic> {
        self.diagnostics.clone()
    }

    /// Number of pieces.
    fn __len__(&self) -> usize {
        self.outline_len()
    }

    fn __repr__(&self) -> String {
        let axes: Vec<String> = self.outline.axes.iter().map(|a| a.to_string()).collect();
        format!(
            "<pvtc.Program {} pieces on {} in {}, {:.6} s, planned for {}>",
            self.outline_len(),
            axes.join(" "),
            self.outline.units.name(),
            self.total_time,
            self.plan.format
        )
    }

    /// Writes the program in `format` (by default the one it was planned for) exactly as
    /// `pvtc compile --format FORMAT` writes it with the same options: into the file at
    /// `path` (replaced whole, or left untouched on failure), or returned as a str.
    /// `format_options` are `pvtc compile`'s output options: `pmac_program`,
    /// `pmac_coord`, `pmac_axis`, `pmac_rotary`, `pmac_events`, `trigger_every`.
    #[pyo3(signature = (format=None, path=None, **format_options))]
    fn write(
        &self,
        py: Python<'_>,
        format: Option<String>,
        path: Option<&Bound<'_, PyAny>>,
        format_options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Option<String>> {
        guard(|| {
            let mut request = self.plan.request.clone();
            request.format = Some(format.unwrap_or_else(|| self.plan.format.clone()));
            request.add(format_options, Scope::Write)?;
            let options = request.compile_options(py, &self.plan.name)?;
            let bytes = self.bytes(py, &options)?;
            match path {
                Some(path) => {
                    let path = crate::options::path("path", path)?;
                    pvtc::output::write_file(std::path::Path::new(&path), &bytes)
                        .map_err(|f| raise(py, f))?;
                    Ok(None)
                }
                None => String::from_utf8(bytes)
                    .map(Some)
                    .map_err(|e| PyValueError::new_err(e.to_string())),
            }
        })
    }

    /// The motion every `period` seconds from the start to the end, evaluated from the
    /// same cubics the controller builds: `(time, position, velocity, acceleration)`,
    /// shapes (n,), (n, axes), (n, axes), (n, axes).
    fn sample<'py>(&self, py: Python<'py>, period: f64) -> PyResult<Bound<'py, PyTuple>> {
        guard(|| {
            if !(period.is_finite() && period > 0.0) {
                return Err(PyValueError::new_err(format!(
                    "period must be a finite number of seconds greater than zero, not {period}"
                )));
            }
            let samples = self.total_time / period;
            if samples > MAX_SAMPLES {
                return Err(PyValueError::new_err(format!(
                    "period {period} s samples the {} s program {samples:.3e} times, over \
                     {MAX_SAMPLES:e}: give a longer period",
                    self.total_time
                )));
            }
            let program = self.whole(py, "sampled")?;
            let s = py.detach(|| pvt_emit::plot::sample_every(&program, period));
            let n = s.len();
            let dim = s.dim;
            let matrix = |flat: Vec<f64>| {
                Array2::from_shape_vec((n, dim), flat)
                    .map(|a| a.into_pyarray(py))
                    .map_err(|e| PyValueError::new_err(e.to_string()))
            };
            let time = PyArray1::from_vec(py, s.time).into_any();
            let position = matrix(s.position)?.into_any();
            let velocity = matrix(s.velocity)?.into_any();
            let acceleration = matrix(s.acceleration)?.into_any();
            PyTuple::new(py, [time, position, velocity, acceleration])
        })
    }
}

/// A numpy array's data, or why it is not one slice.
fn slice<T>(data: Result<&[T], numpy::AsSliceError>) -> PyResult<&[T]> {
    data.map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Most samples [`Program::sample`] makes.
const MAX_SAMPLES: f64 = 1e8;

impl Program {
    fn outline_len(&self) -> usize {
        Python::attach(|py| self.t.bind(py).len().unwrap_or(0))
    }
}
