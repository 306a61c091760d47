//! Plain lines: the line a CAM program repeats a million times (`G1 X.. Y.. Z.. F..`),
//! recognized in one scan of its bytes so that the interpreter can run it without a
//! [`crate::block::Block`] or a [`crate::request::Request`].
//!
//! Owns the rule of what is plain: blanks, and at most one each of the words X Y Z A B C
//! F (either case, blanks allowed after the letter) with a number
//! [`crate::tokens::plain_number`] reads,
//! and G0 or G1. Such a line reads, through [`crate::parser`] and
//! [`crate::request`], as exactly these words, without a diagnostic; anything else (a
//! comment, a parameter, a repeated word, another code, a number the general reader
//! must read) is not plain, and the general path reads it. It must not change any state:
//! [`crate::interpreter`] decides whether the modal state lets it run the line.

use pvt_core::AXIS_COUNT;

use crate::codes::MotionMode;
use crate::tokens::plain_number_at;

/// The words of a plain line.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PlainLine {
    /// G0 ([`MotionMode::Rapid`]) or G1 ([`MotionMode::Linear`]), if written.
    pub motion: Option<MotionMode>,
    /// The values of X Y Z A B C (by [`pvt_core::Axis::index`]) and F, where written.
    values: [f64; FEED + 1],
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
}

/// Slot of each word a plain line may hold: the axes by index, then F, then G.
const FEED: usize = AXIS_COUNT;
const MOTION: usize = AXIS_COUNT + 1;

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
        let mut sink = Record::default();
        let mut reader = Reader::new(options, &mut sink);
        reader.plain_lines = plain_lines;
        for line in crate::parser::SourceLines::new(source) {
            if !reader.source_line(line) {
                break;
            }
        }
        let result = format!("{:?}", reader.finish());
        sink.0.push(result);
        sink.0
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
                let mut words = [None; FEED + 1];
                for word in &block.words {
                    match word.letter {
                        b'G' => motion = Some(match word.value {
                            0.0 => MotionMode::Rapid,
                            _ => MotionMode::Linear,
                        }),
                        b'F' => words[FEED] = Some(word.value.to_bits()),
                        letter => {
                            let axis = pvt_core::Axis::from_letter(char::from(letter)).unwrap();
                            words[axis.index()] = Some(word.value.to_bits());
                        }
                    }
                }
                let mut got: Vec<_> = (0..AXIS_COUNT).map(|i| plain.axis(i).map(f64::to_bits)).collect();
                got.push(plain.feed().map(f64::to_bits));
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
        for text in [
            "X1 X2", "G2 X1", "X1 (c)", "N1 X1", "X#1", "X1 0", "G1 G0", "G-0", "X",
        ] {
            assert_eq!(plain_line(text), None, "{text}");
        }
    }
}
