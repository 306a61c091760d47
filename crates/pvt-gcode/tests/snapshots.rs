//! Data-driven snapshots: every tests/valid/*.ngc compiles to the recorded summary, every
//! tests/invalid/*.ngc fails with the recorded diagnostics (code, line:column, message).

mod common;

use std::path::{Path, PathBuf};

use pvt_gcode::GcodeOptions;

fn programs(folder: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(folder);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("test folder exists")
        .map(|entry| entry.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no programs in {}", dir.display());
    files
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .expect("a file name")
        .to_string_lossy()
        .into_owned()
}

#[test]
fn valid_programs() {
    for path in programs("valid") {
        let source = std::fs::read_to_string(&path).expect("UTF-8 program");
        let options = GcodeOptions::default();
        assert!(
            pvt_gcode::compile(&source, &options).is_ok(),
            "{}:\n{}",
            path.display(),
            common::render(&source, &options)
        );
        insta::assert_snapshot!(
            format!("valid_{}", stem(&path)),
            common::render(&source, &options)
        );
    }
}

#[test]
fn invalid_programs() {
    for path in programs("invalid") {
        let source = std::fs::read_to_string(&path).expect("UTF-8 program");
        let options = GcodeOptions::default();
        assert!(
            pvt_gcode::compile(&source, &options).is_err(),
            "{} compiled",
            path.display()
        );
        insta::assert_snapshot!(
            format!("invalid_{}", stem(&path)),
            common::render(&source, &options)
        );
    }
}
