//! Writes deterministic large G-code programs for benchmarks and memory tests.
//!
//! ```sh
//! cargo run --release -p pvtc --example generate -- surfacing 1000000 > /tmp/surf_1m.ngc
//! cargo run --release -p pvtc --example generate -- pocket 100000 > /tmp/pocket_100k.ngc
//! cargo run --release -p pvtc --example generate -- mixed 10000 > /tmp/mixed_10k.ngc
//! ```
//!
//! - `surfacing`: a 3D raster of short G1 moves over a smooth surface, as CAM 3D
//!   finishing posts emit it (X Y Z on every line, 4 decimals);
//! - `arcs`: the same raster with one move in ten a shallow G2/G3 helical arc;
//! - `pocket`: concentric G2/G3 arcs and G1 step-overs (I/J centre offsets);
//! - `mixed`: N words, comments, `;` comments, modal words and feed changes between
//!   G1/G2/G3 moves, and the occasional G0 retract.
//!
//! The same kind and line count always give the same bytes.

use std::io::{self, BufWriter, Write};

mod programs;

fn main() -> io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (kind, lines) = match args.as_slice() {
        [kind, n] => (kind.as_str(), n.parse::<usize>().expect("line count")),
        _ => {
            eprintln!("usage: generate surfacing|arcs|pocket|mixed LINES");
            std::process::exit(2);
        }
    };
    let mut out = BufWriter::with_capacity(1 << 20, io::stdout().lock());
    programs::write(kind, lines, &mut out)?;
    out.flush()
}
