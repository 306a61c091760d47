//! Shared helpers of the end-to-end tests: paths, compiling samples, and an independent
//! implementation of seed 000 written from the document's own steps.

pub mod controllers;
pub mod ebnf;
pub mod reference;

use pvt_core::PvtProgram;
use pvt_emit::Format;
use pvtc::{compile, CompileOptions, Source};
use std::path::{Path, PathBuf};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the root")
        .to_path_buf()
}

/// The sample programs of a kind (`gcode`), sorted by name, as paths relative to the root.
pub fn samples(kind: &str, extension: &str) -> Vec<String> {
    let dir = root().join("samples").join(kind);
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| {
            e.expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.ends_with(extension))
        .map(|n| format!("samples/{kind}/{n}"))
        .collect();
    names.sort();
    names
}

/// Compiles a file named relative to the root, the way `pvtc compile NAME` run from the
/// root would, and returns the output bytes.
pub fn compile_file(name: &str, options: &CompileOptions) -> Vec<u8> {
    let bytes = std::fs::read(root().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let source = Source {
        name: name.into(),
        bytes,
    };
    match compile(&source, options) {
        Ok(c) => c.bytes,
        Err(f) => panic!("{name} failed: {:?}", f.codes()),
    }
}

/// Compiles G-code text with the contour planner (seed 000) and reads the JSON output back.
pub fn compile_gcode_to_program(name: &str, text: &str) -> PvtProgram {
    let source = Source::from_text(name, text);
    let mut options = CompileOptions::new(Format::Json);
    options.planner = pvt_core::Planner::Contour;
    let out = match compile(&source, &options) {
        Ok(c) => c.bytes,
        Err(f) => panic!("{name} failed: {:?}", f.codes()),
    };
    pvt_emit::json::read(std::str::from_utf8(&out).expect("JSON is UTF-8"))
        .expect("pvtc reads its own JSON")
}

/// One command of seed 000: end point, end velocity and segment time.
#[derive(Debug, Clone, Copy)]
pub struct Seed000Command {
    /// End position X, Y.
    pub p: [f64; 2],
    /// End velocity X, Y.
    pub v: [f64; 2],
    /// Segment time, seconds.
    pub t: f64,
}

/// Seed 000 step by step, as the document writes it: atan2 chord angles, their mean as the
/// velocity direction (corrected by half a turn when the two angles straddle ±180°, as
/// the source README says the document means), `Vend = Vspec` at interior points and the
/// quadratic's root `(−b + √(b² − 4ac)) / 2a` as the time. Written independently of
/// pvt-core, with the textbook root formula rather than pvt-core's cancellation-free one.
pub fn seed000(points: &[[f64; 2]], vspec: f64) -> Vec<Seed000Command> {
    let n = points.len() - 1;
    let mut out = Vec::with_capacity(n);
    let (mut vstart, mut vxs, mut vys) = (0.0, 0.0, 0.0);
    let angle = |i: usize| {
        libm::atan2(
            points[i + 1][1] - points[i][1],
            points[i + 1][0] - points[i][0],
        )
    };
    let mut phi = angle(0);
    for i in 0..n {
        let (vend, vxe, vye) = if i + 1 < n {
            let next = angle(i + 1);
            let mut theta = (next + phi) / 2.0;
            if (next - phi).abs() > std::f64::consts::PI {
                theta += std::f64::consts::PI;
            }
            phi = next;
            (vspec, vspec * libm::cos(theta), vspec * libm::sin(theta))
        } else {
            (0.0, 0.0, 0.0)
        };
        let vmid = (vend + vstart) / 2.0;
        let (dx, dy) = (
            points[i + 1][0] - points[i][0],
            points[i + 1][1] - points[i][1],
        );
        let (sx, sy) = (vxe + vxs, vye + vys);
        let m2 = vmid * vmid;
        let a = 1.0 - (sx * sx + sy * sy) / 16.0 / m2;
        let b = 0.75 * (dx * sx + dy * sy) / m2;
        let c = -2.25 * (dx * dx + dy * dy) / m2;
        let t = (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        out.push(Seed000Command {
            p: points[i + 1],
            v: [vxe, vye],
            t,
        });
        (vstart, vxs, vys) = (vend, vxe, vye);
    }
    out
}

/// True when `a` and `b` agree to `rel` relative to the larger, or to `abs` absolutely.
pub fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    let d = (a - b).abs();
    d <= abs || d <= rel * a.abs().max(b.abs())
}
