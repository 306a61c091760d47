//! The panels of the plot, drawn with plotters into one SVG document or PNG image.
//!
//! Owns the layout (title, path panel with its colour scale, then speed, axis velocity
//! and axis acceleration against time, and the third axis against time when it moves),
//! the styles, and the choice of backend (SVG text, or a bitmap encoded as PNG). It must not sample the motion:
//! it draws the [`Samples`] it is given, in their order, so the output is deterministic.

use super::sample::Samples;
use super::scale::{extent, padded, tick, Units};
use super::{PlotError, PlotOptions};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use pvt_core::{Interpolation, Motion, PvtProgram};
use std::ops::Range;

/// The font family every label asks for (the SVG viewer picks the face).
pub(super) const FONT: &str = "sans-serif";
/// Gap around each chart, pixels.
pub(super) const MARGIN: u32 = 12;
/// Height of the x label area of a chart, pixels.
pub(super) const X_LABELS: u32 = 46;
/// Width of the y label area of a chart, pixels.
pub(super) const Y_LABELS: u32 = 78;
/// Colour of rapid motion.
pub(super) const RAPID: RGBColor = RGBColor(150, 150, 150);
/// Most points in one wide polyline drawn on a bitmap. Plotters fills a wide polyline as
/// one polygon, and where the line crosses itself (the turns of a helix) the crossings
/// cancel and leave holes; runs this short cannot cross themselves on a smooth path.
const BITMAP_RUN: usize = 12;

/// `points` as polylines of at most `max` points (2 at least), each starting where the
/// last ended, so they join.
pub(super) fn runs_of(points: Vec<(f64, f64)>, max: usize) -> Vec<Vec<(f64, f64)>> {
    let max = max.max(2);
    if points.len() <= max {
        return vec![points];
    }
    let mut out = Vec::new();
    let mut start = 0;
    while start + 1 < points.len() {
        let end = (start + max).min(points.len());
        out.push(points[start..end].to_vec());
        start = end - 1;
    }
    out
}

/// A drawing area of the document (SVG or bitmap).
pub(super) type Area<DB> = DrawingArea<DB, Shift>;
/// A chart with numeric axes on an area.
pub(super) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A stretch of samples of one kind of motion; it also holds the next stretch's first
/// sample, so consecutive stretches join.
pub(super) struct Run {
    /// Rapid or feed.
    pub motion: Motion,
    /// Indices into the samples.
    pub range: Range<usize>,
}

/// What every panel draws from.
pub(super) struct Ctx<'a> {
    /// The program plotted.
    pub program: &'a PvtProgram,
    /// Its sampled motion.
    pub samples: &'a Samples,
    /// Units of its quantities.
    pub units: Units,
    /// Stretches of feed and rapid motion, in time order.
    pub runs: Vec<Run>,
    /// The programmed geometry, when known.
    pub geometry: Option<&'a pvt_core::Toolpath>,
    /// Most points in one wide polyline of the path panel (see [`BITMAP_RUN`]).
    pub longest_run: usize,
}

impl Ctx<'_> {
    /// Axis names in column order.
    pub(super) fn axis_name(&self, axis: usize) -> String {
        self.program.axes[axis].to_string()
    }
}

/// Maps a plotters error into a [`PlotError`].
pub(super) fn failed<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// The whole document as SVG text.
pub(super) fn render(
    program: &PvtProgram,
    samples: &Samples,
    options: &PlotOptions,
) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size(options)).into_drawing_area();
        render_on(&root, program, samples, options, usize::MAX)?;
    }
    Ok(svg)
}

/// The whole document as a PNG file's bytes.
pub(super) fn render_png(
    program: &PvtProgram,
    samples: &Samples,
    options: &PlotOptions,
) -> Result<Vec<u8>, PlotError> {
    let (w, h) = size(options);
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        render_on(&root, program, samples, options, BITMAP_RUN)?;
    }
    let image = image::RgbImage::from_raw(w, h, rgb)
        .ok_or_else(|| PlotError::Draw("bitmap size mismatch".into()))?;
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(failed)?;
    Ok(png)
}

/// Pixel size of the document.
fn size(options: &PlotOptions) -> (u32, u32) {
    (options.width.max(400), options.height.max(600))
}

/// Draws every panel on `root`.
fn render_on<DB: DrawingBackend>(
    root: &Area<DB>,
    program: &PvtProgram,
    samples: &Samples,
    options: &PlotOptions,
    longest_run: usize,
) -> Result<(), PlotError> {
    super::fonts()?;
    let ctx = Ctx {
        program,
        samples,
        units: Units::of(program),
        runs: runs(samples),
        geometry: options.geometry.as_ref(),
        longest_run,
    };
    root.fill(&WHITE).map_err(failed)?;
    let body = root
        .titled(
            &options.title,
            (FONT, 26).into_font().style(FontStyle::Bold),
        )
        .map_err(failed)?;
    let (w, h) = body.dim_in_pixel();
    let (top, bottom) = body.split_vertically(h * 42 / 100);
    let (path, legend) = top.split_horizontally(w.saturating_sub(170));
    super::path::path_panel(&path, &ctx)?;
    super::path::legend_panel(&legend, &ctx)?;
    let third = third_axis(&ctx);
    let rows = bottom.split_evenly((if third.is_some() { 4 } else { 3 }, 1));
    speed_panel(&rows[0], &ctx)?;
    axes_panel(&rows[1], &ctx, Quantity::Velocity, options)?;
    axes_panel(&rows[2], &ctx, Quantity::Acceleration, options)?;
    if let Some(axis) = third {
        position_panel(&rows[3], &ctx, axis)?;
    }
    root.present().map_err(failed)?;
    Ok(())
}

/// The column of the third axis (Z in an XYZ program) when it moves.
fn third_axis(ctx: &Ctx) -> Option<usize> {
    let s = ctx.samples;
    if s.dim < 3 || s.is_empty() {
        return None;
    }
    let column = (0..s.len()).map(|i| s.position(i)[2]);
    let (lo, hi) = column.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    (hi > lo).then_some(2)
}

/// The third axis' position against time: feed dark, rapid grey.
fn position_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    ctx: &Ctx,
    axis: usize,
) -> Result<(), PlotError> {
    let s = ctx.samples;
    let name = ctx.axis_name(axis);
    let (lo, hi) = extent((0..s.len()).map(|i| s.position(i)[axis]))?;
    let caption = format!("{name} against time (the third axis)");
    let unit = format!("{name} ({})", ctx.units.axis[axis]);
    let area = titled(area, &caption)?;
    let mut chart = chart(
        &area,
        (time_range(ctx), padded((lo, hi))),
        ("time (s)", &unit),
    )?;
    for run in &ctx.runs {
        let style = match run.motion {
            Motion::Feed => axis_colour(axis).stroke_width(2),
            Motion::Rapid => RAPID.stroke_width(1),
        };
        let points = run.range.clone().map(|i| (s.time[i], s.position(i)[axis]));
        chart
            .draw_series(LineSeries::new(points, style))
            .map_err(failed)?;
    }
    Ok(())
}

/// Splits the samples where the motion changes between feed and rapid.
fn runs(samples: &Samples) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::new();
    for (i, at) in samples.at.iter().enumerate() {
        match out.last_mut() {
            Some(run) if run.motion == at.motion => run.range.end = i + 1,
            Some(run) => {
                run.range.end = i + 1;
                out.push(Run {
                    motion: at.motion,
                    range: i..i + 1,
                });
            }
            None => out.push(Run {
                motion: at.motion,
                range: i..i + 1,
            }),
        }
    }
    out
}

/// `area` below a panel title `caption`.
pub(super) fn titled<DB: DrawingBackend>(
    area: &Area<DB>,
    caption: &str,
) -> Result<Area<DB>, PlotError> {
    area.titled(caption, (FONT, 18)).map_err(failed)
}

/// A chart filling `area` with ranges `x`, `y` and labelled axes.
pub(super) fn chart<'a, DB: DrawingBackend>(
    area: &'a Area<DB>,
    (x, y): ((f64, f64), (f64, f64)),
    (x_desc, y_desc): (&str, &str),
) -> Result<Chart<'a, DB>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(failed)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(8)
        .y_labels(6)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(failed)?;
    Ok(chart)
}

/// The time axis range of the program.
fn time_range(ctx: &Ctx) -> (f64, f64) {
    let end = ctx.samples.time.last().copied().unwrap_or(0.0);
    (0.0, if end > 0.0 { end } else { 1.0 })
}

/// Vector speed against time: feed dark blue, rapid grey.
fn speed_panel<DB: DrawingBackend>(area: &Area<DB>, ctx: &Ctx) -> Result<(), PlotError> {
    let (_, hi) = extent(ctx.samples.speed.iter().copied())?;
    let y = padded((0.0, hi));
    let unit = format!("speed ({}/s)", ctx.units.speed);
    let area = titled(area, "vector speed against time")?;
    let mut chart = chart(&area, (time_range(ctx), (0.0, y.1)), ("time (s)", &unit))?;
    let s = ctx.samples;
    for run in &ctx.runs {
        let style = match run.motion {
            Motion::Feed => RGBColor(31, 60, 140).stroke_width(2),
            Motion::Rapid => RAPID.stroke_width(1),
        };
        let points = run.range.clone().map(|i| (s.time[i], s.speed[i]));
        chart
            .draw_series(LineSeries::new(points, style))
            .map_err(failed)?;
    }
    Ok(())
}

/// The per-axis quantity a panel shows.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Quantity {
    Velocity,
    Acceleration,
}

/// Line colour of axis column `axis`.
fn axis_colour(axis: usize) -> RGBColor {
    const COLOURS: [RGBColor; 6] = [
        RGBColor(214, 39, 40),
        RGBColor(31, 119, 180),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(140, 86, 75),
    ];
    COLOURS[axis % COLOURS.len()]
}

/// Caption and y description of a per-axis panel.
fn describe(ctx: &Ctx, q: Quantity) -> (String, String) {
    let faded = if ctx.runs.iter().any(|r| r.motion == Motion::Rapid) {
        " (faded: rapid)"
    } else {
        ""
    };
    match q {
        Quantity::Velocity => (
            format!("axis velocity against time{faded}"),
            format!("velocity ({})", ctx.units.joined("/s")),
        ),
        Quantity::Acceleration => {
            let pt = ctx.program.interpolation == Interpolation::Pt;
            let note = if pt {
                " (PT: impulses at the points not drawn)"
            } else {
                ""
            };
            (
                format!("axis acceleration against time{faded}{note}"),
                format!("acceleration ({})", ctx.units.joined("/s²")),
            )
        }
    }
}

/// The limit of `q` on each axis of the program, where `options` gives one.
fn limits_of(ctx: &Ctx, q: Quantity, options: &PlotOptions) -> Vec<Option<f64>> {
    ctx.program
        .axes
        .iter()
        .map(|a| {
            let l = options.limits.get(a)?;
            match q {
                Quantity::Velocity => l.velocity,
                Quantity::Acceleration => l.acceleration,
            }
        })
        .collect()
}

/// Each axis' velocity or acceleration against time, one colour an axis, with its
/// limits (if given) as dashed lines at ± the limit.
fn axes_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    ctx: &Ctx,
    q: Quantity,
    options: &PlotOptions,
) -> Result<(), PlotError> {
    let s = ctx.samples;
    let values = match q {
        Quantity::Velocity => &s.velocity,
        Quantity::Acceleration => &s.acceleration,
    };
    let limits = limits_of(ctx, q, options);
    let (mut lo, mut hi) = extent(values.iter().copied())?;
    for l in limits.iter().flatten() {
        (lo, hi) = (lo.min(-l), hi.max(*l));
    }
    let (caption, y_desc) = describe(ctx, q);
    let area = titled(area, &caption)?;
    let mut chart = chart(
        &area,
        (time_range(ctx), padded((lo.min(0.0), hi.max(0.0)))),
        ("time (s)", &y_desc),
    )?;
    for axis in 0..s.dim {
        let colour = axis_colour(axis);
        for (n, run) in ctx.runs.iter().enumerate() {
            let style = match run.motion {
                Motion::Feed => colour.stroke_width(2),
                Motion::Rapid => colour.mix(0.4).stroke_width(1),
            };
            let points = run
                .range
                .clone()
                .map(|i| (s.time[i], values[i * s.dim + axis]));
            let series = chart
                .draw_series(LineSeries::new(points, style))
                .map_err(failed)?;
            if n == 0 {
                series.label(ctx.axis_name(axis)).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            }
        }
        if let Some(limit) = limits[axis] {
            let (t0, t1) = time_range(ctx);
            let style = colour.mix(0.7).stroke_width(1);
            for sign in [1.0, -1.0] {
                let line =
                    DashedLineSeries::new([(t0, sign * limit), (t1, sign * limit)], 6, 4, style);
                let series = chart.draw_series(line).map_err(failed)?;
                if sign > 0.0 {
                    series
                        .label(format!("{} limit", ctx.axis_name(axis)))
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                }
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(180, 180, 180))
        .draw()
        .map_err(failed)?;
    Ok(())
}
