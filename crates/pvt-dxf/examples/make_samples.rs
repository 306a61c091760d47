//! Writes the sample drawings of `samples/dxf/` and the bad files of `crates/pvt-dxf/tests/bad/`.
//!
//! Run from the workspace root: `cargo run -p pvt-dxf --example make_samples`. The output
//! is deterministic: hand-formatted ASCII DXF for the entity samples, and the `dxf`
//! crate's own writer (a CAD-style file: tables, block records, handles, subclass markers)
//! with its dates and GUIDs pinned for `cad_part.dxf` and its binary twin.

use std::fmt::Write as _;
use std::path::Path;

use dxf::entities::{Circle, Entity, EntityType, Insert, Line, LwPolyline, MText, Text};
use dxf::enums::{AcadVersion, Units};
use dxf::tables::Layer;
use dxf::{Block, LwPolylineVertex, Point};

/// A minimal ASCII DXF writer: group codes and values, handles counted up from 0x100.
struct Dxf {
    out: String,
    handle: u32,
}

impl Dxf {
    fn new() -> Dxf {
        Dxf {
            out: String::new(),
            handle: 0x100,
        }
    }

    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = write!(self.out, "{code:>3}\n{value}\n");
    }

    fn xyz(&mut self, base: i32, p: [f64; 3]) {
        self.pair(base, p[0]);
        self.pair(base + 10, p[1]);
        self.pair(base + 20, p[2]);
    }

    fn start(&mut self, kind: &str, layer: &str) {
        self.pair(0, kind);
        let h = self.handle;
        self.handle += 1;
        self.pair(5, format!("{h:X}"));
        self.pair(8, layer);
    }

    fn normal(&mut self, n: [f64; 3]) {
        if n != [0.0, 0.0, 1.0] {
            self.xyz(210, n);
        }
    }

    fn line(&mut self, layer: &str, a: [f64; 3], b: [f64; 3]) {
        self.start("LINE", layer);
        self.xyz(10, a);
        self.xyz(11, b);
    }

    fn circle(&mut self, layer: &str, c: [f64; 3], r: f64, n: [f64; 3]) {
        self.start("CIRCLE", layer);
        self.xyz(10, c);
        self.pair(40, r);
        self.normal(n);
    }

    fn arc(&mut self, layer: &str, c: [f64; 3], r: f64, a0: f64, a1: f64, n: [f64; 3]) {
        self.start("ARC", layer);
        self.xyz(10, c);
        self.pair(40, r);
        self.normal(n);
        self.pair(50, a0);
        self.pair(51, a1);
    }

    fn lwpolyline(
        &mut self,
        layer: &str,
        verts: &[(f64, f64, f64)],
        closed: bool,
        elevation: f64,
        n: [f64; 3],
    ) {
        self.start("LWPOLYLINE", layer);
        self.pair(90, verts.len());
        self.pair(70, i32::from(closed));
        if elevation != 0.0 {
            self.pair(38, elevation);
        }
        for &(x, y, b) in verts {
            self.pair(10, x);
            self.pair(20, y);
            if b != 0.0 {
                self.pair(42, b);
            }
        }
        self.normal(n);
    }

    fn polyline(&mut self, layer: &str, verts: &[([f64; 3], f64)], flags: i32, elevation: f64) {
        self.start("POLYLINE", layer);
        self.pair(66, 1);
        self.xyz(10, [0.0, 0.0, elevation]);
        self.pair(70, flags);
        for &(p, b) in verts {
            self.start("VERTEX", layer);
            self.xyz(10, p);
            if b != 0.0 {
                self.pair(42, b);
            }
            self.pair(70, if flags & 8 != 0 { 32 } else { 0 });
        }
        self.start("SEQEND", layer);
    }

    #[allow(clippy::too_many_arguments)]
    fn spline(
        &mut self,
        layer: &str,
        flags: i32,
        degree: i32,
        knots: &[f64],
        ctrl: &[[f64; 3]],
        weights: &[f64],
        fit: &[[f64; 3]],
        tangents: Option<([f64; 3], [f64; 3])>,
    ) {
        self.start("SPLINE", layer);
        self.xyz(210, [0.0, 0.0, 1.0]);
        self.pair(70, flags);
        self.pair(71, degree);
        self.pair(72, knots.len());
        self.pair(73, ctrl.len());
        self.pair(74, fit.len());
        if let Some((s, e)) = tangents {
            self.xyz(12, s);
            self.xyz(13, e);
        }
        for k in knots {
            self.pair(40, k);
        }
        for w in weights {
            self.pair(41, w);
        }
        for &p in ctrl {
            self.xyz(10, p);
        }
        for &p in fit {
            self.xyz(11, p);
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn ellipse(
        &mut self,
        layer: &str,
        c: [f64; 3],
        major: [f64; 3],
        ratio: f64,
        t0: f64,
        t1: f64,
        n: [f64; 3],
    ) {
        self.start("ELLIPSE", layer);
        self.xyz(10, c);
        self.xyz(11, major);
        self.xyz(210, n);
        self.pair(40, ratio);
        self.pair(41, t0);
        self.pair(42, t1);
    }

    fn text(&mut self, layer: &str, at: [f64; 3], s: &str) {
        self.start("TEXT", layer);
        self.xyz(10, at);
        self.pair(40, 2.5);
        self.pair(1, s);
    }

    /// The whole file: header with $INSUNITS, then the entities written so far.
    fn finish(self, insunits: i32) -> String {
        let mut head = Dxf::new();
        head.pair(0, "SECTION");
        head.pair(2, "HEADER");
        head.pair(9, "$ACADVER");
        head.pair(1, "AC1015");
        head.pair(9, "$INSUNITS");
        head.pair(70, insunits);
        head.pair(0, "ENDSEC");
        head.pair(0, "SECTION");
        head.pair(2, "ENTITIES");
        let mut s = head.out;
        s.push_str(&self.out);
        s.push_str("  0\nENDSEC\n  0\nEOF\n");
        s
    }
}

const Z: [f64; 3] = [0.0, 0.0, 1.0];
const MINUS_Z: [f64; 3] = [0.0, 0.0, -1.0];

/// LINE, ARC, CIRCLE: a slot drawn out of order with reversed pieces, a circle, a mirrored
/// arc (extrusion −Z) closing a D shape, and an open zig-zag.
fn lines_arcs() -> String {
    let mut d = Dxf::new();
    // Slot: centres (20, 10) and (50, 10), radius 5; lines drawn in scrambled directions.
    d.line("CUT", [50.0, 15.0, 0.0], [20.0, 15.0, 0.0]);
    d.arc("CUT", [50.0, 10.0, 0.0], 5.0, 270.0, 90.0, Z);
    d.line("CUT", [50.0, 5.0, 0.0], [20.0, 5.0, 0.0]);
    d.arc("CUT", [20.0, 10.0, 0.0], 5.0, 90.0, 270.0, Z);
    d.circle("CUT", [80.0, 10.0, 0.0], 6.0, Z);
    // D shape at x 100..110: a line and a half circle drawn mirrored (OCS centre x −100).
    d.line("CUT", [100.0, 30.0, 0.0], [100.0, 50.0, 0.0]);
    d.arc("CUT", [-100.0, 40.0, 0.0], 10.0, 90.0, 270.0, MINUS_Z);
    // Open zig-zag.
    d.line("ENGRAVE", [0.0, 40.0, 0.0], [10.0, 50.0, 0.0]);
    d.line("ENGRAVE", [20.0, 40.0, 0.0], [10.0, 50.0, 0.0]);
    d.line("ENGRAVE", [20.0, 40.0, 0.0], [30.0, 50.0, 0.0]);
    d.finish(4)
}

/// LWPOLYLINE (bulges, closed, elevation, −Z extrusion) and POLYLINE 2D / 3D with VERTEX bulges.
fn polylines() -> String {
    let mut d = Dxf::new();
    // Rounded rectangle 40 × 20, corner radius 5: quarter-circle bulges tan(22.5°).
    let b = libm::tan(std::f64::consts::PI / 8.0);
    d.lwpolyline(
        "CUT",
        &[
            (5.0, 0.0, 0.0),
            (35.0, 0.0, b),
            (40.0, 5.0, 0.0),
            (40.0, 15.0, b),
            (35.0, 20.0, 0.0),
            (5.0, 20.0, b),
            (0.0, 15.0, 0.0),
            (0.0, 5.0, b),
        ],
        true,
        0.0,
        Z,
    );
    // Open wave at elevation 2 with clockwise (negative) bulges.
    d.lwpolyline(
        "CUT",
        &[
            (50.0, 0.0, -1.0),
            (60.0, 0.0, 0.5),
            (70.0, 0.0, 0.0),
            (80.0, 5.0, 0.0),
        ],
        false,
        2.0,
        Z,
    );
    // Mirrored closed pocket: OCS x is world −x.
    d.lwpolyline(
        "CUT",
        &[
            (-90.0, 0.0, 0.0),
            (-110.0, 0.0, 1.0),
            (-110.0, 10.0, 0.0),
            (-90.0, 10.0, 0.0),
        ],
        true,
        0.0,
        MINUS_Z,
    );
    // POLYLINE 2D, closed, with VERTEX bulges: a circle of radius 5 from two semicircles.
    d.polyline(
        "CUT",
        &[([120.0, 5.0, 0.0], 1.0), ([130.0, 5.0, 0.0], 1.0)],
        1,
        0.0,
    );
    // POLYLINE 3D ramp: Z descends along a square.
    d.polyline(
        "RAMP",
        &[
            ([0.0, 40.0, 0.0], 0.0),
            ([10.0, 40.0, -1.0], 0.0),
            ([10.0, 50.0, -2.0], 0.0),
            ([0.0, 50.0, -3.0], 0.0),
        ],
        8,
        0.0,
    );
    d.finish(4)
}

/// SPLINE: clamped cubic, rational quadratic quarter circles, degree 5, periodic cubic,
/// fit points with end tangents and fit points with natural ends.
fn splines() -> String {
    let mut d = Dxf::new();
    d.spline(
        "CUT",
        8,
        3,
        &[0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0],
        &[
            [0.0, 0.0, 0.0],
            [10.0, 20.0, 0.0],
            [20.0, -10.0, 0.0],
            [30.0, 15.0, 0.0],
            [40.0, 0.0, 0.0],
            [50.0, 10.0, 0.0],
        ],
        &[],
        &[],
        None,
    );
    // Half circle of radius 10 about (80, 0) as two rational quadratic quarter arcs.
    let w = std::f64::consts::FRAC_1_SQRT_2;
    d.spline(
        "CUT",
        8 | 4,
        2,
        &[0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0],
        &[
            [90.0, 0.0, 0.0],
            [90.0, 10.0, 0.0],
            [80.0, 10.0, 0.0],
            [70.0, 10.0, 0.0],
            [70.0, 0.0, 0.0],
        ],
        &[1.0, w, 1.0, w, 1.0],
        &[],
        None,
    );
    // Degree 5, non-uniform knots.
    d.spline(
        "CUT",
        8,
        5,
        &[
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
        ],
        &[
            [0.0, 30.0, 0.0],
            [5.0, 45.0, 0.0],
            [15.0, 25.0, 0.0],
            [25.0, 50.0, 0.0],
            [35.0, 20.0, 0.0],
            [45.0, 45.0, 0.0],
            [50.0, 30.0, 0.0],
        ],
        &[],
        &[],
        None,
    );
    // Periodic closed cubic: uniform knots, first three control points repeated at the end.
    let ring = [
        [70.0, 30.0, 0.0],
        [80.0, 25.0, 0.0],
        [90.0, 30.0, 0.0],
        [90.0, 45.0, 0.0],
        [70.0, 45.0, 0.0],
    ];
    let mut ctrl = ring.to_vec();
    ctrl.extend_from_slice(&ring[..3]);
    let knots: Vec<f64> = (0..12).map(f64::from).collect();
    d.spline("CUT", 8 | 2 | 1, 3, &knots, &ctrl, &[], &[], None);
    // Fit points only, with end tangents.
    d.spline(
        "CUT",
        8,
        3,
        &[],
        &[],
        &[],
        &[
            [0.0, 70.0, 0.0],
            [10.0, 80.0, 0.0],
            [25.0, 65.0, 0.0],
            [40.0, 75.0, 0.0],
        ],
        Some(([0.0, 1.0, 0.0], [1.0, 0.0, 0.0])),
    );
    // Fit points only, natural ends.
    d.spline(
        "CUT",
        8,
        3,
        &[],
        &[],
        &[],
        &[
            [60.0, 70.0, 0.0],
            [70.0, 78.0, 0.0],
            [85.0, 66.0, 0.0],
            [95.0, 72.0, 0.0],
            [100.0, 60.0, 0.0],
        ],
        None,
    );
    d.finish(4)
}

/// ELLIPSE: full, partial across the zero parameter, rotated, and mirrored (normal −Z).
fn ellipses() -> String {
    let mut d = Dxf::new();
    d.ellipse(
        "CUT",
        [20.0, 10.0, 0.0],
        [15.0, 0.0, 0.0],
        0.5,
        0.0,
        2.0 * std::f64::consts::PI,
        Z,
    );
    d.ellipse("CUT", [60.0, 10.0, 0.0], [0.0, 12.0, 0.0], 0.4, 5.0, 2.0, Z);
    d.ellipse(
        "CUT",
        [20.0, 50.0, 0.0],
        [8.0, 6.0, 0.0],
        0.3,
        0.0,
        2.0 * std::f64::consts::PI,
        Z,
    );
    d.ellipse(
        "CUT",
        [60.0, 50.0, 0.0],
        [10.0, 0.0, 0.0],
        0.6,
        0.0,
        std::f64::consts::PI,
        MINUS_Z,
    );
    // A circle written as an ellipse (ratio 1) stays an arc.
    d.ellipse(
        "CUT",
        [90.0, 10.0, 0.0],
        [5.0, 0.0, 0.0],
        1.0,
        0.0,
        2.0 * std::f64::consts::PI,
        Z,
    );
    d.text("NOTES", [0.0, -10.0, 0.0], "ellipses");
    d.finish(4)
}

fn entity(layer: &str, specific: EntityType) -> Entity {
    let mut e = Entity::new(specific);
    e.common.layer = layer.to_string();
    e
}

fn line(layer: &str, a: (f64, f64), b: (f64, f64)) -> Entity {
    entity(
        layer,
        EntityType::Line(Line::new(
            Point::new(a.0, a.1, 0.0),
            Point::new(b.0, b.1, 0.0),
        )),
    )
}

fn insert(layer: &str, name: &str, at: (f64, f64), scale: f64, rotation: f64) -> Entity {
    let mut ins = Insert {
        name: name.to_string(),
        location: Point::new(at.0, at.1, 0.0),
        rotation,
        ..Default::default()
    };
    ins.x_scale_factor = scale;
    ins.y_scale_factor = scale;
    ins.z_scale_factor = scale;
    entity(layer, EntityType::Insert(ins))
}

/// A drawing as a CAD program writes one: inch drawing, a millimetre block inserted into
/// an inch block inserted into model space (scaled, rotated), reversed entities, text,
/// a paper-space line.
fn cad_part() -> dxf::Drawing {
    let mut d = dxf::Drawing::new();
    d.header.version = AcadVersion::R2013;
    d.header.default_drawing_units = Units::Inches;
    for name in ["OUTLINE", "HOLES", "NOTES"] {
        d.add_layer(Layer {
            name: name.to_string(),
            ..Default::default()
        });
    }
    // Block in millimetres: a 6 mm diameter hole.
    let mut hole = Block {
        name: "HOLE_6MM".to_string(),
        base_point: Point::new(0.0, 0.0, 0.0),
        ..Default::default()
    };
    hole.entities.push(entity(
        "0",
        EntityType::Circle(Circle::new(Point::new(0.0, 0.0, 0.0), 3.0)),
    ));
    d.add_block(hole);
    // Block in inches: a 2 × 1 inch plate, base point at its centre, with two holes.
    let mut plate = Block {
        name: "PLATE".to_string(),
        base_point: Point::new(1.0, 0.5, 0.0),
        ..Default::default()
    };
    let mut outline = LwPolyline::default();
    for (x, y, b) in [
        (0.0, 0.0, 0.0),
        (2.0, 0.0, 0.0),
        (2.0, 1.0, 0.0),
        (0.0, 1.0, 0.0),
    ] {
        let v = LwPolylineVertex {
            x,
            y,
            bulge: b,
            ..Default::default()
        };
        outline.vertices.push(v);
    }
    outline.flags = 1;
    plate
        .entities
        .push(entity("OUTLINE", EntityType::LwPolyline(outline)));
    plate
        .entities
        .push(insert("HOLES", "HOLE_6MM", (0.5, 0.5), 1.0, 0.0));
    plate
        .entities
        .push(insert("HOLES", "HOLE_6MM", (1.5, 0.5), 1.0, 0.0));
    d.add_block(plate);
    // Adding a block adds its BLOCK_RECORD; give each its insertion units.
    for record in d.block_records_mut() {
        record.insertion_units = match record.name.as_str() {
            "HOLE_6MM" => Units::Millimeters,
            "PLATE" => Units::Inches,
            _ => record.insertion_units,
        };
    }

    // Model space: the plate placed at (3, 2), rotated 30°, scaled 1.5.
    d.add_entity(insert("0", "PLATE", (3.0, 2.0), 1.5, 30.0));
    // A triangle of lines drawn head to head, and an arc drawn against the chain.
    d.add_entity(line("OUTLINE", (6.0, 0.0), (5.0, 0.0)));
    d.add_entity(line("OUTLINE", (6.0, 0.0), (6.0, 1.0)));
    let mut arc = dxf::entities::Arc::new(Point::new(5.5, 1.0, 0.0), 0.5, 0.0, 180.0);
    arc.normal = dxf::Vector::z_axis();
    d.add_entity(entity("OUTLINE", EntityType::Arc(arc)));
    d.add_entity(line("OUTLINE", (5.0, 1.0), (5.0, 0.0)));
    // Notes: text that is not cut.
    let t = Text {
        value: "PART 42".to_string(),
        location: Point::new(0.0, -1.0, 0.0),
        text_height: 0.2,
        ..Default::default()
    };
    d.add_entity(entity("NOTES", EntityType::Text(t)));
    let m = MText {
        text: "ALL DIMENSIONS IN INCHES".to_string(),
        ..Default::default()
    };
    d.add_entity(entity("NOTES", EntityType::MText(m)));
    // A title-block line in paper space.
    let mut paper = line("NOTES", (0.0, 0.0), (10.0, 0.0));
    paper.common.is_in_paper_space = true;
    d.add_entity(paper);
    d
}

/// Replaces the time stamps and GUIDs of the header with fixed values.
fn pin_header(text: &str) -> String {
    let fixed = [
        ("$TDCREATE", "2460311.5"),
        ("$TDUCREATE", "2460311.5"),
        ("$TDUPDATE", "2460311.5"),
        ("$TDUUPDATE", "2460311.5"),
        ("$TDINDWG", "0.0"),
        ("$TDUSRTIMER", "0.0"),
        ("$FINGERPRINTGUID", "{5A1E0000-0000-0000-0000-000000000001}"),
        ("$VERSIONGUID", "{5A1E0000-0000-0000-0000-000000000002}"),
    ];
    let lines: Vec<&str> = text.split("\r\n").collect();
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let mut i = 0;
    while i + 3 < lines.len() {
        if lines[i].trim() == "9" {
            if let Some((_, v)) = fixed.iter().find(|(k, _)| *k == lines[i + 1].trim()) {
                out[i + 3] = v.to_string();
            }
        }
        i += 2;
    }
    out.join("\r\n")
}

fn write(path: &Path, contents: &[u8]) {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).expect("create directory");
    }
    std::fs::write(path, contents).expect("write file");
    println!("wrote {}", path.display());
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let samples = root.join("samples/dxf");
    let bad = root.join("crates/pvt-dxf/tests/bad");
    let lines = lines_arcs();
    write(&samples.join("lines_arcs.dxf"), lines.as_bytes());
    write(&samples.join("polylines.dxf"), polylines().as_bytes());
    write(&samples.join("splines.dxf"), splines().as_bytes());
    write(&samples.join("ellipses.dxf"), ellipses().as_bytes());
    // The writer stamps dates and GUIDs: pin them, then read the file back and write it
    // again so both the ASCII and the binary file are reproducible.
    let mut first = Vec::new();
    cad_part().save(&mut first).expect("save ASCII");
    let pinned = pin_header(&String::from_utf8(first).expect("ASCII DXF"));
    let cad = dxf::Drawing::load(&mut pinned.as_bytes()).expect("reload");
    let mut ascii = Vec::new();
    cad.save(&mut ascii).expect("save ASCII");
    let ascii = pin_header(&String::from_utf8(ascii).expect("ASCII DXF"));
    write(&samples.join("cad_part.dxf"), ascii.as_bytes());
    let cad = dxf::Drawing::load(&mut ascii.as_bytes()).expect("reload");
    let mut binary = Vec::new();
    cad.save_binary(&mut binary).expect("save binary");
    write(&samples.join("cad_part_binary.dxf"), &binary);

    // Bad files.
    let cut = lines.find("ARC").expect("an ARC") + 40;
    write(&bad.join("truncated.dxf"), &lines.as_bytes()[..cut]);
    write(
        &bad.join("wrong_group_codes.dxf"),
        lines.replacen(" 11\n", "1x\n", 1).as_bytes(),
    );
    write(&bad.join("empty.dxf"), Dxf::new().finish(4).as_bytes());
    let mut text = Dxf::new();
    text.text("NOTES", [0.0, 0.0, 0.0], "only text here");
    text.text("NOTES", [0.0, 5.0, 0.0], "and more");
    write(&bad.join("only_text.dxf"), text.finish(4).as_bytes());
    let mut nan = Dxf::new();
    nan.line("CUT", [0.0, 0.0, 0.0], [10.0, 0.0, 0.0]);
    nan.start("LINE", "CUT");
    nan.pair(10, "NaN");
    nan.pair(20, 0.0);
    nan.pair(11, 1.0);
    nan.pair(21, 1.0);
    nan.arc("CUT", [0.0, 0.0, 0.0], 0.0, 0.0, 90.0, Z);
    write(&bad.join("bad_geometry.dxf"), nan.finish(4).as_bytes());
}
