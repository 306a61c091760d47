//! The streaming G-code compile with its planner on a thread of its own writes the
//! bytes, and reports the diagnostics in the order, of the same compile on one thread
//! (the route `pvtc compile` takes inside a rayon worker): on a program with events,
//! G64 P changes, several contours and rapids, into a file and into a pipe, in every
//! format; on the same program with errors on many lines; through a planner failure
//! part way, after which every later G-code diagnostic is still collected; on a late
//! travel refusal and into a pipe that fills part way.

use clap::Parser;
use pvt_core::PieceSink;
use pvt_core::{Element, EventKind, Motion, ToolpathSink};
use pvtc::output::Target;
use pvtc::pipeline::{front_end_threads, planner_aside, planner_threads, Calls};
use pvtc::route::Outlet;

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
    Pipe(&'a mut (dyn std::io::Write + Send)),
}

/// A pipe that takes `room` bytes and then refuses every write.
struct Filling {
    taken: Vec<u8>,
    room: usize,
}

impl std::io::Write for Filling {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.room - self.taken.len());
        if n == 0 && !buf.is_empty() {
            return Err(std::io::Error::other("the pipe is full"));
        }
        self.taken.extend_from_slice(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// `pvtc compile` of `file` with the options `args` into `out`, in a one-thread rayon
/// pool when `alone`: its warnings or its failure's reports (any failure), rendered, and
/// whether it ran the front end and the planner on threads of their own.
fn compile_with(
    file: &std::path::Path,
    args: &[&str],
    alone: bool,
    out: Out<'_>,
) -> (Vec<String>, bool) {
    let path = file.to_str().unwrap();
    let mut words = vec!["pvtc", "compile", path];
    words.extend(args);
    let cli = pvtc::Cli::parse_from(words);
    let pvtc::Command::Compile(args) = cli.command else {
        unreachable!("a compile command")
    };
    let options = args.compile_options(path).unwrap();
    let run = move || {
        let mut target = match out {
            Out::File(file) => Target::File { file, start: 0 },
            Out::Pipe(bytes) => Target::Stream(bytes),
        };
        let before = (front_end_threads(), planner_threads());
        let result = pvtc::route::compile_to(file, &options, false, &mut target);
        let fronts = front_end_threads() - before.0;
        let planners = planner_threads() - before.1;
        // The planner on a thread of its own (or, where nothing is planned, the front
        // end), or neither.
        assert!(fronts == 0 || planners == 0, "threads started");
        let threaded = planners + fronts > 0;
        match result {
            Ok(warnings) => (rendered(&warnings), threaded),
            Err(pvtc::Failure::Input(reports)) => (rendered(&reports), threaded),
            Err(other) => (vec![format!("{other:?}")], threaded),
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
    both_ways_with(text, &[])
}

/// [`both_ways`] with the options `args`.
fn both_ways_with(text: &str, args: &[&str]) -> (Vec<u8>, Vec<String>) {
    use std::io::{Read, Seek};
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("p.ngc");
    std::fs::write(&input, text).unwrap();
    let mut outputs = Vec::new();
    for alone in [false, true] {
        let mut file = tempfile::tempfile().unwrap();
        let (said, threaded) = compile_with(&input, args, alone, Out::File(&mut file));
        assert_eq!(threaded, !alone, "the route taken");
        let mut bytes = Vec::new();
        file.rewind().unwrap();
        file.read_to_end(&mut bytes).unwrap();
        let mut piped = Vec::new();
        let (said_piped, _) = compile_with(&input, args, alone, Out::Pipe(&mut piped));
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

impl pvtc::pipeline::PieceWriter for Pieces<'_> {}

/// Plans `text` with the feed on line `bad` zeroed, the planner on its own thread (the
/// front end and the pieces' sink on this one) or not: what the planner handed on, its
/// failure and the front end's diagnostics.
fn with_planner_failure(
    text: &str,
    bad: u32,
    threaded: bool,
) -> (Vec<String>, String, Vec<String>) {
    let axes = vec![pvt_core::Axis::X, pvt_core::Axis::Y, pvt_core::Axis::Z];
    let mut planned = Vec::new();
    let gcode = pvt_gcode::GcodeOptions::default();
    let front = |sink: &mut dyn ToolpathSink| {
        let mut zeroed = ZeroFeedAt { next: sink, bad };
        pvt_gcode::compile_read(&mut text.as_bytes(), &gcode, &mut zeroed).unwrap()
    };
    let plan = |pieces: &mut dyn PieceSink, calls: Calls<'_>| {
        let options = pvt_core::PlanOptions::default();
        let mut stage = pvt_core::PlanStage::new(axes.clone(), options, Outlet(pieces)).unwrap();
        calls(&mut stage);
        stage.finish().map(|_| ())
    };
    let mut sink = Pieces(&mut planned);
    let (read, finished) = match threaded {
        true => match planner_aside(front, plan, axes.len(), &mut sink) {
            Ok((read, finished)) => (read, finished),
            Err(_) => panic!("no thread started"),
        },
        false => {
            let mut read = None;
            let finished = plan(&mut sink, &mut |stage| read = Some(front(stage)));
            (read.unwrap(), finished)
        }
    };
    let failure = match finished {
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

#[test]
fn the_planner_aside_writes_the_bytes_of_one_thread_in_every_format() {
    let text = program(1_500 + 33, &|_| false);
    let counts = ["--counts-per-unit", "X=1000", "--counts-per-unit", "Y=1000"];
    let counts = [counts.as_slice(), &["--counts-per-unit", "Z=1000"]].concat();
    for format in pvt_emit::Format::ALL.map(pvt_emit::Format::name) {
        let mut args = vec!["--format", format];
        if matches!(format, "galil" | "zaber") {
            args.extend(&counts);
        }
        let (bytes, warnings) = both_ways_with(&text, &args);
        // Independently of the compile: a line or more per move.
        assert!(bytes.split(|b| *b == b'\n').count() > 1_500, "{format}");
        assert!(
            warnings.iter().any(|w| w.contains("pvtc::plan::summary")),
            "{format}"
        );
    }
    // On the quantum grid, and past the PMAC splitter's longest piece (slow feeds).
    let slow = program(800, &|_| false)
        .replace("F900", "F9")
        .replace("F300", "F3");
    for args in [&["--quantize", "1ms"][..], &["--quantize", "off"]] {
        both_ways_with(&slow, args);
    }
}

/// The same program with its last move past the travel a machine file allows: a
/// refusal the writer's checks make after every other piece is written.
#[test]
fn a_late_refusal_fails_the_planner_aside_as_it_fails_one_thread() {
    let dir = tempfile::tempdir().unwrap();
    let machine = dir.path().join("m.toml");
    let axis = "max_velocity = 100.0\nmax_acceleration = 1000.0\nmax_position = 60\n";
    std::fs::write(
        &machine,
        format!("units = \"mm\"\n[axes.X]\n{axis}[axes.Y]\n{axis}[axes.Z]\n{axis}"),
    )
    .unwrap();
    let text = program(2_000, &|_| false).replace("M5\nM30", "G1 X70 Y1\nM5\nM30");
    let machine = machine.to_str().unwrap();
    for format in ["pmac", "json"] {
        let (bytes, errors) = both_ways_with(&text, &["--machine", machine, "--format", format]);
        let all = errors.join("\n");
        assert_eq!(errors.len(), 1, "{all}");
        assert!(all.contains("pvtc::emit::travel_limit"), "{all}");
        // The refusal is late: most of the program went into the file before it.
        assert!(bytes.len() > 50_000, "{} bytes", bytes.len());
    }
}

/// A pipe that fills part way: the write fails on both routes after the same bytes.
#[test]
fn a_writer_failing_part_way_fails_the_planner_aside_as_it_fails_one_thread() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("p.ngc");
    std::fs::write(&input, program(3_000, &|_| false)).unwrap();
    let mut seen = Vec::new();
    for alone in [false, true] {
        let mut pipe = Filling {
            taken: Vec::new(),
            room: 150_000,
        };
        let (said, threaded) = compile_with(&input, &[], alone, Out::Pipe(&mut pipe));
        assert_eq!(threaded, !alone, "the route taken");
        seen.push((said, pipe.taken));
    }
    assert_eq!(seen[0].0, seen[1].0);
    assert!(seen[0].1 == seen[1].1, "the bytes taken differ");
    // Independently: a write failure, after the pipe took all it had room for.
    assert_eq!(seen[0].0.len(), 1);
    assert!(seen[0].0[0].contains("the pipe is full"), "{:?}", seen[0].0);
    assert_eq!(seen[0].1.len(), 150_000);
}
