//! Times `pvt_gcode::compile` on a file: `cargo run --release -p pvt-gcode --example
//! compile_time -- FILE` (generate one with `cargo run --release -p pvtc --example generate
//! -- surfacing 1000000 > /tmp/s.ngc`).

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: compile_time FILE");
        std::process::exit(2);
    };
    let source = match std::fs::read_to_string(&path) {
        Ok(source) => source,
        Err(error) => {
            eprintln!("{path}: {error}");
            std::process::exit(1);
        }
    };
    let options = pvt_gcode::GcodeOptions::default();
    let start = std::time::Instant::now();
    let result = pvt_gcode::compile(&source, &options);
    let elapsed = start.elapsed();
    match result {
        Ok(compiled) => {
            let elements: usize = compiled
                .toolpath
                .contours
                .iter()
                .map(|c| c.elements.len())
                .sum();
            println!(
                "{path}: {elements} elements in {:.3} s",
                elapsed.as_secs_f64()
            );
        }
        Err(errors) => println!(
            "{path}: {} errors in {:.3} s",
            errors.diagnostics.len(),
            elapsed.as_secs_f64()
        ),
    }
}
