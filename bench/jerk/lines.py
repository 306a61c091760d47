#!/usr/bin/env python3
"""Single lines along X from rest to rest under samples/machines/mill.toml (100 mm/s,
1000 mm/s², 50000 mm/s³) against Ruckig's time-optimal jerk-limited profile, plain and
on a 1 ms grid (JSON). Needs `pip install ruckig` (the benchmark only).

Usage: python3 bench/jerk/lines.py [PVTC]   (PVTC: target/release/pvtc)
"""
import json, os, subprocess, sys, tempfile

from ruckig import InputParameter, Result, Ruckig, Trajectory

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LENGTHS = [0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]


def ruckig_time(d):
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [d], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [100.0], [1000.0], [50000.0]
    traj = Trajectory(1)
    assert otg.calculate(inp, traj) == Result.Working
    return traj.duration


def pvtc_time(pvtc, d, quantum, tmp):
    src = os.path.join(tmp, "line.ngc")
    with open(src, "w") as f:
        f.write(f"G21 G90 G94\nG1 X{d} F6000\nM2\n")
    out = os.path.join(tmp, "line.json")
    args = [pvtc, "compile", src, "--machine", os.path.join(ROOT, "samples/machines/mill.toml"),
            "--format", "json", "-o", out]
    if quantum:
        args += ["--quantize", quantum]
    subprocess.run(args, check=True, capture_output=True)
    doc = json.load(open(out))
    return sum(s["t"] for c in doc["contours"] for s in c["segments"])


def main():
    pvtc = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "target/release/pvtc")
    print(f"{'mm':>6} {'ruckig':>9} {'pvtc':>9} {'ratio':>6} {'pvtc 1ms':>9} {'ratio':>6} {'1ms - 1.05 x ruckig':>20}")
    with tempfile.TemporaryDirectory() as tmp:
        for d in LENGTHS:
            r = ruckig_time(d)
            p, g = pvtc_time(pvtc, d, None, tmp), pvtc_time(pvtc, d, "1ms", tmp)
            print(f"{d:6.1f} {r:9.4f} {p:9.4f} {p / r:6.3f} {g:9.4f} {g / r:6.3f} {1000 * (g - 1.05 * r):17.1f} ms")


if __name__ == "__main__":
    main()
