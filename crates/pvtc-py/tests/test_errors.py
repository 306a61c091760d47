"""Errors, warnings and bad options across the boundary: `CompileError` with the CLI's
codes and lines, warnings through Python's `warnings`, `ValueError`/`TypeError` naming
the option, and a Rust panic as `pvtc.InternalError`."""

import json
import warnings

import pytest

import pvtc
from conftest import ROOT, cli

BAD = "G21 G90\nG1 X1 Y1 F100\nG1 X2 Y\nG5 X3\nM2\n"


def cli_diagnostics(*args):
    status, _, err = cli(*args, "--diagnostics", "json", check=False)
    return status, [json.loads(line) for line in err.splitlines() if line.startswith("{")]


def test_errors_carry_the_cli_codes_and_lines(tmp_path):
    path = tmp_path / "bad.ngc"
    path.write_text(BAD)
    status, expected = cli_diagnostics("compile", path, "-o", tmp_path / "out.pmac")
    assert status == 1 and expected
    with pytest.raises(pvtc.CompileError) as error:
        pvtc.plan(path)
    got = error.value.diagnostics
    assert [(d.code, d.line, d.column) for d in got] == [
        (e["code"], e.get("line"), e.get("column")) for e in expected
    ]
    assert all(isinstance(d, pvtc.Diagnostic) and d.severity == "error" for d in got)
    assert got[0].path == str(path)
    assert got[0].message in str(error.value)
    assert not (tmp_path / "out.pmac").exists()


def test_text_errors_name_the_text():
    with pytest.raises(pvtc.CompileError) as error:
        pvtc.plan(pvtc.Text(BAD, name="part.ngc"))
    first = error.value.diagnostics[0]
    assert first.path == "part.ngc" and first.line == 3 and first.column is not None
    assert first.code.startswith("pvtc::gcode::")


def test_a_planning_error_names_its_line(tmp_path):
    path = tmp_path / "nofeed.ngc"
    path.write_text("G21 G90\nG1 X10 Y0\nM2\n")
    status, expected = cli_diagnostics("compile", path)
    with pytest.raises(pvtc.CompileError) as error:
        pvtc.plan(path)
    assert [(d.code, d.line) for d in error.value.diagnostics] == [
        (e["code"], e.get("line")) for e in expected
    ]


def test_warnings_go_through_python_warnings():
    name = "samples/gcode/an208_step.ngc"
    _, _, err = cli("compile", name, "--diagnostics", "json")
    expected = [json.loads(l) for l in err.splitlines() if l.startswith("{")]
    expected_warnings = [e for e in expected if e["severity"] == "warning"]
    assert expected_warnings, "the sample has a zero-length move"
    with pytest.warns(pvtc.PvtcWarning) as caught:
        program = pvtc.plan(name)
    ours = [w for w in caught if issubclass(w.category, pvtc.PvtcWarning)]
    assert [w.message.diagnostic.code for w in ours] == [e["code"] for e in expected_warnings]
    assert all(issubclass(w.category, pvtc.InputWarning) for w in ours)
    assert ours[0].filename == __file__  # at the caller's line
    notes = [d for d in program.diagnostics if d.severity == "advice"]
    assert [d.code for d in notes] == [e["code"] for e in expected if e["severity"] == "advice"]


def test_warnings_as_errors_fail_like_deny_warnings():
    name = "samples/gcode/an208_step.ngc"
    status, _, _ = cli("compile", name, "--deny-warnings", check=False)
    assert status == 1
    notes_only = "samples/gcode/square.ngc"
    assert cli("compile", notes_only, "--deny-warnings", check=False)[0] == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", pvtc.PvtcWarning)
        with pytest.raises(pvtc.InputWarning):
            pvtc.plan(name)
        # Notes never fail, as under --deny-warnings.
        program = pvtc.plan(notes_only)
    assert any(d.severity == "advice" for d in program.diagnostics)


@pytest.mark.parametrize(
    "options, error, word",
    [
        ({"tolerance": "fine"}, TypeError, "tolerance"),
        ({"tolerance": -1.0}, ValueError, "tolerance"),
        ({"quantize": 0.0}, ValueError, "quantize"),
        ({"planner": "fast"}, ValueError, "planner"),
        ({"accel": 100.0}, ValueError, "accel"),
        ({"tolernce": 0.01}, TypeError, "tolernce"),
        ({"start_point": (1.0,)}, ValueError, "start_point"),
        ({"feed": True}, TypeError, "feed"),
        ({"pmac_program": 3}, TypeError, "pmac_program"),
        ({"offsets": ROOT / "no-such-offsets.txt"}, FileNotFoundError, "no-such-offsets"),
    ],
)
def test_bad_options_name_the_option(options, error, word):
    with pytest.raises(error) as raised:
        pvtc.plan(ROOT / "samples/gcode/square.ngc", **options)
    assert word in str(raised.value)


def test_bad_write_options_name_the_option():
    program = pvtc.plan(ROOT / "samples/gcode/square.ngc")
    with pytest.raises(ValueError, match="pmac_program"):
        program.write("json", pmac_program=3)
    with pytest.raises(TypeError, match="tolerance"):
        program.write(tolerance=0.1)


def test_a_missing_file_is_an_os_error():
    with pytest.raises(FileNotFoundError):
        pvtc.plan(ROOT / "samples/gcode/missing.ngc")


def test_a_panic_is_an_internal_error():
    with pytest.raises(pvtc.InternalError, match="the boundary holds"):
        pvtc._panic_inside("the boundary holds")
    assert issubclass(pvtc.InternalError, pvtc.PvtcError)
    # The module still works after it.
    assert len(pvtc.plan(ROOT / "samples/gcode/square.ngc")) > 0
