//! Parameters: RS274NGC numbered (`#1`–`#5399`) and named (`#<name>`, `#<_global>`) values.
//!
//! Owns the store and its rules (names are case-insensitive with blanks removed, numbered
//! parameters start at 0, named ones must be assigned before they are read, reads of
//! machine-specific parameters are refused). It must not parse text (that is
//! [`crate::value`]) nor decide when assignments take effect (after the line is read:
//! [`crate::compile_into`] applies a block's assignments after parsing it).

use std::collections::HashMap;

/// The highest numbered parameter.
pub(crate) const MAX_NUMBERED: usize = 5399;

/// The first numbered parameter that holds machine state (probe results, stored
/// positions, offsets); reading one the program did not assign is refused.
const FIRST_MACHINE: usize = 5000;

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
    /// A parameter that holds machine state pvtc does not know.
    MachineSpecific,
}

/// All parameter values of a program run.
#[derive(Debug, Clone)]
pub(crate) struct Parameters {
    numbered: Vec<f64>,
    assigned: Vec<bool>,
    named: HashMap<String, f64>,
}

impl Default for Parameters {
    fn default() -> Self {
        Parameters {
            numbered: vec![0.0; MAX_NUMBERED + 1],
            assigned: vec![false; MAX_NUMBERED + 1],
            named: HashMap::new(),
        }
    }
}

/// True when `name` (as written) reads machine state: `_hal[…]`, `_ini[…]` or any
/// predefined global such as `_x` that the program has not assigned.
pub(crate) fn is_machine_name(normalized: &str) -> bool {
    normalized.starts_with('_')
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
    /// The value of `#index` (1..=[`MAX_NUMBERED`], checked by the caller).
    pub fn numbered(&self, index: usize) -> Result<f64, ReadProblem> {
        match (self.numbered.get(index), self.assigned.get(index)) {
            (Some(&v), Some(&assigned)) if assigned || index < FIRST_MACHINE => Ok(v),
            _ => Err(ReadProblem::MachineSpecific),
        }
    }

    /// The value of `#<name>` (`name` as written between the angle brackets).
    pub fn named(&self, name: &str) -> Result<f64, ReadProblem> {
        let key = normalize(name);
        match self.named.get(key.as_ref()) {
            Some(&v) => Ok(v),
            None if is_machine_name(&key) => Err(ReadProblem::MachineSpecific),
            None => Err(ReadProblem::Undefined),
        }
    }

    /// True when `#<name>` has a value (`EXISTS[#<name>]`).
    pub fn exists(&self, name: &str) -> bool {
        self.named.contains_key(normalize(name).as_ref())
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
                if let Some(slot) = self.named.get_mut(name) {
                    *slot = value;
                } else {
                    self.named.insert(name.clone(), value);
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
        assert_eq!(p.named("_hal[x.y]"), Err(ReadProblem::MachineSpecific));
    }

    #[test]
    fn numbered_start_at_zero_machine_ones_are_refused() {
        let mut p = Parameters::default();
        assert_eq!(p.numbered(1), Ok(0.0));
        assert_eq!(p.numbered(5221), Err(ReadProblem::MachineSpecific));
        p.set(&ParamRef::Numbered(5221), 3.0);
        assert_eq!(p.numbered(5221), Ok(3.0));
        assert_eq!(p.numbered(9999), Err(ReadProblem::MachineSpecific));
    }
}
