//! Parameters: RS274NGC numbered (`#1`–`#5602`) and named (`#<name>`, `#<_global>`) values.
//!
//! Owns the store and its rules: names are case-insensitive with blanks removed, numbered
//! parameters start at 0, named ones must be assigned before they are read; a
//! subroutine call gets its own `#1`–`#30` (its arguments) and its own names without a
//! leading underscore (locals), while `#31`… and `#<_names>` are global; machine
//! parameters are answered by [`machine`] from the interpreter's state. It must not parse
//! text (that is [`crate::value`]) nor decide when assignments take effect (after the
//! line is read: [`crate::compile_into`] applies a block's assignments after parsing it).

pub(crate) mod machine;

use std::collections::HashMap;

/// The highest numbered parameter (LinuxCNC's last, #5602).
pub(crate) const MAX_NUMBERED: usize = 5602;

/// How many numbered parameters a subroutine call holds as its own: `#1`–`#30`.
pub(crate) const CALL_ARGUMENTS: usize = 30;

/// Which parameter an assignment sets.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ParamRef {
    /// `#n`.
    Numbered(usize),
    /// `#<name>`, normalized (lower case, blanks removed).
    Named(String),
}

/// Why a parameter could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ReadProblem {
    /// A named parameter never assigned.
    Undefined,
    /// A parameter that holds machine state pvtc does not know: the feature.
    MachineSpecific(&'static str),
}

/// A subroutine call's own parameters.
#[derive(Debug, Clone)]
struct Frame {
    /// The caller's `#1`–`#30`, restored on return.
    saved: [f64; CALL_ARGUMENTS],
    /// Names without a leading underscore assigned in the call.
    locals: HashMap<String, f64>,
}

/// All parameter values of a program run.
#[derive(Debug, Clone)]
pub(crate) struct Parameters {
    numbered: Vec<f64>,
    assigned: Vec<bool>,
    /// Global names (leading underscore) and the main program's locals.
    named: HashMap<String, f64>,
    /// One per subroutine call in progress, innermost last.
    frames: Vec<Frame>,
    /// The interpreter's state, for machine parameters (brought up to date before a
    /// line that reads parameters).
    pub view: machine::MachineView,
}

impl Default for Parameters {
    fn default() -> Self {
        Parameters {
            numbered: vec![0.0; MAX_NUMBERED + 1],
            assigned: vec![false; MAX_NUMBERED + 1],
            named: HashMap::new(),
            frames: Vec::new(),
            view: machine::MachineView::default(),
        }
    }
}

/// True when `name` (normalized) is global: it starts with an underscore.
pub(crate) fn is_global_name(normalized: &str) -> bool {
    normalized.starts_with('_')
}

/// True when `name` (normalized) is a predefined parameter a program may not assign:
/// one the interpreter's state answers, `_value` and `_value_returned`, HAL pins and ini
/// values (LinuxCNC refuses these assignments too).
pub(crate) fn is_read_only(normalized: &str) -> bool {
    matches!(normalized, "_value" | "_value_returned")
        || !matches!(
            machine::named(&machine::MachineView::default(), normalized),
            machine::Answer::NotMachine
        )
}

/// `name` lower-cased with blanks removed, borrowed when it already is.
pub(crate) fn normalize(name: &str) -> std::borrow::Cow<'_, str> {
    if name
        .bytes()
        .any(|b| b.is_ascii_uppercase() || b == b' ' || b == b'\t')
    {
        let n: String = name
            .chars()
            .filter(|c| *c != ' ' && *c != '\t')
            .map(|c| c.to_ascii_lowercase())
            .collect();
        std::borrow::Cow::Owned(n)
    } else {
        std::borrow::Cow::Borrowed(name)
    }
}

impl Parameters {
    /// Gives HAL pin `name` (`#<_hal[name]>`) a value, as `--hal NAME=VALUE` does; the
    /// program still may not assign it.
    pub fn set_hal_pin(&mut self, name: &str, value: f64) {
        let key = format!("_hal[{}]", normalize(name));
        self.named.insert(key, value);
    }

    /// The value of `#index` (1..=[`MAX_NUMBERED`], checked by the caller).
    pub fn numbered(&self, index: usize) -> Result<f64, ReadProblem> {
        let (Some(&v), Some(&assigned)) = (self.numbered.get(index), self.assigned.get(index))
        else {
            return Err(ReadProblem::MachineSpecific("parameters above #5602"));
        };
        if index < 5000 {
            return Ok(v);
        }
        match machine::numbered(&self.view, index, assigned) {
            machine::Answer::Value(value) => Ok(value),
            machine::Answer::Machine(feature) => Err(ReadProblem::MachineSpecific(feature)),
            machine::Answer::NotMachine => Ok(v),
        }
    }

    /// The map a name lives in: globals, the innermost call's locals, or the main ones.
    fn scope(&self, key: &str) -> &HashMap<String, f64> {
        match self.frames.last() {
            Some(frame) if !is_global_name(key) => &frame.locals,
            _ => &self.named,
        }
    }

    /// The value of `#<name>` (`name` as written between the angle brackets).
    pub fn named(&self, name: &str) -> Result<f64, ReadProblem> {
        let key = normalize(name);
        if let Some(&v) = self.scope(&key).get(key.as_ref()) {
            return Ok(v);
        }
        if !is_global_name(&key) {
            return Err(ReadProblem::Undefined);
        }
        match machine::named(&self.view, &key) {
            machine::Answer::Value(value) => Ok(value),
            machine::Answer::Machine(feature) => Err(ReadProblem::MachineSpecific(feature)),
            machine::Answer::NotMachine => Err(ReadProblem::Undefined),
        }
    }

    /// True when `#<name>` has a value (`EXISTS[#<name>]`): assigned, or predefined.
    pub fn exists(&self, name: &str) -> bool {
        let key = normalize(name);
        self.scope(&key).contains_key(key.as_ref())
            || (is_global_name(&key)
                && matches!(machine::named(&self.view, &key), machine::Answer::Value(_)))
    }

    /// Enters a subroutine call: `#1`–`#30` become `args` (0 past them), saved for
    /// [`Parameters::leave_call`], and the call gets locals of its own.
    pub fn enter_call(&mut self, args: &[f64]) {
        let mut saved = [0.0; CALL_ARGUMENTS];
        for (i, slot) in saved.iter_mut().enumerate() {
            *slot = self.numbered[i + 1];
            self.numbered[i + 1] = args.get(i).copied().unwrap_or(0.0);
        }
        self.frames.push(Frame {
            saved,
            locals: HashMap::new(),
        });
    }

    /// Leaves the innermost call, restoring the caller's `#1`–`#30` and locals.
    pub fn leave_call(&mut self) {
        if let Some(frame) = self.frames.pop() {
            self.numbered[1..=CALL_ARGUMENTS].copy_from_slice(&frame.saved);
        }
    }

    /// How many calls are in progress.
    pub fn call_level(&self) -> usize {
        self.frames.len()
    }

    /// Sets a parameter.
    pub fn set(&mut self, param: &ParamRef, value: f64) {
        match param {
            ParamRef::Numbered(i) => {
                if let (Some(slot), Some(flag)) =
                    (self.numbered.get_mut(*i), self.assigned.get_mut(*i))
                {
                    *slot = value;
                    *flag = true;
                }
            }
            ParamRef::Named(name) => {
                let map = match self.frames.last_mut() {
                    Some(frame) if !is_global_name(name) => &mut frame.locals,
                    _ => &mut self.named,
                };
                if let Some(slot) = map.get_mut(name) {
                    *slot = value;
                } else {
                    map.insert(name.clone(), value);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_case_and_blank_insensitive() {
        let mut p = Parameters::default();
        p.set(&ParamRef::Named(normalize("X Scale").into_owned()), 2.0);
        assert_eq!(p.named("xscale"), Ok(2.0));
        assert_eq!(p.named("XSCALE"), Ok(2.0));
        assert!(p.exists("x scale"));
        assert_eq!(p.named("other"), Err(ReadProblem::Undefined));
        assert!(matches!(
            p.named("_hal[x.y]"),
            Err(ReadProblem::MachineSpecific(_))
        ));
    }

    #[test]
    fn numbered_start_at_zero_machine_ones_read_the_view() {
        let mut p = Parameters::default();
        assert_eq!(p.numbered(1), Ok(0.0));
        assert_eq!(p.numbered(5221), Ok(0.0));
        p.set(&ParamRef::Numbered(5221), 3.0);
        assert_eq!(p.numbered(5221), Ok(3.0));
        p.view.position[0] = 4.0;
        p.set(&ParamRef::Numbered(5420), 3.0);
        assert_eq!(p.numbered(5420), Ok(4.0));
        assert!(matches!(
            p.numbered(5061),
            Err(ReadProblem::MachineSpecific(_))
        ));
        assert!(matches!(
            p.numbered(9999),
            Err(ReadProblem::MachineSpecific(_))
        ));
    }

    #[test]
    fn calls_have_their_own_arguments_and_locals() {
        let mut p = Parameters::default();
        p.set(&ParamRef::Numbered(1), 7.0);
        p.set(&ParamRef::Numbered(31), 8.0);
        p.set(&ParamRef::Named("main".into()), 1.0);
        p.set(&ParamRef::Named("_g".into()), 2.0);
        p.enter_call(&[5.0]);
        assert_eq!(p.numbered(1), Ok(5.0));
        assert_eq!(p.numbered(2), Ok(0.0));
        assert_eq!(p.numbered(31), Ok(8.0));
        assert_eq!(p.named("main"), Err(ReadProblem::Undefined));
        assert!(!p.exists("main"));
        assert_eq!(p.named("_g"), Ok(2.0));
        p.set(&ParamRef::Named("inner".into()), 3.0);
        p.set(&ParamRef::Named("_g".into()), 4.0);
        p.set(&ParamRef::Numbered(1), 9.0);
        assert_eq!(p.named("inner"), Ok(3.0));
        p.leave_call();
        assert_eq!(p.numbered(1), Ok(7.0));
        assert_eq!(p.named("inner"), Err(ReadProblem::Undefined));
        assert_eq!(p.named("main"), Ok(1.0));
        assert_eq!(p.named("_g"), Ok(4.0));
        assert!(p.exists("_x"));
    }
}
