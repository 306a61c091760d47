//! O-word control flow and machine parameters: what runs, what is refused and where the
//! diagnostics point (the moves themselves are compared with rs274 in
//! `crates/pvtc/tests/dialect.rs`).

mod common;

use std::collections::HashMap;
use std::sync::Arc;

use common::errors;
use pvt_gcode::{
    compile, line_col, GcodeOptions, SubroutineFile, SubroutineFiles, Subroutines,
    MAX_BUFFERED_BYTES, MAX_CALL_DEPTH, MAX_LOOP_ITERATIONS,
};

/// The end points (X, Y, Z) and source lines of a program's elements.
fn ends(source: &str, options: &GcodeOptions) -> Vec<([f64; 3], u32)> {
    let compiled = compile(source, options).unwrap_or_else(|e| {
        panic!(
            "{:?}",
            e.diagnostics
                .iter()
                .map(|d| common::diagnostic_line(source, d))
                .collect::<Vec<_>>()
        )
    });
    compiled
        .toolpath
        .contours
        .iter()
        .flat_map(|c| &c.elements)
        .map(|e| ([e.end[0], e.end[1], e.end[2]], e.span.line))
        .collect()
}

fn xs(source: &str) -> Vec<f64> {
    ends(source, &GcodeOptions::default())
        .iter()
        .map(|(p, _)| p[0])
        .collect()
}

#[test]
fn a_subroutine_body_runs_only_when_called() {
    let source = "o100 sub\nG1 X5 F100\no100 endsub\nG1 X1 F100\nM2\n";
    assert_eq!(xs(source), [1.0]);
    let called = "o100 sub\nG1 X[#1 + 5] F100\no100 endsub\nG1 X1 F100\no100 call [2]\nM2\n";
    assert_eq!(
        ends(called, &GcodeOptions::default()),
        [([1.0, 0.0, 0.0], 4), ([7.0, 0.0, 0.0], 2)]
    );
}

#[test]
fn loops_and_conditionals_count_as_rs274_does() {
    // 0, 1, 2 skipping 1 by continue; break at 4.
    let source = "F100\n#1 = 0\no1 while [#1 LT 10]\n#1 = [#1 + 1]\no2 if [#1 EQ 2]\no1 continue\no2 endif\no3 if [#1 EQ 5]\no1 break\no3 endif\nG1 X#1\no1 endwhile\nM2\n";
    assert_eq!(xs(source), [1.0, 3.0, 4.0]);
    let repeat = "F100\n#1 = 0\no1 repeat [3]\n#1 = [#1 + 2]\nG1 X#1\no1 endrepeat\nM2\n";
    assert_eq!(xs(repeat), [2.0, 4.0, 6.0]);
    let do_while = "F100\n#1 = 5\no1 do\nG1 X#1\n#1 = [#1 + 1]\no1 while [#1 LT 3]\nM2\n";
    assert_eq!(xs(do_while), [5.0]);
}

#[test]
fn an_endless_loop_is_an_error_at_its_o_word_not_a_hang() {
    let source = "G1 X1 F100\n#1 = 0\n  o7 while [1]\n#1 = [#1 + 1]\no7 endwhile\nM2\n";
    assert_eq!(errors(source), [("loop_limit", 3, 3)]);
    // The limit counts iterations: one fewer is fine.
    let below = format!(
        "G1 X1 F100\n#1 = 0\no7 while [#1 LT {}]\n#1 = [#1 + 1]\no7 endwhile\nG1 X#1\nM2\n",
        MAX_LOOP_ITERATIONS
    );
    assert_eq!(xs(&below), [1.0, MAX_LOOP_ITERATIONS as f64]);
}

#[test]
fn runaway_recursion_is_an_error_at_the_call_that_goes_too_deep() {
    let source =
        "G1 X1 F100\no<down> sub\no<down> call [#1 + 1]\no<down> endsub\no<down> call [1]\n";
    assert_eq!(errors(source), [("recursion_limit", 3, 1)]);
    // LinuxCNC's depth: 9 nested calls run, a tenth is refused.
    let depth = |n: usize| {
        format!(
            "o<d> sub\no1 if [#1 LT {n}]\no<d> call [#1 + 1]\no1 endif\nG1 X#1 F100\no<d> endsub\no<d> call [1]\n"
        )
    };
    assert_eq!(xs(&depth(MAX_CALL_DEPTH))[0], MAX_CALL_DEPTH as f64);
    assert_eq!(
        errors(&depth(MAX_CALL_DEPTH + 1)),
        [("recursion_limit", 3, 1)]
    );
}

#[test]
fn errors_in_a_body_name_the_bodys_line() {
    let source = "G1 X1 F100\no1 sub\n  G1 X[1/0]\no1 endsub\no1 call\n#1 = 0\no2 while [#1 LT 2]\n#1 = [#1 + 1]\nG1 E1\no2 endwhile\n";
    let found = errors(source);
    // Each once, though the loop runs the bad line twice.
    assert_eq!(found, [("math_error", 3, 9), ("unknown_word", 9, 4)]);
}

#[test]
fn constructs_without_their_end_and_bad_keywords_are_errors() {
    assert_eq!(
        errors("G1 X1 F100\no1 while [1]\nG1 X2\n"),
        [("oword", 2, 1)]
    );
    assert_eq!(errors("G1 X1 F100\no1 goto\n"), [("oword", 2, 1)]);
    assert_eq!(errors("G1 X1 F100\no1 break\n"), [("oword", 2, 1)]);
    assert_eq!(errors("G1 X1 F100\no1 if\no1 endif\n"), [("oword", 2, 1)]);
    assert_eq!(
        errors("G1 X1 F100\no<nowhere> call\n"),
        [("unknown_subroutine", 2, 1)]
    );
}

#[test]
fn a_program_end_inside_a_subroutine_ends_the_program() {
    let source = "o1 sub\nG1 X2 F100\nM2\no1 endsub\nG1 X1 F100\no1 call\nG1 X9\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap();
    assert_eq!(xs(source), [1.0, 2.0]);
    let warnings: Vec<_> = compiled.warnings.iter().map(|w| w.code()).collect();
    assert_eq!(warnings, ["pvtc::gcode::after_program_end"]);
}

#[test]
fn bodies_held_past_the_limit_are_an_error() {
    let line = "G1 X1 Y2 Z3 (a line of a long subroutine body)\n";
    let mut source = String::from("G1 X1 F100\no1 sub\n");
    for _ in 0..MAX_BUFFERED_BYTES / (line.len() - 1) + 1 {
        source.push_str(line);
    }
    source.push_str("o1 endsub\n");
    assert_eq!(errors(&source), [("body_too_large", 2, 1)]);
}

#[test]
fn machine_parameters_read_the_interpreters_state() {
    // #5420 is the position (no longer out of range), #5220 the coordinate system.
    let source = "G21 G1 X3 Y4 F100\nG56\nG1 X#5420 Y#5220 Z[#<_x> + #<_metric>]\nG20\nG1 X[#5420 * 25.4]\nM2\n";
    let got = ends(source, &GcodeOptions::default());
    assert_eq!(got[1].0, [3.0, 3.0, 4.0]);
    // Under G20 the position reads in inches: 3 mm back to 3 mm.
    assert!((got[2].0[0] - 3.0 * 25.4).abs() < 1e-9, "{got:?}");
    // A work offset reads in millimetres.
    let mut options = GcodeOptions::default();
    options.work_offsets[1] = [10.0, 20.0, 0.0, 0.0, 0.0, 0.0];
    let offsets = "G1 X#5241 Y#5242 F100\nM2\n";
    assert_eq!(ends(offsets, &options)[0].0, [10.0, 20.0, 0.0]);
}

#[test]
fn machine_only_parameters_are_one_unsupported_diagnostic_each() {
    let source = "G1 X1 F100\nG1 X#5061\nG1 Y#5062\nG1 Z#<_hal[probe]>\nG1 X#<_hal[x]>\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap_err();
    let messages: Vec<_> = compiled
        .diagnostics
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        messages,
        [
            "#5061 (probe results (#5061–#5070)) is not supported by pvtc (2 places; the first is shown)",
            "#<_hal[probe]> (HAL pins (#<_hal[…]>) without --hal NAME=VALUE) is not supported by pvtc (2 places; the first is shown)"
        ]
    );
}

/// Subroutine files from memory.
struct Files(HashMap<&'static str, &'static str>);

impl SubroutineFiles for Files {
    fn read(&self, name: &str) -> Result<Option<SubroutineFile>, String> {
        Ok(self.0.get(name).map(|text| SubroutineFile {
            name: format!("lib/{name}.ngc"),
            text: (*text).to_owned(),
        }))
    }

    fn describe(&self) -> String {
        "lib".to_owned()
    }
}

fn with_files(files: &[(&'static str, &'static str)]) -> GcodeOptions {
    GcodeOptions {
        subroutines: Subroutines(Some(Arc::new(Files(files.iter().copied().collect())))),
        ..GcodeOptions::default()
    }
}

#[test]
fn named_subroutines_come_from_files_and_their_errors_name_file_line_and_call() {
    let options = with_files(&[
        (
            "step",
            "(steps)\no<step> sub\nG91 G1 X#1 F100\nG90\no<step> endsub [#1 * 2]\n",
        ),
        (
            "bad",
            "o<bad> sub\nG1 X1\n  G1 X[SQRT[-1]]\no<bad> endsub\n",
        ),
    ]);
    let source = "G1 X1 F100\no<step> call [2]\no<step> call [#<_value>]\nM2\n";
    // Elements from a file carry the line of the call.
    assert_eq!(
        ends(source, &options),
        [
            ([1.0, 0.0, 0.0], 1),
            ([3.0, 0.0, 0.0], 2),
            ([7.0, 0.0, 0.0], 3)
        ]
    );
    let source = "G1 X1 F100\n  o<bad> call\n";
    let errors = compile(source, &options).unwrap_err();
    let d = &errors.diagnostics[0];
    assert_eq!(d.code(), "pvtc::gcode::in_subroutine_file");
    assert_eq!(line_col(source, d.span().start), (2, 3));
    let message = d.to_string();
    assert!(
        message.starts_with("in lib/bad.ngc line 3 column 8"),
        "{message}"
    );
    assert!(message.contains("SQRT"), "{message}");
    // A file without the definition, and no file at all.
    let options = with_files(&[("empty", "G1 X1\n")]);
    let errors = compile("G1 X1 F100\no<empty> call\no<none> call\n", &options).unwrap_err();
    let messages: Vec<_> = errors.diagnostics.iter().map(ToString::to_string).collect();
    assert_eq!(
        messages,
        [
            "no subroutine <empty> (lib/empty.ngc has no o<empty> sub … o<empty> endsub)",
            "no subroutine <none> (not defined in this file; no none.ngc in lib)"
        ]
    );
}

#[test]
fn a_streamed_loop_holds_only_its_body() {
    // The main program streams around a loop: compile_read gives what compile gives.
    let source = "G1 X1 F100\n#1 = 0\no1 while [#1 LT 3]\n#1 = [#1 + 1]\nG1 Y#1\no1 endwhile\nM2\n";
    let mut sink = Count(0);
    let summary =
        pvt_gcode::compile_read(&mut source.as_bytes(), &GcodeOptions::default(), &mut sink)
            .unwrap()
            .unwrap();
    assert!(summary.warnings.is_empty());
    assert_eq!(sink.0, 4);
}

struct Count(usize);

impl pvt_gcode::ToolpathSink for Count {
    fn element(&mut self, _: pvt_core::Motion, _: &pvt_core::Element) {
        self.0 += 1;
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &pvt_core::EventKind, _: u32) {}
}

#[test]
fn fanuc_subprograms_after_the_end_are_called_with_m98_p_l() {
    let source = "O0001\nF100\nG1 X1\nM98 P1000 L2\nG1 Y5\nM98 P1000\nM30\nO1000 (step)\nG91 G1 X1\nG90\nM99\n%\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap();
    assert!(compiled.warnings.is_empty(), "{:?}", compiled.warnings);
    // The held line 5 runs after the call, with its own line number.
    assert_eq!(
        ends(source, &GcodeOptions::default()),
        [
            ([1.0, 0.0, 0.0], 3),
            ([2.0, 0.0, 0.0], 9),
            ([3.0, 0.0, 0.0], 9),
            ([3.0, 5.0, 0.0], 5),
            ([4.0, 5.0, 0.0], 9)
        ]
    );
    assert_eq!(
        errors("G1 X1 F100\nM98 P7\nG1 X2\nM30\n"),
        [("unknown_subroutine", 2, 1)]
    );
    assert_eq!(errors("G1 X1 F100\nM99\n"), [("oword", 2, 1)]);
    assert_eq!(errors("G1 X1 F100\nM98 L2\n"), [("missing_word", 2, 1)]);
}

#[test]
fn nested_loops_stop_at_the_total_iteration_limit() {
    // 10^6 × 10^3 iterations: each loop is within its own limit, together they are not
    // (empty bodies, so that the test is quick).
    let source = "G1 X1 F100\no1 repeat [1000000]\no2 repeat [1000]\no2 endrepeat\no1 endrepeat\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap_err();
    let messages: Vec<_> = compiled
        .diagnostics
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        messages,
        [format!(
            "loops ran {} times in all",
            pvt_gcode::MAX_TOTAL_ITERATIONS
        )]
    );
}

#[test]
fn a_subroutine_defined_after_its_call_is_found_further_on() {
    // The lines between the call and the definition are held, then run after the call.
    let source = "F100\no1 call [2]\nG1 Y1\nM2\no1 sub\nG1 X#1\no1 endsub\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap();
    assert!(compiled.warnings.is_empty(), "{:?}", compiled.warnings);
    assert_eq!(
        ends(source, &GcodeOptions::default()),
        [([2.0, 0.0, 0.0], 6), ([2.0, 1.0, 0.0], 3)]
    );
    // Called from a loop, it must come first: a body cannot wait.
    let in_loop = "F100\no2 repeat [2]\no1 call\no2 endrepeat\no1 sub\nG1 X1\no1 endsub\n";
    assert_eq!(errors(in_loop), [("unknown_subroutine", 3, 1)]);
}

#[test]
fn predefined_parameters_are_read_only() {
    assert_eq!(errors("G1 X1 F100\n#<_x> = 5\n"), [("bad_value", 2, 1)]);
    assert_eq!(
        errors("G1 X1 F100\n  #<_value> = 5\n"),
        [("bad_value", 2, 3)]
    );
    // A global of the program's own may be assigned.
    assert_eq!(xs("#<_mine> = 5\nG1 X#<_mine> F100\n"), [5.0]);
}

#[test]
fn calls_before_definitions_nest_in_bounded_depth() {
    // o1 call, o2 call, …, o40 call, then the definitions from o40 down to o1: each
    // search finds its definition inside the lines an outer search held.
    let n = 40;
    let mut source = String::from("G1 X1 F100\n");
    for i in 1..=n {
        source.push_str(&format!("o{i} call\n"));
    }
    for i in (1..=n).rev() {
        source.push_str(&format!("o{i} sub\nG1 X{i}\no{i} endsub\n"));
    }
    let found = errors(&source);
    assert!(!found.is_empty());
    assert!(
        found
            .iter()
            .all(|(code, _, _)| *code == "unknown_subroutine"),
        "{found:?}"
    );
}
