//! Hostile sizes in bounded memory: a 100 MB line, a million words in one block, an
//! unterminated comment running to the end of a 1 GB input, and a program with an error
//! on every line. Inputs are generated as they are read (nothing is written to disk) and
//! a counting allocator measures the peak memory the front end takes on top of what it
//! held before.

use std::io::{BufReader, Read};
use std::sync::Mutex;

use peak_alloc::PeakAlloc;
use pvt_core::{Element, EventKind, Motion};
use pvt_gcode::{compile_read, GcodeDiagnostic, GcodeOptions, ToolpathSink};

/// Counts the bytes allocated (every thread of this test binary).
#[global_allocator]
static ALLOCATOR: PeakAlloc = PeakAlloc;

/// One measurement at a time: the allocator counts every thread.
static SERIAL: Mutex<()> = Mutex::new(());

/// Runs `f` and returns its result and the most memory it held at once, in bytes.
fn peak_of<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let before = ALLOCATOR.current_usage();
    ALLOCATOR.reset_peak_usage();
    let result = f();
    (result, ALLOCATOR.peak_usage() - before)
}

/// `head`, then `pattern` repeated `times`, then `tail`, produced as it is read.
struct Generated {
    parts: Vec<(Vec<u8>, u64)>,
    at: usize,
    offset: usize,
    left: u64,
}

impl Generated {
    fn new(head: &str, pattern: &str, times: u64, tail: &str) -> BufReader<Generated> {
        // Whole patterns per copy, so a read never splits one.
        let block: Vec<u8> = pattern.repeat(4096 / pattern.len().max(1)).into_bytes();
        let per_block = (block.len() / pattern.len()) as u64;
        let mut parts = vec![(head.as_bytes().to_vec(), 1)];
        parts.push((block, times / per_block));
        parts.push((pattern.repeat((times % per_block) as usize).into_bytes(), 1));
        parts.push((tail.as_bytes().to_vec(), 1));
        let first = parts[0].1;
        BufReader::with_capacity(
            1 << 18,
            Generated {
                parts,
                at: 0,
                offset: 0,
                left: first,
            },
        )
    }
}

impl Read for Generated {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut written = 0;
        while written < buf.len() && self.at < self.parts.len() {
            let (bytes, _) = &self.parts[self.at];
            if self.left == 0 || bytes.is_empty() {
                self.at += 1;
                self.offset = 0;
                self.left = self.parts.get(self.at).map_or(0, |p| p.1);
                continue;
            }
            let n = (bytes.len() - self.offset).min(buf.len() - written);
            buf[written..written + n].copy_from_slice(&bytes[self.offset..self.offset + n]);
            written += n;
            self.offset += n;
            if self.offset == bytes.len() {
                self.offset = 0;
                self.left -= 1;
            }
        }
        Ok(written)
    }
}

/// Counts what the front end hands over.
#[derive(Default)]
struct Count {
    elements: usize,
}

impl ToolpathSink for Count {
    fn element(&mut self, _: Motion, _: &Element) {
        self.elements += 1;
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &EventKind, _: u32) {}
}

/// Compiles generated input; the errors (or none) and the peak memory.
fn compile(mut input: BufReader<Generated>) -> (Vec<GcodeDiagnostic>, usize, usize) {
    let options = GcodeOptions::default();
    let ((errors, elements), peak) = peak_of(|| {
        let mut sink = Count::default();
        let result = compile_read(&mut input, &options, &mut sink).expect("generated input");
        (
            result.err().map(|e| e.diagnostics).unwrap_or_default(),
            sink.elements,
        )
    });
    (errors, elements, peak)
}

const MIB: usize = 1 << 20;

#[test]
fn a_100_mb_line_is_measured_not_held() {
    let input = Generated::new("G21\n(", "x", 100 * MIB as u64, "\nG1 X1 F100\n");
    let (errors, elements, peak) = compile(input);
    assert_eq!(
        errors,
        [GcodeDiagnostic::LineTooLong {
            line: 2,
            length: 100 * MIB + 1,
            limit: pvt_gcode::MAX_LINE_BYTES,
            span: (4..4).into(),
        }]
    );
    assert_eq!(elements, 1, "the line after it is still read");
    assert!(peak < MIB, "peak {peak} bytes");
}

#[test]
fn a_million_words_in_one_block_are_refused_in_bounded_memory() {
    let input = Generated::new("G1", " X1", 1_000_000, "\nG1 X2 F100\n");
    let (errors, _, peak) = compile(input);
    let codes: Vec<_> = errors.iter().map(|e| e.code()).collect();
    assert_eq!(codes, ["pvtc::gcode::line_too_long"]);
    assert!(peak < MIB, "peak {peak} bytes");
}

#[test]
fn an_unterminated_comment_to_the_end_of_a_1_gb_input() {
    let head = "G21\nG1 X1 F100\n(the end is lost";
    let input = Generated::new(head, "c", 1 << 30, "");
    let (errors, elements, peak) = compile(input);
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code(), "pvtc::gcode::line_too_long");
    assert_eq!(errors[0].span(), 15..15);
    assert_eq!(elements, 1);
    assert!(peak < MIB, "peak {peak} bytes");
}

#[test]
fn an_error_on_each_of_200k_lines_keeps_a_thousand_and_counts_the_rest() {
    let input = Generated::new("G21 F100\n", "G1 X1 E7\n", 200_000, "");
    let (errors, _, peak) = compile(input);
    assert_eq!(errors.len(), pvt_gcode::MAX_KEPT_DIAGNOSTICS + 1);
    assert!(errors[..1000]
        .iter()
        .all(|e| e.code() == "pvtc::gcode::unknown_word"));
    let more = errors.last().unwrap();
    assert_eq!(more.code(), "pvtc::gcode::more_errors");
    assert!(more.to_string().starts_with("199000 more errors"), "{more}");
    assert!(peak < MIB, "peak {peak} bytes");
}

#[test]
fn warnings_past_a_thousand_are_counted_as_more_warnings() {
    let text = format!("G1 X1 F100\n{}M2\n", "G1 X1\n".repeat(1100));
    let compiled = pvt_gcode::compile(&text, &GcodeOptions::default()).expect("compiles");
    let warnings = compiled.warnings;
    assert_eq!(warnings.len(), pvt_gcode::MAX_KEPT_DIAGNOSTICS + 1);
    assert!(warnings[..1000]
        .iter()
        .all(|w| w.code() == "pvtc::gcode::zero_length_move"));
    let more = warnings.last().unwrap();
    assert_eq!(more.code(), "pvtc::gcode::more_warnings");
    assert!(more.is_warning());
    assert!(more.to_string().starts_with("100 more warnings"), "{more}");
}

#[test]
fn loops_and_calls_around_a_streamed_program_hold_only_their_bodies() {
    // A subroutine and a loop are held; the 200k lines around them stream.
    let head = "G21 F100\no<step> sub\nG91 G1 X#1\nG90\no<step> endsub\n#1 = 0\n\
                o1 while [#1 LT 1000]\n#1 = [#1 + 1]\no<step> call [0.001]\no1 endwhile\n";
    let input = Generated::new(
        head,
        "o<step> call [0.5]\nG1 Y[#<_y> + 1]\n",
        100_000,
        "M2\n",
    );
    let (errors, elements, peak) = compile(input);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(elements, 1000 + 200_000);
    assert!(peak < MIB, "peak {peak} bytes");
}
