//! The sample drawings: real values, checked against geometry computed independently here.

use pvt_core::{flatten_contour, Axis, ChordTolerance, Contour, ElementKind, Motion, Units};
use pvt_dxf::{read_drawing, Drawing, DxfDiagnostic, DxfOptions};

type P = [f64; 3];
const TOL: f64 = 1e-3;

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(format!(
        "{}/../../samples/dxf/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("sample")
}

fn read(name: &str) -> Drawing {
    let mut o = DxfOptions::with_feed(600.0);
    o.tolerance = Some(TOL);
    read_drawing(&sample(name), &o).unwrap_or_else(|e| panic!("{name}: {e:?}"))
}

fn feeds(d: &Drawing) -> Vec<&Contour> {
    d.toolpath
        .contours
        .iter()
        .filter(|c| c.motion == Motion::Feed)
        .collect()
}

/// Points of a contour in X Y Z: lines and arcs after pvt-core's arc discretization, a
/// Bézier at 256 equal parameter steps of its Bernstein form, evaluated here.
fn points(c: &Contour) -> Vec<P> {
    let mut out = vec![[
        c.elements[0].start[0],
        c.elements[0].start[1],
        c.elements[0].start[2],
    ]];
    for e in &c.elements {
        if let ElementKind::Bezier(b) = e.kind {
            out.extend((1..=256).map(|k| {
                let t = f64::from(k) / 256.0;
                let s = 1.0 - t;
                let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
                let xy = |j: usize| {
                    w[0] * e.start[j]
                        + w[1] * b.controls[0][j]
                        + w[2] * b.controls[1][j]
                        + w[3] * e.end[j]
                };
                [xy(0), xy(1), e.start[2] + (e.end[2] - e.start[2]) * t]
            }));
            continue;
        }
        let one = Contour {
            motion: c.motion,
            elements: vec![*e],
        };
        let pl = flatten_contour(
            &one,
            &[Axis::X, Axis::Y, Axis::Z],
            ChordTolerance::new(TOL).unwrap(),
        );
        out.extend((1..pl.len()).map(|i| {
            let p = pl.point(i);
            [p[0], p[1], p[2]]
        }));
    }
    out
}

fn d(a: P, b: P) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn seg_dist(p: P, a: P, b: P) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    if l2 == 0.0 {
        return d(p, a);
    }
    let t = (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / l2)
        .clamp(0.0, 1.0);
    d(p, [a[0] + ab[0] * t, a[1] + ab[1] * t, a[2] + ab[2] * t])
}

fn poly_dist(p: P, poly: &[P]) -> f64 {
    if poly.len() == 1 {
        return d(p, poly[0]);
    }
    poly.windows(2)
        .map(|w| seg_dist(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Every output point lies within `off` of the true curves and every true point is within
/// the tolerance of the output chords (the sagitta against the true curve).
fn check_against_truth(drawing: &Drawing, truth: &[Vec<P>], off: f64) {
    let out: Vec<Vec<P>> = feeds(drawing).into_iter().map(points).collect();
    for (k, poly) in out.iter().enumerate() {
        for &p in poly {
            let e = truth
                .iter()
                .map(|t| poly_dist(p, t))
                .fold(f64::INFINITY, f64::min);
            assert!(
                e < off,
                "contour {k}: point {p:?} is {e} off the true curve"
            );
        }
    }
    for (k, t) in truth.iter().enumerate() {
        for &p in t {
            let e = out
                .iter()
                .map(|o| poly_dist(p, o))
                .fold(f64::INFINITY, f64::min);
            assert!(
                e <= TOL + 1e-5,
                "true curve {k}: point {p:?} is {e} from the chords"
            );
        }
    }
}

/// Dense samples of a parametric curve.
fn sample_curve(f: impl Fn(f64) -> P, t0: f64, t1: f64, n: usize) -> Vec<P> {
    (0..=n)
        .map(|i| f(t0 + (t1 - t0) * i as f64 / n as f64))
        .collect()
}

fn circle(c: [f64; 2], r: f64, a0: f64, a1: f64) -> Vec<P> {
    sample_curve(
        |t| [c[0] + r * libm::cos(t), c[1] + r * libm::sin(t), 0.0],
        a0,
        a1,
        4000,
    )
}

/// B-spline basis by the Cox–de Boor recursion (independent of the crate's de Boor).
fn basis(i: usize, p: usize, u: f64, k: &[f64]) -> f64 {
    if p == 0 {
        let last = k[k.len() - 1];
        return if (k[i] <= u && u < k[i + 1]) || (u == last && k[i] < u && k[i + 1] == last) {
            1.0
        } else {
            0.0
        };
    }
    let mut v = 0.0;
    if k[i + p] > k[i] {
        v += (u - k[i]) / (k[i + p] - k[i]) * basis(i, p - 1, u, k);
    }
    if k[i + p + 1] > k[i + 1] {
        v += (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * basis(i + 1, p - 1, u, k);
    }
    v
}

fn nurbs(p: usize, k: &[f64], ctrl: &[P], w: &[f64]) -> Vec<P> {
    let n = ctrl.len();
    let (a, b) = (k[p], k[n]);
    sample_curve(
        |u| {
            let (mut s, mut ws) = ([0.0; 3], 0.0);
            for (i, point) in ctrl.iter().enumerate() {
                let bw = basis(i, p, u, k) * w.get(i).copied().unwrap_or(1.0);
                ws += bw;
                for c in 0..3 {
                    s[c] += bw * point[c];
                }
            }
            [s[0] / ws, s[1] / ws, s[2] / ws]
        },
        a,
        b,
        6000,
    )
}

#[test]
fn lines_arcs_chain_close_and_keep_arc_directions() {
    let dr = read("lines_arcs.dxf");
    assert_eq!(dr.toolpath.units, Units::Millimetre);
    assert!(dr.warnings.is_empty());
    let f = feeds(&dr);
    assert_eq!(f.len(), 4);
    // Nearest-neighbour from (0, 0): slot (entered at (20, 5)), zig-zag, circle, D.
    let entries: Vec<[f64; 2]> = f
        .iter()
        .map(|c| [c.elements[0].start[0], c.elements[0].start[1]])
        .collect();
    assert_eq!(
        entries,
        [[20.0, 5.0], [0.0, 40.0], [86.0, 10.0], [100.0, 30.0]]
    );
    for c in &f {
        for w in c.elements.windows(2) {
            assert_eq!(w[0].end, w[1].start);
        }
        assert!(c.elements.iter().all(|e| (e.feed - 10.0).abs() < 1e-12));
    }
    // Slot, circle and D are closed; the zig-zag is open.
    for (i, c) in f.iter().enumerate() {
        let closed = c.elements[0].start == c.elements.last().unwrap().end;
        assert_eq!(closed, i != 1, "contour {i}");
    }
    // Every arc bulges the way its entity does: the slot's ends outwards, the mirrored
    // arc (extrusion −Z) towards +X.
    for c in &f {
        for e in &c.elements {
            if let ElementKind::Arc(arc) = e.kind {
                let sw = arc.sweep(&e.start, &e.end);
                let mid = sw.start_angle + sw.sweep / 2.0;
                let m = [
                    arc.center[0] + sw.start_radius * libm::cos(mid),
                    arc.center[1] + sw.start_radius * libm::sin(mid),
                ];
                match arc.center {
                    [50.0, 10.0] => assert!(m[0] > 54.9, "{m:?}"),
                    [20.0, 10.0] => assert!(m[0] < 15.1, "{m:?}"),
                    [100.0, 40.0] => assert!(m[0] > 109.9, "{m:?}"),
                    [80.0, 10.0] => assert!((sw.sweep.abs() - std::f64::consts::TAU).abs() < 1e-12),
                    other => panic!("unexpected arc centre {other:?}"),
                }
            }
        }
    }
    let truth = vec![
        vec![[20.0, 15.0, 0.0], [50.0, 15.0, 0.0]],
        vec![[20.0, 5.0, 0.0], [50.0, 5.0, 0.0]],
        circle(
            [50.0, 10.0],
            5.0,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
        ),
        circle(
            [20.0, 10.0],
            5.0,
            std::f64::consts::FRAC_PI_2,
            1.5 * std::f64::consts::PI,
        ),
        circle([80.0, 10.0], 6.0, 0.0, std::f64::consts::TAU),
        vec![[100.0, 30.0, 0.0], [100.0, 50.0, 0.0]],
        circle(
            [100.0, 40.0],
            10.0,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
        ),
        vec![
            [0.0, 40.0, 0.0],
            [10.0, 50.0, 0.0],
            [20.0, 40.0, 0.0],
            [30.0, 50.0, 0.0],
        ],
    ];
    check_against_truth(&dr, &truth, 1e-5);
    // Spans point at the entity records.
    assert_eq!(f[0].elements.iter().map(|e| e.span.line).min(), Some(19));
}

#[test]
fn polylines_bulges_elevation_mirror_and_3d() {
    let dr = read("polylines.dxf");
    let f = feeds(&dr);
    assert_eq!(f.len(), 5);
    let b = libm::tan(std::f64::consts::PI / 8.0);
    assert!(b > 0.0);
    let q = std::f64::consts::FRAC_PI_2;
    let pi = std::f64::consts::PI;
    let truth = vec![
        // Rounded rectangle.
        vec![[5.0, 0.0, 0.0], [35.0, 0.0, 0.0]],
        circle([35.0, 5.0], 5.0, -q, 0.0),
        vec![[40.0, 5.0, 0.0], [40.0, 15.0, 0.0]],
        circle([35.0, 15.0], 5.0, 0.0, q),
        vec![[35.0, 20.0, 0.0], [5.0, 20.0, 0.0]],
        circle([5.0, 15.0], 5.0, q, pi),
        vec![[0.0, 15.0, 0.0], [0.0, 5.0, 0.0]],
        circle([5.0, 5.0], 5.0, pi, 1.5 * pi),
        // Wave at Z = 2: bulge −1 is a clockwise half circle (over the top from (50, 0)),
        // bulge 0.5 a counter-clockwise arc (below its chord).
        sample_curve(
            |t| [55.0 + 5.0 * libm::cos(t), 5.0 * libm::sin(t), 2.0],
            pi,
            0.0,
            4000,
        ),
        {
            // Bulge 0.5 over the chord 60 → 70: included angle 4·atan(0.5), centre left.
            let th = 4.0 * libm::atan(0.5);
            let r = 10.0 / (2.0 * libm::sin(th / 2.0));
            let cy = (r * r - 25.0).sqrt();
            let a0 = libm::atan2(0.0 - cy, -5.0);
            sample_curve(
                |t| [65.0 + r * libm::cos(t), cy + r * libm::sin(t), 2.0],
                a0,
                a0 + th,
                4000,
            )
        },
        vec![[70.0, 0.0, 2.0], [80.0, 5.0, 2.0]],
        // Mirrored pocket: OCS (−90, 0) … is world (90, 0) …; the bulge-1 half circle,
        // counter-clockwise in the OCS from (−110, 0) to (−110, 10), is clockwise in the
        // world and bulges inwards to X = 105.
        vec![[90.0, 0.0, 0.0], [110.0, 0.0, 0.0]],
        circle([110.0, 5.0], 5.0, q, 3.0 * q),
        vec![[110.0, 10.0, 0.0], [90.0, 10.0, 0.0], [90.0, 0.0, 0.0]],
        // POLYLINE 2D circle.
        circle([125.0, 5.0], 5.0, 0.0, 2.0 * pi),
        // 3D ramp.
        vec![
            [0.0, 40.0, 0.0],
            [10.0, 40.0, -1.0],
            [10.0, 50.0, -2.0],
            [0.0, 50.0, -3.0],
        ],
    ];
    check_against_truth(&dr, &truth, 1e-5);
    let wave = f
        .iter()
        .find(|c| c.elements[0].start[2] == 2.0)
        .expect("elevated wave");
    assert!(wave
        .elements
        .iter()
        .all(|e| e.start[2] == 2.0 && e.end[2] == 2.0));
    let ramp = f
        .iter()
        .find(|c| c.elements.iter().any(|e| e.end[2] == -3.0))
        .expect("3D ramp");
    assert_eq!(ramp.elements.len(), 3);
    // VERTEX spans: each ramp segment points at its own VERTEX record.
    let lines: Vec<u32> = ramp.elements.iter().map(|e| e.span.line).collect();
    assert!(lines.windows(2).all(|w| w[0] != w[1]), "{lines:?}");
}

/// The true curves of splines.dxf's three open splines (a cubic, a rational quadratic
/// half circle and a quintic), densely evaluated from the sample's own definition.
fn open_splines_truth() -> Vec<Vec<P>> {
    vec![
        nurbs(
            3,
            &[0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0],
            &[
                [0.0, 0.0, 0.0],
                [10.0, 20.0, 0.0],
                [20.0, -10.0, 0.0],
                [30.0, 15.0, 0.0],
                [40.0, 0.0, 0.0],
                [50.0, 10.0, 0.0],
            ],
            &[],
        ),
        nurbs(
            2,
            &[0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0],
            &[
                [90.0, 0.0, 0.0],
                [90.0, 10.0, 0.0],
                [80.0, 10.0, 0.0],
                [70.0, 10.0, 0.0],
                [70.0, 0.0, 0.0],
            ],
            &[
                1.0,
                std::f64::consts::FRAC_1_SQRT_2,
                1.0,
                std::f64::consts::FRAC_1_SQRT_2,
                1.0,
            ],
        ),
        nurbs(
            5,
            &[
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
            ],
            &[
                [0.0, 30.0, 0.0],
                [5.0, 45.0, 0.0],
                [15.0, 25.0, 0.0],
                [25.0, 50.0, 0.0],
                [35.0, 20.0, 0.0],
                [45.0, 45.0, 0.0],
                [50.0, 30.0, 0.0],
            ],
            &[],
        ),
    ]
}

#[test]
fn splines_follow_the_true_nurbs_and_pass_through_fit_points() {
    let dr = read("splines.dxf");
    assert_eq!(feeds(&dr).len(), 6);
    let ring = [
        [70.0, 30.0, 0.0],
        [80.0, 25.0, 0.0],
        [90.0, 30.0, 0.0],
        [90.0, 45.0, 0.0],
        [70.0, 45.0, 0.0],
    ];
    let mut ctrl = ring.to_vec();
    ctrl.extend_from_slice(&ring[..3]);
    let knots: Vec<f64> = (0..12).map(f64::from).collect();
    let mut truth = open_splines_truth();
    truth.push(nurbs(3, &knots, &ctrl, &[]));
    // The rational spline is a half circle, fitted by cubics within the tolerance:
    // check that directly too.
    let half = feeds(&dr)
        .into_iter()
        .find(|c| {
            c.elements[0].start == [90.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                || c.elements[0].start == [70.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        })
        .expect("half circle");
    for p in points(half) {
        assert!((d(p, [80.0, 0.0, 0.0]) - 10.0).abs() < TOL && p[1] >= -TOL);
    }
    let out: Vec<Vec<P>> = feeds(&dr).into_iter().map(points).collect();
    // Control-point splines: both directions of the distance check.
    for t in &truth {
        for &p in t {
            let e = out
                .iter()
                .map(|o| poly_dist(p, o))
                .fold(f64::INFINITY, f64::min);
            assert!(e <= TOL + 1e-5, "true point {p:?} is {e} from the chords");
        }
    }
    let fit_a = [
        [0.0, 70.0, 0.0],
        [10.0, 80.0, 0.0],
        [25.0, 65.0, 0.0],
        [40.0, 75.0, 0.0],
    ];
    let fit_b = [
        [60.0, 70.0, 0.0],
        [70.0, 78.0, 0.0],
        [85.0, 66.0, 0.0],
        [95.0, 72.0, 0.0],
        [100.0, 60.0, 0.0],
    ];
    for (k, poly) in out.iter().enumerate() {
        let is_fit = poly.iter().all(|p| p[1] >= 59.0);
        if is_fit {
            // Interpolation: the curve passes through every fit point (a vertex within the
            // tolerance of each) and leaves along the given start tangent (+Y).
            let fit: &[P] = if poly[0][0] < 50.0 { &fit_a } else { &fit_b };
            for &f in fit {
                assert!(
                    poly.iter().any(|&p| d(p, f) < 1e-9) || poly_dist(f, poly) < 1e-9,
                    "fit point {f:?} missed"
                );
            }
            if poly[0] == fit_a[0] {
                let dir = [poly[1][0] - poly[0][0], poly[1][1] - poly[0][1]];
                assert!(
                    dir[1] > 0.0 && dir[0].abs() < 0.2 * dir[1],
                    "start tangent {dir:?}"
                );
            }
            continue;
        }
        // The cubic splines (0 and 3) are their Béziers exactly; the rational and the
        // quintic ones (1 and 2) are fitted within the tolerance.
        for &p in poly {
            let (e, nearest) = truth
                .iter()
                .enumerate()
                .map(|(i, t)| (poly_dist(p, t), i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            let off = if nearest == 1 || nearest == 2 {
                TOL
            } else {
                1e-5
            };
            assert!(e < off, "contour {k}: {p:?} is {e} off NURBS {nearest}");
        }
    }
    // The periodic spline closes, one Bézier per knot span.
    assert!(feeds(&dr).iter().any(|c| c.elements.len() == 5
        && c.elements
            .iter()
            .all(|e| matches!(e.kind, ElementKind::Bezier(_)))
        && c.elements[0].start == c.elements.last().unwrap().end));
}

#[test]
fn ellipses_full_partial_rotated_and_mirrored() {
    let dr = read("ellipses.dxf");
    assert_eq!(
        dr.warnings,
        [DxfDiagnostic::Unsupported {
            kind: "TEXT".to_string(),
            count: 1
        }]
    );
    assert_eq!(dr.warnings[0].code_str(), "pvtc::dxf::unsupported_entity");
    let tau = std::f64::consts::TAU;
    let ell = |c: [f64; 2], maj: [f64; 2], minor: [f64; 2], t0: f64, t1: f64| {
        sample_curve(
            |t| {
                [
                    c[0] + maj[0] * libm::cos(t) + minor[0] * libm::sin(t),
                    c[1] + maj[1] * libm::cos(t) + minor[1] * libm::sin(t),
                    0.0,
                ]
            },
            t0,
            t1,
            4000,
        )
    };
    let truth = vec![
        ell([20.0, 10.0], [15.0, 0.0], [0.0, 7.5], 0.0, tau),
        // Major (0, 12), ratio 0.4: minor = Z × major · 0.4 = (−4.8, 0); 5 → 2 wraps through 0.
        ell([60.0, 10.0], [0.0, 12.0], [-4.8, 0.0], 5.0, 2.0 + tau),
        ell([20.0, 50.0], [8.0, 6.0], [-1.8, 2.4], 0.0, tau),
        // Normal −Z: minor = (−Z) × (10, 0) · 0.6 = (0, −6): the lower half.
        ell(
            [60.0, 50.0],
            [10.0, 0.0],
            [0.0, -6.0],
            0.0,
            std::f64::consts::PI,
        ),
        ell([90.0, 10.0], [5.0, 0.0], [0.0, 5.0], 0.0, tau),
    ];
    // Ellipses are cubics within the tolerance of the true curve.
    check_against_truth(&dr, &truth, TOL);
    let f = feeds(&dr);
    let arcs = f
        .iter()
        .filter(|c| matches!(c.elements[0].kind, ElementKind::Arc(_)))
        .count();
    assert_eq!(arcs, 1, "only the ratio-1 ellipse stays an arc");
}

#[test]
fn cad_part_blocks_units_nesting_and_reversed_entities() {
    let dr = read("cad_part.dxf");
    assert_eq!(dr.toolpath.units, Units::Inch);
    let codes: Vec<String> = dr.warnings.iter().map(|w| w.code_str()).collect();
    assert_eq!(
        codes,
        [
            "pvtc::dxf::unsupported_entity",
            "pvtc::dxf::unsupported_entity",
            "pvtc::dxf::paper_space"
        ]
    );
    let f = feeds(&dr);
    assert_eq!(f.len(), 4);
    // Plate: 2 × 1 in, base (1, 0.5), at (3, 2), scale 1.5, rotated 30°.
    let (s, c) = (libm::sin(30f64.to_radians()), libm::cos(30f64.to_radians()));
    let place = |x: f64, y: f64| {
        let (u, v) = ((x - 1.0) * 1.5, (y - 0.5) * 1.5);
        [3.0 + u * c - v * s, 2.0 + u * s + v * c]
    };
    // Holes: 6 mm diameter block in an inch drawing, then scaled 1.5 → r = 4.5 / 25.4 in.
    let r = 4.5 / 25.4;
    let mut holes = 0;
    for contour in &f {
        if let [e] = contour.elements.as_slice() {
            let ElementKind::Arc(arc) = e.kind else {
                panic!("a one-element contour must be a hole")
            };
            let want = [place(0.5, 0.5), place(1.5, 0.5)];
            assert!(want
                .iter()
                .any(|w| (w[0] - arc.center[0]).abs() < 1e-12
                    && (w[1] - arc.center[1]).abs() < 1e-12));
            let sw = arc.sweep(&e.start, &e.end);
            assert!(
                (sw.start_radius - r).abs() < 1e-12,
                "radius {} want {r}",
                sw.start_radius
            );
            holes += 1;
        }
    }
    assert_eq!(holes, 2);
    let outline = f
        .iter()
        .find(|c| c.elements.len() == 4 && c.elements.iter().all(|e| e.kind == ElementKind::Line))
        .expect("plate");
    for e in &outline.elements {
        let corners = [
            place(0.0, 0.0),
            place(2.0, 0.0),
            place(2.0, 1.0),
            place(0.0, 1.0),
        ];
        assert!(corners
            .iter()
            .any(|k| (k[0] - e.start[0]).abs() < 1e-12 && (k[1] - e.start[1]).abs() < 1e-12));
    }
    // The reversed triangle-and-arc chain closes, and its arc still bulges upwards.
    let d_shape = f
        .iter()
        .find(|c| {
            c.elements
                .iter()
                .any(|e| matches!(e.kind, ElementKind::Arc(_)))
                && c.elements.len() == 4
        })
        .expect("arc chain");
    assert_eq!(d_shape.elements[0].start, d_shape.elements[3].end);
    for e in &d_shape.elements {
        if let ElementKind::Arc(arc) = e.kind {
            let sw = arc.sweep(&e.start, &e.end);
            let mid = sw.start_angle + sw.sweep / 2.0;
            assert!((arc.center[1] + 0.5 * libm::sin(mid)) > 1.49);
        }
    }
    // The binary twin gives the same toolpath (without line numbers).
    let bin = read("cad_part_binary.dxf");
    assert_eq!(bin.toolpath.contours.len(), dr.toolpath.contours.len());
    for (a, b) in bin.toolpath.contours.iter().zip(&dr.toolpath.contours) {
        assert_eq!(a.motion, b.motion);
        for (x, y) in a.elements.iter().zip(&b.elements) {
            assert_eq!(
                (x.kind, x.start, x.end, x.feed),
                (y.kind, y.start, y.end, y.feed)
            );
        }
    }
    // Overriding the units reads the same drawing as millimetres.
    let mut o = DxfOptions::with_feed(600.0);
    o.units = Some(Units::Millimetre);
    let mm = read_drawing(&sample("cad_part.dxf"), &o).unwrap();
    assert_eq!(mm.toolpath.units, Units::Millimetre);
}

#[test]
fn output_is_deterministic_and_layers_select() {
    for name in [
        "lines_arcs.dxf",
        "polylines.dxf",
        "splines.dxf",
        "ellipses.dxf",
        "cad_part.dxf",
    ] {
        assert_eq!(read(name), read(name), "{name}");
    }
    let mut o = DxfOptions::with_feed(600.0);
    o.layers = vec!["engrave".to_string()];
    let only = read_drawing(&sample("lines_arcs.dxf"), &o).unwrap();
    assert_eq!(feeds(&only).len(), 1);
    assert_eq!(feeds(&only)[0].elements.len(), 3);
    // Layer-0 block contents take the INSERT's layer; HOLES selects only the holes.
    o.layers = vec!["HOLES".to_string()];
    assert_eq!(
        feeds(&read_drawing(&sample("cad_part.dxf"), &o).unwrap()).len(),
        2
    );
}

#[test]
fn safe_z_rapids_plunge_and_retract() {
    let mut o = DxfOptions::with_feed(600.0);
    o.safe_z = Some(5.0);
    o.start_point = [100.0, 100.0];
    o.rapid = Some(3000.0);
    let dr = read_drawing(&sample("lines_arcs.dxf"), &o).unwrap();
    let c = &dr.toolpath.contours;
    assert_eq!(c[0].motion, Motion::Rapid);
    assert_eq!(c[0].elements[0].start, [100.0, 100.0, 5.0, 0.0, 0.0, 0.0]);
    assert_eq!(c[0].elements[0].feed, 50.0);
    // Rapid over the entry at safe Z, feed plunge, cut, rapid retract.
    // The nearest entry is the D shape's arc start (100, 50): the closed chain is rotated.
    assert_eq!(c[0].elements[0].end, [100.0, 50.0, 5.0, 0.0, 0.0, 0.0]);
    assert_eq!(
        (c[1].motion, c[1].elements[0].end),
        (Motion::Feed, [100.0, 50.0, 0.0, 0.0, 0.0, 0.0])
    );
    assert_eq!(c[3].motion, Motion::Rapid);
    assert_eq!(c[3].elements[0].end[2], 5.0);
    assert!(c
        .iter()
        .filter(|c| c.motion == Motion::Rapid)
        .all(|c| c.elements.len() == 1));
    assert_eq!(c.last().unwrap().elements[0].end[2], 5.0);
}

/// The planned motion of splines.dxf's control-point splines against the true NURBS
/// (Cox–de Boor, evaluated here): with the drawing's curves within half the tolerance
/// (as pvtc reads them for the path planner) and the motion planned within the other
/// half of those Béziers, every cubic piece, evaluated at 32 points from its end states
/// (Bézier p₀, p₀ + v₀T/3, p₁ − v₁T/3, p₁), is within the tolerance of the true curve.
#[test]
fn spline_motion_stays_within_the_tolerance_of_the_true_nurbs() {
    let mut o = DxfOptions::with_feed(6000.0);
    o.tolerance = Some(TOL);
    o.curve_share = 0.5;
    let dr = read_drawing(&sample("splines.dxf"), &o).unwrap();
    let truth = open_splines_truth();
    let options = pvt_core::PathOptions {
        tolerance: 0.5 * TOL,
        corner_tolerance: None,
        limits: Default::default(),
        quantum: None,
        servo_period: 0.0005,
        position_resolution: 0.0,
    };
    let xyz = [Axis::X, Axis::Y, Axis::Z];
    let mut measured = 0;
    for c in feeds(&dr) {
        let s = c.elements[0].start;
        let on = |t: &Vec<P>| {
            d(t[0], [s[0], s[1], s[2]]) < 1e-9 || d(*t.last().unwrap(), [s[0], s[1], s[2]]) < 1e-9
        };
        let Some(t) = truth.iter().find(|t| on(t)) else {
            continue;
        };
        let (planned, _) = pvt_core::plan_path(c, &xyz, &options).unwrap();
        let mut p0: Vec<f64> = planned.start.clone();
        let mut v0 = vec![0.0; 3];
        for i in 0..planned.len() {
            let seg = planned.segment(i);
            let tt = seg.duration;
            let cp: Vec<P> = vec![
                [p0[0], p0[1], p0[2]],
                std::array::from_fn(|k| p0[k] + v0[k] * tt / 3.0),
                std::array::from_fn(|k| seg.end[k] - seg.velocity[k] * tt / 3.0),
                [seg.end[0], seg.end[1], seg.end[2]],
            ];
            for j in 0..=32 {
                let u = f64::from(j) / 32.0;
                let w = [
                    (1.0 - u).powi(3),
                    3.0 * (1.0 - u).powi(2) * u,
                    3.0 * (1.0 - u) * u * u,
                    u.powi(3),
                ];
                let p: P = std::array::from_fn(|k| (0..4).map(|m| w[m] * cp[m][k]).sum());
                let e = poly_dist(p, t);
                assert!(
                    e <= TOL + 1e-5,
                    "piece {i}: {p:?} is {e} from the true NURBS"
                );
            }
            (p0, v0) = (seg.end.to_vec(), seg.velocity.to_vec());
        }
        measured += 1;
    }
    assert_eq!(measured, 3, "the three open control-point splines");
}
