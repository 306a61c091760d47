//! Times the G-code front end alone on a file, as `pvtc compile` streams it (a 256 KiB
//! buffered read into [`pvt_gcode::compile_read`], default options), into a sink that
//! only counts what it is handed: `cargo run --release -p pvt-gcode --example front_end
//! -- FILE [RUNS]` (generate a file with `cargo run --release -p pvtc --example generate
//! -- surfacing 1000000 > /tmp/s.ngc`). Prints the counts and the best time of RUNS
//! (default 1).

use pvt_core::{Element, EventKind, Motion, ToolpathSink};

/// Counts elements, contour ends and events, and folds every element's end point into
/// a checksum so that nothing the front end computes can be left out.
#[derive(Default)]
struct Counting {
    elements: u64,
    contours: u64,
    events: u64,
    checksum: u64,
}

impl ToolpathSink for Counting {
    fn element(&mut self, _: Motion, element: &Element) {
        self.elements += 1;
        let bits = element
            .end
            .iter()
            .map(|v| v.to_bits())
            .fold(0, u64::wrapping_add);
        self.checksum = self
            .checksum
            .wrapping_add(bits ^ element.feed.to_bits() ^ element.span.start as u64);
    }
    fn end_contour(&mut self) {
        self.contours += 1;
    }
    fn event(&mut self, _: &EventKind, _: u32) {
        self.events += 1;
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: front_end FILE [RUNS]");
        std::process::exit(2);
    };
    let runs: u32 = args.next().and_then(|r| r.parse().ok()).unwrap_or(1);
    let options = pvt_gcode::GcodeOptions::default();
    let mut best = f64::INFINITY;
    for _ in 0..runs.max(1) {
        let file = match std::fs::File::open(&path) {
            Ok(file) => file,
            Err(error) => {
                eprintln!("{path}: {error}");
                std::process::exit(1);
            }
        };
        let mut input = std::io::BufReader::with_capacity(1 << 18, file);
        let mut sink = Counting::default();
        let start = std::time::Instant::now();
        let result = pvt_gcode::compile_read(&mut input, &options, &mut sink);
        best = best.min(start.elapsed().as_secs_f64());
        let outcome = match result {
            Ok(Ok(summary)) => format!("{} warnings", summary.warnings.len()),
            Ok(Err(errors)) => format!("{} errors", errors.diagnostics.len()),
            Err(error) => format!("read error: {error}"),
        };
        println!(
            "{path}: {} elements, {} contour ends, {} events, {outcome}, checksum {:016x}",
            sink.elements, sink.contours, sink.events, sink.checksum
        );
    }
    println!("best of {runs}: {best:.3} s");
}
