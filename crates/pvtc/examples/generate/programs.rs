//! Deterministic large G-code programs for benchmarks and memory tests (shared by the
//! `generate` example and the `pipeline` benchmark).

use std::io::{self, Write};

/// Writes a program of `kind` (`surfacing`, `arcs`, `pocket`, `mixed`) with about `lines` lines.
pub fn write(kind: &str, lines: usize, out: &mut impl Write) -> io::Result<()> {
    match kind {
        "surfacing" => surfacing(out, lines),
        "arcs" => arcs(out, lines),
        "pocket" => pocket(out, lines),
        "mixed" => mixed(out, lines),
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("unknown kind {kind}"),
        )),
    }
}

/// Height of the surfaced part at (x, y): gentle waves, always below zero.
fn surface(x: f64, y: f64) -> f64 {
    -2.0 + libm::sin(x * 0.05) * libm::cos(y * 0.07) - 0.001 * (x - 50.0) * (y - 40.0) / 10.0
}

/// The first five lines of a raster program: a comment, the modes, and the plunge to the
/// surface at the origin.
fn raster_start(out: &mut impl Write, kind: &str, lines: usize) -> io::Result<()> {
    writeln!(out, "({kind} benchmark program, {lines} lines)")?;
    writeln!(out, "G21 G90 G94 G17")?;
    writeln!(out, "G0 Z5.0000")?;
    writeln!(out, "G0 X0.0000 Y0.0000")?;
    writeln!(out, "G1 Z{:.4} F1500", surface(0.0, 0.0))
}

fn surfacing(out: &mut impl Write, lines: usize) -> io::Result<()> {
    raster_start(out, "surfacing", lines)?;
    let per_row = 500;
    let step = 0.2;
    let mut written = 5;
    let mut row = 0usize;
    while written < lines {
        let y = row as f64 * 0.5;
        for i in 1..=per_row {
            if written >= lines {
                break;
            }
            let k = if row.is_multiple_of(2) {
                i
            } else {
                per_row - i
            };
            let x = k as f64 * step;
            writeln!(out, "X{x:.4} Y{y:.4} Z{:.4}", surface(x, y))?;
            written += 1;
        }
        row += 1;
    }
    writeln!(out, "G0 Z5.0000")?;
    writeln!(out, "M2")
}

/// The surfacing raster with one move in ten a shallow helical arc in XY to the same
/// point (centre 1 mm above the chord's middle, about 11°); a row's first move, which
/// also steps in Y, is never one, as CAM arc fitting leaves it.
fn arcs(out: &mut impl Write, lines: usize) -> io::Result<()> {
    raster_start(out, "arcs", lines)?;
    let (per_row, step) = (500, 0.2);
    let mut written = 5;
    let mut row = 0usize;
    while written < lines {
        let y = row as f64 * 0.5;
        let forward = row.is_multiple_of(2);
        for i in 1..=per_row {
            if written >= lines {
                break;
            }
            let k = if forward { i } else { per_row - i };
            let x = k as f64 * step;
            let z = surface(x, y);
            if written.is_multiple_of(10) {
                // The centre 1 mm above the chord's middle: counterclockwise going +X.
                let (g, i_offset) = if forward { (3, 0.1) } else { (2, -0.1) };
                writeln!(out, "G{g} X{x:.4} Y{y:.4} Z{z:.4} I{i_offset:.4} J1.0000")?;
            } else {
                writeln!(out, "G1 X{x:.4} Y{y:.4} Z{z:.4}")?;
            }
            written += 1;
        }
        row += 1;
    }
    writeln!(out, "G0 Z5.0000")?;
    writeln!(out, "M2")
}

fn pocket(out: &mut impl Write, lines: usize) -> io::Result<()> {
    writeln!(out, "(pocket benchmark program, {lines} lines)")?;
    writeln!(out, "G21 G90 G94 G17")?;
    writeln!(out, "G0 X1.0000 Y0.0000")?;
    writeln!(out, "G1 F800")?;
    let mut r = 1.0;
    let mut written = 4;
    while written + 4 < lines {
        // A full circle as two half arcs, then a step-over.
        writeln!(out, "G3 X{:.4} Y0.0000 I{:.4} J0.0000", -r, -r)?;
        writeln!(out, "G3 X{r:.4} Y0.0000 I{r:.4} J0.0000")?;
        writeln!(out, "G1 X{:.4} Y0.0000", r + 0.5)?;
        r += 0.5;
        written += 3;
        if r > 20.0 {
            writeln!(out, "G1 X1.0000 Y0.0000")?;
            r = 1.0;
            written += 1;
        }
    }
    writeln!(out, "M2")
}

/// A small deterministic generator (64-bit LCG), so the file never depends on a crate.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn mixed(out: &mut impl Write, lines: usize) -> io::Result<()> {
    let mut rng = Lcg(42);
    writeln!(out, "%")?;
    writeln!(out, "(mixed benchmark program, {lines} lines)")?;
    writeln!(out, "N10 G21 G90 G94 G17 ; metric, absolute")?;
    writeln!(out, "N15 G1 F900")?;
    let (mut x, mut y) = (0.0f64, 0.0f64);
    let mut n = 20;
    let mut written = 4;
    let mut modal_g1 = true;
    while written < lines {
        let roll = rng.next();
        let (nx, ny) = (x + rng.next() * 4.0 - 2.0, y + rng.next() * 4.0 - 2.0);
        if roll < 0.6 {
            writeln!(
                out,
                "N{n} G1 X{nx:.3} Y{ny:.3} F{}",
                600 + (rng.next() * 10.0) as u32 * 100
            )?;
            modal_g1 = true;
        } else if roll < 0.8 {
            // A half circle to the new point, centre at the midpoint: always consistent.
            let (i, j) = ((nx - x) / 2.0, (ny - y) / 2.0);
            let g = if roll < 0.7 { 2 } else { 3 };
            writeln!(
                out,
                "N{n} G{g} X{:.4} Y{:.4} I{i:.4} J{j:.4} (arc)",
                x + 2.0 * i,
                y + 2.0 * j
            )?;
            let (ex, ey) = (x + 2.0 * i, y + 2.0 * j);
            let (ex, ey) = ((ex * 1e4).round() / 1e4, (ey * 1e4).round() / 1e4);
            x = ex;
            y = ey;
            modal_g1 = false;
            n += 10;
            written += 1;
            continue;
        } else if roll < 0.95 && modal_g1 {
            writeln!(out, "N{n} X{nx:.3} Y{ny:.3}")?;
        } else if roll < 0.95 {
            writeln!(out, "N{n} G1 X{nx:.3} Y{ny:.3}")?;
            modal_g1 = true;
        } else {
            writeln!(out, "N{n} G0 X{nx:.3} Y{ny:.3} ; reposition")?;
            writeln!(out, "G1 F900")?;
            modal_g1 = true;
            written += 1;
        }
        x = (nx * 1e3).round() / 1e3;
        y = (ny * 1e3).round() / 1e3;
        n += 10;
        written += 1;
    }
    writeln!(out, "M30")?;
    writeln!(out, "%")
}
