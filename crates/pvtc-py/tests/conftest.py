"""Shared fixtures of the pvtc Python tests: the repository root, the `pvtc` binary the
package is compared with (PVTC_BIN, set by crates/pvtc/tests/python.rs), and helpers that
run it and read its JSON program back as flat arrays."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(os.environ.get("PVTC_ROOT", Path(__file__).resolve().parents[3]))
BIN = os.environ.get("PVTC_BIN", str(ROOT / "target" / "debug" / "pvtc"))


def cli(*args, check=True):
    """Runs `pvtc ARGS` in the repository root: (status, stdout bytes, stderr text)."""
    done = subprocess.run([BIN, *map(str, args)], cwd=ROOT, capture_output=True)
    if check and done.returncode != 0:
        raise AssertionError(f"pvtc {' '.join(map(str, args))}: {done.stderr.decode()}")
    return done.returncode, done.stdout, done.stderr.decode()


def flat(document):
    """A pvtc JSON program as the arrays `pvtc.Program` holds, computed from the JSON's
    own fields: per piece t, p, v, line and contour index; per contour kind; start."""
    t, p, v, line, contour, kind = [], [], [], [], [], []
    for c, entry in enumerate(document["contours"]):
        kind.append(entry["kind"])
        for seg in entry["segments"]:
            t.append(seg["t"])
            p.append(seg["p"])
            v.append(seg["v"])
            line.append(seg["line"])
            contour.append(c)
    dim = len(document["axes"])
    start = document["contours"][0]["start"] if document["contours"] else [0.0] * dim
    return {
        "t": np.array(t, dtype=float),
        "p": np.array(p, dtype=float).reshape(-1, dim),
        "v": np.array(v, dtype=float).reshape(-1, dim),
        "line": np.array(line, dtype=np.uint32),
        "contour": np.array(contour, dtype=np.uint32),
        "kind": tuple(kind),
        "start": np.array(start, dtype=float),
        "axes": tuple(document["axes"]),
        "units": document["units"],
        "total_time": document["total_time"],
    }


def cli_json(*args):
    """The JSON program `pvtc compile ARGS --format json` writes, as arrays."""
    _, out, _ = cli("compile", *args, "--format", "json")
    return flat(json.loads(out))


def assert_same_arrays(program, expected):
    """Every array of `program` equals the CLI's, bit for bit."""
    for name in ("t", "p", "v", "line", "contour", "start"):
        got = np.asarray(getattr(program, name))
        want = expected[name]
        assert got.shape == want.shape, (name, got.shape, want.shape)
        assert np.array_equal(got, want), name
    assert program.kind == expected["kind"]
    assert program.axes == expected["axes"]
    assert program.units == expected["units"]
    assert program.total_time == expected["total_time"]


@pytest.fixture
def root():
    return ROOT
