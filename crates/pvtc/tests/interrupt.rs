//! Ctrl-C (SIGINT) in the middle of a compile leaves no partial file and the previous
//! output untouched, for one file, for standard output redirected to a file, and for a
//! batch.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

/// A surfacing program long enough to be interrupted while it is written.
fn big_program(lines: usize) -> String {
    let mut text = String::from("G21 G90 G94\nG0 X0 Y0 Z1\n");
    for i in 0..lines {
        let x = (i % 1000) as f64 * 0.05;
        let y = (i / 1000) as f64 * 0.5;
        let z = -((i % 37) as f64) * 0.01;
        text.push_str(&format!("G1 X{x:.3} Y{y:.3} Z{z:.3} F1500\n"));
    }
    text
}

fn partial_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".partial"))
        .collect()
}

/// Waits until `dir` holds a partial output of `child`, then sends it SIGINT.
fn interrupt_while_writing(child: &mut Child, dir: &Path) {
    interrupt_once(child, || !partial_files(dir).is_empty());
}

/// Waits until `writing` says `child` is writing its output, then sends it SIGINT.
fn interrupt_once(child: &mut Child, writing: impl Fn() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !writing() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "pvtc finished before it could be interrupted"
        );
        assert!(Instant::now() < deadline, "no output appeared");
        std::thread::sleep(Duration::from_millis(2));
    }
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

#[test]
fn ctrl_c_leaves_no_partial_file_and_the_old_output_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("big.ngc");
    std::fs::write(&input, big_program(300_000)).unwrap();
    let out = dir.path().join("big.pmac");
    std::fs::write(&out, "old output\n").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .args([
            "compile",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    interrupt_while_writing(&mut child, dir.path());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(partial_files(dir.path()), Vec::<PathBuf>::new());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old output\n");
}

/// Standard output redirected to a file is written in place: an interrupt cuts it back to
/// what it held before.
#[test]
fn ctrl_c_cuts_redirected_standard_output_back() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("big.ngc");
    std::fs::write(&input, big_program(300_000)).unwrap();
    let out = dir.path().join("log.pmac");
    std::fs::write(&out, "kept\n").unwrap();
    let append = std::fs::OpenOptions::new().append(true).open(&out).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .args(["compile", input.to_str().unwrap()])
        .stdout(append)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    interrupt_once(&mut child, || std::fs::metadata(&out).unwrap().len() > 5);
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept\n");
}

#[test]
fn ctrl_c_in_a_batch_leaves_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    let outputs = dir.path().join("out");
    std::fs::create_dir_all(&inputs).unwrap();
    std::fs::create_dir_all(&outputs).unwrap();
    let program = big_program(150_000);
    for i in 0..4 {
        std::fs::write(inputs.join(format!("p{i}.ngc")), &program).unwrap();
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .args(["compile", inputs.to_str().unwrap(), "--out-dir"])
        .arg(&outputs)
        .args(["-j", "2"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    interrupt_while_writing(&mut child, &outputs);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(partial_files(&outputs), Vec::<PathBuf>::new());
    for done in std::fs::read_dir(&outputs).unwrap() {
        let done = done.unwrap().path();
        let text = std::fs::read_to_string(&done).unwrap();
        assert!(text.ends_with("CLOSE\n"), "{} is not whole", done.display());
    }
}
