//! `pvtc.check`: what a program's motion will do, as data: the report `pvtc check
//! --json` prints, with the piece each peak happens in.
//!
//! Owns the Python shape of the report ([`Report`], [`Peak`], [`Violation`]) and which
//! program and geometry are checked (a `Program` with its input read again, or a source
//! planned as `pvtc check` plans it). It must not compute a number of the check:
//! pvt-core's check does, through the CLI's `commands::verify`.

use crate::errors::{guard, raise, warn_all, Diagnostic};
use crate::options::{Request, Scope};
use crate::program::Program;
use pvtc::commands::verify::{self, Given};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A peak value with where it happens: `time` (s from the start), `piece` (index of
/// the piece running then, into the program's arrays) and the source `line`.
#[pyclass(module = "pvtc", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Peak {
    /// The value (absolute for an axis quantity).
    pub value: f64,
    /// Seconds from the start of the motion.
    pub time: f64,
    /// Index of the piece running then (the last one starting at or before `time`).
    pub piece: usize,
    /// Source line of that piece (0 where unknown).
    pub line: u32,
}

#[pymethods]
impl Peak {
    fn __repr__(&self) -> String {
        format!(
            "Peak(value={}, time={}, piece={}, line={})",
            self.value, self.time, self.piece, self.line
        )
    }
}

/// A limit exceeded: `axis`, `quantity` (`velocity`, `acceleration`, `jerk`, …), the
/// `value` reached, the `limit`, and where (`time`, `piece`, `line`).
#[pyclass(module = "pvtc", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Violation {
    /// Axis name.
    pub axis: String,
    /// The quantity over its limit.
    pub quantity: String,
    /// The value reached.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// Seconds from the start.
    pub time: f64,
    /// Index of the piece running then.
    pub piece: usize,
    /// Source line.
    pub line: u32,
}

#[pymethods]
impl Violation {
    fn __repr__(&self) -> String {
        format!(
            "Violation(axis={:?}, quantity={:?}, value={}, limit={}, time={}, piece={}, line={})",
            self.axis, self.quantity, self.value, self.limit, self.time, self.piece, self.line
        )
    }
}

/// What a program's motion will do: `total_time`, `servo_period`, per axis the `peaks`
/// (`peaks["X"]["velocity"]` is a `Peak`; also `acceleration`, `jerk`,
/// `acceleration_step`, `sampled_velocity`, `sampled_acceleration`), the `violations`
/// of the limits, the `path_error` (a `Peak`, `None` without source geometry) and
/// `max_path_error`, the vector `speed` against the feed, and `exceeded`.
/// `as_dict()` is the object `pvtc check --json` prints.
#[pyclass(module = "pvtc", frozen, get_all)]
pub struct Report {
    /// Seconds of motion.
    pub total_time: f64,
    /// The servo period sampled at, seconds.
    pub servo_period: f64,
    /// The largest distance from the source geometry, or `None`.
    pub max_path_error: Option<f64>,
    /// Where that distance is, or `None`.
    pub path_error: Option<Peak>,
    /// Axis name → quantity → `Peak`.
    pub peaks: Py<PyDict>,
    /// The vector speed (`min` and `max` as `Peak`s, `rms_error`, `samples`), or `None`.
    pub speed: Option<Py<PyDict>>,
    /// Every limit exceeded.
    pub violations: Vec<Violation>,
    /// True when a limit is exceeded.
    pub exceeded: bool,
    json: String,
}

#[pymethods]
impl Report {
    /// The report as `pvtc check --json` prints it (a dict of plain values).
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (&self.json,))
    }

    fn __repr__(&self) -> String {
        format!(
            "<pvtc.Report {:.6} s, {} limit(s) exceeded, path error {}>",
            self.total_time,
            self.violations.len(),
            self.max_path_error
                .map_or_else(|| "unknown".to_string(), |e| format!("{e}"))
        )
    }
}

/// Where each piece is in time and source: its start (summed as the check sums
/// them) and its line.
struct Pieces {
    starts: Vec<f64>,
    lines: Vec<u32>,
}

impl Pieces {
    fn of(program: &pvt_core::PvtProgram) -> Pieces {
        let mut clock = 0.0;
        let mut starts = Vec::with_capacity(program.segment_count());
        for d in program.contours.iter().flat_map(|c| c.durations.iter()) {
            starts.push(clock);
            clock += d;
        }
        let lines = program
            .contours
            .iter()
            .flat_map(|c| c.lines.iter().copied())
            .collect();
        Pieces { starts, lines }
    }

    /// The piece a peak at `time` on source `line` happens in: the last one starting at
    /// or before it, or at a knot the one ending there when the check names its line.
    fn at(&self, time: f64, line: u32) -> usize {
        let i = self
            .starts
            .partition_point(|s| *s <= time)
            .saturating_sub(1);
        let at_knot = i > 0 && self.starts[i] == time;
        match at_knot && self.lines[i] != line && self.lines[i - 1] == line {
            true => i - 1,
            false => i,
        }
    }
}

fn source_line(value: &serde_json::Value) -> u32 {
    value
        .get("line")
        .and_then(serde_json::Value::as_u64)
        .map_or(0, |l| l as u32)
}

fn peak(value: &serde_json::Value, pieces: &Pieces) -> Option<Peak> {
    let number = |k: &str| value.get(k).and_then(serde_json::Value::as_f64);
    let time = number("time")?;
    let line = source_line(value);
    Some(Peak {
        value: number("value")?,
        time,
        piece: pieces.at(time, line),
        line,
    })
}

/// The report of `json` (`pvtc check --json`'s object) on a program of `pieces`.
fn report(py: Python<'_>, json: &serde_json::Value, pieces: &Pieces) -> PyResult<Report> {
    let peaks = PyDict::new(py);
    if let Some(axes) = json["peaks"].as_object() {
        for (axis, value) in axes {
            let quantities = PyDict::new(py);
            if let Some(at) = value["at"].as_object() {
                for (quantity, p) in at {
                    if let Some(p) = peak(p, pieces) {
                        quantities.set_item(quantity, Py::new(py, p)?)?;
                    }
                }
            }
            peaks.set_item(axis, quantities)?;
        }
    }
    let speed = match json["speed"].as_object() {
        None => None,
        Some(s) => {
            let d = PyDict::new(py);
            for key in ["min", "max"] {
                if let Some(p) = peak(&s[key], pieces) {
                    d.set_item(key, Py::new(py, p)?)?;
                }
            }
            d.set_item("rms_error", s["rms_error"].as_f64())?;
            d.set_item("samples", s["samples"].as_u64())?;
            Some(d.unbind())
        }
    };
    let violations = json["violations"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|v| {
            let time = v["time"].as_f64().unwrap_or(0.0);
            let line = source_line(v);
            Violation {
                axis: v["axis"].as_str().unwrap_or("").into(),
                quantity: v["quantity"].as_str().unwrap_or("").into(),
                value: v["value"].as_f64().unwrap_or(f64::NAN),
                limit: v["limit"].as_f64().unwrap_or(f64::NAN),
                time,
                piece: pieces.at(time, line),
                line,
            }
        })
        .collect();
    Ok(Report {
        total_time: json["total_time"].as_f64().unwrap_or(0.0),
        servo_period: json["servo_period"].as_f64().unwrap_or(0.0),
        max_path_error: json["max_path_error"].as_f64(),
        path_error: peak(&json["path_error"], pieces),
        peaks: peaks.unbind(),
        speed,
        violations,
        exceeded: json["exceeded"].as_bool().unwrap_or(false),
        json: json.to_string(),
    })
}

/// Checks `program` (its input read again for the geometry) against `machine` (else
/// the machine it was planned with) at `servo_period`.
fn check_program(
    py: Python<'_>,
    program: &Program,
    machine: Option<&Bound<'_, PyAny>>,
    servo_period: Option<f64>,
) -> PyResult<Report> {
    let whole = program.whole(py, "checked")?;
    let mut options = program.plan.options.clone();
    if let Some(machine) = machine {
        let mut request = Request::default();
        let given = PyDict::new(py);
        given.set_item("machine", machine)?;
        request.add(Some(&given), Scope::Plan)?;
        options.machine = match request.machine {
            Some(m) => Some(m),
            None => {
                let path = crate::options::path("machine", machine)?;
                Some(
                    pvtc::machine::Machine::read(std::path::Path::new(&path))
                        .map_err(|f| raise(py, f))?,
                )
            }
        };
    }
    let source = program.source().map_err(|f| raise(py, f))?;
    let given = Given {
        limits: Default::default(),
        servo_period,
        max_samples: MAX_SAMPLES,
    };
    let checked = py.detach(|| {
        let toolpath = match &source {
            Some(source) => Some(pvtc::embed::toolpath(source, &options)?),
            None => None,
        };
        verify::checked(&whole, toolpath.as_ref(), &options, &given)
    });
    let checked = checked.map_err(|f| raise(py, f))?;
    report(py, &verify::to_json(&checked), &Pieces::of(&whole))
}

/// `pvtc check --max-samples`' default.
const MAX_SAMPLES: u64 = 1_000_000_000;

/// Checks a source (path or `pvtc.Text`) as `pvtc check --json` does.
fn check_source(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    mut request: Request,
    servo_period: Option<f64>,
) -> PyResult<Report> {
    if request.format.is_some() {
        return Err(PyTypeError::new_err(
            "check plans as `pvtc check` does (the JSON format's options): format is not one of its options",
        ));
    }
    let input = crate::Input::of(source, &mut request)?;
    let args = request.check_args(py, input.name(), servo_period)?;
    let loaded = py.detach(|| match &input {
        crate::Input::File { path, .. } => verify::load_quietly(path, &args.pipeline),
        crate::Input::Held(source) => verify::load_source(source, &args.pipeline),
    });
    let (loaded, warnings) = loaded.map_err(|f| raise(py, f))?;
    warn_all(py, &Diagnostic::all(&warnings))?;
    let given = Given {
        limits: args.limits(),
        servo_period: args.servo_period,
        max_samples: args.max_samples,
    };
    let checked = py
        .detach(|| {
            verify::checked(
                &loaded.program,
                loaded.toolpath.as_ref(),
                &loaded.options,
                &given,
            )
        })
        .map_err(|f| raise(py, f))?;
    report(py, &verify::to_json(&checked), &Pieces::of(&loaded.program))
}

/// Checks what a program's motion will do, as `pvtc check --json` does: per-axis peaks
/// of velocity, acceleration and jerk with where each happens, the limits exceeded and
/// the path error. `program_or_source` is a `Program` (its input is read again for the
/// geometry; `machine` defaults to the one it was planned with) or a source (a path or
/// `pvtc.Text`, planned with `options` as `pvtc check` plans it). `servo_period` is in
/// seconds (default: the machine's, else 0.5 ms).
#[pyfunction]
#[pyo3(signature = (program_or_source, machine=None, servo_period=None, **options))]
pub fn check(
    py: Python<'_>,
    program_or_source: &Bound<'_, PyAny>,
    machine: Option<&Bound<'_, PyAny>>,
    servo_period: Option<f64>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Report> {
    guard(|| {
        if let Ok(program) = program_or_source.cast::<Program>() {
            if options.is_some_and(|o| !o.is_empty()) {
                return Err(PyTypeError::new_err(
                    "a Program is planned already: planning options go to pvtc.plan",
                ));
            }
            return check_program(py, program.get(), machine, servo_period);
        }
        let mut request = Request::default();
        request.add(options, Scope::Plan)?;
        if let Some(machine) = machine {
            let given = PyDict::new(py);
            given.set_item("machine", machine)?;
            request.add(Some(&given), Scope::Plan)?;
        }
        check_source(py, program_or_source, request, servo_period)
    })
}
