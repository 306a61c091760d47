//! G70, G71, G72 (and the .1 and .2 forms) in the interpreter, as LinuxCNC 2.9 runs them.
//!
//! Owns the cycle block's checks (Q, G18, no compensation but for G70, I > 0), the rapid
//! to its X Z, the profile read from the subroutine Q names (the reader calls it:
//! [`Interpreter::lathe_profile_wanted`], then every block of it comes to
//! [`Interpreter::profile_block`] while recording: its G0–G3, X Z, U W, I K, R, A
//! (fillet), C (chamfer) make the profile, everything else is ignored, and the position
//! `#<_x>`, `#<_z>` read is the profile's), and running the cuts [`crate::lathe`] makes
//! from it: rapids, feeds at the F in force and arcs in the ZX plane. It must not compute
//! the cycle's geometry (that is [`crate::lathe`]).

use pvt_core::{Arc, ArcDirection, Element, ElementKind, Motion, Plane, Position};

use super::Interpreter;
use crate::block::{Block, Word};
use crate::codes::{Distance, LatheCycle};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::lathe::{self, Cut, Numbers, Profile, Segment, Shape, Zx};
use crate::request::Request;

/// A lathe cycle between its block and its cuts.
#[derive(Debug, Clone)]
pub(crate) struct LatheRun {
    cycle: LatheCycle,
    /// The subroutine's label (`100` for Q100).
    label: String,
    numbers: Numbers,
    /// The cycle block, for its spans.
    block: Block,
    /// The machine position the cuts start from (after the cycle's rapid).
    resume: Position,
    /// The profile so far, and where its next segment starts (program units).
    profile: Vec<Segment>,
    cursor: Zx,
    /// The profile's motion mode (tenths: 0, 10, 20, 30).
    mode: u32,
    /// The profile is being read (the reader is running the subroutine).
    recording: bool,
    /// The reader has been asked for the profile.
    asked: bool,
}

impl Interpreter<'_> {
    /// A lathe cycle block: checked, a rapid to its X Z, then its profile is wanted.
    pub(super) fn lathe_cycle(&mut self, cycle: LatheCycle, request: &Request, block: &Block) {
        let at = super::motion::move_span(request, block);
        let refuse = |detail: &str| GcodeDiagnostic::Cycle {
            code: cycle.name(),
            detail: detail.to_owned(),
            span: span(at.clone()),
        };
        let Some(q) = request.q else {
            let word = request.motion.map_or(at.clone(), |(_, w)| w.span());
            return self.push(super::missing_at(
                cycle.name(),
                word,
                "a Q word (the profile's subroutine)",
            ));
        };
        if self.modal.plane != Plane::ZX {
            return self.push(refuse("can only be used in the XZ plane (G18)"));
        }
        if self.cutter_on() && cycle != LatheCycle::Finishing {
            return self.push(refuse("cannot be used with cutter compensation on"));
        }
        let value = |w: Option<Word>| w.map(|w| w.value);
        let i = value(request.offsets[0]).unwrap_or(1.0);
        if i <= 0.0 {
            return self.push(refuse("I must be greater than zero"));
        }
        let scale = self.scale();
        let here = self.to_program(self.position);
        let (mut x, mut z) = (here[0] / scale, here[2] / scale);
        let [x_word, z_word] = [value(request.axes[0]), value(request.axes[2])];
        match self.modal.distance {
            Distance::Incremental => {
                x += x_word.unwrap_or(0.0);
                z += z_word.unwrap_or(0.0);
            }
            Distance::Absolute => {
                x = x_word.unwrap_or(x);
                z = z_word.unwrap_or(z);
            }
        }
        let start = self.program_xz(x, z);
        self.rapid_to(start, block);
        self.lathe = Some(Box::new(LatheRun {
            cycle,
            label: format!("{}", q.value.trunc()),
            numbers: Numbers {
                start: Zx::new(z, x),
                d: value(request.d).unwrap_or(0.0),
                e: value(request.e).unwrap_or(0.0),
                i,
                p: value(request.p).unwrap_or(1.0),
                r: value(request.radius).unwrap_or(0.5),
                // U and W of the block (with U W axes only, which pvtc does not drive).
                shift: Zx::default(),
            },
            block: block.clone(),
            resume: self.position,
            profile: Vec::new(),
            cursor: Zx::new(z, x),
            mode: 0,
            recording: false,
            asked: false,
        }));
    }

    /// The label of the subroutine a lathe cycle waits for as its profile, once: the
    /// reader then runs it between [`Self::begin_profile`] and [`Self::end_profile`].
    pub(crate) fn lathe_profile_wanted(&mut self) -> Option<String> {
        let run = self.lathe.as_mut().filter(|r| !r.asked)?;
        run.asked = true;
        Some(run.label.clone())
    }

    /// The blocks from here on make the profile.
    pub(crate) fn begin_profile(&mut self) {
        if let Some(run) = self.lathe.as_mut() {
            run.recording = true;
        }
    }

    /// True while a lathe cycle's profile is being read.
    pub(crate) fn recording_profile(&self) -> bool {
        self.lathe.as_ref().is_some_and(|r| r.recording)
    }

    /// A block of the profile: its motion words make a segment, the rest is ignored.
    pub(crate) fn profile_block(&mut self, block: &Block) {
        let Some(mut run) = self.lathe.take() else {
            return;
        };
        match self.profile_segment(&mut run, block) {
            Ok(()) => {
                let point = self.program_xz(run.cursor.im, run.cursor.re);
                self.position = point;
            }
            Err(detail) => self.push(GcodeDiagnostic::Cycle {
                code: run.cycle.name(),
                detail,
                span: span(block.span()),
            }),
        }
        self.lathe = Some(run);
    }

    /// The segment (and fillet or chamfer) `block` adds to the profile.
    fn profile_segment(&self, run: &mut LatheRun, block: &Block) -> Result<(), String> {
        let mut words = [None; 9];
        for w in &block.words {
            let slot = match w.letter {
                b'G' if [0.0, 1.0, 2.0, 3.0].contains(&w.value) => {
                    run.mode = (w.value * 10.0) as u32;
                    continue;
                }
                b'X' => 0,
                b'Z' => 1,
                b'U' => 2,
                b'W' => 3,
                b'I' => 4,
                b'K' => 5,
                b'R' => 6,
                b'A' => 7,
                b'C' => 8,
                _ => continue,
            };
            words[slot] = Some(w.value);
        }
        let [x, z, u, w, i, k, r, fillet, chamfer] = words;
        let corner = match (fillet, chamfer) {
            (Some(_), Some(_)) => return Err("both A and C are given on a corner".into()),
            (Some(a), None) => Some(Shape::Fillet(a)),
            (None, Some(c)) => Some(Shape::Chamfer(c)),
            (None, None) => None,
        };
        let incremental = self.modal.distance == Distance::Incremental;
        let start = run.cursor;
        let mut end = if incremental { Zx::default() } else { start };
        let half = |v: f64| if self.modal.diameter { v / 2.0 } else { v };
        end.im = along(end.im, x, u.map(half), incremental, "U and X")?;
        end.re = along(end.re, z, w, incremental, "W and Z")?;
        if incremental {
            end = end + start;
        }
        if start == end {
            return Ok(());
        }
        let segment = match run.mode {
            20 | 30 => {
                let ccw = run.mode == 30;
                let centers = self.modal.arc_centers.0;
                let center = profile_center(start, end, ccw, r, [i, k], centers)?;
                Segment {
                    start,
                    end,
                    shape: Shape::Arc { ccw, center },
                }
            }
            _ => Segment::line(start, end),
        };
        run.profile.push(segment);
        if let Some(shape) = corner {
            run.profile.push(Segment {
                start: end,
                end,
                shape,
            });
        }
        run.cursor = end;
        Ok(())
    }

    /// The profile is read: the cuts the cycle makes of it, from where the tool stands.
    pub(crate) fn end_profile(&mut self) {
        let Some(run) = self.lathe.take() else {
            return;
        };
        self.position = run.resume;
        if run.profile.is_empty() {
            return;
        }
        let profile = Profile::new(run.profile.clone());
        let cuts = match run.cycle {
            LatheCycle::Finishing => lathe::finishing(&profile, &run.numbers),
            LatheCycle::Roughing { facing, pockets } => {
                lathe::roughing(&profile, lathe::Roughing { facing, pockets }, &run.numbers)
            }
        };
        match cuts {
            Ok(cuts) => {
                for cut in cuts {
                    if !self.lathe_cut(cut, &run.block) {
                        break;
                    }
                }
            }
            Err(detail) => self.push(GcodeDiagnostic::Cycle {
                code: run.cycle.name(),
                detail,
                span: span(run.block.span()),
            }),
        }
    }

    /// One cut; false after an error (no feed, an arc off its circle).
    fn lathe_cut(&mut self, cut: Cut, block: &Block) -> bool {
        let (to, arc) = match cut {
            Cut::Rapid(p) => {
                let end = self.program_xz(p.im, p.re);
                self.rapid_to(end, block);
                return true;
            }
            Cut::Feed(p) => (p, None),
            Cut::Arc { ccw, center, end } => (end, Some((ccw, center))),
        };
        let Some(rate) = self.lathe_feed(block) else {
            return false;
        };
        let start = self.machine_position();
        let end = self.program_xz(to.im, to.re);
        let close = |a: &Position, b: &Position| {
            let scale = self.scale();
            (a[0] - b[0]).abs() < 1e-4 * scale && (a[2] - b[2]).abs() < 1e-4 * scale
        };
        let kind = match arc {
            None if super::motion::no_move(&start, &end) => return true,
            None => ElementKind::Line,
            // As LinuxCNC: an arc to where the tool is (within 0.0001) is no move.
            Some(_) if close(&start, &end) => return true,
            Some((ccw, center)) => {
                let center = Plane::ZX.project(&self.program_xz(center.im, center.re));
                let (from, to) = (Plane::ZX.project(&start), Plane::ZX.project(&end));
                let offsets = [center[0] - from[0], center[1] - from[1]];
                if let Err(problem) =
                    crate::arcs::center_from_offsets(from, to, offsets, self.arc_tolerance())
                {
                    let detail = format!("an arc of its cut is off its circle ({problem:?})");
                    self.push(GcodeDiagnostic::Cycle {
                        code: "G7x",
                        detail,
                        span: span(block.span()),
                    });
                    return false;
                }
                ElementKind::Arc(Arc {
                    plane: Plane::ZX,
                    center,
                    direction: match ccw {
                        true => ArcDirection::CounterClockwise,
                        false => ArcDirection::Clockwise,
                    },
                    extra_turns: 0,
                })
            }
        };
        self.position = end;
        let element = Element {
            kind,
            start,
            end,
            feed: rate,
            span: super::motion::element_span(block),
        };
        self.route(Motion::Feed, element);
        true
    }

    /// The feed of a cut, units per second; `None` (reported once) without one.
    fn lathe_feed(&mut self, block: &Block) -> Option<f64> {
        let rate = self
            .feed_per_minute(self.modal.feed)
            .and_then(super::motion::feed_per_second);
        if rate.is_none() && !self.feed_reported {
            self.feed_reported = true;
            self.push(GcodeDiagnostic::NoFeed {
                span: span(block.span()),
            });
        }
        rate
    }
}

/// A profile coordinate: `from` moved by `shift` (U or W, absolute mode only), else the
/// axis word `word`; both in one block are refused (`both` names them).
fn along(
    from: f64,
    word: Option<f64>,
    shift: Option<f64>,
    incremental: bool,
    both: &str,
) -> Result<f64, String> {
    match (shift, word) {
        (Some(_), _) if incremental => Err(format!("{both}: U and W cannot be used in G91")),
        (Some(_), Some(_)) => Err(format!("{both} cannot be used in one block")),
        (Some(shift), None) => Ok(from + shift),
        (None, Some(word)) => Ok(word),
        (None, None) => Ok(from),
    }
}

/// The centre of a profile arc from `start` to `end`: from R (`ccw`: G3), or from I K,
/// absolute under G90.1, from the start under G91.1.
fn profile_center(
    start: Zx,
    end: Zx,
    ccw: bool,
    r: Option<f64>,
    [i, k]: [Option<f64>; 2],
    centers: Distance,
) -> Result<Zx, String> {
    if let Some(r) = r {
        if i.is_some() || k.is_some() {
            return Err("both R and I or K are given for an arc".into());
        }
        let chord = end - start;
        let rise = ((r * r - chord.norm() / 4.0) / chord.norm()).sqrt();
        let d = Zx::new(0.0, rise) * chord;
        let mid = (start + end).scale(0.5);
        return Ok(if ccw { mid + d } else { mid - d });
    }
    if i.is_none() && k.is_none() {
        return Err("an arc needs I or K".into());
    }
    let center = Zx::new(k.unwrap_or(0.0), i.unwrap_or(0.0));
    Ok(match centers {
        Distance::Incremental => center + start,
        Distance::Absolute => center,
    })
}
