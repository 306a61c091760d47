//! Throughput of the pipeline: parse only ([`pvt_gcode::check_syntax`]: words, values,
//! spans and diagnostics, no meaning), parse and interpret, plan only, end to end in
//! memory (`compile-to-pmac`) and as the CLI does it (`stream-to-pmac`: a file on disk
//! through [`pvtc::route::compile_streaming`] into a file, prescan included), and the
//! `gcode` crate parsing the same text as a peer baseline.
//!
//! ```sh
//! cargo bench -p pvtc --bench pipeline              # all sizes: 10^4, 10^5, 10^6 lines
//! PVTC_BENCH_LINES=100000 cargo bench -p pvtc --bench pipeline
//! ```
//!
//! Inputs come from the same generator as `cargo run -p pvtc --example generate`
//! (surfacing: 3D short G1 moves; pocket: G2/G3 arcs), built in memory, deterministic.

use criterion::{criterion_main, BenchmarkId, Criterion, Throughput};
use pvt_core::{plan_toolpath, PlanOptions};
use pvt_emit::Format;
use pvtc::{compile, CompileOptions, Source};
use std::hint::black_box;

#[path = "../examples/generate/programs.rs"]
mod programs;

fn sizes() -> Vec<usize> {
    match std::env::var("PVTC_BENCH_LINES") {
        Ok(n) => vec![n.parse().expect("PVTC_BENCH_LINES is a line count")],
        Err(_) => vec![10_000, 100_000, 1_000_000],
    }
}

fn text(kind: &str, lines: usize) -> String {
    let mut out = Vec::new();
    programs::write(kind, lines, &mut out).expect("in memory");
    String::from_utf8(out).expect("ASCII")
}

fn bench(c: &mut Criterion) {
    for kind in ["surfacing", "pocket"] {
        let mut group = c.benchmark_group(kind);
        group.sample_size(10);
        for lines in sizes() {
            let src = text(kind, lines);
            group.throughput(Throughput::Elements(lines as u64));
            group.bench_with_input(BenchmarkId::new("parse/pvtc", lines), &src, |b, src| {
                b.iter(|| pvt_gcode::check_syntax(black_box(src)).words)
            });
            group.bench_with_input(
                BenchmarkId::new("parse+interpret/pvtc", lines),
                &src,
                |b, src| {
                    b.iter(|| {
                        pvt_gcode::compile(black_box(src), &Default::default()).expect("valid")
                    })
                },
            );
            group.bench_with_input(
                BenchmarkId::new("parse/gcode-crate", lines),
                &src,
                |b, src| {
                    b.iter(|| {
                        gcode::parse(black_box(src))
                            .map(|g| g.arguments().len())
                            .sum::<usize>()
                    })
                },
            );
            let toolpath = pvt_gcode::compile(&src, &Default::default())
                .expect("valid")
                .toolpath;
            group.bench_with_input(BenchmarkId::new("plan", lines), &toolpath, |b, t| {
                b.iter(|| plan_toolpath(black_box(t), &PlanOptions::default()).expect("plans"))
            });
            let source = Source::from_text("bench.ngc", &src);
            group.bench_with_input(
                BenchmarkId::new("compile-to-pmac", lines),
                &source,
                |b, s| {
                    b.iter(|| {
                        compile(black_box(s), &contour_options())
                            .expect("compiles")
                            .bytes
                            .len()
                    })
                },
            );
            let dir = tempfile::tempdir().expect("a temporary directory");
            let path = dir.path().join("bench.ngc");
            std::fs::write(&path, &src).expect("writes the program");
            let mut out = tempfile::tempfile_in(dir.path()).expect("a temporary file");
            group.bench_with_input(BenchmarkId::new("stream-to-pmac", lines), &path, |b, p| {
                b.iter(|| {
                    let mut target = pvtc::output::Target::File {
                        file: &mut out,
                        start: 0,
                    };
                    target.restart().expect("empties the file");
                    let options = contour_options();
                    pvtc::route::compile_streaming(
                        black_box(p),
                        "bench.ngc",
                        &options,
                        false,
                        &mut target,
                    )
                    .expect("compiles")
                    .len()
                })
            });
        }
        group.finish();
    }
}

// criterion's macros define undocumented items.
#[allow(missing_docs)]
mod harness {
    criterion::criterion_group!(benches, super::bench);
}
criterion_main!(harness::benches);

/// PMAC output planned by the contour planner (seed 000), the rows the README reports.
fn contour_options() -> CompileOptions {
    let mut options = CompileOptions::new(Format::Pmac);
    options.planner = pvt_core::Planner::Contour;
    options
}
