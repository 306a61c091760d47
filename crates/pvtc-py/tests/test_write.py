"""`Program.write` against the bytes `pvtc compile` writes: every format, from a program
planned for that format (its pieces written) and from one planned for another (planned
again as the CLI plans it), with the output options."""

import pytest

import pvtc
from conftest import ROOT, cli

COUNTS = {"X": 1000, "Y": 1000, "Z": 1000}
FORMATS = ["pmac", "movepvt", "json", "xps", "galil", "zaber", "powerpmac", "csv"]


def cli_bytes(name, fmt, *args):
    scale = [w for a, c in COUNTS.items() for w in ("--counts-per-unit", f"{a}={c}")]
    extra = scale if fmt in ("galil", "zaber") else []
    return cli("compile", name, "--format", fmt, *extra, *args)[1]


def options(fmt):
    return {"counts_per_unit": COUNTS} if fmt in ("galil", "zaber") else {}


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize(
    "name", ["samples/gcode/square.ngc", "samples/gcode/linuxcnc_helix.ngc", "samples/csv/an208_zigzag.csv"]
)
def test_planned_for_the_format(name, fmt):
    if name.endswith(".csv") and fmt in ("galil", "zaber"):
        pytest.skip("the series is in counts already")
    program = pvtc.plan(name, format=fmt, **options(fmt))
    assert program.write().encode() == cli_bytes(name, fmt)


@pytest.mark.parametrize("fmt", ["json", "xps", "csv", "movepvt"])
def test_planned_for_another_format(fmt):
    name = "samples/gcode/linuxcnc_planes.ngc"
    program = pvtc.plan(name)  # planned for pmac's 1 ms grid
    assert program.write(fmt).encode() == cli_bytes(name, fmt)


def test_text_source_writes_as_the_file_does():
    name = "samples/gcode/fanuc_post_dwell_checksum.ngc"
    text = (ROOT / name).read_text()
    program = pvtc.plan(pvtc.Text(text, name=name))
    assert program.write().encode() == cli_bytes(name, "pmac")
    assert program.write("json").encode() == cli_bytes(name, "json")


def test_output_options():
    name = "samples/gcode/square.ngc"
    program = pvtc.plan(name)
    got = program.write(pmac_program=7, pmac_coord=2, pmac_axis=["#1->1000X", "#2->1000Y"], pmac_events="commands")
    want = cli_bytes(
        name, "pmac", "--pmac-program", "7", "--pmac-coord", "2",
        "--pmac-axis", "#1->1000X", "--pmac-axis", "#2->1000Y", "--pmac-events", "commands",
    )
    assert got.encode() == want
    json_program = pvtc.plan(name, format="json")
    assert json_program.write(trigger_every="5mm").encode() == cli_bytes(name, "json", "--trigger-every", "5mm")
    assert json_program.write(trigger_every=0.05).encode() == cli_bytes(name, "json", "--trigger-every", "50ms")


def test_write_into_a_file(tmp_path):
    name = "samples/gcode/an208_step.ngc"
    out = tmp_path / "out.pmac"
    assert pvtc.plan(name).write(path=out) is None
    assert out.read_bytes() == cli_bytes(name, "pmac")


def test_a_format_refusal_is_a_compile_error():
    program = pvtc.plan(ROOT / "samples/gcode/square.ngc")
    with pytest.raises(pvtc.CompileError) as refused:
        program.write("galil")
    assert refused.value.diagnostics[0].code == "pvtc::emit::no_scale"
    with pytest.raises(pvtc.CompileError) as undefined:
        program.write(pmac_coord=1, pmac_axis=["#1->1000X"])
    assert undefined.value.diagnostics[0].code == "pvtc::pmac::undefined_axis"
