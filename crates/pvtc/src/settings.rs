//! Settings: the one place pvtc applies a default. What the command line asked
//! ([`Asked`], no defaults) becomes the [`CompileOptions`] every route reads
//! ([`compile_options`], the one builder, which [`CompileOptions::new`] and the golden
//! tests call too); the planner's options ([`plan_options`]: tolerance and its curve
//! share, machine limits, servo period), the limits and servo period `check` and `plot`
//! use ([`machine_limits`], [`check_options`]), the back end's options
//! ([`emit_options`]) and the settings each output header names ([`header_lines`]) are
//! resolved here, once, for every route.
//!
//! The default values themselves are pvt-core's (`pvt_core::defaults`) and each
//! library's own `Default`; `tests/tidy.rs` fails on a default constant named anywhere
//! else in pvtc. It must not read a format, plan or write.

use crate::machine::Machine;
use crate::options::{Asked, CompileOptions, Distance, DrawingOptions, Failure, InputKind};
use miette::Report;
use pvt_core::defaults;
use pvt_core::{
    AxisLimits, CheckOptions, ChordTolerance, PlanOptions, Planner, PvtProgram, Rounding, Timing,
    Units,
};
use pvt_emit::{EmitOptions, Format};
use std::collections::BTreeMap;

/// Default rapid rate, mm/min.
pub use pvt_core::defaults::RAPID_MM_PER_MIN as DEFAULT_RAPID_MM_PER_MIN;

/// The options of a compile of the source named `name` into `format`: what `asked`
/// gives, every default applied (the input kind from the name, the planner from the
/// input, `--quantize` from the format, arc tolerances, work offsets, start point).
pub fn compile_options(asked: &Asked, name: &str, format: Format) -> CompileOptions {
    let input = asked.input.unwrap_or_else(|| InputKind::from_name(name));
    CompileOptions {
        format,
        input,
        machine: asked.machine.clone(),
        corner_tolerance: asked.corner_tolerance,
        feed: asked.feed,
        rapid: asked.rapid,
        tolerance: asked.tolerance,
        planner: asked.planner.unwrap_or(default_planner(input)),
        timing: asked
            .time_slice
            .map_or(Timing::default(), Timing::TimeSlice),
        accel: asked.accel,
        quantize: asked.quantize.unwrap_or_else(|| {
            default_quantum(format, asked.machine.as_ref(), &asked.counts_per_unit)
        }),
        counts_per_unit: asked.counts_per_unit.clone(),
        quantize_rounding: asked.quantize_rounding.unwrap_or_default(),
        work_offsets: asked.work_offsets.unwrap_or([[0.0; 6]; 9]),
        subroutine_path: asked.subroutine_path.clone(),
        tool_table: asked.tool_table.clone().unwrap_or_default(),
        hal_pins: asked.hal_pins.clone(),
        probe_results: asked.probe_results.clone(),
        spindle_sync: asked.spindle_sync,
        // The front end resolves it by the program's units (defaults::arc_abs_tolerance).
        arc_abs_tolerance_mm: asked.arc_abs_tolerance_mm,
        arc_rel_tolerance: asked
            .arc_rel_tolerance
            .unwrap_or(defaults::ARC_REL_TOLERANCE),
        drawing: DrawingOptions {
            layers: asked.layers.clone(),
            join_tolerance: asked.join_tolerance,
            start_point: asked.start_point.unwrap_or([0.0, 0.0]),
            safe_z: asked.safe_z,
            max_points: asked.max_points,
            units: asked.units,
        },
        velocities: asked.velocities,
        pmac: pvt_emit::PmacSettings::default(),
        triggers: None,
    }
}

/// Share of an axis' acceleration limit left to whole-count rounding on a format written
/// in counts (Galil, Zaber): [`default_quantum`] makes the grid long enough that a
/// piece of one quantum changes by at most this much, and [`plan_options`] plans the
/// rest.
pub const COUNTS_SHARE: f64 = 0.1;

/// `--quantize`'s default for `format`: the format's ([`pvt_emit::Caps::default_quantum`]),
/// and for a format written in counts with a machine file the whole quanta at which whole
/// counts take at most [`COUNTS_SHARE`] of each axis' acceleration limit
/// ([`pvt_emit::Caps::counts_grid`]; counts per unit from `counts`, `--counts-per-unit`,
/// over the file's, read in the file's units).
pub fn default_quantum(
    format: Format,
    machine: Option<&crate::machine::Machine>,
    counts: &[(pvt_core::Axis, f64)],
) -> Option<f64> {
    let caps = format.caps();
    let (Some(q), Some(m), true) = (caps.default_quantum, machine, caps.scaled) else {
        return caps.default_quantum;
    };
    let grid = m
        .axes
        .iter()
        .filter_map(|(axis, limits)| {
            let given = counts.iter().find(|(a, _)| a == axis).map(|(_, c)| *c);
            let c = given.or(m.setup.get(axis).and_then(|s| s.counts_per_unit))?;
            Some(caps.counts_grid(q, c, limits.acceleration?, COUNTS_SHARE))
        })
        .fold(q, f64::max);
    Some(grid)
}

/// The machine's limits less what whole counts may add to a piece of the shortest time
/// ([`pvt_emit::Caps::rounding_room`]; no less than half of each), so that the written
/// pieces keep them.
fn counts_room(
    options: &CompileOptions,
    units: Units,
    limits: &mut std::collections::BTreeMap<pvt_core::Axis, pvt_core::AxisLimits>,
) {
    let caps = options.format.caps();
    let Some(shortest) = options.quantize.or(caps.time_quantum) else {
        return;
    };
    let setup = emit_options(options, "", Vec::new(), units).axes;
    for (axis, l) in limits.iter_mut() {
        let Some(c) = setup.get(axis).and_then(|s| s.counts_per_unit) else {
            continue;
        };
        let (dv, da) = caps.rounding_room(c, shortest);
        l.velocity = l.velocity.map(|v| (v - dv).max(v / 2.0));
        l.acceleration = l.acceleration.map(|a| (a - da).max(a / 2.0));
    }
}

impl CompileOptions {
    /// Default options writing `format` for a G-code program (with the format's default
    /// `--quantize`): [`compile_options`] of an empty request.
    pub fn new(format: Format) -> CompileOptions {
        compile_options(&Asked::default(), "", format)
    }
}

/// The planner used when none is asked for: `path` for geometry (G-code, DXF),
/// `spline` for a point-time series, which keeps the series' times (and its velocity
/// columns, when it has them).
pub fn default_planner(input: InputKind) -> Planner {
    match input {
        InputKind::Gcode | InputKind::Dxf => Planner::Path,
        InputKind::Csv => Planner::Spline,
    }
}

/// Share of the tolerance a drawing's splines and ellipses are flattened within: the
/// path planner keeps the motion within the rest of it, so that the motion is within
/// the whole tolerance of the true curve; the other planners' chords take all of it.
pub fn curve_share(options: &CompileOptions) -> f64 {
    if options.input == InputKind::Dxf && options.planner == Planner::Path {
        0.5
    } else {
        1.0
    }
}

/// The machine file's limits on `axes`, in `units` (none without a machine file): the
/// one conversion planning, `check` and `plot` use.
pub fn machine_limits(
    machine: Option<&Machine>,
    units: Units,
    axes: &[pvt_core::Axis],
) -> Result<BTreeMap<pvt_core::Axis, AxisLimits>, Failure> {
    match machine {
        Some(m) => m
            .limits_in(units, axes)
            .map_err(|e| Failure::Input(vec![Report::new(e)])),
        None => Ok(BTreeMap::new()),
    }
}

/// What `check` samples `program` against: the machine file's limits, then each limit
/// `given` on the command line over them; the servo period `given`, else the machine
/// file's, else pvt-core's default.
pub fn check_options(
    machine: Option<&Machine>,
    program: &PvtProgram,
    given: BTreeMap<pvt_core::Axis, AxisLimits>,
    servo_period: Option<f64>,
) -> Result<CheckOptions, Failure> {
    let mut limits = machine_limits(machine, program.units, &program.axes)?;
    for (axis, given) in given {
        let l = limits.entry(axis).or_default();
        l.velocity = given.velocity.or(l.velocity);
        l.acceleration = given.acceleration.or(l.acceleration);
        l.jerk = given.jerk.or(l.jerk);
    }
    Ok(CheckOptions {
        servo_period: servo_period
            .or(machine.and_then(|m| m.servo_period))
            .unwrap_or(defaults::SERVO_PERIOD_S),
        limits,
    })
}

/// The tolerances `diff` compares within.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffTolerances {
    /// Farthest apart the positions may be, in the first program's units or in counts.
    pub position: f64,
    /// Whether `position` is in counts.
    pub in_counts: bool,
    /// Largest time shift and difference of total times, seconds.
    pub time: f64,
    /// Largest relative difference of a peak.
    pub peak: f64,
}

/// The tolerances `diff` compares within, each the one given (a length converted into
/// `units`) else pvt-core's default.
pub fn diff_tolerances(
    given: (Option<Distance>, Option<f64>, Option<f64>),
    units: Units,
) -> DiffTolerances {
    let (position, in_counts) = match given.0 {
        Some(Distance::Millimetres(mm)) => (units.from_mm(mm), false),
        Some(Distance::Counts(counts)) => (counts, true),
        None => (units.from_mm(defaults::DIFF_TOLERANCE_MM), false),
    };
    DiffTolerances {
        position,
        in_counts,
        time: given.1.unwrap_or(defaults::DIFF_TIME_TOLERANCE_S),
        peak: given.2.unwrap_or(defaults::DIFF_PEAK_TOLERANCE),
    }
}

/// The servo period of a program's peaks where no limits are checked (`diff`): the
/// machine file's, else pvt-core's default.
pub fn servo_period(machine: Option<&Machine>) -> f64 {
    machine
        .and_then(|m| m.servo_period)
        .unwrap_or(defaults::SERVO_PERIOD_S)
}

/// The most points a drawing may hold: `--max-points`, else pvt-core's default.
pub fn max_points(options: &CompileOptions) -> usize {
    options
        .drawing
        .max_points
        .unwrap_or(defaults::DXF_MAX_POINTS)
}

/// The units an emitted program is read back in: `--units`, else millimetres.
pub fn readback_units(options: &CompileOptions) -> Units {
    options.drawing.units.unwrap_or(Units::Millimetre)
}

/// The planner's options for a program in `units` moving `moved`: every default of the
/// planning resolved here, once, for every route.
pub fn plan_options(
    options: &CompileOptions,
    units: Units,
    moved: &[pvt_core::Axis],
) -> Result<PlanOptions, Failure> {
    let tolerance = ChordTolerance::new(resolved_tolerance(options, units))
        .expect("the CLI accepts only positive tolerances");
    let mut limits = machine_limits(options.machine.as_ref(), units, moved)?;
    counts_room(options, units, &mut limits);
    let share = curve_share(options);
    let path_tolerance = (share < 1.0).then(|| tolerance.get() * (1.0 - share));
    Ok(PlanOptions {
        tolerance,
        path_tolerance,
        corner_tolerance: options.corner_tolerance,
        limits,
        planner: options.planner,
        timing: options.timing,
        accel: options.accel,
        quantize: options.quantize,
        quantize_rounding: options.quantize_rounding,
        servo_period: options.machine.as_ref().and_then(|m| m.servo_period),
        position_resolution: options.format.position_resolution(),
    })
}

/// What the back end is told besides the motion: the source, the header's settings, the
/// PMAC settings and, per axis in `units`, the machine file's travel, limits and counts
/// per unit with `--counts-per-unit` over them.
pub fn emit_options(
    options: &CompileOptions,
    name: &str,
    settings: Vec<(String, String)>,
    units: Units,
) -> EmitOptions {
    let mut axes = options
        .machine
        .as_ref()
        .map(|m| m.setup_in(units))
        .unwrap_or_default();
    for (axis, counts) in &options.counts_per_unit {
        axes.entry(*axis).or_default().counts_per_unit = Some(*counts);
    }
    EmitOptions {
        source: name.to_owned(),
        settings,
        pmac: options.pmac.clone(),
        axes,
        triggers: triggers_in(options, units),
    }
}

/// `--trigger-every` for the back end: a path length in `units`, on the pieces' grid.
fn triggers_in(options: &CompileOptions, units: Units) -> Option<pvt_emit::Triggers> {
    use pvt_emit::TriggerEvery;
    let every = match options.triggers? {
        TriggerEvery::Distance(mm) => TriggerEvery::Distance(units.from_mm(mm)),
        seconds => seconds,
    };
    Some(pvt_emit::Triggers {
        every,
        grid: options.quantize,
    })
}

/// The grid a long piece's time is cut on when the time is on it: `--quantize`, else the
/// time the format's controller rounds to (PMAC: whole ms), so whole times stay whole.
pub fn split_grid(options: &CompileOptions) -> Option<f64> {
    options
        .quantize
        .or_else(|| options.format.piece_time_quantum())
}

/// The tolerance of a program in `units`: `--tolerance`, or pvt-core's default converted
/// (`pvt_core::defaults::tolerance`, which pvt-dxf flattens curves with). Planning and
/// the header both read it.
pub fn resolved_tolerance(options: &CompileOptions, units: Units) -> f64 {
    defaults::tolerance(options.tolerance, units)
}

/// The rapid rate of a program in `units`, per minute: `--rapid`, or pvt-core's default
/// converted by `pvt_core::defaults::rapid_per_minute`, the function the G-code and DXF
/// front ends plan rapids with.
pub fn resolved_rapid(options: &CompileOptions, units: Units) -> f64 {
    defaults::rapid_per_minute(options.rapid, units)
}

/// The settings every output header names, in a fixed order (a CSV series' header leaves
/// out what it does not use: rapid, default feed and, but for `path`, the tolerance).
pub fn header_lines(options: &CompileOptions, units: Units) -> Vec<(String, String)> {
    let u = units.name();
    let tolerance = match options.tolerance {
        Some(t) => t,
        None => significant(resolved_tolerance(options, units)),
    };
    let rapid = match options.rapid {
        Some(r) => format!("{r} {u}/min"),
        None if units == Units::Millimetre => {
            format!("{} {u}/min (default)", resolved_rapid(options, units))
        }
        None => format!(
            "{} {u}/min (default {DEFAULT_RAPID_MM_PER_MIN} mm/min)",
            significant(resolved_rapid(options, units))
        ),
    };
    let feed = match options.feed {
        Some(f) => format!("{f} {u}/min"),
        None => "none (every feed move needs an F word)".into(),
    };
    let tolerance_name = match options.planner {
        Planner::Path => "path tolerance",
        _ => "chord tolerance",
    };
    let mut out = vec![(
        "planner".into(),
        planner_description(options.planner).into(),
    )];
    // A series has no rapid moves, no feed and no arcs: only `path` reads a tolerance.
    let series = options.input == InputKind::Csv;
    if !series || options.planner == Planner::Path {
        out.push((tolerance_name.into(), format!("{tolerance} {u}")));
    }
    if !series {
        out.push(("rapid".into(), rapid));
        out.push(("default feed".into(), feed));
    }
    if let Timing::TimeSlice(t) = options.timing {
        out.push(("time slice".into(), format!("{t} s")));
    }
    if let Some(a) = options.accel {
        out.push(("acceleration".into(), format!("{a} {u}/s^2")));
    }
    if let Some(q) = options.quantize {
        out.push((
            "piece times quantized to".into(),
            format!(
                "{q} s, rounded {}",
                rounding_words(options.quantize_rounding)
            ),
        ));
    }
    if let Some(m) = &options.machine {
        out.push(("machine".into(), m.name.clone()));
    }
    if options.spindle_sync == pvt_gcode::SpindleSync::ProgrammedSpeed {
        out.push((
            "spindle-synchronised motion".into(),
            "at the programmed S taken as exact (--spindle-rpm-exact)".into(),
        ));
    }
    out
}

/// Significant digits of a default converted into other units, as a header prints it.
const HEADER_DIGITS: usize = 6;

/// `x` rounded to [`HEADER_DIGITS`] significant digits, for the header text only (a
/// converted default such as 5000 mm/min reads `196.85 in/min`, not
/// `196.8503937007874`); planning uses the unrounded value.
fn significant(x: f64) -> f64 {
    format!("{x:.*e}", HEADER_DIGITS - 1).parse().unwrap_or(x)
}

/// How a rounding reads after "rounded": `up`, `to nearest`.
pub fn rounding_words(rounding: Rounding) -> &'static str {
    match rounding {
        Rounding::Up => "up",
        Rounding::Nearest => "to nearest",
    }
}

fn planner_description(planner: Planner) -> &'static str {
    match planner {
        Planner::Contour => {
            "contour (bisector velocities at the feed, mid-segment speed = mean of end speeds)"
        }
        Planner::Path => {
            "path (within the path tolerance of the true elements and the axis limits)"
        }
        Planner::Pt => "pt (position-time: constant velocity between points, AN208's PT)",
        Planner::Chord => {
            "chord-forward (velocity at a point = outgoing chord / its time, rest at both ends)"
        }
        Planner::ChordBack => {
            "chord-back (velocity at a point = incoming chord / its time, AN208; rest at both ends)"
        }
        Planner::ConstAccel => {
            "const-accel (each piece at constant acceleration from the previous velocity, AN208)"
        }
        Planner::Spline => "spline (C2 cubic spline through the points, rest at both ends)",
        Planner::Lspb => "lspb (linear segments with parabolic blends at --accel)",
    }
}
