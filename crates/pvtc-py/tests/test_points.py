"""`pvtc.from_points` against the CSV front end: the same points written as a CSV file
and compiled by the CLI give the same arrays, bit for bit."""

import numpy as np
import pytest

import pvtc
from conftest import ROOT, assert_same_arrays, cli_json


def write_csv(path, times, positions, velocities=None, axes=("X", "Y")):
    header = ["t", *axes] + ([f"v{a.lower()}" for a in axes] if velocities is not None else [])
    rows = [",".join(header)]
    for i, t in enumerate(times):
        row = [repr(float(t))] + [repr(float(x)) for x in positions[i]]
        if velocities is not None:
            row += [repr(float(x)) for x in velocities[i]]
        rows.append(",".join(row))
    path.write_text("\n".join(rows) + "\n")


def raster(rows=4, per_row=25):
    rng = np.random.default_rng(7)
    t, p = [], []
    for r in range(rows):
        xs = np.linspace(0.0, 10.0, per_row)
        if r % 2:
            xs = xs[::-1]
        for x in xs:
            p.append((x + rng.normal(0, 1e-3), 0.5 * r))
    p = np.array(p)
    t = np.cumsum(np.full(len(p), 0.01)) - 0.01
    return t, p


@pytest.mark.parametrize("planner", ["spline", "pt", "chord-forward", "path"])
def test_series_as_the_csv_front_end(tmp_path, planner):
    t, p = raster()
    csv = tmp_path / "scan.csv"
    write_csv(csv, t, p)
    expected = cli_json(csv, "--planner", planner)
    got = pvtc.from_points(p, t, planner=planner, format="json")
    assert_same_arrays(got, expected)


def test_velocities_as_the_columns(tmp_path):
    t, p = raster(rows=2, per_row=10)
    v = np.gradient(p, t, axis=0)
    v[0] = v[-1] = 0.0
    csv = tmp_path / "scan.csv"
    write_csv(csv, t, p, v)
    expected = cli_json(csv)
    with _quiet():
        got = pvtc.from_points(p, t, v, format="json")
    assert_same_arrays(got, expected)


def test_one_axis_and_a_sample(tmp_path):
    # samples/csv/an208_step.csv holds t, x, vx.
    data = np.loadtxt(ROOT / "samples/csv/an208_step.csv", delimiter=",", comments="#", skiprows=3)
    t, x, vx = data[:, 0], data[:, 1], data[:, 2]
    expected = cli_json("samples/csv/an208_step.csv")
    got = pvtc.from_points(x, t, vx, axes=("X",), format="json")
    for name in ("t", "p", "v", "start"):
        assert np.array_equal(np.asarray(getattr(got, name)), expected[name]), name


def test_bad_points_are_compile_errors_with_their_line():
    t = np.array([0.0, 0.1, 0.1, 0.3])
    p = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    with pytest.raises(pvtc.CompileError) as error:
        pvtc.from_points(p, t)
    first = error.value.diagnostics[0]
    assert first.code == "pvtc::csv::non_increasing_time"
    assert first.line == 4  # point 2: its line in the series' CSV (header is line 1)


def test_shapes_are_checked():
    with pytest.raises(ValueError, match="positions"):
        pvtc.from_points(np.zeros((5, 3)), np.arange(5.0))
    with pytest.raises(ValueError, match="times"):
        pvtc.from_points(np.zeros((5, 2)), np.arange(4.0))
    with pytest.raises(ValueError, match="axes"):
        pvtc.from_points(np.zeros((5, 2)), np.arange(5.0), axes=("X", "Q"))


class _quiet:
    """Collects warnings without failing on them (the velocity-columns note is a note)."""

    def __enter__(self):
        import warnings

        self._c = warnings.catch_warnings()
        self._c.__enter__()
        warnings.simplefilter("ignore")

    def __exit__(self, *exc):
        self._c.__exit__(*exc)
