//! The interactive HTML view in headless Chromium: `pvtc plot -o FILE.html` and `pvtc
//! diff -o FILE.html` open offline with no console error and no network request, draw,
//! and show the program's own data (piece count, total time, each axis' peaks, computed
//! here from the program's JSON independently of pvtc). Without Chromium each test says
//! SKIPPED; with `PVTC_REQUIRE_CHROMIUM=1` (set by `.ci/run`) it fails instead.
//!
//! `PVTC_VIEW_PROGRAM=FILE cargo test --release -p pvtc --test view -- --ignored`
//! measures a large program's page (bench/view/run.sh): its size and the time to open.

mod common;

use common::chromium::{self, Browser};
use common::{command, root};
use serde_json::Value;
use std::path::Path;

/// Runs `pvtc ARGS`, which must succeed.
fn pvtc(args: &[&str]) {
    let out = command(args).output().unwrap();
    assert!(
        out.status.success(),
        "pvtc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Each axis' largest |v|, |a|, |j| and its position range, from the pieces' cubics
/// written out here (`p(s) = p₀ + v₀s + c₂s² + c₃s³`), with the total time (pieces and
/// dwells) and the piece count.
struct Expected {
    pieces: usize,
    total: f64,
    peaks: Vec<[f64; 5]>,
}

fn expected(program: &pvt_core::PvtProgram) -> Expected {
    let dim = program.axes.len();
    let mut peaks = vec![[0.0, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY]; dim];
    let mut total = 0.0;
    for c in &program.contours {
        let mut from: Vec<(f64, f64)> = c.start.iter().map(|p| (*p, 0.0)).collect();
        for i in 0..c.len() {
            let t = c.durations[i];
            total += t;
            for (k, peak) in peaks.iter_mut().enumerate() {
                let (p0, v0) = from[k];
                let (p1, v1) = (c.ends[i * dim + k], c.velocities[i * dim + k]);
                let d = (p1 - p0) / t;
                let c2 = (3.0 * d - 2.0 * v0 - v1) / t;
                let c3 = (v0 + v1 - 2.0 * d) / (t * t);
                let mut inside = vec![0.0, t];
                if c3 != 0.0 {
                    inside.push(-c2 / (3.0 * c3));
                    let disc = 4.0 * c2 * c2 - 12.0 * c3 * v0;
                    if disc >= 0.0 {
                        inside.push((-2.0 * c2 + disc.sqrt()) / (6.0 * c3));
                        inside.push((-2.0 * c2 - disc.sqrt()) / (6.0 * c3));
                    }
                }
                for s in inside.into_iter().filter(|s| *s >= 0.0 && *s <= t) {
                    let p = p0 + s * (v0 + s * (c2 + s * c3));
                    let v = v0 + s * (2.0 * c2 + 3.0 * s * c3);
                    let a = 2.0 * c2 + 6.0 * c3 * s;
                    peak[0] = f64::max(peak[0], v.abs());
                    peak[1] = f64::max(peak[1], a.abs());
                    peak[3] = peak[3].min(p);
                    peak[4] = peak[4].max(p);
                }
                peak[2] = f64::max(peak[2], (6.0 * c3).abs());
                from[k] = (p1, v1);
            }
        }
    }
    for e in &program.events {
        if let pvt_core::EventKind::Dwell { seconds } = e.kind {
            total += seconds;
        }
    }
    Expected {
        pieces: program.segment_count(),
        total,
        peaks,
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-9)
}

/// Opens `page` and returns its summary and the browser, after asserting that nothing
/// failed and nothing was asked of a network; the screenshot goes to `shot`.
fn open(binary: &Path, page: &Path, shot: &Path) -> (Value, Browser) {
    let mut browser = Browser::start(binary, 1400, 900);
    let url = format!("file://{}", page.display());
    browser.open(&url);
    let summary = browser.evaluate(
        "new Promise((done, fail) => { const wait = () => window.pvtcView && window.pvtcView.ready \
         ? window.pvtcView.ready.then(done, fail) : setTimeout(wait, 20); wait(); })",
    );
    // One more frame, so that what the page drew is on the screenshot.
    browser.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))");
    let png = browser.screenshot();
    std::fs::write(shot, &png).unwrap();
    let errors: Vec<String> = browser
        .events
        .iter()
        .filter(|e| {
            let m = e["method"].as_str().unwrap_or("");
            m == "Runtime.exceptionThrown"
                || (m == "Runtime.consoleAPICalled"
                    && matches!(
                        e["params"]["type"].as_str(),
                        Some("error" | "assert" | "warning")
                    ))
                || (m == "Log.entryAdded"
                    && matches!(
                        e["params"]["entry"]["level"].as_str(),
                        Some("error" | "warning")
                    ))
        })
        .map(Value::to_string)
        .collect();
    assert!(errors.is_empty(), "console errors: {errors:#?}");
    let requests: Vec<String> = browser
        .seen("Network.requestWillBeSent")
        .iter()
        .map(|e| {
            e["params"]["request"]["url"]
                .as_str()
                .unwrap_or("")
                .to_string()
        })
        .filter(|u| *u != url)
        .collect();
    assert!(
        requests.is_empty(),
        "requests besides the page: {requests:?}"
    );
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (1400, 900));
    // The 3D path (left) and the plots (right) draw in colour, not only grey.
    for (x0, x1) in [(20, 560), (620, 1370)] {
        let coloured = (x0..x1)
            .flat_map(|x| (60..560).map(move |y| (x, y)))
            .filter(|&(x, y)| {
                let p = image.get_pixel(x, y).0.map(i32::from);
                (p[0] - p[1]).abs() + (p[1] - p[2]).abs() + (p[0] - p[2]).abs() > 60
            })
            .count();
        assert!(coloured > 300, "{coloured} coloured pixels in x {x0}..{x1}");
    }
    (summary, browser)
}

/// The page's figures against the program's.
fn assert_shows(summary: &Value, motion: usize, program: &pvt_core::PvtProgram) {
    let e = expected(program);
    let m = &summary["motions"][motion];
    assert_eq!(m["pieces"].as_u64().unwrap() as usize, e.pieces, "{m}");
    let total = m["totalTime"].as_f64().unwrap();
    assert!(
        close(total, e.total, 1e-9),
        "total time {total} vs {}",
        e.total
    );
    for (k, axis) in program.axes.iter().enumerate() {
        let shown = &m["peaks"][axis.to_string()];
        let [v, a, j, lo, hi] = e.peaks[k];
        let scale = lo.abs().max(hi.abs());
        for (name, want, rel) in [
            ("velocity", v, 1e-6),
            ("acceleration", a, 1e-6),
            ("jerk", j, 1e-4),
        ] {
            let got = shown[name].as_f64().unwrap();
            assert!(
                close(got, want, rel),
                "{axis} {name}: page {got}, program {want}"
            );
        }
        let range = &shown["position"];
        for (got, want) in [
            (range[0].as_f64().unwrap(), lo),
            (range[1].as_f64().unwrap(), hi),
        ] {
            assert!(
                (got - want).abs() <= 1e-9 * scale.max(1.0),
                "{axis} position {got} vs {want}"
            );
        }
    }
}

fn read_json(path: &Path) -> pvt_core::PvtProgram {
    pvt_emit::json::read(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_plot_page_opens_offline_and_shows_the_programs_data() {
    let Ok(binary) = chromium::required().map_err(|why| println!("SKIPPED: {why}")) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let sample = "samples/gcode/linuxcnc_params_pocket.ngc";
    let machine = "samples/machines/mill.toml";
    let (json, page) = (
        dir.path().join("pocket.json"),
        dir.path().join("pocket.html"),
    );
    let (json_s, page_s) = (json.to_str().unwrap(), page.to_str().unwrap());
    pvtc(&[
        "compile",
        sample,
        "--format",
        "json",
        "--machine",
        machine,
        "-o",
        json_s,
    ]);
    pvtc(&["plot", sample, "--machine", machine, "-o", page_s]);
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("view-plot.png");
    let (summary, mut browser) = open(&binary, &page, &shot);
    assert_eq!(summary["motions"].as_array().unwrap().len(), 1);
    assert_shows(&summary, 0, &read_json(&json));
    assert!(summary["findings"].as_u64().unwrap() >= 4, "{summary}");
    // A click on the velocity plot shows the time, the piece, its line and its text.
    let info = browser.evaluate(
        "pvtcView.texts.then(() => { const c = document.querySelectorAll('#plots-box canvas')[1]; \
         const r = c.getBoundingClientRect(); const at = {clientX: r.left + r.width * 0.4, \
         clientY: r.top + r.height / 2, bubbles: true}; \
         c.dispatchEvent(new MouseEvent('mousedown', at)); c.dispatchEvent(new MouseEvent('mouseup', at)); \
         return document.getElementById('info-body').innerText; })",
    );
    let info = info.as_str().unwrap();
    let line: usize = info
        .split(" · line ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no line in {info:?}"));
    let source = std::fs::read_to_string(root().join(sample)).unwrap();
    let text = source.lines().nth(line - 1).unwrap();
    assert!(
        info.contains("piece ") && info.contains(&format!("{line}: {text}")),
        "{info:?}"
    );
    // A finding jumps to its instant.
    let jumped = browser.evaluate(
        "(() => { document.querySelector('#findings li').click(); \
         return [pvtcView.state.cursor, pvtcView.state.meta.findings[0].time]; })()",
    );
    assert_eq!(jumped[0], jumped[1], "{jumped}");
    println!("screenshot: {}", shot.display());
}

#[test]
fn the_diff_page_overlays_both_motions_and_their_difference() {
    let Ok(binary) = chromium::required().map_err(|why| println!("SKIPPED: {why}")) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let a = root().join("tests/golden/gcode/an208_zigzag.json");
    let b = dir.path().join("moved.ngc");
    let text = std::fs::read_to_string(root().join("samples/gcode/an208_zigzag.ngc")).unwrap();
    std::fs::write(&b, text.replace("Y10000", "Y10000.5")).unwrap();
    let page = dir.path().join("diff.html");
    let (a_s, b_s, page_s) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        page.to_str().unwrap(),
    );
    let out = command(&["diff", a_s, b_s, "-o", page_s]).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("view-diff.png");
    let (summary, _) = open(&binary, &page, &shot);
    assert_eq!(summary["motions"].as_array().unwrap().len(), 2);
    assert_shows(&summary, 0, &read_json(&a));
    println!("screenshot: {}", shot.display());
}

/// The page of a large program (`PVTC_VIEW_PROGRAM`: a source or a pvtc JSON program,
/// plotted with `PVTC_VIEW_ARGS` added to `pvtc plot`, or a page already written): its
/// size and the time from opening it to drawn, read in headless Chromium.
#[test]
#[ignore]
fn a_large_programs_page_opens() {
    let Ok(program) = std::env::var("PVTC_VIEW_PROGRAM") else {
        println!("SKIPPED: set PVTC_VIEW_PROGRAM to a program");
        return;
    };
    let binary = chromium::required().expect("chromium for the measurement");
    let dir = tempfile::tempdir().unwrap();
    // A page already written is opened as it is.
    let (page, written) = if program.ends_with(".html") {
        (
            std::path::PathBuf::from(&program),
            std::time::Duration::ZERO,
        )
    } else {
        let page = dir.path().join("large.html");
        let extra = std::env::var("PVTC_VIEW_ARGS").unwrap_or_default();
        let mut args = vec!["plot", program.as_str(), "-o", page.to_str().unwrap()];
        args.extend(extra.split_whitespace());
        let started = std::time::Instant::now();
        pvtc(&args);
        (page, started.elapsed())
    };
    let bytes = std::fs::metadata(&page).unwrap().len();
    let mut browser = Browser::start(&binary, 1400, 900);
    browser.open("about:blank");
    let idle = browser.cpu_seconds();
    let opened = std::time::Instant::now();
    browser.open(&format!("file://{}", page.display()));
    let summary = browser.evaluate(
        "new Promise((done, fail) => { const wait = () => window.pvtcView && window.pvtcView.ready \
         ? window.pvtcView.ready.then(done, fail) : setTimeout(wait, 20); wait(); })",
    );
    browser.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))");
    let drawn = opened.elapsed();
    let cpu = browser.cpu_seconds() - idle;
    let ready = browser.evaluate("JSON.stringify(pvtcView.timings)");
    std::fs::write(
        Path::new(env!("CARGO_TARGET_TMPDIR")).join("view-large.png"),
        browser.screenshot(),
    )
    .unwrap();
    println!(
        "pieces {}, page {:.1} MB written in {:.1} s; opened and drawn in {:.2} s, {cpu:.2} s of \
         the browser's processor time (the script's times, ms from navigation: {})",
        summary["motions"][0]["pieces"],
        bytes as f64 / 1e6,
        written.as_secs_f64(),
        drawn.as_secs_f64(),
        ready
    );
}
