//! G-code parser + interpreter + planner + every back end: no input may panic, and
//! whatever compiles must plan into finite, positive-time pieces. The streaming reader
//! (`compile_read`, fed in small chunks) must find exactly what the in-memory compile
//! finds, and the prescan must read anything.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pvt_core::{plan_toolpath, Element, EventKind, Motion, PlanOptions};
use pvt_emit::{emit_to_vec, AxisSetup, EmitOptions, Format, InvalidProgram, StreamError};

#[derive(Default)]
struct Count(usize);

impl pvt_gcode::ToolpathSink for Count {
    fn element(&mut self, _: Motion, _: &Element) {
        self.0 += 1;
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &EventKind, _: u32) {}
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let options = pvt_gcode::GcodeOptions::default();
    let compiled = pvt_gcode::compile(&text, &options);
    let chunk = 1 + data.len() % 61;
    let mut input = std::io::BufReader::with_capacity(chunk, text.as_bytes());
    let mut count = Count::default();
    let streamed = pvt_gcode::compile_read(&mut input, &options, &mut count).expect("in memory");
    let _ = pvt_gcode::prescan(&mut text.as_bytes());
    let compiled = match (compiled, streamed) {
        (Ok(compiled), Ok(summary)) => {
            assert_eq!(compiled.warnings, summary.warnings);
            let elements = compiled.toolpath.contours.iter().map(|c| c.elements.len());
            assert_eq!(elements.sum::<usize>(), count.0);
            compiled
        }
        (Err(a), Err(b)) => {
            assert_eq!(a, b);
            return;
        }
        (a, b) => panic!("in memory {:?}, streamed {:?}", a.is_ok(), b.is_ok()),
    };
    let Ok(program) = plan_toolpath(&compiled.toolpath, &PlanOptions::default()) else {
        return;
    };
    // Formats written in counts get 1000 per unit on every axis.
    let setup = AxisSetup {
        counts_per_unit: Some(1000.0),
        ..AxisSetup::default()
    };
    let options = EmitOptions {
        axes: pvt_core::Axis::ALL.iter().map(|a| (*a, setup)).collect(),
        ..EmitOptions::default()
    };
    for format in Format::ALL {
        // A program the planner produced must always pass the back ends' validation; it
        // is planned without the format's grid, so a controller rule may refuse it, with
        // the rule's own code.
        match emit_to_vec(&program, format, &options) {
            Ok(_) => {}
            Err(StreamError::Invalid(e)) if e.code != InvalidProgram::CODE => {}
            Err(e) => panic!("planned programs are valid: {e}"),
        }
    }
});
