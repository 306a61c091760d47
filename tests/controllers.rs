//! Readers of what each controller receives, written from the vendors' documentation
//! (not from pvt-emit's writers), and the controller's cubic recomputed from p, v and T.
//!
//! Each reader turns a program text into the pieces the controller would execute: piece
//! time in seconds, and per axis the end position and end velocity in program units.
//! Sources: Newport XPS-Q8 User's Manual §8.3.6 (XPS), Galil DMC-40x0 User Manual
//! "PVT Mode" (Galil), the Zaber ASCII protocol's `pvt` commands (Zaber), the Turbo
//! PMAC Software Reference's `PVT`/`TA`/`{axis}{data}:{data}` (PMAC, and Power PMAC's
//! `pvt` statement), RFC 4180 (CSV).

/// One piece as the controller executes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Piece time, seconds.
    pub time: f64,
    /// End position per axis, program units.
    pub end: Vec<f64>,
    /// End velocity per axis, program units/s.
    pub velocity: Vec<f64>,
}

/// The motion a text describes: where it starts when the text says, and its pieces.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    /// Pieces in order.
    pub pieces: Vec<Piece>,
    /// Triggers, each as the number of pieces before it (it fires at that knot).
    pub triggers: Vec<usize>,
}

fn number(s: &str) -> f64 {
    s.trim()
        .parse()
        .unwrap_or_else(|e| panic!("{s:?} is not a number: {e}"))
}

/// XPS: `dt, dX1, vX1, dX2, vX2, …` per line, displacements from `start`.
pub fn read_xps(text: &str, start: &[f64]) -> Motion {
    let mut at = start.to_vec();
    let pieces = text
        .lines()
        .map(|line| {
            let fields: Vec<f64> = line.split(',').map(number).collect();
            assert_eq!(fields.len(), 1 + 2 * at.len(), "XPS line {line:?}");
            for (i, p) in at.iter_mut().enumerate() {
                *p += fields[1 + 2 * i];
            }
            Piece {
                time: fields[0],
                end: at.clone(),
                velocity: (0..at.len()).map(|i| fields[2 + 2 * i]).collect(),
            }
        })
        .collect();
    Motion {
        pieces,
        ..Motion::default()
    }
}

/// What a Galil program says besides its pieces.
#[derive(Debug, Clone, Default)]
pub struct GalilFacts {
    /// Segments per axis before `BT`.
    pub before_begin: usize,
    /// Every `t`, samples.
    pub samples: Vec<i64>,
}

/// Galil: `PVa=p,v,t` per axis (incremental counts, counts/s, samples of 1/1024 s),
/// `PVa=0,0,0` ends, `BT` begins; `'` lines are comments. `scale`: counts per unit.
pub fn read_galil(text: &str, start: &[f64], scale: &[f64]) -> (Motion, GalilFacts) {
    let mut columns: Vec<Vec<(i64, i64, i64)>> = vec![Vec::new(); start.len()];
    let mut facts = GalilFacts::default();
    let mut begun = false;
    let mut ended = vec![false; start.len()];
    for line in text.lines().filter(|l| !l.starts_with('\'')) {
        if let Some(axes) = line.strip_prefix("BT") {
            assert!(!begun, "BT twice");
            assert_eq!(axes.len(), start.len(), "{line}");
            begun = true;
            facts.before_begin = columns[0].len();
            continue;
        }
        let rest = line
            .strip_prefix("PV")
            .unwrap_or_else(|| panic!("{line:?}"));
        let axis = (rest.as_bytes()[0] - b'A') as usize;
        let values: Vec<i64> = rest[2..].split(',').map(|x| x.parse().unwrap()).collect();
        let [p, v, t] = values[..] else {
            panic!("{line:?}")
        };
        assert!(!ended[axis], "a segment after PV=0,0,0: {line}");
        if (p, v, t) == (0, 0, 0) {
            ended[axis] = true;
            continue;
        }
        columns[axis].push((p, v, t));
    }
    assert!(
        begun && ended.iter().all(|e| *e),
        "BT and PVa=0,0,0 for every axis"
    );
    let mut counts: Vec<i64> = start
        .iter()
        .zip(scale)
        .map(|(p, s)| libm::round(p * s) as i64)
        .collect();
    let mut pieces = Vec::new();
    for k in 0..columns[0].len() {
        let t = columns[0][k].2;
        facts.samples.push(t);
        let mut velocity = Vec::new();
        for (axis, column) in columns.iter().enumerate() {
            let (p, v, ta) = column[k];
            assert_eq!(ta, t, "every axis' segment {k} lasts the same");
            counts[axis] += p;
            velocity.push(v as f64 / scale[axis]);
        }
        let end = counts
            .iter()
            .zip(scale)
            .map(|(c, s)| *c as f64 / s)
            .collect();
        pieces.push(Piece {
            time: t as f64 / 1024.0,
            end,
            velocity,
        });
    }
    (
        Motion {
            pieces,
            ..Motion::default()
        },
        facts,
    )
}

/// Zaber: `pvt 1 point abs p P… v V… t MS` (microsteps, microsteps/s × 1.6384, ms).
pub fn read_zaber(text: &str, scale: &[f64]) -> Motion {
    let mut pieces = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.first(), Some(&"pvt 1 setup disable"));
    assert_eq!(
        lines.get(2).copied(),
        Some(format!("pvt 1 setup store 1 {}", scale.len()).as_str())
    );
    assert_eq!(lines.last(), Some(&"pvt 1 setup disable"));
    let mut triggers = Vec::new();
    for line in &lines {
        // `pvt 1 io set do 1 L`: a trigger toggles digital output 1.
        if let Some(level) = line.strip_prefix("pvt 1 io set do 1 ") {
            assert_eq!(level, if triggers.len() % 2 == 0 { "1" } else { "0" });
            triggers.push(pieces.len());
            continue;
        }
        let Some(rest) = line.strip_prefix("pvt 1 point abs p ") else {
            continue;
        };
        let (p, rest) = rest.split_once(" v ").unwrap();
        let (v, t) = rest.split_once(" t ").unwrap();
        let whole = |s: &str| -> Vec<f64> {
            s.split(' ')
                .map(|x| x.parse::<i64>().unwrap() as f64)
                .collect()
        };
        pieces.push(Piece {
            time: number(t) / 1000.0,
            end: whole(p).iter().zip(scale).map(|(p, s)| p / s).collect(),
            velocity: whole(v)
                .iter()
                .zip(scale)
                .map(|(v, s)| v / (s * 1.6384))
                .collect(),
        });
    }
    Motion { pieces, triggers }
}

/// Turbo PMAC (`PVT`/`TA` ms, `X{p}:{v}`, `DWELL` ms, `;` comments) or Power PMAC
/// (`pvt` ms, `dwell` ms, `//` comments): the same words, in either case.
pub fn read_pmac(text: &str, start: &[f64]) -> Motion {
    let mut at = start.to_vec();
    let mut time = 0.0;
    let mut pieces = Vec::new();
    let mut triggers = Vec::new();
    for raw in text.lines() {
        let line = raw
            .split("//")
            .next()
            .unwrap()
            .split(';')
            .next()
            .unwrap()
            .trim();
        let upper = line.to_ascii_uppercase();
        if upper.is_empty()
            || upper.starts_with("OPEN")
            || upper == "ABS"
            || upper == "CLOSE"
            || upper.starts_with('&')
            || upper.starts_with('#')
        {
            continue;
        }
        // `M1==L`: a synchronous assignment, done as the next move starts.
        if let Some(level) = upper.strip_prefix("M1==") {
            assert_eq!(level, if triggers.len() % 2 == 0 { "1" } else { "0" });
            triggers.push(pieces.len());
            continue;
        }
        if let Some(ms) = upper.strip_prefix("DWELL") {
            pieces.push(Piece {
                time: number(ms) / 1000.0,
                end: at.clone(),
                velocity: vec![0.0; at.len()],
            });
            continue;
        }
        let mut words = upper.split_whitespace().peekable();
        if let Some(ms) = words.peek().and_then(|w| w.strip_prefix("PVT")) {
            time = number(ms) / 1000.0;
            words.next();
        }
        if let Some(ms) = words.peek().and_then(|w| w.strip_prefix("TA")) {
            time = number(ms) / 1000.0;
            words.next();
        }
        let mut velocity = vec![0.0; at.len()];
        let mut moved = false;
        for (i, word) in words.enumerate() {
            let (p, v) = word[1..]
                .split_once(':')
                .unwrap_or_else(|| panic!("{raw:?}"));
            at[i] = number(p);
            velocity[i] = number(v);
            moved = true;
        }
        if moved {
            pieces.push(Piece {
                time,
                end: at.clone(),
                velocity,
            });
        }
    }
    Motion { pieces, triggers }
}

/// CSV: a header `t,X,vX,…`, then rows of absolute time, position and velocity.
pub fn read_csv(text: &str) -> Motion {
    let mut rows = text.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    assert_eq!(header[0], "t");
    // A last column `trigger`: 1 where a trigger fires.
    let marked = header.last() == Some(&"trigger");
    let mut last: Option<f64> = None;
    let mut pieces = Vec::new();
    let mut triggers = Vec::new();
    for row in rows {
        let mut f: Vec<f64> = row.split(',').map(number).collect();
        assert_eq!(f.len(), header.len(), "{row}");
        if marked && f.pop() == Some(1.0) {
            triggers.push(pieces.len() + usize::from(last.is_some()));
        }
        let n = (f.len() - 1) / 2;
        if let Some(t0) = last {
            pieces.push(Piece {
                time: f[0] - t0,
                end: (0..n).map(|i| f[1 + 2 * i]).collect(),
                velocity: (0..n).map(|i| f[2 + 2 * i]).collect(),
            });
        }
        last = Some(f[0]);
    }
    Motion { pieces, triggers }
}

/// The largest |velocity| and |acceleration| of the cubic a controller builds from
/// (p0, v0) to (p1, v1) in `t` (seed 001's kinematic form, solved here again).
pub fn cubic_peaks(p0: f64, v0: f64, p1: f64, v1: f64, t: f64) -> (f64, f64) {
    let d = p1 - p0;
    let a0 = 6.0 * d / (t * t) - (4.0 * v0 + 2.0 * v1) / t;
    let j = 6.0 * (v0 + v1) / (t * t) - 12.0 * d / (t * t * t);
    let mut v = v0.abs().max(v1.abs());
    if j != 0.0 {
        let tm = -a0 / j;
        if tm > 0.0 && tm < t {
            v = v.max((v0 + a0 * tm + j * tm * tm / 2.0).abs());
        }
    }
    (v, a0.abs().max((a0 + j * t).abs()))
}

/// The lowest and highest position of that cubic, sampled finely.
pub fn cubic_range(p0: f64, v0: f64, p1: f64, v1: f64, t: f64) -> (f64, f64) {
    let d = p1 - p0;
    let a0 = 6.0 * d / (t * t) - (4.0 * v0 + 2.0 * v1) / t;
    let j = 6.0 * (v0 + v1) / (t * t) - 12.0 * d / (t * t * t);
    (0..=1000)
        .map(|k| {
            let s = t * k as f64 / 1000.0;
            p0 + v0 * s + a0 * s * s / 2.0 + j * s * s * s / 6.0
        })
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)))
}
