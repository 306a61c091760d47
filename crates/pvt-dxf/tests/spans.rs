//! Source lines: every element and every generated move of an ASCII drawing carries the
//! DXF line of an entity record, entities inside blocks included (the `dxf` crate gives
//! those new handles, so they cannot be found by handle).

use pvt_core::{Motion, Toolpath};
use pvt_dxf::{read_drawing, DxfError, DxfOptions};

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(format!(
        "{}/../../samples/dxf/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("sample")
}

/// The 1-based line numbers of the `0` lines opening a record of type `kind`.
fn record_lines(text: &str, kind: &str) -> Vec<u32> {
    let lines: Vec<&str> = text.lines().collect();
    (0..lines.len().saturating_sub(1))
        .filter(|&i| lines[i].trim() == "0" && lines[i + 1].trim() == kind)
        .map(|i| i as u32 + 1)
        .collect()
}

fn read(bytes: &[u8], safe_z: Option<f64>) -> Toolpath {
    let mut o = DxfOptions::with_feed(600.0);
    o.safe_z = safe_z;
    read_drawing(bytes, &o).unwrap().toolpath
}

#[test]
fn every_element_and_generated_move_has_an_entity_line() {
    for name in [
        "lines_arcs.dxf",
        "polylines.dxf",
        "splines.dxf",
        "ellipses.dxf",
        "cad_part.dxf",
    ] {
        for safe_z in [None, Some(5.0)] {
            let toolpath = read(&sample(name), safe_z);
            let c = &toolpath.contours;
            let line = |i: usize| c[i].elements[0].span.line;
            let mut travels = 0;
            for i in 0..c.len() {
                for e in &c[i].elements {
                    assert_ne!(e.span.line, 0, "{name} {safe_z:?} contour {i}");
                }
                // A rapid (and a plunge) carries the line of the entity it travels to.
                let plunge = |k: usize| {
                    c.get(k).is_some_and(|p| {
                        p.motion == Motion::Feed
                            && p.elements.len() == 1
                            && p.elements[0].start[2] == 5.0
                    })
                };
                if c[i].motion == Motion::Rapid && i + 1 < c.len() {
                    let target = if safe_z.is_some() {
                        if !plunge(i + 1) {
                            continue; // a retract
                        }
                        assert_eq!(line(i + 1), line(i + 2), "{name} plunge {}", i + 1);
                        i + 2
                    } else {
                        i + 1
                    };
                    assert_eq!(line(i), line(target), "{name} {safe_z:?} rapid {i}");
                    travels += 1;
                }
            }
            assert!(travels > 0, "{name}");
        }
    }
}

#[test]
fn entities_inside_blocks_have_the_line_of_their_record() {
    let bytes = sample("cad_part.dxf");
    let text = String::from_utf8(bytes.clone()).unwrap();
    // The HOLE_6MM block holds the drawing's only CIRCLE, inserted twice.
    let circle = record_lines(&text, "CIRCLE");
    assert_eq!(circle.len(), 1);
    let toolpath = read(&bytes, None);
    let holes: Vec<u32> = toolpath
        .contours
        .iter()
        .filter(|c| c.motion == Motion::Feed && c.elements.len() == 1)
        .map(|c| c.elements[0].span.line)
        .collect();
    assert_eq!(holes, [circle[0], circle[0]]);
}

#[test]
fn a_bad_entity_inside_a_block_is_named_by_its_own_handle_and_line() {
    let text = "  0\nSECTION\n  2\nBLOCKS\n  0\nBLOCK\n  5\n10\n  8\n0\n  2\nB\n 70\n0\n 10\n0\n 20\n0\n 30\n0\n  3\nB\n  0\nLINE\n  5\n77\n  8\n0\n 10\n0\n 20\n0\n 11\n5\n 21\n0\n  0\nLINE\n  5\n78\n  8\n0\n 10\nNaN\n 20\n0\n 11\n1\n 21\n1\n  0\nENDBLK\n  5\n11\n  8\n0\n  0\nENDSEC\n  0\nSECTION\n  2\nENTITIES\n  0\nINSERT\n  5\n20\n  8\n0\n  2\nB\n 10\n0\n 20\n0\n 30\n0\n  0\nENDSEC\n  0\nEOF\n";
    let lines = record_lines(text, "LINE");
    let errors = read_drawing(text.as_bytes(), &DxfOptions::with_feed(600.0))
        .unwrap_err()
        .errors;
    match errors.as_slice() {
        [DxfError::BadGeometry { entity, span, .. }] => {
            assert_eq!(
                (entity.kind.as_str(), entity.handle.as_str()),
                ("LINE", "78")
            );
            assert_eq!(span.line, lines[1]);
        }
        other => panic!("{other:?}"),
    }
}
