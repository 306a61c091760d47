//! Every program in samples/gcode/ compiles with default options (the golden test of the
//! workspace renders them to every back end).

mod common;

use std::path::Path;

use pvt_gcode::{compile, GcodeOptions};

#[test]
fn every_sample_compiles_with_default_options() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/gcode");
    let mut count = 0;
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .expect("samples/gcode exists")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    paths.sort();
    for path in paths {
        let source = std::fs::read_to_string(&path).expect("UTF-8");
        let options = GcodeOptions::default();
        assert!(
            compile(&source, &options).is_ok(),
            "{}:\n{}",
            path.display(),
            common::render(&source, &options)
        );
        count += 1;
    }
    assert!(count >= 15, "only {count} samples");
}

#[test]
#[ignore = "prints every sample's summary: cargo test -p pvt-gcode --test samples -- --ignored --nocapture"]
fn print_samples() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/gcode");
    for entry in std::fs::read_dir(&dir).expect("samples/gcode exists") {
        let path = entry.expect("entry").path();
        let source = std::fs::read_to_string(&path).expect("UTF-8");
        println!(
            "== {}\n{}",
            path.display(),
            common::render(&source, &GcodeOptions::default())
        );
    }
}
