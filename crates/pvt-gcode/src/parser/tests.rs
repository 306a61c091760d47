//! Parser tests, and the check that `grammars/gcode.ebnf` and the parser agree.

use super::*;

fn line(text: &str) -> SourceLine<'_> {
    SourceLine {
        text,
        start: 0,
        number: 1,
    }
}

fn parse(text: &str) -> Result<Block, GcodeDiagnostic> {
    let mut block = Block::default();
    parse_line(line(text), &mut block).map(|_| block)
}

fn full<O>(result: IResult<&str, O>) -> bool {
    matches!(result, Ok(("", _)))
}

/// Whether the parser of `production` accepts all of `text`; `None` for an unknown name.
fn accepts(production: &str, text: &str) -> Option<bool> {
    Some(match production {
        "program" => SourceLines::new(text).all(|l| parse_line(l, &mut Block::default()).is_ok()),
        "newline" => full(newline(text)),
        "line" => parse(text).is_ok(),
        "percent_line" => full(percent_line(text)),
        "block" => matches!(
            parse_line(line(text), &mut Block::default()),
            Ok(LineKind::Block)
        ),
        "block_delete" => full(block_delete(text)),
        "line_number" => full(line_number(text)),
        "word" => full(word(text)),
        "letter" => full(letter(text)),
        "number" => full(number(text)),
        "digit" => full(satisfy(|c: char| c.is_ascii_digit()).parse(text)),
        "comment" => full(comment(text)),
        "end_comment" => full(end_comment(text)),
        "blank" => full(satisfy(|c| c == ' ' || c == '\t').parse(text)),
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
        14,
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
    assert_eq!(error("G1 5"), ("pvtc::gcode::syntax", 3..4));
    assert_eq!(error("G1 @"), ("pvtc::gcode::unknown_word", 3..4));
    assert_eq!(error("G1 é"), ("pvtc::gcode::unknown_word", 3..5));
    assert_eq!(error("G1 X#1"), ("pvtc::gcode::unsupported", 4..6));
    assert_eq!(error("#1=5"), ("pvtc::gcode::unsupported", 0..4));
    assert_eq!(error("G1 X[1+2]"), ("pvtc::gcode::unsupported", 4..9));
    assert_eq!(error("G1 N5"), ("pvtc::gcode::syntax", 3..5));
    assert_eq!(error("N5.5 G1"), ("pvtc::gcode::syntax", 0..4));
}

#[test]
fn words_around_bad_text_are_still_read() {
    let mut block = Block::default();
    let result = parse_line(line("G1 X--1 Y2e3 Z3 #4 F100 (open"), &mut block);
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
