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
    let mut last_line = None;
    let mut control = Control::default();
    for line in &lines {
        let feed = line["feed"].as_f64().unwrap_or(0.0) * mm;
        match line["kind"].as_str() {
            Some("line") => moves.push(Move::Straight {
                rapid: line["motion"] == "rapid",
                end: position(&line["end"]),
                feed,
                control,
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
                // pvtc hands an arc of many turns on a turn at a time: the parts of one
                // block (one source line, one centre) are one arc, as rs274 prints it.
                // (Two arcs of one line with two centres, a compensated arc and the arc
                // around the corner after it, stay two.)
                let part_of_last = last_line == Some(&line["line"]);
                match (moves.last_mut(), part_of_last) {
                    (Some(last), true) if same_centre(last, &arc) => join_turns(last, arc),
                    _ => moves.push(arc),
                }
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
        last_line = (line["kind"] == "arc").then_some(&line["line"]);
    }
    moves
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

/// Whether `last` is an arc about the centre of the arc `next`.
pub(crate) fn same_centre(last: &Move, next: &Move) -> bool {
    match (last, next) {
        (Move::Arc { center: a, .. }, Move::Arc { center: b, .. }) => close(a, b, 1.0),
        _ => false,
    }
}

/// `next`, the next turn of the arc `last` is part of, joined to it: its end and its turn.
pub(crate) fn join_turns(last: &mut Move, next: Move) {
    let (
        Move::Arc {
            end,
            center,
            rotation,
            ..
        },
        Move::Arc {
            end: next_end,
            center: next_center,
            rotation: next_rotation,
            ..
        },
    ) = (last, next)
    else {
        return;
    };
    debug_assert!(close(center, &next_center, 1.0));
    *end = next_end;
    *rotation += next_rotation;
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
