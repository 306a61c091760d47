//! Degenerate entities real CAD files hold: zero-length entities are dropped with a
//! warning, and an ELLIPSE whose axis ratio is a hair above 1 is read with its axes
//! swapped. Each drawing is written here, entity by entity.

use pvt_core::{Motion, Position};
use pvt_dxf::{read_drawing, DxfDiagnostic, DxfOptions};

/// An ASCII DXF in millimetres holding `entities`, each a list of (group code, value).
fn drawing(entities: &[Vec<(u16, String)>]) -> Vec<u8> {
    let mut s = String::from("  0\nSECTION\n  2\nHEADER\n  9\n$ACADVER\n  1\nAC1015\n");
    s += "  9\n$INSUNITS\n 70\n4\n  0\nENDSEC\n  0\nSECTION\n  2\nENTITIES\n";
    for e in entities {
        for (code, value) in e {
            s += &format!("{code:>3}\n{value}\n");
        }
    }
    s += "  0\nENDSEC\n  0\nEOF\n";
    s.into_bytes()
}

fn entity(kind: &str, handle: &str, groups: &[(u16, f64)]) -> Vec<(u16, String)> {
    let mut e = vec![
        (0, kind.to_string()),
        (5, handle.to_string()),
        (8, "CUT".to_string()),
    ];
    // Display writes integers without a point, as integer groups (70, 90) need.
    e.extend(groups.iter().map(|&(c, v)| (c, format!("{v}"))));
    e
}

fn line(handle: &str, a: [f64; 2], b: [f64; 2]) -> Vec<(u16, String)> {
    entity(
        "LINE",
        handle,
        &[
            (10, a[0]),
            (20, a[1]),
            (30, 0.0),
            (11, b[0]),
            (21, b[1]),
            (31, 0.0),
        ],
    )
}

fn options() -> DxfOptions {
    let mut o = DxfOptions::with_feed(600.0);
    o.tolerance = Some(1e-4);
    o
}

/// Every position the feed contours pass through, elements' ends in order.
fn feed_points(d: &pvt_dxf::Drawing) -> Vec<Position> {
    d.toolpath
        .contours
        .iter()
        .filter(|c| c.motion == Motion::Feed)
        .flat_map(|c| {
            std::iter::once(c.elements[0].start).chain(c.elements.iter().flat_map(element_points))
        })
        .collect()
}

/// The points after an element's start: its end, and on a Bézier 255 points before it
/// (Bernstein form, evaluated here; on the ellipses below their chords lie within 2e-5
/// of the cubic).
fn element_points(e: &pvt_core::Element) -> Vec<Position> {
    let pvt_core::ElementKind::Bezier(b) = e.kind else {
        return vec![e.end];
    };
    (1..=256)
        .map(|k| {
            let t = f64::from(k) / 256.0;
            let s = 1.0 - t;
            let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
            let mut p = e.start;
            for (i, q) in p.iter_mut().enumerate() {
                *q = e.start[i] + (e.end[i] - e.start[i]) * t;
            }
            for (j, q) in p.iter_mut().take(2).enumerate() {
                *q = w[0] * e.start[j]
                    + w[1] * b.controls[0][j]
                    + w[2] * b.controls[1][j]
                    + w[3] * e.end[j];
            }
            p
        })
        .collect()
}

#[test]
fn zero_length_entities_are_dropped_with_a_warning_naming_each() {
    let bytes = drawing(&[
        line("A1", [0.0, 0.0], [10.0, 0.0]),
        line("A2", [5.0, 5.0], [5.0, 5.0]),
        // A circle of radius 0 and an arc whose angles are equal.
        entity(
            "CIRCLE",
            "A3",
            &[(10, 3.0), (20, 3.0), (30, 0.0), (40, 0.0)],
        ),
        entity(
            "ARC",
            "A4",
            &[
                (10, 3.0),
                (20, 3.0),
                (30, 0.0),
                (40, 2.0),
                (50, 30.0),
                (51, 30.0),
            ],
        ),
        // A polyline all of whose vertices coincide.
        {
            let mut e = entity("LWPOLYLINE", "A5", &[(90, 2.0), (70, 0.0)]);
            for _ in 0..2 {
                e.push((10, "7".to_string()));
                e.push((20, "7".to_string()));
            }
            e
        },
    ]);
    let d = read_drawing(&bytes, &options()).unwrap_or_else(|e| panic!("{e:?}"));
    let dropped: Vec<(&str, &str, u32)> = d
        .warnings
        .iter()
        .filter_map(|w| match w {
            DxfDiagnostic::ZeroLength { entity, span } => {
                Some((entity.kind.as_str(), entity.handle.as_str(), span.line))
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        dropped,
        [
            ("LINE", "A2", 37),
            ("CIRCLE", "A3", 55),
            ("ARC", "A4", 69),
            ("LWPOLYLINE", "A5", 87)
        ],
        "{:?}",
        d.warnings
    );
    for w in &d.warnings {
        assert_eq!(w.code_str(), "pvtc::dxf::zero_length");
        assert!(w.to_string().contains("dropped"), "{w}");
    }
    assert_eq!(
        feed_points(&d),
        [
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        ]
    );
}

#[test]
fn a_drawing_of_only_zero_length_entities_has_nothing_to_cut() {
    let bytes = drawing(&[line("B1", [1.0, 1.0], [1.0, 1.0])]);
    let e = read_drawing(&bytes, &options()).unwrap_err();
    assert_eq!(e.codes(), ["pvtc::dxf::nothing_to_cut"]);
    assert!(e.to_string().contains("zero length"), "{e}");
}

#[test]
fn zero_length_warnings_are_bounded() {
    let entities: Vec<_> = (0..pvt_dxf::MAX_ZERO_LENGTH_WARNINGS + 5)
        .map(|i| line(&format!("{:X}", 0x100 + i), [1.0, 1.0], [1.0, 1.0]))
        .chain(std::iter::once(line("FFFFF", [0.0, 0.0], [1.0, 0.0])))
        .collect();
    let d = read_drawing(&drawing(&entities), &options()).unwrap();
    assert_eq!(d.warnings.len(), pvt_dxf::MAX_ZERO_LENGTH_WARNINGS + 1);
    assert_eq!(
        d.warnings.last(),
        Some(&DxfDiagnostic::MoreZeroLength { count: 5 })
    );
}

/// An ELLIPSE entity: centre, major axis end point (relative), ratio, parameters.
fn ellipse(
    handle: &str,
    c: [f64; 2],
    major: [f64; 2],
    ratio: f64,
    s: f64,
    e: f64,
) -> Vec<(u16, String)> {
    entity(
        "ELLIPSE",
        handle,
        &[
            (10, c[0]),
            (20, c[1]),
            (30, 0.0),
            (11, major[0]),
            (21, major[1]),
            (31, 0.0),
            (210, 0.0),
            (220, 0.0),
            (230, 1.0),
            (40, ratio),
            (41, s),
            (42, e),
        ],
    )
}

#[test]
fn ellipse_ratio_above_one_is_read_with_its_axes_swapped() {
    for ratio in [1.0000001, 1.25, 2.0] {
        let (c, major, s, e) = ([4.0, 3.0], [6.0, 2.0], 0.3, 2.5);
        let bytes = drawing(&[ellipse("E1", c, major, ratio, s, e)]);
        let d = read_drawing(&bytes, &options()).unwrap_or_else(|e| panic!("{ratio}: {e:?}"));
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        // The curve the entity describes, read literally: c + M cos t + r (Z × M) sin t.
        let at = |t: f64| {
            let minor = [-major[1] * ratio, major[0] * ratio];
            [
                c[0] + major[0] * libm::cos(t) + minor[0] * libm::sin(t),
                c[1] + major[1] * libm::cos(t) + minor[1] * libm::sin(t),
            ]
        };
        let points = feed_points(&d);
        let (first, last) = (points[0], points[points.len() - 1]);
        let close =
            |p: Position, q: [f64; 2]| (p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9;
        // The contour may be entered at either end (the one nearer the start point).
        let ends_match = (close(first, at(s)) && close(last, at(e)))
            || (close(first, at(e)) && close(last, at(s)));
        assert!(
            ends_match,
            "{ratio}: {first:?} to {last:?}, not {:?} to {:?}",
            at(s),
            at(e)
        );
        // Every point of the cubics lies on the curve within the tolerance, and their
        // polyline covers it within tolerance.
        let truth: Vec<[f64; 2]> = (0..=2000)
            .map(|k| at(s + (e - s) * f64::from(k) / 2000.0))
            .collect();
        let near = |p: [f64; 2], pts: &[[f64; 2]]| {
            pts.windows(2)
                .map(|w| seg_dist(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        };
        let chord: Vec<[f64; 2]> = points.iter().map(|p| [p[0], p[1]]).collect();
        for p in &chord {
            assert!(
                near(*p, &truth) < 1.01e-4,
                "{ratio}: {p:?} is off the ellipse"
            );
        }
        for p in &truth {
            assert!(near(*p, &chord) < 1.21e-4, "{ratio}: {p:?} is not covered");
        }
    }
}

fn seg_dist(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 == 0.0 {
        0.0
    } else {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
    };
    libm::hypot(p[0] - a[0] - ab[0] * t, p[1] - a[1] - ab[1] * t)
}

#[test]
fn ellipse_ratio_not_positive_is_still_refused() {
    for ratio in [0.0, -1.0, f64::NAN] {
        let bytes = drawing(&[ellipse("E2", [0.0, 0.0], [1.0, 0.0], ratio, 0.0, 1.0)]);
        let e = read_drawing(&bytes, &options()).unwrap_err();
        assert_eq!(e.codes(), ["pvtc::dxf::bad_geometry"], "{ratio}");
    }
}
