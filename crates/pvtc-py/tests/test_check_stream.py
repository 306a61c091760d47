"""`pvtc.check` against `pvtc check --json`, `Program.sample` against an independent
evaluation of the cubics, and `pvtc.stream`'s chunks: continuous, bounded, and the
whole program when put together."""

import json
import time

import numpy as np
import pytest

import pvtc
from conftest import ROOT, cli

MILL = ROOT / "samples/machines/mill.toml"


@pytest.mark.parametrize(
    "name, args",
    [
        ("samples/gcode/square.ngc", []),
        ("samples/gcode/linuxcnc_helix.ngc", ["--machine", MILL]),
        ("samples/gcode/an208_octagon.ngc", ["--planner", "contour", "--machine", MILL]),
        ("samples/csv/an208_zigzag.csv", []),
        ("samples/dxf/lines_arcs.dxf", ["--feed", "1200", "--machine", MILL]),
    ],
)
def test_check_is_pvtc_check_json(name, args):
    _, out, _ = cli("check", name, "--json", *args, check=False)
    expected = json.loads(out)
    machine = args[args.index("--machine") + 1] if "--machine" in args else None
    options = {}
    if "--planner" in args:
        options["planner"] = args[args.index("--planner") + 1]
    if "--feed" in args:
        options["feed"] = float(args[args.index("--feed") + 1])
    report = pvtc.check(ROOT / name, machine=machine, **options)
    assert report.as_dict() == expected
    assert report.exceeded == expected["exceeded"]
    assert report.total_time == expected["total_time"]
    for axis, peaks in expected["peaks"].items():
        assert report.peaks[axis]["velocity"].value == peaks["velocity"]
        assert report.peaks[axis]["velocity"].line == peaks["at"]["velocity"]["line"]
    assert len(report.violations) == len(expected["violations"])


def test_check_a_program_and_the_piece_of_a_peak():
    name = "samples/gcode/linuxcnc_helix.ngc"
    _, out, _ = cli("check", name, "--json", "--servo-period", "1ms")
    expected = json.loads(out)
    program = pvtc.plan(ROOT / name, format="json")
    report = pvtc.check(program, servo_period=0.001)
    assert report.as_dict() == expected
    starts = np.concatenate(([0.0], np.cumsum(program.t)[:-1]))
    for axis in program.axes:
        peak = report.peaks[axis]["acceleration"]
        assert starts[peak.piece] <= peak.time
        assert peak.piece == len(program) - 1 or peak.time <= starts[peak.piece + 1]
        assert program.line[peak.piece] == peak.line


def test_check_finds_a_limit_exceeded():
    program = pvtc.plan(ROOT / "samples/gcode/square.ngc", planner="contour")
    slow = {"units": "mm", "axes": {a: {"max_velocity": 1.0, "max_acceleration": 1.0} for a in "XYZ"}}
    report = pvtc.check(program, machine=slow)
    assert report.exceeded and report.violations
    v = report.violations[0]
    assert v.value > v.limit and v.quantity in ("velocity", "acceleration")


def hermite(p0, v0, p1, v1, T, s):
    """The cubic through (p0, v0) at 0 and (p1, v1) at T, at s: position, velocity,
    acceleration, from the Hermite basis (written here, not pvtc's)."""
    u = s / T
    h00, h10, h01, h11 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2
    d00, d10, d01, d11 = 6 * u**2 - 6 * u, 3 * u**2 - 4 * u + 1, -6 * u**2 + 6 * u, 3 * u**2 - 2 * u
    a00, a10, a01, a11 = 12 * u - 6, 6 * u - 4, -12 * u + 6, 6 * u - 2
    p = h00 * p0 + h10 * T * v0 + h01 * p1 + h11 * T * v1
    v = (d00 * p0 + d10 * T * v0 + d01 * p1 + d11 * T * v1) / T
    a = (a00 * p0 + a10 * T * v0 + a01 * p1 + a11 * T * v1) / T**2
    return p, v, a


def test_sample_evaluates_the_controllers_cubics():
    program = pvtc.plan(ROOT / "samples/gcode/linuxcnc_helix.ngc", format="json")
    period = 0.0005
    time_, position, velocity, acceleration = program.sample(period)
    n = len(time_)
    assert np.array_equal(time_, np.arange(n) * period)
    assert time_[-1] <= program.total_time < time_[-1] + period * 1.000001
    ends = np.cumsum(program.t)
    starts = ends - program.t
    contour_start = np.r_[True, program.contour[1:] != program.contour[:-1]]
    for k in range(0, n, 7):
        i = min(int(np.searchsorted(starts, time_[k], side="right")) - 1, len(program) - 1)
        # Contours meet end to start: a contour starts at rest where the last one ended.
        p0 = program.start if i == 0 else program.p[i - 1]
        v0 = np.zeros(len(program.axes)) if contour_start[i] else program.v[i - 1]
        s = min(time_[k] - starts[i], program.t[i])
        p, v, a = hermite(p0, v0, program.p[i], program.v[i], program.t[i], s)
        assert np.allclose(position[k], p, rtol=0, atol=1e-9)
        assert np.allclose(velocity[k], v, rtol=1e-9, atol=1e-6)
        assert np.allclose(acceleration[k], a, rtol=1e-7, atol=1e-3)


def raster_program(lines=3000):
    """A G-code raster long enough for many chunks."""
    out = ["G21 G90 G17", "G0 X0 Y0 Z1", "G1 Z0 F600"]
    for i in range(lines):
        y = (i // 100) * 0.5
        x = (i % 100) * 0.3 if (i // 100) % 2 == 0 else (99 - i % 100) * 0.3
        out.append(f"G1 X{x:.3f} Y{y:.3f} Z{0.01 * np.sin(i / 7):.4f} F1200")
    out.append("M2")
    return "\n".join(out) + "\n"


def test_stream_chunks_are_the_program_and_continuous(tmp_path):
    path = tmp_path / "raster.ngc"
    path.write_text(raster_program())
    whole = pvtc.plan(path, format="json")
    chunks = pvtc.stream(path, chunk=500, format="json")
    got = []
    previous = None
    for taken, chunk in enumerate(chunks, start=1):
        assert 0 < len(chunk) <= 500
        if previous is None:
            assert np.array_equal(chunk.start, whole.start)
        elif chunk.first_contour == previous.contour[-1] and chunk.contour[0] == previous.contour[-1]:
            assert np.array_equal(chunk.start, previous.p[-1])
            assert np.array_equal(chunk.start_velocity, previous.v[-1])
        else:
            assert not chunk.start_velocity.any()
        time.sleep(0.02)  # the planner runs ahead as far as it may
        assert chunks.made <= taken + 1
        got.append(chunk)
        previous = chunk
    assert len(got) >= len(whole) // 500
    for field in ("t", "line", "contour"):
        assert np.array_equal(np.concatenate([getattr(c, field) for c in got]), getattr(whole, field))
    for field in ("p", "v"):
        assert np.array_equal(np.vstack([getattr(c, field) for c in got]), getattr(whole, field))


def test_stream_of_a_program_and_of_text():
    program = pvtc.plan(ROOT / "samples/gcode/linuxcnc_helix.ngc", format="json")
    chunks = list(pvtc.stream(program, chunk=64))
    assert np.array_equal(np.concatenate([c.t for c in chunks]), program.t)
    text = pvtc.Text((ROOT / "samples/gcode/square.ngc").read_text())
    chunks = list(pvtc.stream(text, chunk=3, format="json"))
    assert sum(len(c) for c in chunks) == len(pvtc.plan(text, format="json"))


def test_stream_raises_after_the_chunks_before_the_error(tmp_path):
    path = tmp_path / "bad.ngc"
    path.write_text("G21 G90\nG1 X1 Y1 F100\nG1 X2 Y\nM2\n")
    with pytest.raises(pvtc.CompileError):
        list(pvtc.stream(path, chunk=10))
    with pytest.raises(ValueError, match="chunk"):
        pvtc.stream(path, chunk=0)


def test_a_chunk_in_motion_is_not_a_program(tmp_path):
    path = tmp_path / "raster.ngc"
    path.write_text(raster_program(400))
    chunks = list(pvtc.stream(path, chunk=50, format="json"))
    moving = [c for c in chunks if c.start_velocity.any()]
    assert moving
    with pytest.raises(ValueError, match="starts in motion"):
        moving[0].write()
    with pytest.raises(ValueError, match="starts in motion"):
        moving[0].sample(0.001)
