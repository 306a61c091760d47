//! Active comments besides `(MSG,…)`: `(DEBUG,…)` and `(PRINT,…)` become message events
//! with their parameters substituted as LinuxCNC does; `(LOGOPEN,…)`, `(LOGAPPEND,…)`,
//! `(LOG,…)` and `(LOGCLOSE)` are accepted and do nothing (pvtc writes no log files).
//!
//! Owns the recognition of those comments and the substitution: `#1`, `#<name>`, each
//! formatted `%lf` (six decimals) unless a `%d`, `%f`, `%lf` or `%.Nf` is written just
//! before it; a parameter without a value prints `######`. It must not evaluate
//! expressions nor change parameters.

use crate::params::{Parameters, MAX_NUMBERED};

/// What an active comment asks for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Active {
    /// A message to show, substituted.
    Message(String),
    /// A logging comment: accepted, nothing to do.
    Log,
}

/// The active comment `inside` (the text between the parentheses) is, if any.
pub(crate) fn active(inside: &str, params: &Parameters) -> Option<Active> {
    let c = inside.trim_start();
    let (head, rest) = c.split_once(',').unwrap_or((c, ""));
    let head = head.trim_end().to_ascii_lowercase();
    match head.as_str() {
        "debug" | "print" => Some(Active::Message(substitute(rest, params).trim().to_owned())),
        "logopen" | "logappend" | "log" | "logclose" => Some(Active::Log),
        _ => None,
    }
}

/// A `printf` format LinuxCNC accepts before a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Decimals(usize),
    Integer,
}

/// `text` with each parameter reference replaced by its value.
fn substitute(text: &str, params: &Parameters) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(['#', '%']) {
        out.push_str(&rest[..at]);
        rest = &rest[at..];
        let (format, after_format) = match rest.strip_prefix('%') {
            Some(spec) => match format_spec(spec) {
                Some((format, len)) if spec[len..].starts_with('#') => (format, &spec[len..]),
                _ => {
                    out.push('%');
                    rest = spec;
                    continue;
                }
            },
            None => (Format::Decimals(6), rest),
        };
        let Some((value, len)) = reference(&after_format[1..], params) else {
            out.push_str(&rest[..rest.len() - after_format.len() + 1]);
            rest = &after_format[1..];
            continue;
        };
        match (value, format) {
            (None, _) => out.push_str("######"),
            (Some(v), Format::Decimals(n)) => out.push_str(&format!("{v:.n$}")),
            (Some(v), Format::Integer) => out.push_str(&format!("{}", v.trunc())),
        }
        rest = &after_format[1 + len..];
    }
    out.push_str(rest);
    out
}

/// `d`, `f`, `lf`, `.Nf` or `.Nlf` at the start of `spec`, and its length.
fn format_spec(spec: &str) -> Option<(Format, usize)> {
    if spec.starts_with('d') {
        return Some((Format::Integer, 1));
    }
    let (decimals, len) = match spec.strip_prefix('.') {
        Some(digits) => {
            let n = digits.bytes().take_while(u8::is_ascii_digit).count();
            (
                digits[..n].parse().ok().filter(|&d: &usize| d <= 20)?,
                1 + n,
            )
        }
        None => (6, 0),
    };
    let tail = &spec[len..];
    let kind = if tail.starts_with("lf") {
        2
    } else if tail.starts_with('f') {
        1
    } else {
        return None;
    };
    Some((Format::Decimals(decimals), len + kind))
}

/// The parameter after a `#`: its value (`None` when it has none) and the length read.
fn reference(after_hash: &str, params: &Parameters) -> Option<(Option<f64>, usize)> {
    if let Some(named) = after_hash.strip_prefix('<') {
        let end = named.find('>')?;
        return Some((params.named(&named[..end]).ok(), end + 2));
    }
    let digits = after_hash.bytes().take_while(u8::is_ascii_digit).count();
    let index: usize = after_hash[..digits].parse().ok()?;
    let value = (1..=MAX_NUMBERED)
        .contains(&index)
        .then(|| params.numbered(index).ok())
        .flatten();
    Some((value, digits))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamRef;

    #[test]
    fn substitutes_as_linuxcnc_prints() {
        let mut params = Parameters::default();
        params.set(&ParamRef::Numbered(1), 2.5);
        params.set(&ParamRef::Named("a".into()), 3.0);
        // rs274 prints: " a=3.000000 one=2.500000 f=2.50 d=3 u=###### x"
        let got = active(
            "DEBUG, a=#<a> one=#1 f=%.2f#1 d=%d#<a> u=#<nope> x",
            &params,
        );
        let want = "a=3.000000 one=2.500000 f=2.50 d=3 u=###### x";
        assert_eq!(got, Some(Active::Message(want.to_owned())));
        assert_eq!(
            active("print,p #1 100% #", &params),
            Some(Active::Message("p 2.500000 100% #".to_owned()))
        );
        assert_eq!(active("LOGOPEN,log.txt", &params), Some(Active::Log));
        assert_eq!(active("LOGCLOSE", &params), Some(Active::Log));
        assert_eq!(active("debugging notes", &params), None);
    }
}
