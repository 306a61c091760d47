//! The keyword options: each is a `pvtc compile` option with the same name (`_` for
//! `-`) and the same default, turned into that option's command-line words and parsed
//! by the CLI's own parser ([`pvtc::Cli`]), so that every check and default is the
//! command line's.
//!
//! Owns the table of keywords and how a Python value is spelled as the option's value
//! (seconds as `Ns`, a dict as `KEY=VALUE` repeats, a machine dict as TOML). It must not
//! check a value's range or apply a default: the CLI's parser and settings do.

use pvtc::machine::Machine;
use pvtc::{CompileOptions, Failure};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyFloat, PyInt, PyString};

/// How a keyword's Python value is spelled on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Spelling {
    /// A number (int or float).
    Number,
    /// A whole number.
    Whole,
    /// Seconds as a float, written `Ns`.
    Seconds,
    /// Seconds as a float, `None` for `off`.
    Quantum,
    /// A word (`"path"`, `"mm"`).
    Word,
    /// A path (str or `os.PathLike`).
    File,
    /// `(x, y)`.
    Point,
    /// A word or a list of words, one option each.
    Words,
    /// A dict `{"X": 1000}`, one `X=1000` each.
    AxisValues,
    /// A dict `{"pin": 1.0}`, one `pin=1.0` each.
    Pins,
    /// A list of `(x, y, z)`, one `x,y,z` each.
    Points3,
    /// A length (`"5mm"`, `"0.2in"`) or a time (`"20ms"`, or seconds as a float).
    Interval,
    /// A machine file's path, or a dict of the same shape.
    MachineFile,
}

/// When a keyword applies: planning, or writing a planned program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// `plan`, `stream`, `from_points`, `check`.
    Plan,
    /// `Program.write`.
    Write,
}

/// Keyword, command-line flag, spelling, scope.
#[rustfmt::skip]
const KEYWORDS: &[(&str, &str, Spelling, Scope)] = &[
    ("input_format", "input-format", Spelling::Word, Scope::Plan),
    ("planner", "planner", Spelling::Word, Scope::Plan),
    ("machine", "machine", Spelling::MachineFile, Scope::Plan),
    ("corner_tolerance", "corner-tolerance", Spelling::Number, Scope::Plan),
    ("time_slice", "time-slice", Spelling::Seconds, Scope::Plan),
    ("accel", "accel", Spelling::Number, Scope::Plan),
    ("quantize", "quantize", Spelling::Quantum, Scope::Plan),
    ("quantize_rounding", "quantize-rounding", Spelling::Word, Scope::Plan),
    ("feed", "feed", Spelling::Number, Scope::Plan),
    ("counts_per_unit", "counts-per-unit", Spelling::AxisValues, Scope::Plan),
    ("rapid", "rapid", Spelling::Number, Scope::Plan),
    ("tolerance", "tolerance", Spelling::Number, Scope::Plan),
    ("layers", "layer", Spelling::Words, Scope::Plan),
    ("join_tolerance", "join-tolerance", Spelling::Number, Scope::Plan),
    ("start_point", "start-point", Spelling::Point, Scope::Plan),
    ("safe_z", "safe-z", Spelling::Number, Scope::Plan),
    ("max_points", "max-points", Spelling::Whole, Scope::Plan),
    ("units", "units", Spelling::Word, Scope::Plan),
    ("offsets", "offsets", Spelling::File, Scope::Plan),
    ("subroutine_path", "subroutine-path", Spelling::Words, Scope::Plan),
    ("tool_table", "tool-table", Spelling::File, Scope::Plan),
    ("hal", "hal", Spelling::Pins, Scope::Plan),
    ("probe_results", "probe-result", Spelling::Points3, Scope::Plan),
    ("tool_table_units", "tool-table-units", Spelling::Word, Scope::Plan),
    ("arc_abs_tolerance", "arc-abs-tolerance", Spelling::Number, Scope::Plan),
    ("arc_rel_tolerance", "arc-rel-tolerance", Spelling::Number, Scope::Plan),
    ("velocities", "velocities", Spelling::Word, Scope::Plan),
    ("format", "format", Spelling::Word, Scope::Plan),
    ("pmac_program", "pmac-program", Spelling::Whole, Scope::Write),
    ("pmac_coord", "pmac-coord", Spelling::Whole, Scope::Write),
    ("pmac_axis", "pmac-axis", Spelling::Words, Scope::Write),
    ("pmac_rotary", "pmac-rotary", Spelling::Whole, Scope::Write),
    ("pmac_events", "pmac-events", Spelling::Word, Scope::Write),
    ("trigger_every", "trigger-every", Spelling::Interval, Scope::Write),
];

/// The keyword of a command-line flag (`tool-table` → `tool_table`, `layer` →
/// `layers`); a flag without one keeps its name with `_`.
pub fn keyword_of(flag: &str) -> String {
    KEYWORDS
        .iter()
        .find(|(_, f, _, _)| *f == flag)
        .map_or_else(|| flag.replace('-', "_"), |(k, _, _, _)| k.to_string())
}

/// What a call asked for, as command-line words (without the input and `--format`) and
/// a machine given as a dict, read.
#[derive(Debug, Clone, Default)]
pub struct Request {
    /// The options' words.
    pub words: Vec<String>,
    /// A machine given as a dict.
    pub machine: Option<Machine>,
    /// The format asked for (`format=`), if any.
    pub format: Option<String>,
}

impl Request {
    /// The request of `options` (keywords of `scope`; `format` handled apart), added to
    /// `self`; a `TypeError` for an unknown keyword or a value of the wrong type.
    pub fn add(&mut self, options: Option<&Bound<'_, PyDict>>, scope: Scope) -> PyResult<()> {
        let Some(options) = options else {
            return Ok(());
        };
        for (key, value) in options.iter() {
            let key: String = key.extract()?;
            let Some(&(_, flag, spelling, s)) = KEYWORDS.iter().find(|(k, ..)| *k == key) else {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument {key:?}: {}",
                    known(scope)
                )));
            };
            if s != scope {
                return Err(PyTypeError::new_err(format!(
                    "{key:?} is an option of {}, not here",
                    match s {
                        Scope::Plan => "planning (plan, stream, from_points, check)",
                        Scope::Write => "Program.write",
                    }
                )));
            }
            if key == "format" {
                self.format = Some(word(&key, &value)?);
                continue;
            }
            self.spell(&key, flag, spelling, &value)?;
        }
        Ok(())
    }

    /// Adds the words of one keyword.
    fn spell(
        &mut self,
        key: &str,
        flag: &str,
        spelling: Spelling,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        if value.is_none() && spelling != Spelling::Quantum {
            return Ok(());
        }
        let flag = format!("--{flag}");
        let values: Vec<String> = match spelling {
            Spelling::Number => vec![number(key, value)?],
            Spelling::Whole => vec![whole(key, value)?],
            Spelling::Seconds => vec![format!("{}s", number(key, value)?)],
            Spelling::Quantum if value.is_none() => vec!["off".into()],
            Spelling::Quantum => vec![format!("{}s", number(key, value)?)],
            Spelling::Word => vec![word(key, value)?],
            Spelling::File => vec![path(key, value)?],
            Spelling::Point => vec![numbers(key, value, 2)?.join(",")],
            Spelling::Words => words(key, value)?,
            Spelling::AxisValues | Spelling::Pins => pairs(key, value)?,
            Spelling::Points3 => points3(key, value)?,
            Spelling::Interval => vec![interval(key, value)?],
            Spelling::MachineFile => return self.machine_file(key, value),
        };
        // `--flag=value`, so that a value starting with `-` is read as the value.
        self.words
            .extend(values.into_iter().map(|v| format!("{flag}={v}")));
        Ok(())
    }

    /// `machine=`: a path, or a dict read as the file's TOML would be.
    fn machine_file(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        if let Ok(dict) = value.cast::<PyDict>() {
            let table = toml_table(key, dict)?;
            let text = toml::to_string(&table).map_err(|e| PyValueError::new_err(e.to_string()))?;
            self.machine = Some(
                Machine::parse("<machine dict>", &text)
                    .map_err(|e| Failure::Input(vec![miette::Report::new(e)]))
                    .map_err(|f| crate::errors::raise(value.py(), f))?,
            );
            return Ok(());
        }
        self.words.push(format!("--machine={}", path(key, value)?));
        Ok(())
    }

    /// The options of a compile of the input named `name` into the request's format
    /// (else the command's default), as `pvtc compile NAME [--format F] WORDS` gives them.
    pub fn compile_options(&self, py: Python<'_>, name: &str) -> PyResult<CompileOptions> {
        if self.format.as_deref() == Some("toolpath") {
            return Err(PyValueError::new_err(
                "format \"toolpath\" stops before planning: a Program is planned motion",
            ));
        }
        let format = self.format.as_ref().map(|f| format!("--format={f}"));
        let mut words = vec!["compile", name];
        words.extend(format.as_deref());
        let pvtc::Command::Compile(mut args) = self.parse(&words)? else {
            return Err(PyValueError::new_err("not a compile"));
        };
        self.read_files(py, &mut args.pipeline)?;
        args.compile_options(name)
            .map_err(|f| crate::errors::raise(py, f))
    }

    /// The arguments of `pvtc check NAME --json WORDS` (the servo period as seconds).
    pub fn check_args(
        &self,
        py: Python<'_>,
        name: &str,
        servo_period: Option<f64>,
    ) -> PyResult<pvtc::args::CheckArgs> {
        let period = servo_period.map(|p| format!("--servo-period={p}s"));
        let mut words = vec!["check", name, "--json"];
        words.extend(period.as_deref());
        let pvtc::Command::Check(mut args) = self.parse(&words)? else {
            return Err(PyValueError::new_err("not a check"));
        };
        self.read_files(py, &mut args.pipeline)?;
        Ok(args)
    }

    /// `pvtc WORDS`, then the request's words, through the command's own parser.
    fn parse(&self, words: &[&str]) -> PyResult<pvtc::Command> {
        let argv = ["pvtc"]
            .into_iter()
            .chain(words.iter().copied())
            .chain(self.words.iter().map(String::as_str));
        let cli = <pvtc::Cli as clap::Parser>::try_parse_from(argv).map_err(|e| usage_error(&e))?;
        Ok(cli.command)
    }

    /// Reads the side files the options name, the machine given as a dict kept as read.
    fn read_files(&self, py: Python<'_>, pipeline: &mut pvtc::args::PipelineArgs) -> PyResult<()> {
        if let Some(machine) = &self.machine {
            pipeline.machine_read = Some(machine.clone());
        }
        pipeline
            .read_files()
            .map_err(|f| crate::errors::raise(py, f))
    }
}

/// The keywords of `scope`, for a `TypeError`.
fn known(scope: Scope) -> String {
    let names: Vec<&str> = KEYWORDS
        .iter()
        .filter(|(_, _, _, s)| *s == scope)
        .map(|(k, ..)| *k)
        .collect();
    format!("the options are {}", names.join(", "))
}

/// A parse error of the CLI's parser as a `ValueError` naming the keyword.
fn usage_error(e: &clap::Error) -> PyErr {
    let text = e.to_string();
    let first = text
        .lines()
        .next()
        .unwrap_or("")
        .trim_start_matches("error: ");
    // `'--quantize <T|off>'` names the keyword `quantize`.
    let message = crate::errors::keyword_words(&without_value_names(first));
    let detail: Vec<&str> = text
        .lines()
        .skip(1)
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("For more information") && !l.starts_with("Usage:")
        })
        .collect();
    if detail.is_empty() {
        PyValueError::new_err(message)
    } else {
        PyValueError::new_err(format!("{message} ({})", detail.join(" ")))
    }
}

/// `text` without clap's value names (` <T|off>`).
fn without_value_names(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" <") {
        out.push_str(&rest[..at]);
        match rest[at..].find('>') {
            Some(end) => rest = &rest[at + end + 1..],
            None => {
                rest = &rest[at..];
                break;
            }
        }
    }
    out.push_str(rest);
    out
}

fn type_error(key: &str, wanted: &str, value: &Bound<'_, PyAny>) -> PyErr {
    let got = value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    PyTypeError::new_err(format!("{key} must be {wanted}, not {got}"))
}

/// A number's shortest round-trip text (what the CLI's parser reads back exactly).
fn number(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    let numeric = value.is_instance_of::<PyFloat>()
        || value.is_instance_of::<PyInt>()
        || value.hasattr("__float__")?;
    let refused =
        value.is_instance_of::<PyString>() || value.is_instance_of::<pyo3::types::PyBool>();
    if !numeric || refused {
        return Err(type_error(key, "a number", value));
    }
    let x: f64 = value.extract()?;
    Ok(format!("{x}"))
}

fn whole(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    if value.is_instance_of::<pyo3::types::PyBool>() {
        return Err(type_error(key, "a whole number", value));
    }
    let n: i64 = value
        .extract()
        .map_err(|_| type_error(key, "a whole number", value))?;
    Ok(n.to_string())
}

fn word(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    value
        .cast::<PyString>()
        .map(|s| s.to_string())
        .map_err(|_| type_error(key, "a str", value))
}

/// A path: a str or anything `os.fspath` takes.
pub fn path(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    let os = value.py().import("os")?;
    let text = os
        .call_method1("fspath", (value,))
        .map_err(|_| type_error(key, "a path (str or os.PathLike)", value))?;
    text.extract::<String>()
        .map_err(|_| type_error(key, "a path (str or os.PathLike)", value))
}

fn sequence<'py>(
    key: &str,
    value: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if value.is_instance_of::<PyString>() {
        return Err(type_error(key, what, value));
    }
    value
        .try_iter()
        .map_err(|_| type_error(key, what, value))?
        .collect()
}

fn numbers(key: &str, value: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<String>> {
    let items = sequence(key, value, &format!("a sequence of {n} numbers"))?;
    if items.len() != n {
        return Err(PyValueError::new_err(format!(
            "{key} must hold {n} numbers, not {}",
            items.len()
        )));
    }
    items.iter().map(|x| number(key, x)).collect()
}

fn words(key: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if value.is_instance_of::<PyString>() {
        return Ok(vec![word(key, value)?]);
    }
    sequence(key, value, "a str or a list of str")?
        .iter()
        .map(|w| match path(key, w) {
            Ok(p) => Ok(p),
            Err(_) => word(key, w),
        })
        .collect()
}

fn pairs(key: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    let dict = value
        .cast::<PyDict>()
        .map_err(|_| type_error(key, "a dict", value))?;
    dict.iter()
        .map(|(k, v)| Ok(format!("{}={}", word(key, &k)?, number(key, &v)?)))
        .collect()
}

fn points3(key: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    sequence(key, value, "a list of (x, y, z)")?
        .iter()
        .map(|p| Ok(numbers(key, p, 3)?.join(",")))
        .collect()
}

fn interval(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    if value.is_instance_of::<PyString>() {
        return word(key, value);
    }
    Ok(format!("{}s", number(key, value)?))
}

/// A machine dict as a TOML table (str, int, float, bool and nested dicts).
fn toml_table(key: &str, dict: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in dict.iter() {
        let name = word(key, &k)?;
        let value = if let Ok(inner) = v.cast::<PyDict>() {
            toml::Value::Table(toml_table(key, inner)?)
        } else if v.is_instance_of::<PyString>() {
            toml::Value::String(v.extract()?)
        } else if v.is_instance_of::<pyo3::types::PyBool>() {
            toml::Value::Boolean(v.extract()?)
        } else if v.is_instance_of::<PyInt>() {
            toml::Value::Integer(v.extract()?)
        } else {
            toml::Value::Float(v.extract().map_err(|_| {
                type_error(&format!("{key}[{name:?}]"), "a number, str or dict", &v)
            })?)
        };
        table.insert(name, value);
    }
    Ok(table)
}
