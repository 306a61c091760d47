//! What the workspace manifest declares about licensing and origin is true: both licence
//! texts of `MIT OR Apache-2.0` are in the repository root, and no placeholder repository
//! address is published.

use pvtc_tests::root;

#[test]
fn both_declared_licences_are_present_and_no_placeholder_repository() {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    assert!(manifest.contains("license = \"MIT OR Apache-2.0\""));
    assert!(
        !manifest.contains("example.invalid"),
        "Cargo.toml names a placeholder repository"
    );
    let mit = std::fs::read_to_string(root().join("LICENSE-MIT")).unwrap();
    assert!(mit.starts_with("MIT License\n\nCopyright (c) 2026 the pvtc authors\n"));
    assert!(mit.contains("THE SOFTWARE IS PROVIDED \"AS IS\""));
    let apache = std::fs::read_to_string(root().join("LICENSE-APACHE")).unwrap();
    assert!(apache.contains("Apache License\n                        Version 2.0, January 2004"));
    assert!(apache.contains("END OF TERMS AND CONDITIONS"));
    assert!(apache.contains("Copyright (c) 2026 the pvtc authors"));
}
