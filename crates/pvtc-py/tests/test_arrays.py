"""Every array of `pvtc.plan` against the CLI's JSON program, for the shipped samples,
planners and inputs: the same pieces, bit for bit."""

import pathlib

import numpy as np
import pytest

import pvtc
from conftest import ROOT, assert_same_arrays, cli, cli_json

GCODE = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "samples/gcode").glob("*.ngc"))
DXF = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "samples/dxf").glob("*.dxf"))
CSV = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "samples/csv").glob("*.csv"))


def plan(name, **options):
    return pvtc.plan(ROOT / name, **options)


@pytest.mark.parametrize("name", GCODE)
@pytest.mark.parametrize("planner", ["path", "contour"])
def test_gcode_samples(name, planner):
    expected = cli_json(name, "--planner", planner)
    assert_same_arrays(plan(name, planner=planner, format="json"), expected)


@pytest.mark.parametrize(
    "planner, extra",
    [
        ("pt", {}),
        ("chord-forward", {}),
        ("chord-back", {}),
        ("const-accel", {}),
        ("spline", {}),
        ("lspb", {"accel": 2000}),
    ],
)
@pytest.mark.parametrize("name", ["samples/gcode/square.ngc", "samples/gcode/an208_octagon.ngc"])
def test_time_planners(name, planner, extra):
    args = ["--planner", planner] + [w for k, v in extra.items() for w in (f"--{k}", str(v))]
    expected = cli_json(name, *args)
    assert_same_arrays(plan(name, planner=planner, format="json", **extra), expected)


@pytest.mark.parametrize("name", DXF)
def test_drawings(name):
    expected = cli_json(name, "--feed", "1200")
    assert_same_arrays(plan(name, feed=1200, format="json"), expected)


@pytest.mark.parametrize("name", CSV)
@pytest.mark.parametrize("planner", ["spline", "pt", "chord-back"])
def test_series(name, planner):
    expected = cli_json(name, "--planner", planner)
    assert_same_arrays(plan(name, planner=planner, format="json"), expected)


def test_machine_limits_and_quantum():
    name = "samples/gcode/linuxcnc_helix.ngc"
    machine = ROOT / "samples/machines/mill.toml"
    expected = cli_json(name, "--machine", machine, "--quantize", "1ms")
    assert_same_arrays(plan(name, machine=machine, quantize=0.001, format="json"), expected)


def test_machine_as_a_dict_is_the_file():
    machine = ROOT / "samples/machines/mill.toml"
    linear = {"max_velocity": 100.0, "max_acceleration": 1000.0, "max_jerk": 50000.0}
    rotary = {"max_velocity": 360.0, "max_acceleration": 3600.0}
    shape = {
        "units": "mm",
        "servo_period": 0.0005,
        "axes": {
            "X": linear,
            "Y": linear,
            "Z": {"max_velocity": 50.0, "max_acceleration": 500.0},
            **{a: rotary for a in "ABC"},
        },
    }
    name = "samples/gcode/square.ngc"
    from_file = plan(name, machine=machine, format="json")
    from_dict = plan(name, machine=shape, format="json")
    for field in ("t", "p", "v"):
        assert np.array_equal(getattr(from_file, field), getattr(from_dict, field))


def test_the_default_format_plans_as_pmac_does():
    name = "samples/gcode/square.ngc"
    expected = cli_json(name, "--quantize", "1ms")
    program = plan(name)
    assert program.format == "pmac"
    assert_same_arrays(program, expected)


def test_text_and_pathlike_sources():
    name = "samples/gcode/square.ngc"
    text = (ROOT / name).read_text()
    from_path = pvtc.plan(pathlib.Path(ROOT / name), format="json")
    from_text = pvtc.plan(pvtc.Text(text, kind="gcode", name=name), format="json")
    for field in ("t", "p", "v", "line"):
        assert np.array_equal(getattr(from_path, field), getattr(from_text, field))


def test_arrays_are_read_only_and_shaped():
    program = plan("samples/gcode/square.ngc", format="json")
    n = len(program)
    assert program.t.shape == (n,)
    assert program.p.shape == (n, len(program.axes))
    assert program.v.dtype == np.float64 and program.line.dtype == np.uint32
    with pytest.raises(ValueError):
        program.t[0] = 1.0
    assert program.total_time == pytest.approx(float(np.sum(program.t)), rel=1e-12)
