//! No input panics, and every diagnostic points into the source on a character boundary.

use proptest::prelude::*;
use pvt_gcode::{compile, line_col, GcodeOptions};

/// Compiles `source` and checks every invariant a caller relies on.
fn check(source: &str) {
    let options = GcodeOptions::default();
    let diagnostics = match compile(source, &options) {
        Ok(compiled) => {
            for e in compiled.toolpath.contours.iter().flat_map(|c| &c.elements) {
                assert!(e.start.iter().chain(&e.end).all(|x| x.is_finite()), "{e:?}");
                assert!(e.feed.is_finite() && e.feed > 0.0, "{e:?}");
                assert!(e.span.start <= e.span.end && e.span.end <= source.len());
            }
            assert!(compiled
                .toolpath
                .contours
                .iter()
                .all(|c| !c.elements.is_empty()));
            compiled.warnings
        }
        Err(errors) => {
            assert!(!errors.diagnostics.is_empty());
            let starts: Vec<_> = errors.diagnostics.iter().map(|d| d.span().start).collect();
            assert!(
                starts.windows(2).all(|w| w[0] <= w[1]),
                "errors in source order"
            );
            errors.diagnostics
        }
    };
    for d in &diagnostics {
        let span = d.span();
        assert!(span.start <= span.end && span.end <= source.len(), "{d:?}");
        assert!(
            source.is_char_boundary(span.start) && source.is_char_boundary(span.end),
            "{d:?}"
        );
        let _ = line_col(source, span.start);
        assert!(!d.to_string().is_empty());
    }
}

/// Tokens that real and broken programs are made of.
fn token() -> impl Strategy<Value = String> {
    let fixed = prop::sample::select(vec![
        "G0",
        "G1",
        "G2",
        "G3",
        "G17",
        "G18",
        "G19",
        "G20",
        "G21",
        "G90",
        "G91",
        "G94",
        "G80",
        "G81",
        "G41",
        "G38.2",
        "M0",
        "M1",
        "M2",
        "M30",
        "M6",
        "F0",
        "F-1",
        "F100",
        "R-5",
        "R0",
        "I0",
        "J0",
        "K0",
        "N10",
        "/",
        "%",
        "(",
        ")",
        "(c)",
        ";c",
        "#1",
        "[",
        "Q5",
        "@",
        "é",
        "\u{feff}",
        "X",
        "1e3",
        ".",
        "-",
        " ",
        "\t",
        "\n",
        "\r\n",
        "\r",
        "G1.5",
        "X1e400",
        "X99999999999999999999999999999999999999999999999999999999999999999999999",
    ])
    .prop_map(str::to_owned);
    let word = (
        prop::sample::select(vec![
            'X', 'Y', 'Z', 'A', 'B', 'C', 'I', 'J', 'K', 'R', 'F', 'x', 'i',
        ]),
        -1e4f64..1e4,
    )
        .prop_map(|(l, v)| format!("{l}{v:.3}"));
    let small = (
        prop::sample::select(vec!['X', 'Y', 'Z', 'I', 'J', 'R']),
        -3i32..4,
    )
        .prop_map(|(l, v)| format!("{l}{v}"));
    prop_oneof![fixed, word, small]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_strings_never_panic(source in any::<String>()) {
        check(&source);
    }

    #[test]
    fn printable_ascii_never_panics(source in "[ -~\n\r\t]{0,200}") {
        check(&source);
    }

    #[test]
    fn plausible_token_sequences_never_panic(tokens in prop::collection::vec(token(), 0..80)) {
        check(&tokens.join(" "));
        check(&tokens.concat());
    }
}

#[test]
fn pathological_inputs() {
    for source in [
        "G2 X1e300",
        &format!("G91 G2 X{n} I{n} F1\nG2 X{n} I{n}", n = "9".repeat(300)),
        &format!("G20 G0 X{}", "9".repeat(308)),
        &format!(
            "G0 X{}\nG3 X0 Y{} R-{} F1",
            "1".repeat(300),
            "1".repeat(300),
            "1".repeat(299)
        ),
        "G2 X0.0000000001 R0.00000000005 F1",
        "G3 I1e-300 F1",
        "(((((((",
        ")))))",
        "\u{feff}\u{feff}G0 X1",
        "G0 X1\r",
        "\r\r\r",
        "N",
        "N99999999999999999999999999999",
        "/",
        "%%%",
        "G",
        "G0 X-",
        "X+.",
    ] {
        check(source);
    }
}
