//! Plain lines: the line a CAM program repeats a million times (`G1 X.. Y.. Z.. F..`,
//! `G2 X.. Y.. I.. J..`), recognized in one scan of its bytes so that the interpreter
//! can run it without a [`crate::block::Block`] or a [`crate::request::Request`].
//!
//! Owns the rule of what is plain: blanks, and at most one each of the words X Y Z A B C
//! F I J (either case, blanks allowed after the letter) with a number
//! [`crate::tokens::plain_number`] reads,
//! and G0, G1, G2 or G3. Such a line reads, through [`crate::parser`] and
//! [`crate::request`], as exactly these words, without a diagnostic; anything else (a
//! comment, a parameter, a repeated word, another code, a number the general reader
//! must read) is not plain, and the general path reads it. It must not change any state:
//! [`crate::interpreter`] decides whether the modal state lets it run the line.

use pvt_core::{ArcDirection, AXIS_COUNT};

use crate::codes::MotionMode;
use crate::tokens::plain_number_at;

/// The words of a plain line.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PlainLine {
    /// G0 ([`MotionMode::Rapid`]), G1 ([`MotionMode::Linear`]), G2 or G3
    /// ([`MotionMode::Arc`]), if written.
    pub motion: Option<MotionMode>,
    /// The values of X Y Z A B C (by [`pvt_core::Axis::index`]), F, I and J, where
    /// written.
    values: [f64; J + 1],
    /// Bit `i` is set when the word of `values[i]` is written.
    written: u32,
}

impl PlainLine {
    /// The value of axis word `i` ([`pvt_core::Axis::index`]), if written.
    #[inline]
    pub fn axis(&self, i: usize) -> Option<f64> {
        (i < AXIS_COUNT && self.written & (1 << i) != 0).then(|| self.values[i])
    }

    /// The F word's value, if written.
    pub fn feed(&self) -> Option<f64> {
        (self.written & (1 << FEED) != 0).then_some(self.values[FEED])
    }

    /// True when the line has an axis word.
    pub fn has_axis_words(&self) -> bool {
        self.written & ((1 << AXIS_COUNT) - 1) != 0
    }

    /// The I and J words' values (the arc centre's offsets in the XY plane), where
    /// written.
    pub fn center_words(&self) -> [Option<f64>; 2] {
        [I, J].map(|slot| (self.written & (1 << slot) != 0).then_some(self.values[slot]))
    }

    /// True when the line has an I or J word.
    pub fn has_center_words(&self) -> bool {
        self.written & (1 << I | 1 << J) != 0
    }
}

/// Slot of each word a plain line may hold: the axes by index, then F, I, J, then G.
const FEED: usize = AXIS_COUNT;
const I: usize = AXIS_COUNT + 1;
const J: usize = AXIS_COUNT + 2;
const MOTION: usize = AXIS_COUNT + 3;

/// The words of `text` (a line without its line end) when it is plain; `None` otherwise.
pub(crate) fn plain_line(text: &str) -> Option<PlainLine> {
    let b = text.as_bytes();
    let mut line = PlainLine::default();
    let mut seen = 0u32;
    let mut at = skip_blanks(b, 0);
    while let Some(&c) = b.get(at) {
        let slot = match c.to_ascii_uppercase() {
            b'X' => 0,
            b'Y' => 1,
            b'Z' => 2,
            b'A' => 3,
            b'B' => 4,
            b'C' => 5,
            b'F' => FEED,
            b'I' => I,
            b'J' => J,
            b'G' => MOTION,
            _ => return None,
        };
        if seen & (1 << slot) != 0 {
            return None;
        }
        seen |= 1 << slot;
        let (end, value) = plain_number_at(b, skip_blanks(b, at + 1))?;
        at = skip_blanks(b, end);
        match slot {
            MOTION => {
                line.motion = Some(match value.to_bits() {
                    bits if bits == 0f64.to_bits() => MotionMode::Rapid,
                    bits if bits == 1f64.to_bits() => MotionMode::Linear,
                    bits if bits == 2f64.to_bits() => MotionMode::Arc(ArcDirection::Clockwise),
                    bits if bits == 3f64.to_bits() => {
                        MotionMode::Arc(ArcDirection::CounterClockwise)
                    }
                    _ => return None,
                })
            }
            word => line.values[word] = value,
        }
    }
    line.written = seen & !(1 << MOTION);
    Some(line)
}

#[inline(always)]
fn skip_blanks(b: &[u8], mut at: usize) -> usize {
    while matches!(b.get(at), Some(b' ' | b'\t')) {
        at += 1;
    }
    at
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GcodeOptions, Reader};
    use proptest::prelude::*;
    use pvt_core::{Element, EventKind, Motion, ToolpathSink};

    /// Everything a sink is handed, spelled out (`{:?}` of an `f64` is exact).
    #[derive(Default)]
    struct Record(Vec<String>);

    impl ToolpathSink for Record {
        fn element(&mut self, motion: Motion, element: &Element) {
            self.0.push(format!("{motion:?} {element:?}"));
        }
        fn end_contour(&mut self) {
            self.0.push("end".to_owned());
        }
        fn event(&mut self, event: &EventKind, line: u32) {
            self.0.push(format!("{event:?} at {line}"));
        }
        fn path_tolerance(&mut self, tolerance: f64) {
            self.0.push(format!("tolerance {tolerance:?}"));
        }
    }

    /// The sink's record and the result of compiling `source`, plain lines run as such
    /// or all through the general path.
    fn compiled(source: &str, options: &GcodeOptions, plain_lines: bool) -> Vec<String> {
        compiled_counting(source, options, plain_lines).0
    }

    /// [`compiled`], and how many lines ran as plain lines.
    fn compiled_counting(
        source: &str,
        options: &GcodeOptions,
        plain_lines: bool,
    ) -> (Vec<String>, usize) {
        let mut sink = Record::default();
        let mut reader = Reader::new(options, &mut sink);
        reader.plain_lines = plain_lines;
        for line in crate::parser::SourceLines::new(source) {
            if !reader.source_line(line) {
                break;
            }
        }
        let runs = reader.plain_runs;
        let result = format!("{:?}", reader.finish());
        sink.0.push(result);
        (sink.0, runs)
    }

    /// Arcs as CAM writes them: G2/G3 with X Y (Z) and I J (one of them left out where it
    /// is zero, and full circles without axis words), their centres consistent to the
    /// four decimals written, under G90/G91, G90.1/G91.1, G20/G21 and a work offset.
    /// Each runs as a plain line, to the general path's elements bit for bit.
    #[test]
    fn plain_arcs_run_as_the_general_path_runs_them() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut runs_seen = 0;
        for case in 0..64 {
            let (incremental, absolute_centers, inch) =
                (case & 1 != 0, case & 2 != 0, case & 4 != 0);
            // At the program's origin (work offset 1 applied), then in the modes.
            let mut source = format!(
                "G17 {} G90 {} F{}\nG0 X0 Y0\n{}\n",
                if inch { "G20" } else { "G21" },
                if absolute_centers { "G90.1" } else { "G91.1" },
                if inch { 20 } else { 600 },
                if incremental { "G91" } else { "G90" },
            );
            let (mut x, mut y) = (0.0f64, 0.0f64);
            let mut arcs = 0;
            for _ in 0..40 {
                let radius = 0.5 + 5.0 * next();
                let angle = std::f64::consts::TAU * next();
                let (cx, cy) = (x - radius * libm::cos(angle), y - radius * libm::sin(angle));
                let full = next() < 0.1;
                let turn = if full { 0.0 } else { 3.0 * (next() - 0.5) };
                let (ex, ey) = (
                    cx + radius * libm::cos(angle + turn),
                    cy + radius * libm::sin(angle + turn),
                );
                let (ex, ey) = (
                    format!("{ex:.4}").parse::<f64>().unwrap(),
                    format!("{ey:.4}").parse::<f64>().unwrap(),
                );
                let code = if next() < 0.5 { "G2" } else { "G3" };
                let (i, j) = match absolute_centers {
                    true => (cx, cy),
                    false => (cx - x, cy - y),
                };
                let mut text = code.to_owned();
                if !full {
                    let (wx, wy) = match incremental {
                        true => (ex - x, ey - y),
                        false => (ex, ey),
                    };
                    text += &format!(" X{wx:.4} Y{wy:.4}");
                    if next() < 0.3 {
                        text += &format!(" Z{:.4}", next() - 0.5);
                    }
                    (x, y) = (ex, ey);
                }
                let (i, j) = (format!("{i:.4}"), format!("{j:.4}"));
                for (letter, value) in [("I", i), ("J", j)] {
                    if value.trim_start_matches('-') != "0.0000" || next() < 0.5 {
                        text += &format!(" {letter}{value}");
                    }
                }
                if next() < 0.2 {
                    text += &format!(" F{}", 100 + (next() * 900.0) as u32);
                }
                source += &text;
                source.push('\n');
                arcs += 1;
            }
            let options = GcodeOptions {
                work_offsets: {
                    let mut offsets = [[0.0; 6]; 9];
                    offsets[0] = [10.0, -3.3, 0.7, 0.0, 0.0, 0.0];
                    offsets
                },
                ..GcodeOptions::default()
            };
            let (plain, runs) = compiled_counting(&source, &options, true);
            assert_eq!(plain, compiled(&source, &options, false), "{source}");
            let elements = plain.iter().filter(|r| r.starts_with("Feed")).count();
            let result = plain.last().unwrap();
            let settled = elements >= arcs && result.starts_with("Ok");
            assert!(settled, "{elements} moves, {arcs} arcs\n{source}\n{result}");
            runs_seen += runs;
        }
        assert!(runs_seen > 64 * 40 * 9 / 10, "{runs_seen} plain arcs ran");
    }

    fn number() -> impl Strategy<Value = String> {
        prop_oneof![
            6 => (-2000i32..2000, 0u32..5).prop_map(|(n, d)| match d {
                0 => n.to_string(),
                d => format!("{:.*}", d as usize, f64::from(n) / 7.0),
            }),
            1 => prop::sample::select(vec![
                "0", "-0", "+1", "1.", ".5", "-.5", "00", "01", "1.0", "1 0", "1e3", "1..2",
                "", "#1", "[1+2]", "12345678901234567", "9.87654321", "1E300", "-0.0000",
            ])
            .prop_map(str::to_owned),
        ]
    }

    fn word() -> impl Strategy<Value = String> {
        let letter = prop::sample::select(vec![
            "X", "Y", "Z", "A", "B", "C", "F", "x", "f", "G", "g", "I", "J", "R", "P", "S", "M",
        ]);
        let code = prop::sample::select(vec![
            "G0",
            "G1",
            "G01",
            "g1",
            "G2",
            "G3",
            "G20",
            "G21",
            "G90",
            "G91",
            "G93",
            "G94",
            "G17",
            "G18",
            "G53",
            "G92",
            "G92.1",
            "G7",
            "G8",
            "G61",
            "G64",
            "G80",
            "G55",
            "G10 L2 P2 R30",
            "G10 L2 P2 X1",
            "G41 D1",
            "G41.1 D2",
            "G40",
            "G5.2",
            "G5.3",
            "M2",
            "M3",
            "M98",
            "G1.0",
            "G0.0",
            "G-0",
            "G100",
        ]);
        prop_oneof![
            8 => (letter, prop::sample::select(vec!["", " ", "\t"]), number())
                .prop_map(|(l, blank, n)| format!("{l}{blank}{n}")),
            2 => code.prop_map(str::to_owned),
            1 => prop::sample::select(vec!["(cut)", "(MSG, hi)", ";end", "#1=2", "N10", "/", "%", "o100 sub"])
                .prop_map(str::to_owned),
        ]
    }

    fn line() -> impl Strategy<Value = String> {
        let separator = prop::sample::select(vec![" ", "", "  ", "\t"]);
        (
            prop::sample::select(vec!["", " ", "\t"]),
            prop::collection::vec((word(), separator), 0..6),
        )
            .prop_map(|(lead, words)| {
                let mut text = lead.to_owned();
                for (word, separator) in words {
                    text.push_str(&word);
                    text.push_str(separator);
                }
                text
            })
    }

    fn options() -> impl Strategy<Value = GcodeOptions> {
        (
            prop::sample::select(vec![None, Some(600.0), Some(0.0)]),
            prop::sample::select(vec![None, Some(pvt_core::Units::Inch)]),
            any::<bool>(),
        )
            .prop_map(|(default_feed, units, offsets)| {
                let mut work_offsets = [[0.0; 6]; 9];
                if offsets {
                    work_offsets[0] = [10.0, -3.3, 0.7, 15.0, 0.0, -2.0];
                    work_offsets[1] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
                }
                GcodeOptions {
                    default_feed,
                    units,
                    work_offsets,
                    ..GcodeOptions::default()
                }
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        /// Running plain lines as such changes nothing: every element bit for bit, every
        /// contour end and event, every diagnostic with its span, in order.
        #[test]
        fn plain_lines_run_as_the_general_path_runs_them(
            lines in prop::collection::vec(line(), 0..24),
            options in options(),
        ) {
            let source = lines.join("\n");
            prop_assert_eq!(
                compiled(&source, &options, true),
                compiled(&source, &options, false),
                "{}", source
            );
        }

        /// A line is plain exactly when the parser reads it as G0/G1, axis and F words,
        /// each letter once, without a diagnostic; and then as the same words.
        #[test]
        fn a_plain_line_is_what_the_parser_reads(text in line()) {
            let mut block = crate::block::Block::default();
            let params = crate::params::Parameters::default();
            let source_line = crate::parser::SourceLine { text: &text, start: 0, number: 1 };
            let parsed = crate::parser::parse_line(source_line, &mut block, &params);
            if let Some(plain) = plain_line(&text) {
                prop_assert_eq!(parsed, Ok(crate::parser::LineKind::Block));
                let mut motion = None;
                let mut words = [None; J + 1];
                for word in &block.words {
                    match word.letter {
                        b'G' => motion = Some(match word.value {
                            0.0 => MotionMode::Rapid,
                            1.0 => MotionMode::Linear,
                            2.0 => MotionMode::Arc(ArcDirection::Clockwise),
                            _ => MotionMode::Arc(ArcDirection::CounterClockwise),
                        }),
                        b'F' => words[FEED] = Some(word.value.to_bits()),
                        b'I' => words[I] = Some(word.value.to_bits()),
                        b'J' => words[J] = Some(word.value.to_bits()),
                        letter => {
                            let axis = pvt_core::Axis::from_letter(char::from(letter)).unwrap();
                            words[axis.index()] = Some(word.value.to_bits());
                        }
                    }
                }
                let mut got: Vec<_> = (0..AXIS_COUNT).map(|i| plain.axis(i).map(f64::to_bits)).collect();
                got.push(plain.feed().map(f64::to_bits));
                got.extend(plain.center_words().map(|w| w.map(f64::to_bits)));
                prop_assert_eq!(got, words.to_vec());
                prop_assert_eq!(plain.motion, motion);
                prop_assert!(block.message.is_none() && block.assignments.is_empty());
            }
        }
    }

    /// Plain lines in bodies (a subroutine, a loop, a Fanuc subprogram) run as the
    /// general path runs them, warnings of repeated bodies included.
    #[test]
    fn plain_lines_in_bodies_run_as_the_general_path_runs_them() {
        let source = "G21 G90 G1 F600\n\
            o100 sub\n G91\n X1 Y1\n G1 X2\n X0 Y0\n G90\no100 endsub\n\
            o100 call\n\
            o1 repeat [3]\n G0 X5\n X5\n G1 Y-1 F300\no1 endrepeat\n\
            M98 P200 L2\n\
            G1 X9 Z1\n\
            M30\n\
            O200\n G91 X0.5\n G90\nM99\n";
        for options in [
            GcodeOptions::default(),
            GcodeOptions {
                units: Some(pvt_core::Units::Inch),
                ..GcodeOptions::default()
            },
        ] {
            let plain = compiled(source, &options, true);
            assert!(
                plain
                    .iter()
                    .filter(|r| r.starts_with("Feed") || r.starts_with("Rapid"))
                    .count()
                    > 4
            );
            assert_eq!(plain, compiled(source, &options, false));
        }
    }

    #[test]
    fn plain_and_not_plain() {
        let plain = plain_line(" G1 x1.5\tY -2 F1500 ").unwrap();
        assert_eq!(plain.motion, Some(MotionMode::Linear));
        assert_eq!(plain.axis(0), Some(1.5));
        assert_eq!(plain.axis(1), Some(-2.0));
        assert_eq!(plain.axis(2), None);
        assert_eq!(plain.feed(), Some(1500.0));
        assert_eq!(plain_line(""), Some(PlainLine::default()));
        let arc = plain_line("G3 X1 Y0 i0.5 J-1").unwrap();
        assert_eq!(
            arc.motion,
            Some(MotionMode::Arc(ArcDirection::CounterClockwise))
        );
        assert_eq!(arc.center_words(), [Some(0.5), Some(-1.0)]);
        for text in [
            "X1 X2", "G2 X1 K1", "G2 R1", "I1 I2", "X1 (c)", "N1 X1", "X#1", "X1 0", "G1 G0",
            "G-0", "G4", "X",
        ] {
            assert_eq!(plain_line(text), None, "{text}");
        }
    }
}
