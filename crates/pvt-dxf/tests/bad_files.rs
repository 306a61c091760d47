//! Bad drawings give clear errors with exact codes, and no toolpath.

use pvt_dxf::{read_drawing, DxfError, DxfOptions};

fn bad(name: &str) -> Vec<DxfError> {
    let path = format!("{}/tests/bad/{name}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(path).expect("bad file");
    read_drawing(&bytes, &DxfOptions::with_feed(600.0))
        .expect_err("must fail")
        .errors
}

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(format!(
        "{}/../../samples/dxf/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("sample")
}

#[test]
fn truncated_file_is_a_read_error_at_its_last_line() {
    let errors = bad("truncated.dxf");
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code_str(), "pvtc::dxf::read");
    assert_eq!(errors[0].span().line, 48);
    assert!(
        errors[0].to_string().contains("unexpectedly ended"),
        "{}",
        errors[0]
    );
}

#[test]
fn wrong_group_code_is_a_read_error_near_the_bad_line() {
    let errors = bad("wrong_group_codes.dxf");
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code_str(), "pvtc::dxf::read");
    // Line 31 holds the code "1x"; the parser stops on the pair after it.
    assert_eq!(errors[0].span().line, 32);
}

#[test]
fn empty_drawing() {
    let errors = bad("empty.dxf");
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code_str(), "pvtc::dxf::empty_drawing");
    let zero = read_drawing(b"", &DxfOptions::with_feed(600.0)).unwrap_err();
    assert_eq!(zero.codes(), ["pvtc::dxf::empty_drawing"]);
}

#[test]
fn only_text_is_nothing_to_cut() {
    let errors = bad("only_text.dxf");
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].code_str(), "pvtc::dxf::nothing_to_cut");
    assert!(errors[0].to_string().contains("2 TEXT"), "{}", errors[0]);
}

#[test]
fn bad_geometry_names_handle_layer_and_line_of_every_bad_entity() {
    let errors = bad("bad_geometry.dxf");
    assert_eq!(errors.len(), 2);
    for e in &errors {
        assert_eq!(e.code_str(), "pvtc::dxf::bad_geometry");
    }
    match &errors[0] {
        DxfError::BadGeometry { entity, span, .. } => {
            assert_eq!(
                (
                    entity.kind.as_str(),
                    entity.handle.as_str(),
                    entity.layer.as_str()
                ),
                ("LINE", "101", "CUT")
            );
            assert_eq!(span.line, 37);
        }
        other => panic!("{other:?}"),
    }
    match &errors[1] {
        DxfError::BadGeometry {
            entity,
            reason,
            span,
        } => {
            assert_eq!(
                (entity.kind.as_str(), entity.handle.as_str()),
                ("ARC", "102")
            );
            assert!(reason.contains("radius"));
            assert_eq!(span.line, 51);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn unknown_layer_and_bad_options() {
    let mut o = DxfOptions::with_feed(600.0);
    o.layers = vec!["NOPE".to_string()];
    let e = read_drawing(&sample("lines_arcs.dxf"), &o).unwrap_err();
    assert_eq!(e.codes(), ["pvtc::dxf::no_such_layer"]);
    assert!(
        e.to_string().contains("CUT") && e.to_string().contains("ENGRAVE"),
        "{e}"
    );
    let e = read_drawing(&sample("lines_arcs.dxf"), &DxfOptions::with_feed(-1.0)).unwrap_err();
    assert_eq!(e.codes(), ["pvtc::dxf::bad_option"]);
    // A layer that exists but holds only text: nothing to cut.
    o.layers = vec!["notes".to_string()];
    let e = read_drawing(&sample("ellipses.dxf"), &o).unwrap_err();
    assert_eq!(e.codes(), ["pvtc::dxf::nothing_to_cut"]);
    // Miette sees the code of the first error.
    use miette::Diagnostic;
    assert_eq!(e.code().unwrap().to_string(), "pvtc::dxf::nothing_to_cut");
}
