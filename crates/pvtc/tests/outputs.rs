//! The command line's output conveniences: PMAC program settings and event commands,
//! shell completions, the manual page, and the plot's file formats.

mod common;

use common::{root, run as pvtc, text};

use std::process::Command;

#[test]
fn pmac_settings_write_the_coordinate_system_axes_and_program_number() {
    let o = pvtc(&[
        "compile",
        "samples/gcode/square.ngc",
        "--pmac-program",
        "20",
        "--pmac-coord",
        "2",
        "--pmac-axis",
        "#1->1000X",
        "--pmac-axis",
        "#2->1000Y",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let body: Vec<&str> = out.lines().filter(|l| !l.starts_with(';')).collect();
    assert_eq!(
        body[..5],
        ["&2", "#1->1000X", "#2->1000Y", "OPEN PROG 20 CLEAR", "ABS"]
    );
    // Without them the program is the golden file, byte for byte.
    let plain = pvtc(&["compile", "samples/gcode/square.ngc"]);
    let golden = std::fs::read(root().join("tests/golden/gcode/square.pmac")).unwrap();
    assert_eq!(plain.stdout, golden);
}

#[test]
fn pmac_settings_that_cannot_work_are_refused() {
    let usage = [
        &["--format", "json", "--pmac-program", "3"][..],
        &["--format", "movepvt", "--pmac-events", "commands"],
        &["--format", "toolpath", "--pmac-coord", "1"],
        &["--pmac-program", "1001"],
        &["--pmac-program", "0"],
        &["--pmac-program", "40000"],
        &["--pmac-coord", "17"],
        &["--pmac-axis", "#1->1000X"],
        &["--pmac-coord", "1", "--pmac-axis", "#1->X"],
        &["--pmac-coord", "1", "--pmac-axis", "#1->1000.X"],
        &["--pmac-coord", "1", "--pmac-axis", "#1->0X"],
        &["--pmac-coord", "1", "--pmac-axis", "1->1000X"],
        &["--pmac-coord", "1", "--pmac-axis", "#33->1000X"],
        &[
            "--pmac-coord",
            "1",
            "--pmac-axis",
            "#1->1000X",
            "--pmac-axis",
            "#2->1000X",
        ],
        &[
            "--pmac-coord",
            "1",
            "--pmac-axis",
            "#1->1000X",
            "--pmac-axis",
            "#1->1000Y",
        ],
    ];
    for extra in usage {
        let mut args = vec!["compile", "samples/gcode/square.ngc"];
        args.extend_from_slice(extra);
        let o = pvtc(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o.stderr));
        assert!(o.stdout.is_empty(), "{extra:?}");
    }
    // The square moves X and Y: defining only X would leave Y unmoved on the controller.
    let o = pvtc(&[
        "compile",
        "samples/gcode/square.ngc",
        "--pmac-coord",
        "1",
        "--pmac-axis",
        "#1->1000X",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("pvtc::pmac::undefined_axis") && err.contains("moves Y"),
        "{err}"
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn man_page_renders_and_names_every_subcommand_and_option() {
    let o = pvtc(&["man"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let page = text(&o.stdout);
    assert!(
        page.starts_with(".ie") || page.contains(".TH pvtc 1"),
        "{page}"
    );
    assert_eq!(page.as_bytes(), pvtc::man_page_text());
    // One page: no pointer to a `pvtc-compile(1)` page that does not exist.
    assert!(!page.contains("(1)"), "{page}");
    assert!(page.contains("(see PVTC COMPILE below)"), "{page}");
    for (name, longs) in common::long_options() {
        assert!(
            page.contains(&format!(".SH \"PVTC {}\"", name.to_uppercase())),
            "no section for {name}"
        );
        for long in longs {
            // roff escapes the dashes of option names.
            let escaped = long.replace('-', "\\-");
            assert!(
                page.contains(&escaped) || page.contains(&long),
                "{name} {long} is missing from the man page"
            );
        }
    }
    // When man(1) is installed, it formats the page without a warning.
    let file = std::env::temp_dir().join(format!("pvtc-man-{}.1", std::process::id()));
    std::fs::write(&file, &o.stdout).unwrap();
    if let Ok(man) = Command::new("man")
        .arg("-l")
        .arg(&file)
        .env("MANWIDTH", "100")
        .output()
    {
        if man.status.success() {
            assert!(man.stderr.is_empty(), "man warns: {}", text(&man.stderr));
            // Drop the overstrike bold (`N\x08N`) man prints into a pipe.
            let mut shown = String::new();
            for c in text(&man.stdout).chars() {
                if c == '\x08' {
                    shown.pop();
                } else {
                    shown.push(c);
                }
            }
            assert!(
                shown.contains("PVTC COMPILE") && shown.contains("pmac"),
                "{shown}"
            );
        } else {
            eprintln!("SKIPPED: man -l failed here: {}", text(&man.stderr));
        }
    } else {
        eprintln!("SKIPPED: no man(1) on this machine to format the page");
    }
    let _ = std::fs::remove_file(file);
}

#[test]
fn completions_cover_every_subcommand_in_each_shell() {
    for shell in ["bash", "zsh", "fish"] {
        let o = pvtc(&["completions", shell]);
        assert!(o.status.success(), "{shell}: {}", text(&o.stderr));
        let script = text(&o.stdout);
        for (name, longs) in common::long_options() {
            assert!(script.contains(&name), "{shell}: no {name}");
            for long in longs {
                let bare = long.trim_start_matches('-');
                assert!(script.contains(bare), "{shell}: no {long} of {name}");
            }
        }
        if shell == "bash" {
            // The script parses in bash where bash is installed.
            match Command::new("bash")
                .arg("-n")
                .arg("-c")
                .arg(&script)
                .output()
            {
                Ok(check) => assert!(check.status.success(), "{}", text(&check.stderr)),
                Err(_) => eprintln!("SKIPPED: no bash here to parse the bash script"),
            }
        }
    }
    let o = pvtc(&["completions", "tcsh"]);
    assert_eq!(o.status.code(), Some(2));
}

/// `plot -o part.png` writes a PNG image (it used to be refused), `.svg` an SVG; the
/// programmed path of a G-code file with arcs is drawn under the motion.
#[test]
fn plot_writes_png_for_png_and_svg_for_svg() {
    let dir = std::env::temp_dir().join(format!("pvtc-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("part.png");
    let svg = dir.join("part.svg");
    for out in [&png, &svg] {
        let o = pvtc(&[
            "plot",
            "samples/gcode/grbl_r_arcs.ngc",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, at bytes 16..24.
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (1000, 1500));
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.starts_with("<svg"));
    assert!(
        svg_text.contains("stroke=\"#C8C8C8\" stroke-width=\"6\""),
        "no programmed path"
    );
    assert!(
        svg_text.contains("against time (the third axis)"),
        "grbl_r_arcs moves Z"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
