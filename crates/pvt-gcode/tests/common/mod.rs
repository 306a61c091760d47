//! Helpers shared by the integration tests: compact renderings of results and errors.
#![allow(dead_code)]

use std::fmt::Write;

use pvt_core::{ArcDirection, Axis, Element, ElementKind, Plane, Position};
use pvt_gcode::{compile, line_col, Compiled, GcodeDiagnostic, GcodeOptions};

/// Every element of a compiled program, contour after contour.
pub fn elements(c: &Compiled) -> Vec<Element> {
    c.toolpath
        .contours
        .iter()
        .flat_map(|c| c.elements.clone())
        .collect()
}

/// A number with up to six decimals, trailing zeros trimmed, `-0` shown as `0`.
pub fn num(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_owned()
    } else {
        s.to_owned()
    }
}

fn position(p: &Position, axes: &[Axis]) -> String {
    axes.iter()
        .map(|a| format!("{a}{}", num(p[a.index()])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `line:col code message` for one diagnostic (code without the `pvtc::gcode::` prefix).
pub fn diagnostic_line(source: &str, d: &GcodeDiagnostic) -> String {
    // Every diagnostic's own code must agree with miette's.
    let miette_code = miette::Diagnostic::code(d).map(|c| c.to_string());
    assert_eq!(miette_code.as_deref(), Some(d.code()));
    let (line, col) = line_col(source, d.span().start);
    let code = d.code().trim_start_matches("pvtc::gcode::");
    format!("{line}:{col} {code}: {d}")
}

/// A summary of a compiled program: units, contours, elements, end points, feeds, warnings.
pub fn render_compiled(source: &str, compiled: &Compiled) -> String {
    let toolpath = &compiled.toolpath;
    let axes = toolpath.moved_axes();
    let mut out = String::new();
    let names: Vec<_> = axes.iter().map(ToString::to_string).collect();
    writeln!(
        out,
        "units {}; axes {}",
        toolpath.units.name(),
        names.join(" ")
    )
    .unwrap();
    for (index, contour) in toolpath.contours.iter().enumerate() {
        render_events(&mut out, compiled, index);
        let start = &contour.elements[0].start;
        writeln!(
            out,
            "{} contour from {}",
            contour.motion.name(),
            position(start, &axes)
        )
        .unwrap();
        for e in &contour.elements {
            let what = match e.kind {
                ElementKind::Line => "line".to_owned(),
                ElementKind::Arc(arc) => {
                    let dir = match arc.direction {
                        ArcDirection::Clockwise => "cw",
                        ArcDirection::CounterClockwise => "ccw",
                    };
                    let plane = match arc.plane {
                        Plane::XY => "XY",
                        Plane::ZX => "ZX",
                        Plane::YZ => "YZ",
                    };
                    let sweep = arc.sweep(&e.start, &e.end).sweep.to_degrees();
                    format!(
                        "arc {dir} {plane} centre {} {} sweep {}°",
                        num(arc.center[0]),
                        num(arc.center[1]),
                        num(sweep)
                    )
                }
                ElementKind::Bezier(b) => format!(
                    "bezier controls {} {}, {} {}",
                    num(b.controls[0][0]),
                    num(b.controls[0][1]),
                    num(b.controls[1][0]),
                    num(b.controls[1][1])
                ),
            };
            writeln!(
                out,
                "  {}: {what} to {} at {}/s",
                e.span.line,
                position(&e.end, &axes),
                num(e.feed)
            )
            .unwrap();
        }
    }
    render_events(&mut out, compiled, toolpath.contours.len());
    if let Some(p) = compiled.path_tolerance {
        writeln!(out, "G64 P tolerance {}", num(p)).unwrap();
    }
    for w in &compiled.warnings {
        let kind = match miette::Diagnostic::severity(w) {
            Some(miette::Severity::Advice) => "note",
            _ => "warning",
        };
        writeln!(out, "{kind} {}", diagnostic_line(source, w)).unwrap();
    }
    out
}

/// The events before contour `index`, one line each.
fn render_events(out: &mut String, compiled: &Compiled, index: usize) {
    use pvt_core::EventKind;
    for event in compiled
        .toolpath
        .events
        .iter()
        .filter(|e| e.before_contour == index)
    {
        let detail = match &event.kind {
            EventKind::Dwell { seconds } => format!(" {}s", num(*seconds)),
            EventKind::SpindleSpeed { rpm } => format!(" {}", num(*rpm)),
            EventKind::ToolSelect { tool } => format!(" {tool}"),
            EventKind::Message { text } => format!(" {text:?}"),
            _ => String::new(),
        };
        writeln!(out, "  {}: event {}{detail}", event.line, event.kind.name()).unwrap();
    }
}

/// Every diagnostic of a failed compile, one per line; or the summary when it compiled.
pub fn render(source: &str, options: &GcodeOptions) -> String {
    match compile(source, options) {
        Ok(compiled) => render_compiled(source, &compiled),
        Err(errors) => {
            let mut out = format!("{errors}\n");
            for d in &errors.diagnostics {
                writeln!(out, "{}", diagnostic_line(source, d)).unwrap();
            }
            out
        }
    }
}

/// Compiles with default options and a feed, panicking with the diagnostics on failure.
pub fn ok(source: &str) -> Compiled {
    compile(source, &GcodeOptions::default())
        .unwrap_or_else(|_| panic!("{}", render(source, &GcodeOptions::default())))
}

/// The (code, line, column) of every error of a program that must fail.
pub fn errors(source: &str) -> Vec<(&'static str, usize, usize)> {
    let errors = compile(source, &GcodeOptions::default()).expect_err("the program must fail");
    errors
        .diagnostics
        .iter()
        .map(|d| {
            let (line, col) = line_col(source, d.span().start);
            (d.code().trim_start_matches("pvtc::gcode::"), line, col)
        })
        .collect()
}

/// rs274's reading of `source`: the point counts of its NURBS_FEED calls in order, or
/// its error line; `None` when rs274 is not installed.
pub fn rs274_nurbs_counts(source: &str, name: &str) -> Option<Result<Vec<usize>, String>> {
    let canon = rs274_canon(source, name)?;
    Some(canon.map(|text| {
        text.lines()
            .filter_map(|l| l.split("NURBS_FEED(").nth(1))
            .map(|rest| rest.split(',').next().unwrap().trim().parse().unwrap())
            .collect()
    }))
}

/// The X Y Z of every STRAIGHT_FEED rs274 makes of `source`, in order, or its error
/// line; `None` when rs274 is not installed.
pub fn rs274_feed_ends(source: &str, name: &str) -> Option<Result<Vec<[f64; 3]>, String>> {
    let canon = rs274_canon(source, name)?;
    Some(canon.map(|text| {
        text.lines()
            .filter_map(|l| l.split("STRAIGHT_FEED(").nth(1))
            .map(|rest| {
                let v: Vec<f64> = rest
                    .trim_end_matches(')')
                    .split(',')
                    .map(|x| x.trim().parse().unwrap())
                    .collect();
                [v[0], v[1], v[2]]
            })
            .collect()
    }))
}

/// rs274's canonical calls for `source` (`rs274 -g`), or its error line; `None` when
/// rs274 is not installed.
pub fn rs274_canon(source: &str, name: &str) -> Option<Result<String, String>> {
    if std::process::Command::new("rs274")
        .arg("-h")
        .output()
        .is_err()
    {
        assert!(
            std::env::var_os("PVTC_REQUIRE_RS274").is_none(),
            "rs274 is not installed, and PVTC_REQUIRE_RS274 is set"
        );
        return None;
    }
    let dir = std::env::temp_dir().join(format!("pvtc-rs274-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (ngc, out) = (dir.join("p.ngc"), dir.join("out.txt"));
    std::fs::write(&ngc, source).unwrap();
    // Two rs274 runs at once can kill each other (shared memory): try again.
    for _ in 0..20 {
        let run = std::process::Command::new("rs274")
            .arg("-g")
            .arg(&ngc)
            .arg(&out)
            .stdin(std::process::Stdio::null())
            .output()
            .expect("rs274 runs");
        if run.status.code().is_none() {
            std::thread::sleep(std::time::Duration::from_millis(200));
            continue;
        }
        let text = std::fs::read_to_string(&out).unwrap_or_default();
        let said = String::from_utf8_lossy(&run.stdout).to_string()
            + &String::from_utf8_lossy(&run.stderr);
        std::fs::remove_dir_all(&dir).ok();
        return Some(match run.status.success() {
            true => Ok(text),
            false => Err(said),
        });
    }
    panic!("rs274 was killed 20 times");
}

/// A NURBS curve in a plane evaluated here, independently of pvt-core: the Cox–de Boor
/// recursion in homogeneous coordinates (half-open knot spans, the domain's end closing
/// the last), and the distance of a point from it: the nearest of `per_span` samples of
/// each knot span (searched near the last match), refined by golden-section search of
/// the parameter between that sample's neighbours on the true curve.
pub struct TrueNurbs {
    pub points: Vec<[f64; 2]>,
    pub weights: Vec<f64>,
    pub knots: Vec<f64>,
    pub order: usize,
    ts: Vec<f64>,
    samples: Vec<[f64; 2]>,
}

impl TrueNurbs {
    /// The curve of `points`, `weights`, `knots` (points + order of them) and `order`.
    pub fn new(
        points: &[[f64; 2]],
        weights: &[f64],
        knots: &[f64],
        order: usize,
        per_span: usize,
    ) -> TrueNurbs {
        assert_eq!(knots.len(), points.len() + order);
        let mut curve = TrueNurbs {
            points: points.to_vec(),
            weights: weights.to_vec(),
            knots: knots.to_vec(),
            order,
            ts: Vec::new(),
            samples: Vec::new(),
        };
        for pair in knots.windows(2).filter(|w| w[1] > w[0]) {
            for j in 0..per_span {
                curve
                    .ts
                    .push(pair[0] + (pair[1] - pair[0]) * j as f64 / per_span as f64);
            }
        }
        curve.ts.push(*knots.last().unwrap());
        curve.samples = curve.ts.iter().map(|&t| curve.at(t)).collect();
        curve
    }

    /// LinuxCNC's G5.2 curve: knots `order` zeros, 1, 2, …, `order` copies of the last.
    pub fn uniform(points: &[[f64; 2]], weights: &[f64], order: usize, per_span: usize) -> Self {
        let m = (points.len() - order + 1) as f64;
        let knots: Vec<f64> = (0..points.len() + order)
            .map(|i| (i as f64 - order as f64 + 1.0).clamp(0.0, m))
            .collect();
        TrueNurbs::new(points, weights, &knots, order, per_span)
    }

    /// `N(i, order)` at `t`.
    fn basis(&self, i: usize, order: usize, t: f64) -> f64 {
        let k = &self.knots;
        if order == 1 {
            let end = *k.last().unwrap();
            let inside = k[i] <= t && t < k[i + 1];
            let last = t == end && k[i] < k[i + 1] && k[i + 1] == end;
            return f64::from(u8::from(inside || last));
        }
        let mut value = 0.0;
        let left = k[i + order - 1] - k[i];
        if left > 0.0 {
            value += (t - k[i]) / left * self.basis(i, order - 1, t);
        }
        let right = k[i + order] - k[i + 1];
        if right > 0.0 {
            value += (k[i + order] - t) / right * self.basis(i + 1, order - 1, t);
        }
        value
    }

    /// The point at `t`.
    pub fn at(&self, t: f64) -> [f64; 2] {
        let (mut x, mut y, mut w) = (0.0, 0.0, 0.0);
        for i in 0..self.points.len() {
            let b = self.basis(i, self.order, t) * self.weights[i];
            x += b * self.points[i][0];
            y += b * self.points[i][1];
            w += b;
        }
        [x / w, y / w]
    }

    /// The distance from `p` to the curve near sample `at` (updated to the nearest):
    /// every local minimum of the sample distances within one sample spacing of the
    /// least one is refined, so a loop passing near itself does not mislead it.
    pub fn distance(&self, p: [f64; 2], at: &mut usize) -> f64 {
        let n = self.samples.len();
        let (lo, hi) = (at.saturating_sub(2000), (*at + 2000).min(n - 1));
        let d2 = |q: [f64; 2]| (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        let d: Vec<f64> = (lo..=hi).map(|i| d2(self.samples[i]).sqrt()).collect();
        let spacing = (lo..hi)
            .map(|i| {
                let (a, b) = (self.samples[i], self.samples[i + 1]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        let least = d.iter().copied().fold(f64::INFINITY, f64::min);
        let mut best = (f64::INFINITY, *at);
        for k in 0..d.len() {
            let local = (k == 0 || d[k] <= d[k - 1]) && (k + 1 == d.len() || d[k] <= d[k + 1]);
            if !local || d[k] > least + spacing {
                continue;
            }
            let i = lo + k;
            let (mut a, mut b) = (self.ts[i.saturating_sub(1)], self.ts[(i + 1).min(n - 1)]);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..60 {
                let (c, e) = (b - g * (b - a), a + g * (b - a));
                if d2(self.at(c)) < d2(self.at(e)) {
                    b = e;
                } else {
                    a = c;
                }
            }
            let refined = d2(self.at(0.5 * (a + b))).sqrt().min(d[k]);
            if refined < best.0 {
                best = (refined, i);
            }
        }
        *at = best.1;
        best.0
    }
}

/// The largest distance from `curve` (in the plane of `axes`) of the motion the path
/// planner (default options) makes of `source`'s feed moves on `lines`: every PVT
/// segment's cubic evaluated here (Hermite form) at 64 times.
pub fn planned_distance(source: &str, curve: &TrueNurbs, axes: [Axis; 2], lines: &[u32]) -> f64 {
    let compiled = compile(source, &GcodeOptions::default()).expect("compiles");
    let options = pvt_core::PlanOptions {
        planner: pvt_core::Planner::Path,
        ..pvt_core::PlanOptions::default()
    };
    let program = pvt_core::plan_toolpath(&compiled.toolpath, &options).expect("planned");
    let column = |a: Axis| program.axes.iter().position(|&b| b == a).expect("moves");
    let (c0, c1) = (column(axes[0]), column(axes[1]));
    let mut worst: f64 = 0.0;
    let mut at = 0;
    for contour in program
        .contours
        .iter()
        .filter(|c| c.motion == pvt_core::Motion::Feed)
    {
        let dim = contour.dim;
        let mut from = (contour.start.clone(), vec![0.0; dim]);
        for i in 0..contour.durations.len() {
            let t = contour.durations[i];
            let (e, v) = (
                &contour.ends[dim * i..dim * (i + 1)],
                &contour.velocities[dim * i..dim * (i + 1)],
            );
            if lines.contains(&contour.lines[i]) {
                for j in 0..=64 {
                    let s = f64::from(j) / 64.0;
                    let h = [
                        2.0 * s * s * s - 3.0 * s * s + 1.0,
                        s * s * s - 2.0 * s * s + s,
                        -2.0 * s * s * s + 3.0 * s * s,
                        s * s * s - s * s,
                    ];
                    let p = [c0, c1].map(|k| {
                        h[0] * from.0[k] + h[1] * t * from.1[k] + h[2] * e[k] + h[3] * t * v[k]
                    });
                    worst = worst.max(curve.distance(p, &mut at));
                }
            }
            from = (e.to_vec(), v.to_vec());
        }
    }
    worst
}

/// The Bézier elements `source` compiles to (it must compile).
pub fn bezier_elements(source: &str) -> Vec<Element> {
    compile(source, &GcodeOptions::default())
        .unwrap_or_else(|e| panic!("{source}: {:?}", e.diagnostics))
        .toolpath
        .contours
        .into_iter()
        .flat_map(|c| c.elements)
        .filter(|e| matches!(e.kind, ElementKind::Bezier(_)))
        .collect()
}

/// The point at `u` of a Bézier element, in its plane's (first, second) coordinates,
/// from its Bernstein form.
pub fn bezier_point(e: &Element, u: f64) -> [f64; 2] {
    let ElementKind::Bezier(b) = e.kind else {
        panic!("not a Bézier: {e:?}");
    };
    let p = [
        b.plane.project(&e.start),
        b.controls[0],
        b.controls[1],
        b.plane.project(&e.end),
    ];
    let s = 1.0 - u;
    let w = [s * s * s, 3.0 * s * s * u, 3.0 * s * u * u, u * u * u];
    [0, 1].map(|k| (0..4).map(|i| w[i] * p[i][k]).sum())
}
