//! No input bytes make the reader panic: random bytes and mutated valid drawings.

use proptest::prelude::*;
use pvt_dxf::{read_drawing, DxfOptions};

fn samples() -> Vec<Vec<u8>> {
    [
        "lines_arcs.dxf",
        "polylines.dxf",
        "splines.dxf",
        "ellipses.dxf",
        "cad_part.dxf",
        "cad_part_binary.dxf",
    ]
    .iter()
    .map(|n| {
        std::fs::read(format!(
            "{}/../../samples/dxf/{n}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    })
    .collect()
}

fn options() -> DxfOptions {
    let mut o = DxfOptions::with_feed(600.0);
    o.tolerance = Some(0.01);
    o
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = read_drawing(&bytes, &options());
        let mut dxfish = b"  0\nSECTION\n  2\nENTITIES\n".to_vec();
        dxfish.extend_from_slice(&bytes);
        let _ = read_drawing(&dxfish, &options());
    }

    #[test]
    fn mutated_samples_never_panic(
        which in 0usize..6,
        edits in proptest::collection::vec((any::<u32>(), any::<u8>(), 0u8..4), 1..8),
        cut in proptest::option::of(any::<u32>()),
    ) {
        let mut bytes = samples()[which].clone();
        for (at, value, how) in edits {
            if bytes.is_empty() { break; }
            let i = at as usize % bytes.len();
            match how {
                0 => bytes[i] = value,
                1 => { bytes.remove(i); }
                2 => bytes.insert(i, value),
                _ => {
                    // Swap a digit for a different digit or sign: plausible but wrong numbers.
                    let digits = b"0123456789-.e";
                    bytes[i] = digits[value as usize % digits.len()];
                }
            }
        }
        if let Some(c) = cut {
            let len = bytes.len();
            if len > 0 { bytes.truncate(c as usize % len); }
        }
        let _ = read_drawing(&bytes, &options());
    }
}
