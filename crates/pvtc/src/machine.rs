//! The machine file: per-axis velocity, acceleration and jerk limits in TOML.
//!
//! Owns reading and validating `--machine FILE` (with the `toml` and `serde` crates) and
//! converting its limits into a program's units. It must not plan or check motion: the
//! limits it returns go to the path planner and to `check`.
//!
//! ```toml
//! units = "mm"              # units of the numbers below: "mm" or "in" (rotary axes: degrees)
//! servo_period = 0.0005     # seconds, optional: the period `check` samples at
//! [axes.X]
//! max_velocity = 100.0      # units/s
//! max_acceleration = 1000.0 # units/s²
//! max_jerk = 50000.0        # units/s³, optional
//! ```

use miette::{Diagnostic, NamedSource, SourceSpan};
use pvt_core::{Axis, AxisLimits, Units};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use toml::Spanned;

/// A machine's limits, as read from its file.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// The file's name, for diagnostics.
    pub name: String,
    /// Units of the linear limits.
    pub units: Units,
    /// Servo period, seconds, when the file gives one.
    pub servo_period: Option<f64>,
    /// Limits per axis, in the file's units.
    pub axes: BTreeMap<Axis, AxisLimits>,
    text: Arc<str>,
}

/// Why a machine file cannot be used.
#[derive(Debug, thiserror::Error, Diagnostic)]
pub enum MachineError {
    /// The file is not TOML of the documented shape (unknown key, wrong type, …).
    #[error("{message}")]
    #[diagnostic(code(pvtc::machine::invalid))]
    Invalid {
        /// What the TOML reader says.
        message: String,
        /// The file.
        #[source_code]
        src: NamedSource<Arc<str>>,
        /// Where.
        #[label("here")]
        span: Option<SourceSpan>,
    },
    /// A limit that is zero, negative or not finite.
    #[error("{key} of axis {axis} is {value}; a limit must be finite and positive")]
    #[diagnostic(code(pvtc::machine::bad_limit))]
    BadLimit {
        /// The axis.
        axis: char,
        /// The key.
        key: &'static str,
        /// The value given.
        value: f64,
        /// The file.
        #[source_code]
        src: NamedSource<Arc<str>>,
        /// Where.
        #[label("not a positive number")]
        span: SourceSpan,
    },
    /// The program moves an axis the file gives no limits for.
    #[error("the program moves axis {axis}, which the machine file does not limit")]
    #[diagnostic(
        code(pvtc::machine::missing_axis),
        help("add [axes.{axis}] with max_velocity and max_acceleration")
    )]
    MissingAxis {
        /// The axis.
        axis: char,
        /// The file.
        #[source_code]
        src: NamedSource<Arc<str>>,
        /// The axes table.
        #[label("no [axes.{axis}] here")]
        span: SourceSpan,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileShape {
    units: Spanned<String>,
    servo_period: Option<Spanned<f64>>,
    axes: Spanned<BTreeMap<String, Spanned<AxisShape>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisShape {
    max_velocity: Spanned<f64>,
    max_acceleration: Spanned<f64>,
    max_jerk: Option<Spanned<f64>>,
}

impl Machine {
    /// Reads and validates the machine file at `path`.
    pub fn read(path: &Path) -> Result<Machine, crate::failure::Failure> {
        let text = std::fs::read_to_string(path).map_err(|error| crate::failure::Failure::Io {
            path: path.to_path_buf(),
            action: "read",
            error,
        })?;
        Machine::parse(&path.display().to_string(), &text)
            .map_err(|e| crate::failure::Failure::Input(vec![miette::Report::new(e)]))
    }

    /// Parses machine-file text named `name`.
    pub fn parse(name: &str, text: &str) -> Result<Machine, MachineError> {
        let shared: Arc<str> = Arc::from(text);
        let src = || NamedSource::new(name, shared.clone());
        let invalid =
            |message: String, span: Option<std::ops::Range<usize>>| MachineError::Invalid {
                message,
                src: src(),
                span: span.map(SourceSpan::from),
            };
        let shape: FileShape =
            toml::from_str(text).map_err(|e| invalid(e.message().to_string(), e.span()))?;
        let units = match shape.units.get_ref().as_str() {
            "mm" => Units::Millimetre,
            "in" => Units::Inch,
            other => {
                return Err(invalid(
                    format!("units must be \"mm\" or \"in\", not \"{other}\""),
                    Some(shape.units.span()),
                ))
            }
        };
        let mut axes = BTreeMap::new();
        for (letter, limits) in shape.axes.get_ref() {
            let axis = single_letter(letter)
                .and_then(Axis::from_letter)
                .ok_or_else(|| {
                    invalid(
                        format!("`{letter}` is not an axis; axes are X Y Z A B C"),
                        Some(limits.span()),
                    )
                })?;
            let positive = |key: &'static str, v: &Spanned<f64>| {
                let value = *v.get_ref();
                if value.is_finite() && value > 0.0 {
                    Ok(value)
                } else {
                    Err(MachineError::BadLimit {
                        axis: axis.letter(),
                        key,
                        value,
                        src: src(),
                        span: v.span().into(),
                    })
                }
            };
            let l = limits.get_ref();
            let jerk = match &l.max_jerk {
                Some(j) => Some(positive("max_jerk", j)?),
                None => None,
            };
            axes.insert(
                axis,
                AxisLimits {
                    velocity: Some(positive("max_velocity", &l.max_velocity)?),
                    acceleration: Some(positive("max_acceleration", &l.max_acceleration)?),
                    jerk,
                },
            );
        }
        let servo_period = match shape.servo_period {
            Some(p) if !(p.get_ref().is_finite() && *p.get_ref() > 0.0) => {
                return Err(invalid(
                    "servo_period must be a positive number of seconds".into(),
                    Some(p.span()),
                ))
            }
            p => p.map(|p| *p.get_ref()),
        };
        Ok(Machine {
            name: name.to_owned(),
            units,
            servo_period,
            axes,
            text: shared,
        })
    }

    /// The limits in `units` (linear axes converted; rotary axes stay in degrees),
    /// refusing a file that does not limit one of `moved`.
    pub fn limits_in(
        &self,
        units: Units,
        moved: &[Axis],
    ) -> Result<BTreeMap<Axis, AxisLimits>, MachineError> {
        if let Some(axis) = moved.iter().find(|a| !self.axes.contains_key(a)) {
            let at = self.text.find("[axes").unwrap_or(0);
            return Err(MachineError::MissingAxis {
                axis: axis.letter(),
                src: NamedSource::new(&self.name, self.text.clone()),
                span: (at..at).into(),
            });
        }
        let scale = self.units.mm_per_unit() / units.mm_per_unit();
        Ok(self
            .axes
            .iter()
            .map(|(&axis, l)| {
                let k = if axis.is_rotary() { 1.0 } else { scale };
                let s = |v: Option<f64>| v.map(|v| v * k);
                let limits = AxisLimits {
                    velocity: s(l.velocity),
                    acceleration: s(l.acceleration),
                    jerk: s(l.jerk),
                };
                (axis, limits)
            })
            .collect())
    }
}

fn single_letter(text: &str) -> Option<char> {
    let mut chars = text.chars();
    let c = chars.next()?;
    chars.next().is_none().then_some(c.to_ascii_uppercase())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "units = \"mm\"\n[axes.X]\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n[axes.Y]\nmax_velocity = 50\nmax_acceleration = 500.0\nmax_jerk = 1e5\n";

    fn code(e: &MachineError) -> String {
        e.code().map(|c| c.to_string()).unwrap_or_default()
    }

    #[test]
    fn reads_limits_and_converts_units() {
        let m = Machine::parse("m.toml", GOOD).unwrap();
        assert_eq!(m.axes[&Axis::Y].jerk, Some(1e5));
        let inch = m.limits_in(Units::Inch, &[Axis::X]).unwrap();
        let v = inch[&Axis::X].velocity.unwrap();
        assert!((v - 100.0 / 25.4).abs() < 1e-12);
    }

    #[test]
    fn unknown_key_is_named_at_its_line() {
        let text = GOOD.replace("max_velocity = 50", "max_velocity = 50\nmax_speed = 3");
        let e = Machine::parse("m.toml", &text).unwrap_err();
        assert_eq!(code(&e), "pvtc::machine::invalid");
        let MachineError::Invalid { span, message, .. } = &e else {
            panic!("{e:?}")
        };
        assert!(message.contains("max_speed"), "{message}");
        assert_eq!(
            pvt_core::text::line_of(text.as_bytes(), span.unwrap().offset()),
            7
        );
    }

    #[test]
    fn non_positive_limit_is_named_at_its_line() {
        let text = GOOD.replace("max_acceleration = 500.0", "max_acceleration = -5.0");
        let e = Machine::parse("m.toml", &text).unwrap_err();
        assert_eq!(code(&e), "pvtc::machine::bad_limit");
        let MachineError::BadLimit { span, .. } = &e else {
            panic!("{e:?}")
        };
        assert_eq!(pvt_core::text::line_of(text.as_bytes(), span.offset()), 7);
    }

    #[test]
    fn a_moved_axis_without_limits_is_refused() {
        let m = Machine::parse("m.toml", GOOD).unwrap();
        let e = m
            .limits_in(Units::Millimetre, &[Axis::X, Axis::Z])
            .unwrap_err();
        assert_eq!(code(&e), "pvtc::machine::missing_axis");
    }

    #[test]
    fn bad_units_and_axes_are_refused() {
        let e = Machine::parse("m.toml", &GOOD.replace("\"mm\"", "\"cm\"")).unwrap_err();
        assert_eq!(code(&e), "pvtc::machine::invalid");
        let e = Machine::parse("m.toml", &GOOD.replace("axes.Y", "axes.Q")).unwrap_err();
        assert_eq!(code(&e), "pvtc::machine::invalid");
    }
}
