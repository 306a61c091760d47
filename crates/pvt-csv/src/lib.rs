//! pvt-csv: the point-time CSV front end of pvtc.
//!
//! Owns the reading of point-time series as seed 001 tabulates them: a header row, then
//! one row per point. Columns: `t` (absolute time, s) or `dt` (time of the piece that
//! reaches the row's point, s; the first row's `dt` is the start time), axis names
//! `X Y Z A B C` (any case), and optionally `v<axis>` velocity columns (`vx`), given for
//! every axis or none and used as given by the PVT velocity methods, and an optional
//! `trigger` column of 0s and 1s (pvtc's own `--format csv --trigger-every` table), read
//! and checked but not part of the motion. Lines starting with
//! `#` are comments; blank lines are skipped; fields may be padded with spaces.
//!
//! It produces a [`PointSeries`] (axes in X..C order, units, start time and a
//! [`TimedPoints`] whose first point is the first row) or [`CsvErrors`] listing every bad
//! row with a stable code and a line/column span. It must not plan, never panics on any
//! input, and does no I/O: the caller reads the file.

mod diagnostic;

pub use diagnostic::{CsvDiagnostic, CsvErrorKind, CsvErrors};

use std::ops::Range;

use pvt_core::{
    Axis, Contour, Element, ElementKind, Motion, Position, Span, TimedPoints, Toolpath, Units,
    AXIS_COUNT,
};

/// A point-time series read from CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSeries {
    /// The axes given, in X Y Z A B C order (the order of every point's coordinates).
    pub axes: Vec<Axis>,
    /// Units of the linear axes (rotary axes are in degrees).
    pub units: Units,
    /// Time of the first row, seconds.
    pub start_time: f64,
    /// The points, segment times, velocities (if given) and each segment's line.
    pub points: TimedPoints,
    /// Where each row (point) is in the source.
    pub spans: Vec<Span>,
}

impl PointSeries {
    /// The straight lines through the points as a toolpath, for checking motion against
    /// them; each line's feed is its chord over its time (0 for a dwell).
    pub fn toolpath(&self) -> Toolpath {
        let p = &self.points;
        let position = |i: usize| -> Position {
            let mut out = [0.0; AXIS_COUNT];
            for (k, a) in self.axes.iter().enumerate() {
                out[a.index()] = p.point(i)[k];
            }
            out
        };
        let elements = (1..p.len())
            .map(|i| {
                let chord: f64 = p
                    .point(i)
                    .iter()
                    .zip(p.point(i - 1))
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum();
                Element {
                    kind: ElementKind::Line,
                    start: position(i - 1),
                    end: position(i),
                    feed: chord.sqrt() / p.durations[i - 1],
                    span: self.spans[i],
                }
            })
            .collect();
        Toolpath {
            units: self.units,
            contours: vec![Contour {
                motion: Motion::Feed,
                elements,
            }],
            events: Vec::new(),
            path_tolerances: Vec::new(),
        }
    }
}

/// What a header column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    Time,
    Dt,
    Position(Axis),
    Velocity(Axis),
    /// pvtc's `trigger` column: 0 or 1 on each row, no part of the motion.
    Trigger,
}

impl Column {
    /// The axes of the velocity columns (`velocity`) or of the position columns, in
    /// column order.
    fn axes(columns: &[Column], velocity: bool) -> Vec<Axis> {
        columns
            .iter()
            .filter_map(|c| match (c, velocity) {
                (Column::Position(a), false) | (Column::Velocity(a), true) => Some(*a),
                _ => None,
            })
            .collect()
    }
}

/// One field of a line: trimmed text and its byte range in the source.
struct Field<'a> {
    text: &'a str,
    range: Range<usize>,
}

/// One content line (not blank, not a comment).
struct Line<'a> {
    number: u32,
    range: Range<usize>,
    fields: Vec<Field<'a>>,
}

/// Reads a point-time CSV file; see the crate documentation for the format.
pub fn read_points(source: &str, units: Units) -> Result<PointSeries, CsvErrors> {
    let mut errors = Vec::new();
    let lines = content_lines(source);
    let Some((header, rows)) = lines.split_first() else {
        errors.push(diagnose(
            source,
            CsvErrorKind::MissingHeader,
            "the file has no header row".into(),
            0..0,
        ));
        return Err(CsvErrors {
            diagnostics: errors,
        });
    };
    let columns = read_header(source, header, &mut errors);
    if !errors.is_empty() {
        return Err(CsvErrors {
            diagnostics: errors,
        });
    }
    let series = read_rows(source, header, &columns, rows, units, &mut errors);
    if errors.is_empty() {
        if let Some(series) = series {
            return Ok(series);
        }
        let end = header.range.end;
        errors.push(diagnose(
            source,
            CsvErrorKind::NoRows,
            "no data row after the header".into(),
            end..end,
        ));
    }
    Err(CsvErrors {
        diagnostics: errors,
    })
}

/// Splits the source into content lines with their fields and byte ranges.
fn content_lines(source: &str) -> Vec<Line<'_>> {
    let mut out = Vec::new();
    for line in pvt_core::text::lines(source.as_bytes()) {
        let raw = &source[line.range.clone()];
        let mut text = raw.strip_suffix('\r').unwrap_or(raw);
        let mut base = line.range.start;
        if line.number == 1 {
            if let Some(rest) = text.strip_prefix('\u{feff}') {
                text = rest;
                base += '\u{feff}'.len_utf8();
            }
        }
        let trimmed = text.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let mut fields = Vec::new();
        let mut at = base;
        for part in text.split(',') {
            let lead = part.len() - part.trim_start().len();
            let field = part.trim();
            fields.push(Field {
                text: field,
                range: at + lead..at + lead + field.len(),
            });
            at += part.len() + 1;
        }
        let number = u32::try_from(line.number).unwrap_or(u32::MAX);
        out.push(Line {
            number,
            range: base..base + text.len(),
            fields,
        });
    }
    out
}

fn diagnose(
    source: &str,
    kind: CsvErrorKind,
    message: String,
    span: Range<usize>,
) -> CsvDiagnostic {
    let pvt_core::text::SourceLocation { line, column, .. } =
        pvt_core::text::SourceLocation::of(source, span.clone());
    CsvDiagnostic {
        kind,
        message,
        line,
        column,
        span,
    }
}

/// The meaning of each header field; errors for unknown, repeated or missing columns.
fn read_header(source: &str, header: &Line<'_>, errors: &mut Vec<CsvDiagnostic>) -> Vec<Column> {
    if header.fields.iter().all(|f| f.text.parse::<f64>().is_ok()) {
        let message = format!("line {} holds numbers, not column names", header.number);
        errors.push(diagnose(
            source,
            CsvErrorKind::MissingHeader,
            message,
            header.range.clone(),
        ));
        return Vec::new();
    }
    let mut columns: Vec<Column> = Vec::new();
    for f in &header.fields {
        let Some(column) = column_named(f.text) else {
            let message = format!("unknown column `{}`", f.text);
            errors.push(diagnose(
                source,
                CsvErrorKind::UnknownColumn,
                message,
                f.range.clone(),
            ));
            continue;
        };
        let time = |c: &Column| matches!(c, Column::Time | Column::Dt);
        if columns
            .iter()
            .any(|c| *c == column || (time(c) && time(&column)))
        {
            let message = format!("column `{}` repeats a column or the time", f.text);
            errors.push(diagnose(
                source,
                CsvErrorKind::DuplicateColumn,
                message,
                f.range.clone(),
            ));
        }
        columns.push(column);
    }
    if errors.is_empty() {
        check_header(source, header, &columns, errors);
    }
    columns
}

fn column_named(name: &str) -> Option<Column> {
    let lower = name.to_ascii_lowercase();
    let mut chars = lower.chars();
    match (lower.as_str(), chars.next(), chars.next(), chars.next()) {
        ("t", ..) => Some(Column::Time),
        ("dt", ..) => Some(Column::Dt),
        ("trigger", ..) => Some(Column::Trigger),
        (_, Some(c), None, _) => Axis::from_letter(c).map(Column::Position),
        (_, Some('v'), Some(c), None) => Axis::from_letter(c).map(Column::Velocity),
        _ => None,
    }
}

/// Time and axis columns present, velocities for every axis or none.
fn check_header(
    source: &str,
    header: &Line<'_>,
    columns: &[Column],
    errors: &mut Vec<CsvDiagnostic>,
) {
    let whole = header.range.clone();
    if !columns
        .iter()
        .any(|c| matches!(c, Column::Time | Column::Dt))
    {
        errors.push(diagnose(
            source,
            CsvErrorKind::NoTimeColumn,
            "no t or dt column".into(),
            whole.clone(),
        ));
    }
    let axes = Column::axes(columns, false);
    if axes.is_empty() {
        errors.push(diagnose(
            source,
            CsvErrorKind::NoAxisColumn,
            "no axis column".into(),
            whole.clone(),
        ));
    }
    let velocities = Column::axes(columns, true);
    if velocities.is_empty() {
        return;
    }
    for (f, c) in header.fields.iter().zip(columns) {
        if let Column::Velocity(a) = c {
            if !axes.contains(a) {
                let message = format!("velocity column `{}` without an {a} column", f.text);
                errors.push(diagnose(
                    source,
                    CsvErrorKind::IncompleteVelocities,
                    message,
                    f.range.clone(),
                ));
            }
        }
    }
    for a in axes.iter().filter(|a| !velocities.contains(a)) {
        let message = format!("velocities are given, but not for axis {a}");
        errors.push(diagnose(
            source,
            CsvErrorKind::IncompleteVelocities,
            message,
            whole.clone(),
        ));
    }
}

/// Parses every row; `None` when there is none.
fn read_rows(
    source: &str,
    header: &Line<'_>,
    columns: &[Column],
    rows: &[Line<'_>],
    units: Units,
    errors: &mut Vec<CsvDiagnostic>,
) -> Option<PointSeries> {
    let mut axes = Column::axes(columns, false);
    axes.sort();
    let has_velocity = columns.iter().any(|c| matches!(c, Column::Velocity(_)));
    let dim = axes.len();
    let mut builder = Builder {
        dim,
        ..Builder::default()
    };
    for row in rows {
        if row.fields.len() != header.fields.len() {
            let message = format!(
                "{} fields where the header has {}",
                row.fields.len(),
                header.fields.len()
            );
            errors.push(diagnose(
                source,
                CsvErrorKind::WrongFieldCount,
                message,
                row.range.clone(),
            ));
            continue;
        }
        let Some(values) = row_values(source, row, errors) else {
            continue;
        };
        let mut point = vec![0.0; dim];
        let mut velocity = vec![0.0; dim];
        let mut time = (0.0, 0..0, false);
        for ((c, v), f) in columns.iter().zip(&values).zip(&row.fields) {
            match c {
                Column::Time => time = (*v, f.range.clone(), false),
                Column::Dt => time = (*v, f.range.clone(), true),
                Column::Position(a) => point[axes.binary_search(a).unwrap_or(0)] = *v,
                Column::Velocity(a) => velocity[axes.binary_search(a).unwrap_or(0)] = *v,
                Column::Trigger if *v != 0.0 && *v != 1.0 => errors.push(diagnose(
                    source,
                    CsvErrorKind::BadTrigger,
                    format!("trigger `{}` is neither 0 nor 1", f.text),
                    f.range.clone(),
                )),
                Column::Trigger => {}
            }
        }
        let span = Span {
            start: row.range.start,
            end: row.range.end,
            line: row.number,
        };
        if let Err(message) = builder.add(time.0, time.2, &point, &velocity, span) {
            errors.push(diagnose(
                source,
                CsvErrorKind::NonIncreasingTime,
                message,
                time.1,
            ));
        }
    }
    builder.finish(axes, units, has_velocity)
}

/// The numbers of a row, or `None` after recording every bad field.
fn row_values(source: &str, row: &Line<'_>, errors: &mut Vec<CsvDiagnostic>) -> Option<Vec<f64>> {
    let mut values = Vec::with_capacity(row.fields.len());
    let before = errors.len();
    for f in &row.fields {
        match f.text.parse::<f64>() {
            Ok(v) if v.is_finite() => values.push(v),
            Ok(_) => {
                let message = format!("`{}` is not a finite number", f.text);
                errors.push(diagnose(
                    source,
                    CsvErrorKind::NotFinite,
                    message,
                    f.range.clone(),
                ));
            }
            Err(_) => {
                let message = format!("`{}` is not a number", f.text);
                errors.push(diagnose(
                    source,
                    CsvErrorKind::NotANumber,
                    message,
                    f.range.clone(),
                ));
            }
        }
    }
    (errors.len() == before).then_some(values)
}

/// Collects the good rows into a series.
#[derive(Default)]
struct Builder {
    dim: usize,
    last_time: Option<f64>,
    start_time: f64,
    points: Option<TimedPoints>,
    velocities: Vec<f64>,
    spans: Vec<Span>,
}

impl Builder {
    /// Adds a row at absolute time `t` (or after piece time `t` when `is_dt`).
    fn add(
        &mut self,
        t: f64,
        is_dt: bool,
        point: &[f64],
        velocity: &[f64],
        span: Span,
    ) -> Result<(), String> {
        let duration = match (self.last_time, is_dt) {
            (None, _) => None,
            (Some(_), true) if t > 0.0 => Some(t),
            (Some(_), true) => return Err(format!("piece time {t} s is not positive")),
            (Some(last), false) if t > last => Some(t - last),
            (Some(last), false) => {
                return Err(format!(
                    "time {t} s is not after the previous row's {last} s"
                ))
            }
        };
        let now = match (self.last_time, is_dt) {
            (Some(last), true) => last + t,
            _ => t,
        };
        match (&mut self.points, duration) {
            (Some(points), Some(d)) => points.push(point, d, span.line),
            _ => {
                self.start_time = now;
                self.points = Some(TimedPoints::start_at(point));
            }
        }
        self.last_time = Some(now);
        self.velocities.extend_from_slice(velocity);
        self.spans.push(span);
        Ok(())
    }

    fn finish(self, axes: Vec<Axis>, units: Units, has_velocity: bool) -> Option<PointSeries> {
        let mut points = self.points?;
        if has_velocity {
            points.velocities = Some(self.velocities);
        }
        debug_assert_eq!(points.dim, self.dim);
        Some(PointSeries {
            axes,
            units,
            start_time: self.start_time,
            points,
            spans: self.spans,
        })
    }
}

#[cfg(test)]
mod tests;
