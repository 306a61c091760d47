//! Real programs written by CAM posts (`tests/corpus/`, sources and licences in its
//! README): each compiles with and without `samples/machines/mill.toml`, and its motion
//! stays within the path tolerance of its own `--format toolpath`, every cubic sampled by
//! the independent reference (`tests/reference.rs`). A file the README lists as refused
//! must fail with the code it names.

mod common;

#[path = "../../../tests/reference.rs"]
#[allow(dead_code)]
mod reference;

use common::{root, run as pvtc, text};
use pvt_core::{
    Arc, ArcDirection, Contour, Element, ElementKind, Motion, Plane, Span, Toolpath, Units,
};
use serde_json::Value;

/// Each file of the corpus README's table with what it must do: `compiles`, or the code
/// it is refused with (each the first quoted word of the row's last cell).
fn expected() -> Vec<(String, String)> {
    let readme = std::fs::read_to_string(root().join("tests/corpus/README.md")).unwrap();
    readme
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let file = cells[1].trim_matches('`').to_string();
            // The first `quoted` word of the last cell: `compiles`, or a code.
            let outcome = cells[cells.len() - 2]
                .split('`')
                .nth(1)
                .unwrap_or("")
                .to_string();
            (file, outcome)
        })
        .collect()
}

/// A position of six axes from its JSON array.
fn position(v: &Value) -> [f64; 6] {
    let mut p = [0.0; 6];
    for (i, x) in p.iter_mut().enumerate() {
        *x = v[i].as_f64().expect("a coordinate");
    }
    p
}

/// The toolpath `--format toolpath` prints, read back from its JSON lines, with the
/// loosest path tolerance it sets (a `path_tolerance` line, G64 P).
fn toolpath_of(lines: &str) -> (Toolpath, Option<f64>) {
    let mut toolpath = Toolpath {
        units: Units::Millimetre,
        contours: Vec::new(),
        events: Vec::new(),
        path_tolerances: Vec::new(),
    };
    let mut open: Option<Contour> = None;
    let mut loosest: Option<f64> = None;
    for line in lines.lines() {
        let v: Value = serde_json::from_str(line).expect("a JSON line");
        let kind = match v["kind"].as_str() {
            Some("line") => ElementKind::Line,
            Some("arc") => ElementKind::Arc(Arc {
                plane: match v["plane"].as_str() {
                    Some("ZX") => Plane::ZX,
                    Some("YZ") => Plane::YZ,
                    _ => Plane::XY,
                },
                center: [
                    v["center"][0].as_f64().unwrap(),
                    v["center"][1].as_f64().unwrap(),
                ],
                direction: match v["direction"].as_str() {
                    Some("cw") => ArcDirection::Clockwise,
                    _ => ArcDirection::CounterClockwise,
                },
                extra_turns: v["turns"].as_u64().unwrap() as u32,
            }),
            Some("bezier") => ElementKind::Bezier(pvt_core::Bezier {
                plane: match v["plane"].as_str() {
                    Some("ZX") => Plane::ZX,
                    Some("YZ") => Plane::YZ,
                    _ => Plane::XY,
                },
                controls: std::array::from_fn(|i| {
                    std::array::from_fn(|j| v["controls"][i][j].as_f64().unwrap())
                }),
                fit: 0.0,
            }),
            Some("end_contour") => {
                toolpath.contours.extend(open.take());
                continue;
            }
            Some("path_tolerance") => {
                let t = v["tolerance"].as_f64().unwrap();
                loosest = Some(loosest.map_or(t, |l: f64| l.max(t)));
                continue;
            }
            Some("end") => {
                if v["units"] == "in" {
                    toolpath.units = Units::Inch;
                }
                continue;
            }
            _ => continue,
        };
        let motion = match v["motion"].as_str() {
            Some("rapid") => Motion::Rapid,
            _ => Motion::Feed,
        };
        let element = Element {
            kind,
            start: position(&v["start"]),
            end: position(&v["end"]),
            feed: v["feed"].as_f64().unwrap() / 60.0,
            span: Span {
                line: v["line"].as_u64().unwrap() as u32,
                ..Span::default()
            },
        };
        open.get_or_insert_with(|| Contour {
            motion,
            elements: Vec::new(),
        })
        .elements
        .push(element);
    }
    toolpath.contours.extend(open);
    (toolpath, loosest)
}

/// Compiles `file` (with `extra` options) and returns what happened: the program, or the
/// codes of the errors.
fn compile(file: &str, extra: &[&str]) -> Result<pvt_core::PvtProgram, Vec<String>> {
    let args = [
        &["compile", file, "--format", "json", "--diagnostics", "json"][..],
        extra,
    ]
    .concat();
    let o = pvtc(&args);
    if o.status.success() {
        return Ok(pvt_emit::json::read(&text(&o.stdout)).expect("a pvtc program"));
    }
    Err(text(&o.stderr)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["code"]
                .as_str()
                .unwrap_or("")
                .to_string()
        })
        .collect())
}

#[test]
fn cam_programs_follow_their_own_toolpath_within_the_tolerance() {
    let expected = expected();
    let mut files: Vec<String> = std::fs::read_dir(root().join("tests/corpus"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "README.md")
        .collect();
    files.sort();
    let listed: Vec<&String> = expected.iter().map(|(f, _)| f).collect();
    assert_eq!(
        files.iter().collect::<Vec<_>>(),
        listed,
        "the README lists every file, in order"
    );
    let machine = root().join("samples/machines/mill.toml");
    for (file, outcome) in &expected {
        let path = format!("tests/corpus/{file}");
        for extra in [&[][..], &["--machine", machine.to_str().unwrap()]] {
            let compiled = compile(&path, extra);
            if outcome != "compiles" {
                let codes = compiled.expect_err(&path);
                assert!(codes.contains(outcome), "{path} {extra:?}: {codes:?}");
                continue;
            }
            let program = compiled.unwrap_or_else(|codes| panic!("{path} {extra:?}: {codes:?}"));
            let lines = pvtc(&["compile", &path, "--format", "toolpath"]);
            assert!(lines.status.success(), "{}", text(&lines.stderr));
            let (toolpath, set) = toolpath_of(&text(&lines.stdout));
            assert_eq!(toolpath.units, program.units);
            let default = program.units.from_mm(pvt_core::ChordTolerance::DEFAULT_MM);
            let tol = set.map_or(default, |t| t.max(default));
            let d = reference::deviation(&program, &toolpath, 10.0 * tol);
            let slack = 1e-9 * tol;
            assert!(
                d.error <= tol + slack,
                "{path} {extra:?}: {} from the path > {tol}",
                d.error
            );
            assert!(
                d.gap <= tol + slack,
                "{path} {extra:?}: path {} from the motion > {tol}",
                d.gap
            );
        }
    }
}
