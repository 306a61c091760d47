//! The pipeline: source → front end → toolpath → planner → back end → bytes.
//!
//! Owns the order of the phases and the settings each gets. It must not parse, plan or
//! format by itself, and it does no output I/O (see [`crate::output`]).

use miette::{LabeledSpan, NamedSource, Report};
use pvt_core::{plan_toolpath, ChordTolerance, PlanOptions, PvtProgram, Units};
use pvt_emit::{emit_to_vec, EmitOptions, Format, StreamError};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Default rapid rate, mm/min.
pub const DEFAULT_RAPID_MM_PER_MIN: f64 = 5000.0;

/// An input, read whole.
#[derive(Debug, Clone)]
pub struct Source {
    /// The name diagnostics and headers use: the path as given, or `<stdin>`.
    pub name: String,
    /// The bytes read.
    pub bytes: Vec<u8>,
}

impl Source {
    /// Reads `path`, or standard input for `-`.
    pub fn read(path: &Path) -> Result<Source, Failure> {
        let io_failure = |error| Failure::Io {
            path: path.to_path_buf(),
            action: "read",
            error,
        };
        if path == Path::new("-") {
            let mut bytes = Vec::new();
            std::io::stdin()
                .read_to_end(&mut bytes)
                .map_err(io_failure)?;
            return Ok(Source {
                name: "<stdin>".into(),
                bytes,
            });
        }
        let bytes = std::fs::read(path).map_err(io_failure)?;
        Ok(Source {
            name: path.display().to_string(),
            bytes,
        })
    }

    /// A source from text already in memory.
    pub fn from_text(name: &str, text: &str) -> Source {
        Source {
            name: name.into(),
            bytes: text.as_bytes().to_vec(),
        }
    }
}

/// The front ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// RS274/NGC G-code.
    Gcode,
    /// DXF drawing.
    Dxf,
}

impl InputKind {
    /// The front end a file name suggests: `.dxf` is a drawing, anything else G-code.
    pub fn from_name(name: &str) -> InputKind {
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".dxf") {
            InputKind::Dxf
        } else {
            InputKind::Gcode
        }
    }
}

/// Options only drawings use.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DrawingOptions {
    /// Layers to cut; empty is every layer.
    pub layers: Vec<String>,
    /// Join tolerance, drawing units; `None` is 0.01 mm.
    pub join_tolerance: Option<f64>,
    /// Where the machine starts (X, Y).
    pub start_point: [f64; 2],
    /// Safe Z for travel between contours.
    pub safe_z: Option<f64>,
    /// The drawing's units, overriding $INSUNITS.
    pub units: Option<Units>,
}

/// Everything a compilation depends on besides the source.
#[derive(Debug, Clone, PartialEq)]
pub struct CompileOptions {
    /// Output format.
    pub format: Format,
    /// Front end.
    pub input: InputKind,
    /// Feed for moves before the first F word, program units per minute.
    pub feed: Option<f64>,
    /// Rapid rate, program units per minute; `None` is 5000 mm/min.
    pub rapid: Option<f64>,
    /// Chord tolerance, program units; `None` is 0.001 mm.
    pub tolerance: Option<f64>,
    /// Options only drawings use.
    pub drawing: DrawingOptions,
}

impl CompileOptions {
    /// Default options writing `format`.
    pub fn new(format: Format) -> CompileOptions {
        CompileOptions {
            format,
            input: InputKind::Gcode,
            feed: None,
            rapid: None,
            tolerance: None,
            drawing: DrawingOptions::default(),
        }
    }
}

/// A successful compilation.
#[derive(Debug)]
pub struct Compiled {
    /// The output, exactly as it is to be written.
    pub bytes: Vec<u8>,
    /// The planned program.
    pub program: PvtProgram,
    /// Warnings, ready to print.
    pub warnings: Vec<Report>,
}

/// Why a run failed.
#[derive(Debug)]
pub enum Failure {
    /// A file could not be read or written.
    Io {
        /// The file.
        path: PathBuf,
        /// `read` or `write`.
        action: &'static str,
        /// What the system said.
        error: std::io::Error,
    },
    /// The input has errors; every one of them, ready to print.
    Input(Vec<Report>),
    /// The command line asks for something impossible (exit status 2).
    Usage(String),
}

impl Failure {
    /// The stable codes of the diagnostics, in order (for tests and tools).
    pub fn codes(&self) -> Vec<String> {
        match self {
            Failure::Io { .. } => vec!["pvtc::io".into()],
            Failure::Usage(_) => vec!["pvtc::usage".into()],
            Failure::Input(reports) => reports
                .iter()
                .map(|r| r.code().map(|c| c.to_string()).unwrap_or_default())
                .collect(),
        }
    }
}

/// Compiles `source` into the bytes of `options.format`.
pub fn compile(source: &Source, options: &CompileOptions) -> Result<Compiled, Failure> {
    let (toolpath, warnings) = crate::front::read(&source.name, &source.bytes, options)?;
    let text = String::from_utf8_lossy(&source.bytes).into_owned();
    let named = || NamedSource::new(source.name.clone(), text.clone());
    let units = toolpath.units;
    let tolerance = options
        .tolerance
        .unwrap_or(units.from_mm(ChordTolerance::DEFAULT_MM));
    let tolerance =
        ChordTolerance::new(tolerance).expect("the CLI accepts only positive tolerances");
    let program = plan_toolpath(
        &toolpath,
        &PlanOptions {
            tolerance,
            ..PlanOptions::default()
        },
    )
    .map_err(|e| {
        Failure::Input(vec![
            at_line(e.code(), &e.to_string(), e.line(), &text).with_source_code(named())
        ])
    })?;
    let emit_options = EmitOptions {
        source: source.name.clone(),
        settings: settings(options, units, tolerance),
        program_number: 1,
    };
    let bytes = emit_to_vec(&program, options.format, &emit_options).map_err(|e| match e {
        StreamError::Invalid(invalid) => Failure::Input(vec![at_line(
            pvt_emit::InvalidProgram::CODE,
            &invalid.to_string(),
            invalid.line,
            &text,
        )
        .with_source_code(named())]),
        StreamError::Io(error) => Failure::Io {
            path: PathBuf::from("<memory>"),
            action: "write",
            error,
        },
        StreamError::Unsupported(interpolation) => Failure::Input(vec![miette::miette!(
            code = "pvtc::emit::unsupported_interpolation",
            help = "choose --format json or movepvt, or a PVT planner",
            "the {} format cannot express {interpolation:?} motion",
            options.format.name()
        )]),
    })?;
    Ok(Compiled {
        bytes,
        program,
        warnings,
    })
}

/// A diagnostic labelling the whole of 1-based `line` of `text`.
fn at_line(code: &str, message: &str, line: u32, text: &str) -> Report {
    let mut start = 0;
    for _ in 1..line.max(1) {
        match text[start..].find('\n') {
            Some(i) => start += i + 1,
            None => break,
        }
    }
    let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    miette::miette!(
        code = code.to_string(),
        labels = vec![LabeledSpan::at(start..end, "this line")],
        "{message}"
    )
}

fn settings(
    options: &CompileOptions,
    units: Units,
    tolerance: ChordTolerance,
) -> Vec<(String, String)> {
    let u = units.name();
    let rapid = match options.rapid {
        Some(r) => format!("{r} {u}/min"),
        None if units == Units::Millimetre => {
            format!("{DEFAULT_RAPID_MM_PER_MIN} {u}/min (default)")
        }
        None => format!(
            "{} {u}/min (default 5000 mm/min)",
            units.from_mm(DEFAULT_RAPID_MM_PER_MIN)
        ),
    };
    let feed = match options.feed {
        Some(f) => format!("{f} {u}/min"),
        None => "none (every feed move needs an F word)".into(),
    };
    vec![
        (
            "planner".into(),
            "contour (seed 000: bisector velocities, mid-segment speed = mean of end speeds)"
                .into(),
        ),
        ("chord tolerance".into(), format!("{} {u}", tolerance.get())),
        ("rapid".into(), rapid),
        ("default feed".into(), feed),
    ]
}
