//! Parser tests, and the check that `grammars/gcode.ebnf` and the parser agree.

use super::*;
use crate::tokens::short_decimal;
use crate::value::Reader;

/// Parameters the examples may read: `#1` = 3, `#<scale>` = 2.
fn params() -> Parameters {
    let mut p = Parameters::default();
    p.set(&ParamRef::Numbered(1), 3.0);
    p.set(&ParamRef::Named("scale".to_owned()), 2.0);
    p
}

/// Whether a value reader accepts all of `text` as one value starting with `first`.
fn value(text: &str, first: char) -> bool {
    let p = params();
    let mut reader = Reader::new(text, 0, 0, &p);
    text.starts_with(first) && reader.real_value().is_ok() && reader.pos == text.len()
}

fn line(text: &str) -> SourceLine<'_> {
    SourceLine {
        text,
        start: 0,
        number: 1,
    }
}

fn parse(text: &str) -> Result<Block, GcodeDiagnostic> {
    let mut block = Block::default();
    parse_line(line(text), &mut block, &params()).map(|_| block)
}

fn full<O>(result: IResult<&str, O>) -> bool {
    matches!(result, Ok(("", _)))
}

/// Whether the parser of `production` accepts all of `text`; `None` for an unknown name.
fn accepts(production: &str, text: &str) -> Option<bool> {
    Some(match production {
        "program" => {
            SourceLines::new(text).all(|l| parse_line(l, &mut Block::default(), &params()).is_ok())
        }
        "newline" => full(newline(text)),
        "line" => {
            matches!(crate::oword::parse_control(text, 0), Some(Ok(_))) || parse(text).is_ok()
        }
        "percent_line" => full(percent_line(text)),
        "control_line" => matches!(crate::oword::parse_control(text, 0), Some(Ok(_))),
        "block" => matches!(
            parse_line(line(text), &mut Block::default(), &params()),
            Ok(LineKind::Block)
        ),
        "block_delete" => full(block_delete(text)),
        "line_number" => full(line_number(text)),
        "word" => parse(text).is_ok_and(|b| b.words.len() == 1),
        "digits" => {
            text.chars()
                .all(|c| c.is_ascii_digit() || c == ' ' || c == '\t')
                && full(number(text))
        }
        "letter" => full(letter(text)),
        "number" => full(number(text)),
        "digit" => full(satisfy(|c: char| c.is_ascii_digit()).parse(text)),
        "comment" => full(comment(text)),
        "end_comment" => full(end_comment(text)),
        "blank" => full(satisfy(|c| c == ' ' || c == '\t').parse(text)),
        "real_value" => value(text, text.chars().next().unwrap_or(' ')),
        "expression" => value(text, '['),
        "parameter" => value(text, '#'),
        "function" => value(
            text,
            text.chars()
                .next()
                .filter(char::is_ascii_alphabetic)
                .unwrap_or(' '),
        ),
        "assignment" => parse(text).is_ok_and(|b| b.assignments.len() == 1 && b.words.is_empty()),
        "checksum" => full(checksum(text)),
        "message" => matches!(comment(text), Ok(("", inside)) if message(inside).is_some()),
        _ => return None,
    })
}

fn unescape(text: &str) -> String {
    text.replace("\\n", "\n")
        .replace("\\r", "\r")
        .replace("\\t", "\t")
        .replace("\\s", " ")
        .replace("\\u{feff}", "\u{feff}")
}

#[test]
fn grammar_file_examples() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../grammars/gcode.ebnf");
    let grammar = std::fs::read_to_string(path).expect("grammars/gcode.ebnf is readable");
    let mut production: Option<&str> = None;
    let mut examples = std::collections::BTreeMap::<&str, usize>::new();
    for text in grammar.lines() {
        let head = text.split(" = ").next().unwrap_or("");
        if text.contains(" = ")
            && !head.is_empty()
            && head.chars().all(|c| c.is_ascii_lowercase() || c == '_')
        {
            assert!(
                accepts(head, "").is_some(),
                "production `{head}` has no parser in the test table"
            );
            production = Some(head);
            examples.insert(head, 0);
            continue;
        }
        let trimmed = text.trim_start();
        let (expect, body) = if let Some(b) = trimmed.strip_prefix("(* example: ") {
            (true, b)
        } else if let Some(b) = trimmed.strip_prefix("(* rejected: ") {
            (false, b)
        } else {
            continue;
        };
        let name = production.expect("an example follows a production");
        let example = unescape(
            body.strip_suffix(" *)")
                .expect("an example ends with ` *)`"),
        );
        assert_eq!(
            accepts(name, &example),
            Some(expect),
            "{name}: {example:?} should be {}",
            if expect { "accepted" } else { "rejected" }
        );
        if expect {
            *examples.entry(name).or_default() += 1;
        }
    }
    for (name, count) in &examples {
        assert!(*count > 0, "production `{name}` has no example");
    }
    assert_eq!(
        examples.len(),
        23,
        "every parser in the table has a production: {examples:?}"
    );
}

#[test]
fn words_keep_spans_and_values() {
    let b = parse("n10 g1x-.5 Y3. f+2 (c) z 7").unwrap();
    assert_eq!(b.line_number, Some(10));
    let got: Vec<_> = b
        .words
        .iter()
        .map(|w| (w.letter_char(), w.value, w.start, w.end))
        .collect();
    assert_eq!(
        got,
        [
            ('G', 1.0, 4, 6),
            ('X', -0.5, 6, 10),
            ('Y', 3.0, 11, 14),
            ('F', 2.0, 15, 18),
            ('Z', 7.0, 23, 26)
        ]
    );
}

#[test]
fn block_delete_and_comments() {
    let b = parse(" / G0 X1 ; rest (").unwrap();
    assert!(b.block_delete);
    assert_eq!(b.words.len(), 2);
    assert!(parse("(a)(b)G1(c)").unwrap().words.len() == 1);
}

fn error(text: &str) -> (&'static str, std::ops::Range<usize>) {
    let d = parse(text).unwrap_err();
    (d.code(), d.span())
}

#[test]
fn malformed_text_is_located() {
    assert_eq!(error("G1 X--1"), ("pvtc::gcode::syntax", 3..7));
    assert_eq!(error("G1 X"), ("pvtc::gcode::syntax", 3..4));
    assert_eq!(error("G1 X1e3"), ("pvtc::gcode::syntax", 5..7));
    assert_eq!(error("G1 (open"), ("pvtc::gcode::syntax", 3..8));
    assert_eq!(error("G1 ~"), ("pvtc::gcode::unknown_word", 3..4));
    assert_eq!(error("G1 @"), ("pvtc::gcode::syntax", 3..4));
    assert_eq!(error("G1 é"), ("pvtc::gcode::unknown_word", 3..5));
    assert_eq!(
        error("G1 X#<nope>"),
        ("pvtc::gcode::undefined_parameter", 4..11)
    );
    assert_eq!(error("#1"), ("pvtc::gcode::syntax", 0..2));
    assert_eq!(error("G1 X[1+2"), ("pvtc::gcode::syntax", 4..8));
    assert_eq!(error("G1 X[1/0]"), ("pvtc::gcode::math_error", 6..7));
    assert_eq!(error("G1 X[SQRT[-1]]"), ("pvtc::gcode::math_error", 5..13));
    assert_eq!(error("G1 X#0"), ("pvtc::gcode::out_of_range", 4..6));
    assert_eq!(error("G1 X1 *1"), ("pvtc::gcode::checksum_mismatch", 6..8));
    assert_eq!(error("o100 sub"), ("pvtc::gcode::oword", 0..8));
    assert_eq!(
        error("G92 Z[25.0 - #<_hal[plasmac.float-switch-travel]>]"),
        ("pvtc::gcode::unsupported", 13..49)
    );
    assert_eq!(error("G1 N5"), ("pvtc::gcode::syntax", 3..5));
    assert_eq!(error("N5.5 G1"), ("pvtc::gcode::syntax", 0..4));
}

#[test]
fn words_around_bad_text_are_still_read() {
    let mut block = Block::default();
    let result = parse_line(line("G1 X--1 Y2e3 Z3 #4 F100 (open"), &mut block, &params());
    // Only the first error of the line is reported.
    assert_eq!(result.unwrap_err().span(), 3..7);
    let letters: String = block.words.iter().map(Word::letter_char).collect();
    assert_eq!(
        letters, "GZF",
        "X--1, Y2e3 and #4 are bad; the rest is read"
    );
}

#[test]
fn huge_numbers_are_errors_not_infinity() {
    let text = format!("X{}", "9".repeat(400));
    let d = parse(&text).unwrap_err();
    assert_eq!(d.code(), "pvtc::gcode::syntax");
    assert_eq!(d.span(), 0..401);
    assert!(parse(&format!("X{}", "9".repeat(300))).is_ok());
}

#[test]
fn lines_handle_crlf_bom_and_missing_final_newline() {
    let src = "\u{feff}G0\r\nG1\n\nG2";
    let lines: Vec<_> = SourceLines::new(src)
        .map(|l| (l.text, l.start, l.number))
        .collect();
    assert_eq!(
        lines,
        [("G0", 3, 1), ("G1", 7, 2), ("", 10, 3), ("G2", 11, 4)]
    );
    assert_eq!(SourceLines::new("G0\n").count(), 1);
    assert_eq!(SourceLines::new("").count(), 0);
}

#[test]
fn numbers_at_the_end_of_a_line_keep_their_fraction() {
    // nom 8.0.0's `digit0` on a &str that is all digits reports the wrong remainder, so a
    // `recognize` around it cut `4.95` to `4.`; the parser must not use it.
    assert_eq!(number("4.95"), Ok(("", "4.95")));
    assert_eq!(parse("G0 Y4.95").unwrap().words[1].value, 4.95);
}

#[test]
fn blanks_inside_numbers_join_the_digits() {
    let b = parse("G 1 X 1 0.5 Y- 2 .5").unwrap();
    let got: Vec<_> = b.words.iter().map(|w| (w.letter_char(), w.value)).collect();
    assert_eq!(got, [('G', 1.0), ('X', 10.5), ('Y', -2.5)]);
    assert_eq!(parse("G1 5").unwrap().words[0].value, 15.0);
}

fn value_of(text: &str) -> f64 {
    let b = parse(&format!("X{text}")).unwrap_or_else(|d| panic!("{text}: {d}"));
    b.words[0].value
}

#[test]
fn expressions_follow_rs274ngc_precedence() {
    assert_eq!(value_of("[1 + 2 * 3]"), 7.0);
    assert_eq!(value_of("[2 ** 3 ** 2]"), 64.0);
    assert_eq!(value_of("[-2 ** 2]"), 4.0);
    assert_eq!(value_of("[7 MOD 3]"), 1.0);
    assert_eq!(value_of("[-7 MOD 3]"), 2.0);
    assert_eq!(value_of("[1 + 1 EQ 2]"), 1.0);
    assert_eq!(value_of("[1 LT 2 AND 3 GE 3]"), 1.0);
    assert_eq!(value_of("[0 OR 0 XOR 1]"), 1.0);
    assert_eq!(value_of("[1 NE 1]"), 0.0);
    assert_eq!(value_of("[#<scale>*-25.372]"), -50.744);
    assert_eq!(value_of("-#1"), -3.0);
    assert_eq!(value_of("##1"), 0.0);
    assert_eq!(value_of("#[#1-2]"), 3.0);
    assert_eq!(value_of("ABS[-2]"), 2.0);
    assert!((value_of("SIN[30]") - 0.5).abs() < 1e-12);
    assert!((value_of("COS[60]") - 0.5).abs() < 1e-12);
    assert!((value_of("ATAN[1]/[1]") - 45.0).abs() < 1e-12);
    assert!((value_of("ACOS[0]") - 90.0).abs() < 1e-12);
    assert_eq!(value_of("FIX[-1.5]"), -2.0);
    assert_eq!(value_of("FUP[1.2]"), 2.0);
    assert_eq!(value_of("ROUND[2.5]"), 3.0);
    assert_eq!(value_of("SQRT[16]"), 4.0);
    assert!((value_of("LN[EXP[2]]") - 2.0).abs() < 1e-12);
    assert_eq!(value_of("EXISTS[#<scale>]"), 1.0);
    assert_eq!(value_of("EXISTS[#<other>]"), 0.0);
    assert_eq!(value_of("[[1+2]/[3-1]]"), 1.5);
}

#[test]
fn assignments_are_collected_not_applied() {
    let b = parse("#1 = 5 #<a b> = [#1 + 1] G1 X#1").unwrap();
    assert_eq!(b.words[1].value, 3.0, "X reads #1 from before the line");
    assert_eq!(b.assignments.len(), 2);
    assert_eq!(b.assignments[0].value, 5.0);
    assert_eq!(b.assignments[1].param, ParamRef::Named("ab".to_owned()));
    assert_eq!(b.assignments[1].value, 4.0);
}

#[test]
fn messages_checksums_and_program_numbers() {
    let b = parse("G0 X1 (MSG, change tool) ").unwrap();
    assert_eq!(b.message.as_deref(), Some("change tool"));
    assert!(parse("N1 G1 X1*96").is_ok());
    let o = parse("O1001 (part)").unwrap();
    assert_eq!(o.words[0].letter, b'O');
    assert_eq!(error("O1 G1 X1").0, "pvtc::gcode::oword");
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    let deep = format!("X{}1{}", "[".repeat(10_000), "]".repeat(10_000));
    assert_eq!(error(&deep).0, "pvtc::gcode::syntax");
    let hashes = format!("X{}1", "#".repeat(10_000));
    assert_eq!(error(&hashes).0, "pvtc::gcode::syntax");
}

#[test]
fn short_decimals_take_the_fast_path_and_long_ones_do_not() {
    assert_eq!(short_decimal("-12.5"), Some(-12.5));
    assert_eq!(short_decimal("+.25"), Some(0.25));
    assert_eq!(short_decimal("7."), Some(7.0));
    assert_eq!(
        short_decimal("-0").map(f64::to_bits),
        Some((-0.0f64).to_bits())
    );
    assert_eq!(short_decimal("123456789012345"), Some(123456789012345.0));
    assert_eq!(short_decimal("1234567890123456"), None);
    assert_eq!(short_decimal("1 0"), None);
    assert_eq!(short_decimal("."), None);
    assert_eq!(number_value("0.1000000000000000055511151231257827"), 0.1);
}

proptest::proptest! {
    /// The fast path is bit-identical to the standard library's correctly rounded parse.
    #[test]
    fn number_value_is_bit_identical_to_str_parse(
        negative in proptest::bool::ANY,
        whole in 0u64..1_000_000_000,
        fraction in 0u64..10_000_000,
        places in 0usize..8,
    ) {
        let sign = if negative { "-" } else { "" };
        let text = if places == 0 {
            format!("{sign}{whole}")
        } else {
            let f = fraction % 10u64.pow(places as u32);
            format!("{sign}{whole}.{f:0places$}")
        };
        let expected: f64 = text.parse().unwrap();
        proptest::prop_assert_eq!(number_value(&text).to_bits(), expected.to_bits(), "{}", text);
    }
}

/// What the general value reader makes of `text` (value and length), or `None`.
fn general_value(text: &str) -> Option<(usize, u64)> {
    let p = Parameters::default();
    let mut reader = Reader::new(text, 0, 0, &p);
    let value = reader.real_value().ok()?;
    Some((reader.pos, value.to_bits()))
}

#[test]
fn plain_numbers_leave_the_unusual_to_the_general_reader() {
    assert_eq!(plain_number(b"-12.5 Y1"), Some((5, -12.5)));
    assert_eq!(plain_number(b"3Y1"), Some((1, 3.0)));
    for unusual in [
        "1 0",
        "1. 5",
        "1e3",
        "1.2.3",
        "- 2",
        "[1]",
        "#1",
        "1234567890123456",
    ] {
        assert_eq!(plain_number(unusual.as_bytes()), None, "{unusual}");
    }
}

proptest::proptest! {
    /// Where the fast path answers, it answers as the general reader does, bit for bit.
    #[test]
    fn plain_number_agrees_with_the_general_reader(text in "[-+]?[0-9]{0,9}(\\.[0-9]{0,8})?[ XE.0-9]{0,3}") {
        if let Some((len, value)) = plain_number(text.as_bytes()) {
            proptest::prop_assert_eq!(general_value(&text[..len]), Some((len, value.to_bits())));
            let stop = general_value(&text).map(|(n, _)| n);
            proptest::prop_assert!(stop.is_none() || stop == Some(len), "{} {:?}", text, stop);
        }
    }
}

/// Lines of words, nearly: letters (N, O and lower case among them), plain and unusual
/// numbers, blanks, and now and then a comment, parameter or stray character.
fn near_word_lines() -> impl proptest::strategy::Strategy<Value = String> {
    use proptest::prelude::*;
    let letter = prop::sample::select(b"GXYZIJKFSMPRNOxgab".to_vec());
    let number = prop::sample::select(vec![
        "0",
        "1",
        "-2.5",
        "+.5",
        "10.",
        "0001.2500",
        "1 0",
        "1e3",
        "1..2",
        "",
        "#1",
        "[1]",
        "123456789012345678",
        "-0",
        "7.0000001",
    ]);
    let piece = prop_oneof![
        8 => (letter, prop::sample::select(vec!["", " ", "\t"]), number)
            .prop_map(|(l, blank, n)| format!("{}{blank}{n}", char::from(l))),
        1 => prop::sample::select(vec!["(c)", ";x", "#1=2", "$1", "@2", "%", "/", "*5", "é"])
            .prop_map(str::to_owned),
    ];
    (
        prop::sample::select(vec!["", " "]),
        prop::collection::vec((piece, prop::sample::select(vec!["", " ", "  "])), 0..7),
    )
        .prop_map(|(lead, pieces)| {
            let mut text = lead.to_owned();
            for (piece, gap) in pieces {
                text.push_str(&piece);
                text.push_str(gap);
            }
            text
        })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(5_000))]

    /// A line of words alone read without the general loop gives the block and result
    /// the general loop gives, words, values (bit for bit) and spans.
    #[test]
    fn words_alone_read_as_the_general_loop_reads_them(text in near_word_lines(), start in 0usize..100) {
        let params = Parameters::default();
        let line = SourceLine { text: &text, start, number: 7 };
        let (mut fast, mut general) = (Block::default(), Block::default());
        let fast_result = super::parse(line, &mut fast, &params, true);
        let general_result = super::parse(line, &mut general, &params, false);
        proptest::prop_assert_eq!(fast_result, general_result, "{:?}", text);
        proptest::prop_assert_eq!(format!("{fast:?}"), format!("{general:?}"), "{:?}", text);
    }
}
