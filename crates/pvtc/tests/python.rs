//! The Python package (`crates/pvtc-py`) built and tested from `cargo test`: a virtual
//! environment in `target/pvtc-py/venv` (kept between runs) with maturin, numpy and
//! pytest, the extension built into it by `maturin develop` (the dev profile, in the
//! workspace's `target`, whose dependencies it shares: its numbers are the release
//! build's, and it builds in a fraction of the time; cargo holds no lock on `target`
//! while tests run), then pytest over `crates/pvtc-py/tests` against this build's `pvtc`
//! binary.
//!
//! Without Python, or without a way to make the environment (no `venv` module, no
//! package index), the test says SKIPPED and why; with `PVTC_REQUIRE_PYTHON=1` (set by
//! `.ci/run`, which installs what it needs) it fails instead. `PVTC_PYTHON` names the
//! Python that makes the environment (default `python3`); `PVTC_PYTHON_VENV` and
//! `PVTC_PY_CARGO_TARGET` move the environment and maturin's build elsewhere.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Where the environment is kept: `PVTC_PYTHON_VENV`, else `target/pvtc-py/venv`.
fn venv() -> PathBuf {
    match std::env::var_os("PVTC_PYTHON_VENV") {
        Some(dir) => PathBuf::from(dir),
        None => root().join("target/pvtc-py/venv"),
    }
}

/// Where maturin builds: `PVTC_PY_CARGO_TARGET`, else the workspace's `target`.
fn cargo_target() -> PathBuf {
    match std::env::var_os("PVTC_PY_CARGO_TARGET") {
        Some(dir) => PathBuf::from(dir),
        None => root().join("target"),
    }
}

/// Skips with `why`, or fails when Python is required.
fn unavailable(why: &str) {
    if std::env::var_os("PVTC_REQUIRE_PYTHON").is_some() {
        panic!("{why}, and PVTC_REQUIRE_PYTHON is set");
    }
    println!("SKIPPED: {why}");
}

/// Runs `command`, its output shown; whether it succeeded.
fn run(command: &mut Command) -> bool {
    println!("$ {command:?}");
    match command.output() {
        Ok(out) => {
            println!("{}", String::from_utf8_lossy(&out.stdout));
            println!("{}", String::from_utf8_lossy(&out.stderr));
            out.status.success()
        }
        Err(e) => {
            println!("cannot run it: {e}");
            false
        }
    }
}

/// The environment's Python with maturin, numpy and pytest, made where missing;
/// `Err` says why there is none.
fn environment() -> Result<PathBuf, String> {
    let python = venv().join("bin/python");
    let ready = |python: &Path| {
        Command::new(python)
            .args(["-c", "import maturin, numpy, pytest"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if ready(&python) {
        return Ok(python);
    }
    let system = std::env::var("PVTC_PYTHON").unwrap_or_else(|_| "python3".into());
    if !run(Command::new(&system).arg("--version")) {
        return Err(format!("no Python ({system})"));
    }
    if !python.exists() && !run(Command::new(&system).args(["-m", "venv"]).arg(venv())) {
        return Err(format!(
            "{system} cannot make a virtual environment (apt-get install python3-venv)"
        ));
    }
    let pip = [
        "-m",
        "pip",
        "install",
        "-q",
        "maturin>=1.5,<2",
        "numpy",
        "pytest",
    ];
    if !run(Command::new(&python).args(pip)) || !ready(&python) {
        return Err("pip could not install maturin, numpy and pytest".into());
    }
    Ok(python)
}

#[test]
fn the_python_package_passes_its_tests() {
    let python = match environment() {
        Ok(python) => python,
        Err(why) => return unavailable(&why),
    };
    let manifest = root().join("crates/pvtc-py/Cargo.toml");
    let built = run(Command::new(&python)
        .args(["-m", "maturin", "develop", "--quiet", "--manifest-path"])
        .arg(&manifest)
        .env("VIRTUAL_ENV", venv())
        .env("CARGO_TARGET_DIR", cargo_target()));
    assert!(built, "maturin develop failed");
    let tests = run(Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root().join("crates/pvtc-py/tests"))
        .env("PVTC_BIN", env!("CARGO_BIN_EXE_pvtc"))
        .env("PVTC_ROOT", root())
        .current_dir(root()));
    assert!(tests, "pytest failed");
}
