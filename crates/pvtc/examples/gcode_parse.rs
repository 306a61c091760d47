//! The `gcode` crate's parse alone over a file, for the speed benchmark
//! (`bench/speed/run.sh`): the yardstick a full compile is measured against.
//!
//! ```sh
//! cargo run --release -p pvtc --example gcode_parse -- program.ngc
//! ```
//!
//! Reads the file whole (the crate parses a `&str`), parses every block and prints the
//! number of words, so the parse cannot be optimised away. It must not compile anything.

fn main() -> std::io::Result<()> {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        eprintln!("usage: gcode_parse FILE");
        std::process::exit(2);
    });
    let text = std::fs::read_to_string(path)?;
    let words: usize = gcode::parse(&text).map(|g| g.arguments().len() + 1).sum();
    println!("{words} words");
    Ok(())
}
