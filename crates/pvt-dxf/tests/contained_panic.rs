//! Panic containment: a panic inside the `dxf` crate's parse becomes `pvtc::dxf::read`,
//! and `panic_is_contained` holds for that panic only, by a flag around that one call
//! (no source-path matching): a panic elsewhere, even on the same thread right after,
//! is not contained. Its own test binary, since it installs a process-wide panic hook.

use std::cell::Cell;
use std::sync::{Mutex, Once};

thread_local! {
    /// What `panic_is_contained` said for each panic on this thread, in order.
    static SEEN: Cell<Option<bool>> = const { Cell::new(None) };
}

static HOOK: Once = Once::new();
static ORDER: Mutex<()> = Mutex::new(());

/// A hook that records, on the panicking thread, whether pvt-dxf contains the panic.
fn record_panics() {
    HOOK.call_once(|| {
        std::panic::set_hook(Box::new(|_| {
            SEEN.with(|s| s.set(Some(pvt_dxf::panic_is_contained())));
        }));
    });
}

fn regression(name: &str) -> Vec<u8> {
    let path = format!(
        "{}/../../tests/fuzz-regressions/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read(path).unwrap()
}

#[test]
fn a_panic_in_the_dxf_crate_is_contained_and_reported_as_read() {
    let _order = ORDER.lock().unwrap();
    record_panics();
    for name in ["dxf_crate_panic.dxf", "dxf_chrono_panic.dxf"] {
        SEEN.with(|s| s.set(None));
        let result =
            pvt_dxf::read_drawing(&regression(name), &pvt_dxf::DxfOptions::with_feed(1200.0));
        let e = result.err().unwrap_or_else(|| panic!("{name} reads"));
        assert_eq!(e.codes(), ["pvtc::dxf::read"], "{name}");
        // The file does make the dxf crate panic, and that panic was the contained one.
        assert_eq!(SEEN.with(Cell::get), Some(true), "{name}");
        assert!(
            !pvt_dxf::panic_is_contained(),
            "the flag is cleared after the call"
        );
    }
}

#[test]
fn any_other_panic_is_not_contained() {
    let _order = ORDER.lock().unwrap();
    record_panics();
    SEEN.with(|s| s.set(None));
    let caught = std::panic::catch_unwind(|| panic!("a bug elsewhere"));
    assert!(caught.is_err());
    assert_eq!(SEEN.with(Cell::get), Some(false));
    // Nor right after a contained one on the same thread (the flag is cleared on unwind).
    let _ = pvt_dxf::read_drawing(
        &regression("dxf_crate_panic.dxf"),
        &pvt_dxf::DxfOptions::with_feed(1200.0),
    );
    let caught = std::panic::catch_unwind(|| panic!("another bug"));
    assert!(caught.is_err());
    assert_eq!(SEEN.with(Cell::get), Some(false));
}
