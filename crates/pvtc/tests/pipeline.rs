//! The streaming G-code compile with its front end on a thread of its own writes the
//! bytes, and reports the diagnostics in the order, of the same compile on one thread
//! (the route `pvtc compile` takes inside a rayon worker): on a program with events,
//! G64 P changes, several contours and rapids, into a file and into a pipe; on the same
//! program with errors on many lines; and through a planner failure part way, after
//! which every later G-code diagnostic is still collected.

use clap::Parser;
use pvt_core::{Element, EventKind, Motion, ToolpathSink};
use pvtc::output::Target;
use pvtc::pipeline::{front_end_threads, in_two_threads};

mod common;

/// A program of `n` moves: lines and arcs, a dwell, the spindle off and on again and a
/// G64 P change every so often, a rapid between contours; `bad` marks every line it
/// names with a word the front end refuses.
fn program(n: usize, bad: &dyn Fn(usize) -> bool) -> String {
    let mut lines = vec![
        "G21 G90 G17".to_string(),
        "G1 X0 Y0 F600".into(),
        "M3 S1200".into(),
    ];
    for i in 0..n {
        let (x, y) = ((i * 37 % 50) as f64 + 0.25, (i * 11 % 50) as f64 + 0.5);
        match i {
            _ if i % 97 == 0 => lines.push("G4 P0.2".into()),
            _ if i % 131 == 0 => lines.extend(["M5".into(), "M3 S900".into()]),
            _ if i % 211 == 0 => lines.push(format!("G64 P{:.3}", 0.001 + (i % 50) as f64 * 1e-3)),
            _ => {}
        }
        let mut line = match i % 53 {
            0 => format!("G0 Z5\nG0 X{x:.3} Y{y:.3}\nG1 Z0 F300"),
            k if k % 7 == 0 => format!("G2 X{x:.3} Y{y:.3} R40 F900"),
            _ => format!("G1 X{x:.3} Y{y:.3}"),
        };
        if bad(i) {
            line.push_str(" Q");
        }
        lines.push(line);
    }
    lines.extend(["M5".into(), "M30".into()]);
    lines.join("\n") + "\n"
}

/// Each report as the terminal shows it, in order.
fn rendered(reports: &[miette::Report]) -> Vec<String> {
    reports.iter().map(|r| format!("{r:?}")).collect()
}

/// Where a compile writes: a file, or a pipe (a [`Target::Stream`]).
enum Out<'a> {
    File(&'a mut std::fs::File),
    Pipe(&'a mut Vec<u8>),
}

/// `pvtc compile` of `file` into `out`, in a one-thread rayon pool when `alone`: its
/// warnings or its failure's reports, rendered, and whether it ran the front end on a
/// thread of its own.
fn compile(file: &std::path::Path, alone: bool, out: Out<'_>) -> (Vec<String>, bool) {
    let path = file.to_str().unwrap();
    let cli = pvtc::Cli::parse_from(["pvtc", "compile", path]);
    let pvtc::Command::Compile(args) = cli.command else {
        unreachable!("a compile command")
    };
    let options = args.compile_options(path).unwrap();
    let run = move || {
        let mut target = match out {
            Out::File(file) => Target::File { file, start: 0 },
            Out::Pipe(bytes) => Target::Stream(bytes),
        };
        let before = front_end_threads();
        let result = pvtc::route::compile_to(file, &options, false, &mut target);
        let threaded = front_end_threads() > before;
        match result {
            Ok(warnings) => (rendered(&warnings), threaded),
            Err(pvtc::Failure::Input(reports)) => (rendered(&reports), threaded),
            Err(other) => panic!("{other:?}"),
        }
    };
    match alone {
        true => rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(run),
        false => run(),
    }
}

/// Compiles `text` both ways into a file and into a pipe; the bytes and diagnostics of
/// the threaded compile, after checking them against the one-thread compile's.
fn both_ways(text: &str) -> (Vec<u8>, Vec<String>) {
    use std::io::{Read, Seek};
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("p.ngc");
    std::fs::write(&input, text).unwrap();
    let mut outputs = Vec::new();
    for alone in [false, true] {
        let mut file = tempfile::tempfile().unwrap();
        let (said, threaded) = compile(&input, alone, Out::File(&mut file));
        assert_eq!(threaded, !alone, "the route taken");
        let mut bytes = Vec::new();
        file.rewind().unwrap();
        file.read_to_end(&mut bytes).unwrap();
        let mut piped = Vec::new();
        let (said_piped, _) = compile(&input, alone, Out::Pipe(&mut piped));
        outputs.push((bytes, said, piped, said_piped));
    }
    let (threaded, alone) = (&outputs[0], &outputs[1]);
    assert!(threaded.0 == alone.0, "the file's bytes differ");
    assert_eq!(threaded.1, alone.1);
    assert!(threaded.2 == alone.2, "the pipe's bytes differ");
    assert_eq!(threaded.3, alone.3);
    (threaded.0.clone(), threaded.1.clone())
}

#[test]
fn two_threads_write_the_bytes_and_warnings_of_one() {
    let (bytes, warnings) = both_ways(&program(3_000 + 33, &|_| false));
    let text = String::from_utf8(bytes).unwrap();
    // Independently of the compile: the dwells, the spindle commands and the moves
    // are all there.
    assert!(
        text.lines().filter(|l| l.contains("DWELL")).count() >= 5,
        "{text:.400}"
    );
    assert!(text.lines().count() > 3_000);
    assert!(warnings.iter().any(|w| w.contains("pvtc::plan::summary")));
}

#[test]
fn two_threads_report_every_error_of_one_in_its_order() {
    let (bytes, errors) = both_ways(&program(3_000 + 33, &|i| i % 61 == 5));
    assert!(!errors.is_empty());
    drop(bytes);
    let all = errors.join("\n");
    // A report for each marked move.
    let marked = (0..3_000 + 33).filter(|i| i % 61 == 5).count();
    let syntax = errors
        .iter()
        .filter(|e| e.contains("Q must be followed by a number"));
    assert_eq!(syntax.count(), marked, "{all}");
}

/// Forwards a front end's calls, setting the feed of the moves on line `bad` to zero:
/// a planner failure (`pvtc::plan::bad_feed`) the front end does not see.
struct ZeroFeedAt<'a> {
    next: &'a mut dyn ToolpathSink,
    bad: u32,
}

impl ToolpathSink for ZeroFeedAt<'_> {
    fn element(&mut self, motion: Motion, element: &Element) {
        let mut element = *element;
        if element.span.line == self.bad {
            element.feed = 0.0;
        }
        self.next.element(motion, &element);
    }
    fn end_contour(&mut self) {
        self.next.end_contour();
    }
    fn event(&mut self, event: &EventKind, line: u32) {
        self.next.event(event, line);
    }
    fn path_tolerance(&mut self, tolerance: f64) {
        self.next.path_tolerance(tolerance);
    }
}

/// Records what the planner hands on, every number exactly.
struct Pieces<'a>(&'a mut Vec<String>);

impl pvt_core::PieceSink for Pieces<'_> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        self.0.push(format!("contour {motion:?} {start:?} {line}"));
    }
    fn piece(&mut self, p: &pvt_core::SegmentRef<'_>) {
        let piece = (p.end, p.velocity, p.duration, p.line);
        self.0.push(format!("piece {piece:?}"));
    }
    fn event(&mut self, event: &pvt_core::ProgramEvent) {
        self.0.push(format!("event {event:?}"));
    }
}

/// Plans `text` with the feed on line `bad` zeroed, the front end on its own thread or
/// not: what the planner handed on, its failure and the front end's diagnostics.
fn with_planner_failure(
    text: &str,
    bad: u32,
    threaded: bool,
) -> (Vec<String>, String, Vec<String>) {
    let axes = vec![pvt_core::Axis::X, pvt_core::Axis::Y, pvt_core::Axis::Z];
    let mut planned = Vec::new();
    let options = pvt_core::PlanOptions::default();
    let mut stage = pvt_core::PlanStage::new(axes, options, Pieces(&mut planned)).unwrap();
    let gcode = pvt_gcode::GcodeOptions::default();
    let front = |sink: &mut dyn ToolpathSink| {
        let mut zeroed = ZeroFeedAt { next: sink, bad };
        pvt_gcode::compile_read(&mut text.as_bytes(), &gcode, &mut zeroed).unwrap()
    };
    let read = match threaded {
        true => in_two_threads(front, &mut stage),
        false => front(&mut stage),
    };
    let failure = match stage.finish() {
        Err(e) => format!("{} {e}", e.code()),
        Ok(_) => panic!("not a planner failure"),
    };
    let diagnostics = read.expect_err("the program has errors").diagnostics;
    let diagnostics = diagnostics.iter().map(|d| format!("{d:?}")).collect();
    (planned, failure, diagnostics)
}

#[test]
fn a_planner_failure_part_way_stops_the_plan_not_the_front_end_on_either_route() {
    let moves = 5_000;
    let text = program(moves, &|i| i > 3_500 && i % 17 == 0);
    // A feed move three fifths of the way in, after several windows of the planner.
    let bad = text
        .lines()
        .enumerate()
        .skip(text.lines().count() * 3 / 5)
        .find(|(_, l)| l.starts_with("G1 X"))
        .map(|(i, _)| i as u32 + 1)
        .unwrap();
    let one = with_planner_failure(&text, bad, false);
    let two = with_planner_failure(&text, bad, true);
    assert!(
        one.0 == two.0,
        "the bytes written before the failure differ"
    );
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
    assert!(one.1.starts_with("pvtc::plan::bad_feed"), "{}", one.1);
    assert!(one.1.contains(&format!("line {bad}")), "{}", one.1);
    // Independently: every marked move after the failure is a diagnostic.
    let marked = text.lines().filter(|l| l.ends_with(" Q")).count();
    assert!(marked > 10);
    assert_eq!(two.2.len(), marked);
    // Pieces were planned before the failure: the failure is part way.
    let pieces = two.0.iter().filter(|p| p.starts_with("piece")).count();
    assert!(pieces > 1_000, "{pieces} pieces: {}", one.1);
    assert!(two.0.iter().any(|p| p.starts_with("event")));
}
