//! pvtc's side of the differential tests: running `pvtc compile --format toolpath` on a
//! program and reading its lines as machine moves.

use super::*;

/// pvtc's reading of `program` as moves, or its diagnostics.
pub(crate) fn pvtc_moves(program: &Path) -> Result<Vec<Move>, String> {
    let mut command = Command::new(env!("CARGO_BIN_EXE_pvtc"));
    command
        .arg("compile")
        .arg(program)
        .args(["--format", "toolpath"])
        .current_dir(program.parent().expect("a folder"))
        .env("NO_COLOR", "1");
    if let Some(table) = sidecar(program, "tbl") {
        command.arg("--tool-table").arg(table);
    }
    if let Some(args) = sidecar(program, "args") {
        let text = std::fs::read_to_string(args).expect("args file");
        command.args(text.lines().map(str::trim).filter(|l| !l.is_empty()));
    }
    let output = command.output().expect("pvtc runs");
    if !output.status.success() {
        return Err(format!(
            "pvtc failed on {}:\n{}",
            program.display(),
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    Ok(toolpath_moves(&String::from_utf8_lossy(&output.stdout)))
}

/// The `--format toolpath` lines as moves, in millimetres.
pub(crate) fn toolpath_moves(text: &str) -> Vec<Move> {
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect();
    let end = lines.last().expect("an end line");
    assert_eq!(end["kind"], "end", "the toolpath output is complete");
    let mm = if end["units"] == "in" { 25.4 } else { 1.0 };
    let position = |v: &serde_json::Value| -> [f64; 6] {
        let mut p = [0.0; 6];
        for (i, x) in p.iter_mut().enumerate() {
            let value = v[i].as_f64().expect("a number");
            *x = if i < 3 { value * mm } else { value };
        }
        p
    };
    let mut moves = Vec::new();
    let mut control = Control::default();
    for line in &lines {
        let feed = line["feed"].as_f64().unwrap_or(0.0) * mm;
        match line["kind"].as_str() {
            Some("line") => moves.push(Move::Straight {
                rapid: line["motion"] == "rapid",
                end: position(&line["end"]),
                feed,
                control,
                minutes: rotary_minutes(line),
                unit: 0.0,
                spread: 0.0,
            }),
            Some("arc") => {
                let turns = line["turns"].as_i64().expect("turns") + 1;
                let arc = Move::Arc {
                    plane: match line["plane"].as_str() {
                        Some("ZX") => "ZX",
                        Some("YZ") => "YZ",
                        _ => "XY",
                    },
                    end: position(&line["end"]),
                    center: [
                        line["center"][0].as_f64().expect("centre") * mm,
                        line["center"][1].as_f64().expect("centre") * mm,
                    ],
                    rotation: if line["direction"] == "cw" {
                        -turns
                    } else {
                        turns
                    },
                    feed,
                    control,
                    unit: 0.0,
                    spread: 0.0,
                };
                // An arc of many turns comes a turn at a time: the comparison joins
                // them where rs274 prints one arc (`turns_of_one_arc`).
                moves.push(arc);
            }
            Some("event") => moves.extend(event(line)),
            Some("path_control") => {
                control = Control {
                    mode: match line["control"].as_str() {
                        Some("exact_path") => "exact_path",
                        Some("exact_stop") => "exact_stop",
                        _ => "continuous",
                    },
                    p: line["tolerance"].as_f64().unwrap_or(0.0) * mm,
                    q: line["naive_cam_tolerance"].as_f64().unwrap_or(0.0) * mm,
                }
            }
            _ => {}
        }
    }
    moves
}

/// The minutes a feed `line` that turns a rotary axis takes: its length over every axis
/// (output units and degrees, as the planner measures it) over its feed; 0 for others.
fn rotary_minutes(line: &serde_json::Value) -> f64 {
    let at = |key: &str, i: usize| line[key][i].as_f64().unwrap_or(0.0);
    let d: Vec<f64> = (0..6).map(|i| at("end", i) - at("start", i)).collect();
    let turns = d[3..].iter().any(|v| v.abs() > 1e-9);
    match turns && line["motion"] == "feed" {
        true => d.iter().map(|v| v * v).sum::<f64>().sqrt() / line["feed"].as_f64().unwrap_or(1.0),
        false => 0.0,
    }
}

/// A timing-relevant `event` line as a move: a dwell, the spindle, its speed, coolant.
fn event(line: &serde_json::Value) -> Option<Move> {
    Some(match line["event"].as_str()? {
        "dwell" => Move::Dwell(line["seconds"].as_f64().expect("seconds")),
        "spindle_cw" => Move::Spindle("cw"),
        "spindle_ccw" => Move::Spindle("ccw"),
        "spindle_off" => Move::Spindle("off"),
        "spindle_speed" => Move::Speed(line["rpm"].as_f64().expect("rpm")),
        "coolant_mist" => Move::Coolant("mist"),
        "coolant_flood" => Move::Coolant("flood"),
        "coolant_off" => Move::Coolant("off"),
        _ => return None,
    })
}

/// Whether pvtc compiles `program`, and its diagnostics as (code, line).
pub(crate) fn pvtc_diagnostics(program: &Path) -> (bool, Vec<(String, usize)>) {
    let output = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .arg("compile")
        .arg(program)
        .args([
            "--format",
            "toolpath",
            "--diagnostics",
            "json",
            "-o",
            "/dev/null",
        ])
        .output()
        .expect("pvtc runs");
    let diagnostics = String::from_utf8_lossy(&output.stderr)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .map(|d| {
            let code = d["code"].as_str().unwrap_or("").to_owned();
            (code, d["line"].as_u64().unwrap_or(0) as usize)
        })
        .collect();
    (output.status.success(), diagnostics)
}
