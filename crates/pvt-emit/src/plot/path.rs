//! The path panel (the motion in its plane, coloured by speed) and its colour scale.
//!
//! Owns how the path is projected (first two axes, or position against time for a
//! one-axis program), the equal aspect ratio, the programmed path drawn under the motion
//! (lines, and arcs and helices as true arcs, from the toolpath), the speed colouring,
//! the markers of the programmed end points of elements and the legend. It must not
//! sample the motion.

use super::draw::{
    chart, failed, runs_of, titled, Area, Ctx, FONT, MARGIN, RAPID, X_LABELS, Y_LABELS,
};
use super::scale::{bin, equal_aspect, extent, padded, ramp, tick, BINS};
use super::PlotError;
use plotters::prelude::*;
use pvt_core::{ElementKind, Motion, Position, PvtProgram, Toolpath};

/// Most programmed points marked; beyond it every n-th is.
const MAX_MARKERS: usize = 2_000;
/// Colour of the programmed path drawn under the motion.
pub(super) const PROGRAMMED: RGBColor = RGBColor(200, 200, 200);
/// Width of the programmed path, pixels (wider than the motion, which lies on it).
const PROGRAMMED_WIDTH: u32 = 6;
/// Largest angle between two points of an arc drawn as the programmed path, radians (1°).
const ARC_STEP: f64 = std::f64::consts::PI / 180.0;
/// Most points of the programmed path drawn.
const MAX_PATH_POINTS: usize = 200_000;

/// Points of a line drawn in the plane.
type Polyline = Vec<(f64, f64)>;

/// The two coordinates the path panel plots.
#[derive(Clone, Copy)]
enum Plane {
    /// Axis columns 0 and 1.
    Axes,
    /// Time and axis column 0.
    Time,
}

impl Plane {
    fn of(ctx: &Ctx) -> Plane {
        if ctx.samples.dim >= 2 {
            Plane::Axes
        } else {
            Plane::Time
        }
    }

    /// The plotted point of a position at a time.
    fn point(self, time: f64, position: &[f64]) -> (f64, f64) {
        match self {
            Plane::Axes => (position[0], position[1]),
            Plane::Time => (time, position[0]),
        }
    }
}

/// The programmed points (contour starts and segment ends) as (time, position), every
/// n-th of them beyond `max` (and the last).
fn programmed_points(program: &PvtProgram, max: usize) -> Vec<(f64, &[f64])> {
    let starts = program.contours.iter().filter(|c| !c.is_empty()).count();
    let total = program.segment_count() + starts;
    let stride = total.div_ceil(max.max(2) - 1).max(1);
    let keep = |r: usize| r.is_multiple_of(stride) || r + 1 == total;
    let mut out = Vec::new();
    let (mut clock, mut r) = (0.0, 0);
    for contour in program.contours.iter().filter(|c| !c.is_empty()) {
        if keep(r) {
            out.push((clock, &contour.start[..]));
        }
        r += 1;
        for seg in contour.segments() {
            clock += seg.duration;
            if keep(r) {
                out.push((clock, seg.end));
            }
            r += 1;
        }
    }
    out
}

/// Points drawn along one Bézier element.
const BEZIER_POINTS: usize = 32;

/// The points of an element in its true shape: a line's two ends; an arc or helix at
/// most [`ARC_STEP`] apart (the radius and the other axes change linearly with angle, as
/// [`pvt_core::Arc`] defines); a Bézier at [`BEZIER_POINTS`] equal parameter steps.
fn element_points(kind: &ElementKind, start: &Position, end: &Position) -> Vec<Position> {
    if let ElementKind::Bezier(bezier) = kind {
        let mut points = vec![*start];
        points.extend(
            (1..=BEZIER_POINTS)
                .map(|k| bezier.position(start, end, k as f64 / BEZIER_POINTS as f64)),
        );
        return points;
    }
    let ElementKind::Arc(arc) = kind else {
        return vec![*start, *end];
    };
    let sweep = arc.sweep(start, end);
    let n = (sweep.sweep.abs() / ARC_STEP).ceil().clamp(1.0, 100_000.0) as usize;
    let (a, b, _) = arc.plane.axes();
    (0..=n)
        .map(|k| {
            let f = k as f64 / n as f64;
            let mut p = *start;
            for (q, (s, e)) in p.iter_mut().zip(start.iter().zip(end)) {
                *q = s + (e - s) * f;
            }
            let angle = sweep.start_angle + sweep.sweep * f;
            let r = sweep.start_radius + (sweep.end_radius - sweep.start_radius) * f;
            p[a.index()] = arc.center[0] + r * libm::cos(angle);
            p[b.index()] = arc.center[1] + r * libm::sin(angle);
            if k == n {
                p = *end;
            }
            p
        })
        .collect()
}

/// The programmed path of the feed contours in the plane of the first two axes: one
/// polyline a contour.
fn programmed_path(ctx: &Ctx, geometry: &Toolpath) -> Vec<Polyline> {
    let axes = &ctx.program.axes;
    let (i, j) = (axes[0].index(), axes[1].index());
    let mut out = Vec::new();
    let mut total = 0;
    // Rapids are drawn by the motion itself (thin grey); only feed contours are cut.
    for contour in geometry
        .contours
        .iter()
        .filter(|c| c.motion == Motion::Feed)
    {
        let mut line: Vec<(f64, f64)> = Vec::new();
        for e in &contour.elements {
            let points = element_points(&e.kind, &e.start, &e.end);
            let skip = usize::from(!line.is_empty());
            line.extend(points.iter().skip(skip).map(|p| (p[i], p[j])));
        }
        total += line.len();
        if total > MAX_PATH_POINTS {
            break;
        }
        out.push(line);
    }
    out
}

/// The programmed end points of the elements (and each contour's start), every n-th
/// beyond `max` (and the last).
fn element_ends(ctx: &Ctx, geometry: &Toolpath, max: usize) -> Vec<(f64, f64)> {
    let axes = &ctx.program.axes;
    let (i, j) = (axes[0].index(), axes[1].index());
    let all: Vec<(f64, f64)> = geometry
        .contours
        .iter()
        .filter(|c| !c.elements.is_empty())
        .flat_map(|c| {
            std::iter::once(&c.elements[0].start)
                .chain(c.elements.iter().map(|e| &e.end))
                .map(|p| (p[i], p[j]))
        })
        .collect();
    let stride = all.len().div_ceil(max.max(2) - 1).max(1);
    let last = all.len().saturating_sub(1);
    all.iter()
        .enumerate()
        .filter(|(r, _)| r % stride == 0 || *r == last)
        .map(|(_, p)| *p)
        .collect()
}

/// The programmed geometry to draw in this plane, if there is one.
fn geometry_of<'a>(ctx: &Ctx<'a>, plane: Plane) -> Option<&'a Toolpath> {
    let g = ctx.geometry?;
    let has_elements = g.contours.iter().any(|c| !c.elements.is_empty());
    (matches!(plane, Plane::Axes) && has_elements).then_some(g)
}

/// The path with the programmed end points marked over the programmed path (grey),
/// rapid grey, feed coloured by speed.
pub(super) fn path_panel<DB: DrawingBackend>(area: &Area<DB>, ctx: &Ctx) -> Result<(), PlotError> {
    let plane = Plane::of(ctx);
    let s = ctx.samples;
    let geometry = geometry_of(ctx, plane);
    let (marks, drawn): (Vec<(f64, f64)>, Vec<Polyline>) = match geometry {
        Some(g) => (element_ends(ctx, g, MAX_MARKERS), programmed_path(ctx, g)),
        None => (
            programmed_points(ctx.program, MAX_MARKERS)
                .into_iter()
                .map(|(t, p)| plane.point(t, p))
                .collect(),
            Vec::new(),
        ),
    };
    let all: Vec<(f64, f64)> = (0..s.len())
        .map(|i| plane.point(s.time[i], s.position(i)))
        .chain(marks.iter().copied())
        .chain(drawn.iter().flatten().copied())
        .collect();
    let x = padded(extent(all.iter().map(|p| p.0))?);
    let y = padded(extent(all.iter().map(|p| p.1))?);
    let (caption, names) = match plane {
        Plane::Axes => {
            let (a, b) = (ctx.axis_name(0), ctx.axis_name(1));
            let units = &ctx.units.axis;
            let names = (format!("{a} ({})", units[0]), format!("{b} ({})", units[1]));
            (
                format!("path in the {a}{b} plane, coloured by speed"),
                names,
            )
        }
        Plane::Time => {
            let a = ctx.axis_name(0);
            let names = (
                "time (s)".to_string(),
                format!("{a} ({})", ctx.units.axis[0]),
            );
            (format!("{a} against time, coloured by speed"), names)
        }
    };
    let area = titled(area, &caption)?;
    let (x, y) = match plane {
        Plane::Axes => equal_aspect(x, y, plot_pixels(&area)),
        Plane::Time => (x, y),
    };
    let mut chart = chart(&area, (x, y), (&names.0, &names.1))?;
    let programmed = PROGRAMMED.stroke_width(PROGRAMMED_WIDTH);
    let programmed_runs = drawn
        .into_iter()
        .flat_map(|l| runs_of(l, ctx.longest_run))
        .map(|l| PathElement::new(l, programmed));
    chart.draw_series(programmed_runs).map_err(failed)?;
    let scale = speed_scale(ctx)?;
    for run in &ctx.runs {
        let points: Vec<(f64, f64)> = run
            .range
            .clone()
            .map(|i| plane.point(s.time[i], s.position(i)))
            .collect();
        let paths = match run.motion {
            Motion::Rapid => vec![PathElement::new(points, RAPID.stroke_width(1))],
            Motion::Feed => {
                let speed = &s.speed[run.range.clone()];
                coloured(&points, speed, scale, ctx.longest_run)
            }
        };
        chart.draw_series(paths).map_err(failed)?;
    }
    let marker = |p: &(f64, f64)| Circle::new(*p, 4, BLACK.stroke_width(1));
    chart
        .draw_series(marks.iter().map(marker))
        .map_err(failed)?;
    Ok(())
}

/// Pixel size of the plotting area a [`chart`] on `area` gets.
fn plot_pixels<DB: DrawingBackend>(area: &Area<DB>) -> (u32, u32) {
    let (w, h) = area.dim_in_pixel();
    (
        w.saturating_sub(2 * MARGIN + Y_LABELS),
        h.saturating_sub(2 * MARGIN + X_LABELS),
    )
}

/// The range the colour scale spans: speeds of feed samples (of all when none is feed).
fn speed_scale(ctx: &Ctx) -> Result<(f64, f64), PlotError> {
    let s = ctx.samples;
    let feed = (0..s.len()).filter(|&i| s.at[i].motion == Motion::Feed);
    match extent(feed.map(|i| s.speed[i])) {
        Err(PlotError::Empty) => extent(s.speed.iter().copied()),
        other => other,
    }
}

/// Polylines through `points`, one per stretch of equal speed colour.
fn coloured(
    points: &[(f64, f64)],
    speed: &[f64],
    scale: (f64, f64),
    longest_run: usize,
) -> Vec<PathElement<(f64, f64)>> {
    let mut out = Vec::new();
    let mut start = 0;
    let colour_of = |i: usize| bin((speed[i] + speed[i + 1]) / 2.0, scale);
    for i in 0..points.len().saturating_sub(1) {
        let last = i + 2 == points.len();
        if last || colour_of(i + 1) != colour_of(start) {
            let style = ramp(colour_of(start)).stroke_width(2);
            for run in runs_of(points[start..i + 2].to_vec(), longest_run) {
                out.push(PathElement::new(run, style));
            }
            start = i + 1;
        }
    }
    out
}

/// The colour scale of the speed, min and max with units, and the key to the marks.
pub(super) fn legend_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    ctx: &Ctx,
) -> Result<(), PlotError> {
    let scale = speed_scale(ctx)?;
    let unit = format!("speed ({}/s)", ctx.units.speed);
    let area = titled(area, "speed scale")?;
    let (_, h) = area.dim_in_pixel();
    let (bar, key) = area.split_vertically(h.saturating_sub(130));
    let (lo, hi) = if scale.1 > scale.0 {
        scale
    } else {
        padded(scale)
    };
    let mut c = ChartBuilder::on(&bar)
        .margin(MARGIN)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(failed)?;
    c.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(unit.as_str())
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(failed)?;
    let step = (hi - lo) / BINS as f64;
    let rects = (0..BINS).map(|b| {
        let y0 = lo + step * b as f64;
        Rectangle::new([(0.0, y0), (1.0, y0 + step)], ramp(b).filled())
    });
    c.draw_series(rects).map_err(failed)?;
    key_text(&key, ctx, scale)
}

/// The key under the colour bar: speed extremes, rapid line, point marker.
fn key_text<DB: DrawingBackend>(
    area: &Area<DB>,
    ctx: &Ctx,
    (lo, hi): (f64, f64),
) -> Result<(), PlotError> {
    let font = (FONT, 13).into_font();
    let unit = format!("{}/s", ctx.units.speed);
    let lines = [
        format!("min {} {unit}", tick(lo)),
        format!("max {} {unit}", tick(hi)),
        "rapid".to_string(),
        "element end".to_string(),
        "programmed path".to_string(),
    ];
    for (n, line) in lines.iter().enumerate() {
        let y = 14 + 20 * n as i32;
        area.draw(&Text::new(line.as_str(), (40, y), font.clone()))
            .map_err(failed)?;
    }
    let rapid = PathElement::new(vec![(12, 61), (34, 61)], RAPID.stroke_width(1));
    area.draw(&rapid).map_err(failed)?;
    area.draw(&Circle::new((23, 81), 4, BLACK.stroke_width(1)))
        .map_err(failed)?;
    let path = PathElement::new(
        vec![(12, 101), (34, 101)],
        PROGRAMMED.stroke_width(PROGRAMMED_WIDTH),
    );
    area.draw(&path).map_err(failed)?;
    if ctx.samples.decimated {
        let note = Text::new("(piece ends only)", (40, 114), font);
        area.draw(&note).map_err(failed)?;
    }
    Ok(())
}
