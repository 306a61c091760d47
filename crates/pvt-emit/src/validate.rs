//! The last check before output: every number finite, every piece time positive and
//! within the format's longest.
//!
//! Owns the guarantee that no back end prints NaN, infinity, a non-positive time or a time
//! over the format's longest (PMAC: 4095 ms). It
//! must not repair anything: a program that fails is an internal error of a planner, except
//! a piece too long for the format that could not be cut (longer than
//! `pvt_core::split::MAX_SUB_PIECES` of the format's longest), which its input asked for.

use pvt_core::{PvtProgram, SegmentRef};

/// A program value no controller may receive, with where it is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}contour {contour}, segment {segment} (source line {line}) has {what}; no output was written", if *internal { "internal error: " } else { "" })]
pub struct InvalidProgram {
    /// 1-based contour number.
    pub contour: usize,
    /// 1-based segment number within the contour (0: the contour's start).
    pub segment: usize,
    /// Source line of the segment.
    pub line: u32,
    /// What is wrong, in words.
    pub what: String,
    /// A planner's fault (NaN, infinity, a non-positive time), not the input's.
    pub internal: bool,
    /// Stable code: [`InvalidProgram::CODE`], or the controller rule broken
    /// ([`crate::rules`]).
    pub code: &'static str,
}

impl InvalidProgram {
    /// Stable code of this error.
    pub const CODE: &'static str = "pvtc::emit::invalid_program";
}

/// Checks a contour's start position.
pub fn check_start(start: &[f64], contour: usize, line: u32) -> Result<(), InvalidProgram> {
    if start.iter().all(|x| x.is_finite()) {
        return Ok(());
    }
    Err(InvalidProgram {
        contour,
        segment: 0,
        line,
        what: "a start position that is not finite".into(),
        internal: true,
        code: InvalidProgram::CODE,
    })
}

/// Checks one segment's piece time, positions and velocities.
#[inline]
pub fn check_segment(
    seg: &SegmentRef<'_>,
    contour: usize,
    segment: usize,
) -> Result<(), InvalidProgram> {
    // x·0 is 0 for every finite x and NaN for any other: one sum answers for all.
    let zeros = |values: &[f64]| values.iter().fold(0.0, |sum, x| sum + x * 0.0);
    let time_ok = seg.duration.is_finite() && seg.duration > 0.0;
    if time_ok && zeros(seg.end) + zeros(seg.velocity) == 0.0 {
        return Ok(());
    }
    Err(segment_refusal(seg, contour, segment))
}

/// Why [`check_segment`] refuses `seg`: its time first, then its values.
#[cold]
fn segment_refusal(seg: &SegmentRef<'_>, contour: usize, segment: usize) -> InvalidProgram {
    let what = if !(seg.duration.is_finite() && seg.duration > 0.0) {
        format!(
            "piece time {} s (a trajectory the XPS refuses with -75: non-positive time)",
            seg.duration
        )
    } else {
        "a position or velocity that is not finite".into()
    };
    InvalidProgram {
        contour,
        segment,
        line: seg.line,
        what,
        internal: true,
        code: InvalidProgram::CODE,
    }
}

/// Checks that a segment's piece time is at most `max_seconds` (within a relative 1e-12,
/// the rounding of a time cut into equal parts), for formats with a longest piece time.
#[inline]
pub fn check_piece_time(
    seg: &SegmentRef<'_>,
    max_seconds: f64,
    contour: usize,
    segment: usize,
) -> Result<(), InvalidProgram> {
    if seg.duration <= max_seconds * (1.0 + 1e-12) {
        return Ok(());
    }
    Err(piece_time_refusal(seg, max_seconds, contour, segment))
}

/// Why [`check_piece_time`] refuses `seg`.
#[cold]
fn piece_time_refusal(
    seg: &SegmentRef<'_>,
    max_seconds: f64,
    contour: usize,
    segment: usize,
) -> InvalidProgram {
    InvalidProgram {
        contour,
        segment,
        line: seg.line,
        what: format!(
            "piece time {} s, over the format's longest, {max_seconds} s, and too long to cut",
            seg.duration
        ),
        internal: false,
        code: InvalidProgram::CODE,
    }
}

/// Checks every position, velocity and piece time of `program`.
pub fn validate(program: &PvtProgram) -> Result<(), InvalidProgram> {
    for (c, contour) in program.contours.iter().enumerate() {
        check_start(
            &contour.start,
            c + 1,
            contour.lines.first().copied().unwrap_or(0),
        )?;
        for (i, seg) in contour.segments().enumerate() {
            check_segment(&seg, c + 1, i + 1)?;
        }
    }
    Ok(())
}
