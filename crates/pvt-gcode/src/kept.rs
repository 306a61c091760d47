//! The bounded list of one severity of diagnostics (errors or warnings) of a program.
//!
//! Owns the memory bound on diagnostics: a ten-million-line program with a bad word on
//! every line must not hold ten million diagnostics. It keeps the first
//! [`MAX_KEPT_DIAGNOSTICS`], merges every use of one unsupported feature into a single
//! diagnostic as it arrives (there are few features, so those are always kept), and
//! counts the rest. It must not decide what is an error or a warning.

use std::ops::Range;

use crate::diagnostic::{span, GcodeDiagnostic};

/// How many errors (and, separately, warnings) a compile keeps; the rest are counted and
/// reported as one `more_errors` / `more_warnings` diagnostic.
pub const MAX_KEPT_DIAGNOSTICS: usize = 1000;

/// Diagnostics of one severity, at most [`MAX_KEPT_DIAGNOSTICS`] of them plus one per
/// unsupported feature.
#[derive(Debug, Default)]
pub(crate) struct Kept {
    list: Vec<GcodeDiagnostic>,
    /// Each unsupported feature met and the index of its diagnostic in `list`.
    features: Vec<(&'static str, usize)>,
    dropped: usize,
    first_dropped: Option<Range<usize>>,
}

impl Kept {
    /// Keeps `diagnostic`, merges it into its feature's, or counts it.
    pub fn push(&mut self, diagnostic: GcodeDiagnostic) {
        if let GcodeDiagnostic::Unsupported { feature, .. } = &diagnostic {
            match self.features.iter().find(|(f, _)| f == feature) {
                Some(&(_, index)) => merge_use(&mut self.list[index], diagnostic),
                None => {
                    self.features.push((feature, self.list.len()));
                    self.list.push(diagnostic);
                }
            }
            return;
        }
        if self.list.len() - self.features.len() >= MAX_KEPT_DIAGNOSTICS {
            self.dropped += 1;
            self.first_dropped.get_or_insert_with(|| diagnostic.span());
            return;
        }
        self.list.push(diagnostic);
    }

    /// True when `diagnostic` is kept already (the same code, text and place).
    pub fn contains(&self, diagnostic: &GcodeDiagnostic) -> bool {
        self.list.contains(diagnostic)
    }

    /// True when nothing was pushed.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty() && self.dropped == 0
    }

    /// The kept diagnostics in source order, then `more(count, span)` for those counted.
    pub fn into_sorted(
        self,
        more: impl FnOnce(usize, miette::SourceSpan) -> GcodeDiagnostic,
    ) -> Vec<GcodeDiagnostic> {
        let mut list = self.list;
        list.sort_by_key(|d| d.span().start);
        if let Some(first) = self.first_dropped {
            list.push(more(self.dropped, span(first.start..first.start)));
        }
        list
    }
}

/// Counts one more place of `kept`'s feature; the diagnostic shows the first in the file.
fn merge_use(kept: &mut GcodeDiagnostic, new: GcodeDiagnostic) {
    let earlier = new.span().start < kept.span().start;
    let (
        GcodeDiagnostic::Unsupported {
            code, places, span, ..
        },
        GcodeDiagnostic::Unsupported {
            code: new_code,
            span: new_span,
            ..
        },
    ) = (kept, new)
    else {
        return;
    };
    *places += 1;
    if earlier {
        *code = new_code;
        *span = new_span;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unknown(at: usize) -> GcodeDiagnostic {
        GcodeDiagnostic::UnknownWord {
            word: "Q1".to_owned(),
            meaning: "test",
            span: span(at..at + 2),
        }
    }

    fn unsupported(code: &str, at: usize) -> GcodeDiagnostic {
        GcodeDiagnostic::Unsupported {
            code: code.to_owned(),
            feature: "canned cycles",
            places: 1,
            span: span(at..at + 3),
        }
    }

    fn more(count: usize, span: miette::SourceSpan) -> GcodeDiagnostic {
        GcodeDiagnostic::MoreErrors { count, span }
    }

    #[test]
    fn keeps_the_first_thousand_and_counts_the_rest() {
        let mut kept = Kept::default();
        for line in 0..(MAX_KEPT_DIAGNOSTICS + 250) {
            kept.push(unknown(line * 10));
        }
        let list = kept.into_sorted(more);
        assert_eq!(list.len(), MAX_KEPT_DIAGNOSTICS + 1);
        assert_eq!(list[999].span(), 9990..9992);
        assert_eq!(
            list[1000],
            GcodeDiagnostic::MoreErrors {
                count: 250,
                span: span(10000..10000)
            }
        );
    }

    #[test]
    fn one_diagnostic_per_unsupported_feature_at_its_first_place() {
        let mut kept = Kept::default();
        kept.push(unsupported("G83", 50));
        for at in 0..5000 {
            kept.push(unknown(100 + at));
        }
        kept.push(unsupported("G81", 20));
        kept.push(unsupported("G82", 70));
        let list = kept.into_sorted(more);
        assert_eq!(
            list[0],
            GcodeDiagnostic::Unsupported {
                code: "G81".to_owned(),
                feature: "canned cycles",
                places: 3,
                span: span(20..23),
            }
        );
        assert_eq!(list.len(), 1 + MAX_KEPT_DIAGNOSTICS + 1);
    }
}
