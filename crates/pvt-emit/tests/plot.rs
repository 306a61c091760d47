//! The SVG plot back end on hand-made programs: the sampling, and the document.
//!
//! Set `PVT_PLOT_DIR` to a folder to also write the plots there for a person to look at.

use pvt_core::{Axis, Interpolation, Motion, PvtContour, PvtProgram, Units};
use pvt_emit::plot::{plot_svg, sample_program, PlotError, PlotOptions, SampleOptions, Samples};

const R: f64 = 5000.0;
const T: f64 = 0.25;

/// Point `k` of seed 001's octagon: radius 5000 about (0, 5000), from 6 o'clock, CCW.
fn octagon_point(k: usize) -> [f64; 2] {
    let (s, c) = sin_cos_45(k);
    [R * s, R - R * c]
}

/// Sine and cosine of `k` times 45° (std's are banned, and exact values are at hand).
fn sin_cos_45(k: usize) -> (f64, f64) {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let table = [
        (0.0, 1.0),
        (h, h),
        (1.0, 0.0),
        (h, -h),
        (0.0, -1.0),
        (-h, -h),
        (-1.0, 0.0),
        (-h, h),
    ];
    table[k % 8]
}

/// The octagon as PVT: tangent velocities of the circle's speed, rest at both ends.
fn octagon(interpolation: Interpolation) -> PvtProgram {
    let speed = R * std::f64::consts::FRAC_PI_4 / T;
    let mut c = PvtContour::new(Motion::Feed, vec![0.0, 0.0]);
    for k in 1..=8 {
        let (sin, cos) = sin_cos_45(k);
        let v = match (interpolation, k) {
            (Interpolation::Pvt, 8) => [0.0, 0.0],
            (Interpolation::Pvt, _) => [speed * cos, speed * sin],
            (Interpolation::Pt, _) => {
                let (p0, p1) = (octagon_point(k - 1), octagon_point(k));
                [(p1[0] - p0[0]) / T, (p1[1] - p0[1]) / T]
            }
        };
        c.push(&octagon_point(k), &v, T, 10 + k as u32);
    }
    program(vec![Axis::X, Axis::Y], interpolation, vec![c])
}

fn program(axes: Vec<Axis>, interpolation: Interpolation, contours: Vec<PvtContour>) -> PvtProgram {
    PvtProgram {
        axes,
        units: Units::Millimetre,
        interpolation,
        contours,
        events: Vec::new(),
    }
}

/// A rapid to the start, then a short feed: two contours of different motion.
fn rapid_then_feed() -> PvtProgram {
    let mut rapid = PvtContour::new(Motion::Rapid, vec![0.0, 0.0]);
    rapid.push(&[10.0, 5.0], &[0.0, 0.0], 0.5, 1);
    let mut feed = PvtContour::new(Motion::Feed, vec![10.0, 5.0]);
    feed.push(&[20.0, 5.0], &[10.0, 0.0], 1.0, 2);
    feed.push(&[20.0, 15.0], &[0.0, 0.0], 1.2, 3);
    program(
        vec![Axis::X, Axis::Y],
        Interpolation::Pvt,
        vec![rapid, feed],
    )
}

fn options(title: &str) -> PlotOptions {
    PlotOptions {
        title: title.to_string(),
        ..PlotOptions::default()
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

/// Sample ranges of each (contour, segment), in order.
fn pieces(s: &Samples) -> Vec<(usize, usize, std::ops::Range<usize>)> {
    let mut out: Vec<(usize, usize, std::ops::Range<usize>)> = Vec::new();
    for (i, at) in s.at.iter().enumerate() {
        let Some(seg) = at.segment else { continue };
        match out.last_mut() {
            Some(p) if (p.0, p.1) == (at.contour, seg) => p.2.end = i + 1,
            _ => out.push((at.contour, seg, i..i + 1)),
        }
    }
    out
}

#[test]
fn each_pvt_piece_is_sampled_from_its_start_to_its_end() {
    let p = octagon(Interpolation::Pvt);
    let s = sample_program(
        &p,
        &SampleOptions {
            per_piece: 16,
            max_samples: 20_000,
        },
    );
    assert!(!s.decimated);
    assert_eq!(s.len(), 8 * 16);
    let c = &p.contours[0];
    for (contour, seg, range) in pieces(&s) {
        assert_eq!((contour, range.len()), (0, 16));
        let start = if seg == 0 {
            &c.start[..]
        } else {
            c.segment(seg - 1).end
        };
        let (first, last) = (s.position(range.start), s.position(range.end - 1));
        for a in 0..2 {
            assert!(close(first[a], start[a]), "segment {seg} axis {a} start");
            assert!(
                close(last[a], c.segment(seg).end[a]),
                "segment {seg} axis {a} end"
            );
        }
    }
}

#[test]
fn pvt_speed_and_acceleration_are_the_hermite_cubics() {
    let p = octagon(Interpolation::Pvt);
    let s = sample_program(&p, &SampleOptions::default());
    let c = &p.contours[0];
    for (_, seg, range) in pieces(&s) {
        let t0 = T * seg as f64;
        for i in range {
            let (x, y) = (
                c.hermite(seg, 0).at(s.time[i] - t0),
                c.hermite(seg, 1).at(s.time[i] - t0),
            );
            let speed = (x.velocity * x.velocity + y.velocity * y.velocity).sqrt();
            assert!(close(s.speed[i], speed));
            assert!(close(s.acceleration(i)[0], x.acceleration));
            assert!(close(s.acceleration(i)[1], y.acceleration));
        }
    }
    assert_eq!(s.speed[0], 0.0);
    assert!(s
        .speed
        .iter()
        .all(|v| *v < 1.5 * R * std::f64::consts::FRAC_PI_4 / T));
}

#[test]
fn pt_pieces_move_at_their_stored_velocity_and_rest_at_the_ends() {
    let p = octagon(Interpolation::Pt);
    let s = sample_program(
        &p,
        &SampleOptions {
            per_piece: 4,
            max_samples: 20_000,
        },
    );
    assert_eq!(s.len(), 8 * 4 + 2);
    let (first, last) = (s.at[0], s.at[s.len() - 1]);
    assert_eq!((first.segment, last.segment), (None, None));
    assert_eq!((s.speed[0], s.speed[s.len() - 1]), (0.0, 0.0));
    let c = &p.contours[0];
    for (_, seg, range) in pieces(&s) {
        let v = c.segment(seg).velocity;
        for i in range.clone() {
            assert_eq!(s.velocity(i), v);
            assert_eq!(s.acceleration(i), [0.0, 0.0]);
        }
        assert_eq!(s.position(range.end - 1), c.segment(seg).end);
    }
    let mid = 1 + 4 + 1; // second piece, a third of the way
    let (a, b) = (octagon_point(1), octagon_point(2));
    assert!(close(s.position(mid)[0], a[0] + (b[0] - a[0]) / 3.0));
}

#[test]
fn long_programs_are_decimated_under_the_cap() {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
    for k in 1..=100_000 {
        c.push(&[k as f64 * 0.01], &[1.0], 0.01, k);
    }
    let p = program(vec![Axis::X], Interpolation::Pvt, vec![c]);
    let s = sample_program(&p, &SampleOptions::default());
    assert!(
        s.decimated && s.len() <= 20_000 && s.len() > 10_000,
        "{}",
        s.len()
    );
    assert!(s.time.windows(2).all(|w| w[0] < w[1]));
    assert!(close(*s.time.last().unwrap(), 1000.0));
    assert!(close(s.position(s.len() - 1)[0], 1000.0));
    let svg = plot_svg(&p, &options("long")).unwrap();
    assert!(svg.len() < 3_000_000, "{} bytes", svg.len());
    assert!(svg.contains("(piece ends only)"));
}

/// Every `<text>` element's content.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim().to_string())
        })
        .collect()
}

/// The value of attribute `name` in each element `tag`.
fn attributes(svg: &str, tag: &str, name: &str) -> Vec<String> {
    let key = format!(" {name}=\"");
    svg.split(&format!("<{tag} "))
        .skip(1)
        .filter_map(|e| {
            let e = format!(" {}", &e[..e.find("/>")?]);
            let v = &e[e.find(&key)? + key.len()..];
            Some(v[..v.find('"')?].to_string())
        })
        .collect()
}

fn well_formed(svg: &str) {
    assert!(svg.starts_with("<svg"), "{}", &svg[..80]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<svg").count(), 1);
}

#[test]
fn the_octagon_plot_has_its_panels_labels_and_units() {
    let svg = plot_svg(
        &octagon(Interpolation::Pvt),
        &options("AN208 octagon (PVT)"),
    )
    .unwrap();
    well_formed(&svg);
    let t = texts(&svg);
    for label in [
        "AN208 octagon (PVT)",
        "path in the XY plane, coloured by speed",
        "vector speed against time",
        "axis velocity against time",
        "axis acceleration against time",
        "X (mm)",
        "Y (mm)",
        "time (s)",
        "speed (mm/s)",
        "velocity (mm/s)",
        "acceleration (mm/s²)",
        "speed scale",
        "element end",
        "programmed path",
    ] {
        assert!(t.iter().any(|x| x == label), "no text {label:?} in {t:?}");
    }
    assert!(t
        .iter()
        .any(|x| x.starts_with("max ") && x.ends_with(" mm/s")));
    // Path (one polyline per colour at least), speed 1, velocity 2, acceleration 2.
    assert!(svg.matches("<polyline").count() >= 6);
    keep("octagon_plot.svg", &svg);
    let pt = plot_svg(&octagon(Interpolation::Pt), &options("AN208 octagon (PT)")).unwrap();
    keep("octagon_pt_plot.svg", &pt);
}

/// Writes `svg` into `$PVT_PLOT_DIR` when it is set, for a person to look at.
fn keep(name: &str, svg: &str) {
    if let Some(dir) = std::env::var_os("PVT_PLOT_DIR") {
        std::fs::write(std::path::Path::new(&dir).join(name), svg).unwrap();
    }
}

#[test]
fn every_panel_has_its_lines() {
    let svg = plot_svg(&octagon(Interpolation::Pvt), &options("lines")).unwrap();
    let strokes = attributes(&svg, "polyline", "stroke");
    let count = |c: &str| strokes.iter().filter(|s| *s == c).count();
    assert!(count("#1F3C8C") >= 1, "speed panel");
    // Velocity and acceleration panels: a line and a legend entry an axis each.
    assert!(
        count("#D62728") >= 4 && count("#1F77B4") >= 4,
        "axis panels"
    );
    let others = ["#1F3C8C", "#D62728", "#1F77B4", "#000000"];
    let path = strokes
        .iter()
        .filter(|s| !others.contains(&s.as_str()))
        .count();
    assert!(path >= 1, "path panel: {strokes:?}");
}

#[test]
fn the_plotted_path_passes_through_every_marked_point() {
    let svg = plot_svg(&octagon(Interpolation::Pvt), &options("octagon")).unwrap();
    let pixel = |s: &str| s.parse::<i32>().unwrap();
    let cx = attributes(&svg, "circle", "cx");
    let cy = attributes(&svg, "circle", "cy");
    assert_eq!(cx.len(), 9 + 1, "nine points and the legend's marker");
    let mut path: Vec<(i32, i32)> = Vec::new();
    for points in attributes(&svg, "polyline", "points") {
        for p in points.split_whitespace() {
            let (x, y) = p.split_once(',').unwrap();
            path.push((pixel(x), pixel(y)));
        }
    }
    for (x, y) in cx.iter().zip(&cy).take(9) {
        let (x, y) = (pixel(x), pixel(y));
        let hit = path
            .iter()
            .any(|p| (p.0 - x).abs() <= 1 && (p.1 - y).abs() <= 1);
        assert!(hit, "marker ({x}, {y}) is off the path");
    }
}

#[test]
fn the_same_program_gives_the_same_bytes() {
    for p in [
        octagon(Interpolation::Pvt),
        octagon(Interpolation::Pt),
        rapid_then_feed(),
    ] {
        let a = plot_svg(&p, &options("same")).unwrap();
        let b = plot_svg(&p, &options("same")).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn pt_plot_says_its_acceleration_impulses_are_not_drawn() {
    let svg = plot_svg(&octagon(Interpolation::Pt), &options("PT")).unwrap();
    well_formed(&svg);
    assert!(texts(&svg)
        .iter()
        .any(|t| t.contains("PT: impulses at the points not drawn")));
}

#[test]
fn rapids_are_grey_and_feeds_are_coloured() {
    let svg = plot_svg(&rapid_then_feed(), &options("rapid then feed")).unwrap();
    well_formed(&svg);
    keep("rapid_feed_plot.svg", &svg);
    let strokes = attributes(&svg, "polyline", "stroke");
    assert!(strokes.iter().any(|s| s == "#969696"), "{strokes:?}");
    assert!(texts(&svg).iter().any(|t| t.contains("(faded: rapid)")));
}

#[test]
fn one_axis_programs_plot_position_against_time() {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
    c.push(&[90.0], &[0.0], 2.0, 1);
    let p = program(vec![Axis::C], Interpolation::Pvt, vec![c]);
    let svg = plot_svg(&p, &options("one rotary axis")).unwrap();
    keep("rotary_plot.svg", &svg);
    let t = texts(&svg);
    for label in [
        "C against time, coloured by speed",
        "C (deg)",
        "speed (deg/s)",
    ] {
        assert!(t.iter().any(|x| x == label), "no text {label:?} in {t:?}");
    }
}

#[test]
fn empty_and_invalid_programs_are_refused() {
    let empty = program(vec![Axis::X], Interpolation::Pvt, Vec::new());
    assert_eq!(
        plot_svg(&empty, &PlotOptions::default()),
        Err(PlotError::Empty)
    );
    let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
    c.push(&[1.0], &[0.0], 0.0, 7);
    let bad = program(vec![Axis::X], Interpolation::Pvt, vec![c]);
    assert!(matches!(
        plot_svg(&bad, &PlotOptions::default()),
        Err(PlotError::Invalid(_))
    ));
}

/// Position of X, Y (and Z) in a six-axis position.
fn at(x: f64, y: f64, z: f64) -> pvt_core::Position {
    [x, y, z, 0.0, 0.0, 0.0]
}

/// A half circle of radius 10 about the origin from (10, 0) to (-10, 0), counter-clockwise,
/// then a line to (-10, -5): the programmed geometry, and a program that runs the half
/// circle as four chords (45° each, at rest at every point, so each piece is its chord).
fn half_circle() -> (PvtProgram, pvt_core::Toolpath) {
    use pvt_core::{Arc, ArcDirection, Contour, Element, ElementKind, Plane, Span, Toolpath};
    let arc = Element {
        kind: ElementKind::Arc(Arc {
            plane: Plane::XY,
            center: [0.0, 0.0],
            direction: ArcDirection::CounterClockwise,
            extra_turns: 0,
        }),
        start: at(10.0, 0.0, 0.0),
        end: at(-10.0, 0.0, 0.0),
        feed: 600.0,
        span: Span::default(),
    };
    let line = Element {
        kind: ElementKind::Line,
        start: at(-10.0, 0.0, 0.0),
        end: at(-10.0, -5.0, 0.0),
        feed: 600.0,
        span: Span::default(),
    };
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements: vec![arc, line],
        }],
        ..Toolpath::default()
    };
    let mut c = PvtContour::new(Motion::Feed, vec![10.0, 0.0]);
    for k in 1..=4 {
        let (s, co) = sin_cos_45(k);
        c.push(&[10.0 * co, 10.0 * s], &[0.0, 0.0], 0.5, 1);
    }
    c.push(&[-10.0, -5.0], &[0.0, 0.0], 0.5, 2);
    let p = program(vec![Axis::X, Axis::Y], Interpolation::Pvt, vec![c]);
    (p, toolpath)
}

fn with_geometry(toolpath: pvt_core::Toolpath) -> PlotOptions {
    PlotOptions {
        geometry: Some(toolpath),
        ..options("half circle")
    }
}

/// Pixel points of the polylines drawn with `stroke`.
fn polyline_points(svg: &str, stroke: &str) -> Vec<Vec<(f64, f64)>> {
    let strokes = attributes(svg, "polyline", "stroke");
    let points = attributes(svg, "polyline", "points");
    strokes
        .iter()
        .zip(&points)
        .filter(|(s, _)| s.as_str() == stroke)
        .map(|(_, p)| {
            p.split_whitespace()
                .map(|xy| {
                    let (x, y) = xy.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

/// The programmed path is drawn as the true arc (every point at the radius, one a
/// degree), not as the chords the motion takes; only the elements' end points are
/// marked, not every piece end.
#[test]
fn the_programmed_path_is_the_true_arc_and_only_element_ends_are_marked() {
    let (p, toolpath) = half_circle();
    let svg = plot_svg(&p, &with_geometry(toolpath)).unwrap();
    well_formed(&svg);
    // The contour's polyline, and the legend's two-point key line.
    let programmed = polyline_points(&svg, "#C8C8C8");
    assert_eq!(programmed.len(), 2, "one contour, one key");
    let line = &programmed[0];
    // The ends of the half circle: (10, 0) first; (-10, 0) where the line turns down.
    let start = line[0];
    let turn = line
        .iter()
        .position(|q| q.0 == line.last().unwrap().0)
        .unwrap();
    let end = line[turn];
    let centre = ((start.0 + end.0) / 2.0, (start.1 + end.1) / 2.0);
    let r = (start.0 - end.0).abs() / 2.0;
    assert!(r > 100.0, "a readable circle: radius {r} px");
    let dist = |q: &(f64, f64)| ((q.0 - centre.0).powi(2) + (q.1 - centre.1).powi(2)).sqrt();
    for q in &line[..=turn] {
        assert!(
            (dist(q) - r).abs() <= 1.5,
            "{q:?} is off the circle of {r} px"
        );
    }
    assert!(turn >= 170, "one point a degree: {turn}");
    // The motion runs the chords: their middles are inside the circle by r(1 - cos 22.5°).
    let motion: Vec<(f64, f64)> = attributes(&svg, "polyline", "points")
        .iter()
        .flat_map(|p| p.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .map(|xy| {
            let (x, y) = xy.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect();
    let inside = motion.iter().map(dist).fold(f64::INFINITY, f64::min);
    assert!(inside < r * 0.95, "the chords dip to {inside} of {r}");
    // Markers: the three element ends and the legend's, not the six piece ends.
    let cx = attributes(&svg, "circle", "cx");
    assert_eq!(cx.len(), 3 + 1, "{cx:?}");
    // Without the geometry every piece end is marked, as before.
    let plain = plot_svg(&p, &options("plain")).unwrap();
    assert_eq!(attributes(&plain, "circle", "cx").len(), 6 + 1);
    assert_eq!(polyline_points(&plain, "#C8C8C8").len(), 1, "the key only");
}

/// A program whose third axis moves gets a panel of it against time; one in a plane does not.
#[test]
fn a_moving_third_axis_gets_its_own_panel() {
    let mut c = PvtContour::new(Motion::Feed, vec![0.0, 0.0, 0.0]);
    c.push(&[10.0, 0.0, -2.0], &[0.0, 0.0, 0.0], 1.0, 1);
    c.push(&[10.0, 10.0, -2.0], &[0.0, 0.0, 0.0], 1.0, 2);
    let xyz = program(vec![Axis::X, Axis::Y, Axis::Z], Interpolation::Pvt, vec![c]);
    let svg = plot_svg(&xyz, &options("xyz")).unwrap();
    assert!(
        svg.contains("Z against time (the third axis)"),
        "no Z panel"
    );
    assert!(svg.contains("Z (mm)"), "no Z axis label");
    let flat = plot_svg(&octagon(Interpolation::Pvt), &options("flat")).unwrap();
    assert!(!flat.contains("third axis"));
    // A third axis that stays put gets no panel.
    let mut c = PvtContour::new(Motion::Feed, vec![0.0, 0.0, 1.0]);
    c.push(&[10.0, 0.0, 1.0], &[0.0, 0.0, 0.0], 1.0, 1);
    let still = program(vec![Axis::X, Axis::Y, Axis::Z], Interpolation::Pvt, vec![c]);
    assert!(!plot_svg(&still, &options("still"))
        .unwrap()
        .contains("third axis"));
}

/// PNG: a real image of the asked size, with the programmed path's grey and the title's
/// text drawn in it (the built-in font), the same bytes every time.
#[test]
fn png_plots_are_images_with_the_path_and_the_text_drawn() {
    let (p, toolpath) = half_circle();
    let options = with_geometry(toolpath);
    let png = pvt_emit::plot::plot_png(&p, &options).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(png, pvt_emit::plot::plot_png(&p, &options).unwrap());
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (1000, 1500));
    let grey = image.pixels().filter(|px| px.0 == [200, 200, 200]).count();
    assert!(grey > 500, "programmed path pixels: {grey}");
    // The title is drawn: dark pixels in the top 30 rows.
    let dark = (0..1000)
        .flat_map(|x| (0..30).map(move |y| (x, y)))
        .filter(|&(x, y)| image.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count();
    assert!(dark > 50, "title pixels: {dark}");
    if let Some(dir) = std::env::var_os("PVT_PLOT_DIR") {
        std::fs::write(std::path::Path::new(&dir).join("half_circle.png"), &png).unwrap();
    }
}

/// A path that crosses itself (two turns of a circle) is drawn solid in PNG: plotters
/// fills a wide polyline as one polygon, whose overlapping turns would cancel.
#[test]
fn png_draws_a_path_that_crosses_itself_solid() {
    use pvt_core::{Arc, ArcDirection, Contour, Element, ElementKind, Plane, Span, Toolpath};
    let turns = Element {
        kind: ElementKind::Arc(Arc {
            plane: Plane::XY,
            center: [0.0, 0.0],
            direction: ArcDirection::CounterClockwise,
            extra_turns: 1,
        }),
        start: at(10.0, 0.0, 0.0),
        end: at(10.0, 0.0, 0.0),
        feed: 600.0,
        span: Span::default(),
    };
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements: vec![turns],
        }],
        ..Toolpath::default()
    };
    let mut c = PvtContour::new(Motion::Feed, vec![10.0, 0.0]);
    for k in 1..=16 {
        let (s, co) = sin_cos_45(k);
        c.push(&[10.0 * co, 10.0 * s], &[0.0, 0.0], 0.25, 1);
    }
    let p = program(vec![Axis::X, Axis::Y], Interpolation::Pvt, vec![c]);
    let options = with_geometry(toolpath);
    // The SVG has the same layout: the top of the programmed circle in pixels.
    let svg = plot_svg(&p, &options).unwrap();
    let circle = polyline_points(&svg, "#C8C8C8")
        .into_iter()
        .max_by_key(|l| l.len())
        .unwrap();
    let top = circle
        .iter()
        .copied()
        .fold((0.0, f64::INFINITY), |a, q| if q.1 < a.1 { q } else { a });
    let image = image::load_from_memory(&pvt_emit::plot::plot_png(&p, &options).unwrap())
        .unwrap()
        .to_rgb8();
    let (x, y) = (top.0 as u32, top.1 as u32);
    let inked = (x - 3..=x + 3)
        .flat_map(|x| (y - 3..=y + 3).map(move |y| (x, y)))
        .filter(|&(x, y)| image.get_pixel(x, y).0 == [200, 200, 200])
        .count();
    assert!(
        inked >= 10,
        "{inked} grey pixels around the top of the circle ({x}, {y})"
    );
}
