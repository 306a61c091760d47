"""A fly scan for a Newport XPS: a raster of points with the speeds a detector needs,
planned by pvtc from numpy arrays, checked against the stage's limits, and written as
XPS trajectory files of a few rows each (the XPS verifies a file whole, rest to rest).

    python crates/pvtc-py/examples/fly_scan.py /tmp/scan [machine.toml]

Each row is scanned at a constant speed, one point per detector frame, with a ramp of
constant acceleration before and after it; the motion stops at each row's end and steps
to the next row. The velocities are given with the points (the PVT "file"
velocities), so every chunk of whole rows starts and ends at rest, each file starting
where the last one ended.
"""

import pathlib
import sys

import numpy as np

import pvtc

ROWS = 12  # rows of the raster
FRAMES = 41  # points (detector frames) per row
WIDTH = 8.0  # mm, the scanned length of a row
STEP = 0.25  # mm between rows
FRAME = 0.02  # s per frame
RAMP = 0.1  # s to reach the scan speed from rest, and to stop
TURN = 0.2  # s to step to the next row
ROWS_PER_FILE = 4

# An XY stage: mm, mm/s, mm/s^2 (the shape of a machine TOML file, as a dict).
STAGE = {
    "units": "mm",
    "axes": {
        "X": {"max_velocity": 50.0, "max_acceleration": 500.0},
        "Y": {"max_velocity": 50.0, "max_acceleration": 500.0},
    },
}


def raster():
    """Positions (N, 2), times (N,) and velocities (N, 2) of a serpentine raster."""
    speed = WIDTH / ((FRAMES - 1) * FRAME)
    ramp = speed * RAMP / 2  # mm covered while ramping at constant acceleration
    positions, times, velocities = [], [], []
    clock = 0.0
    for row in range(ROWS):
        sign = 1.0 if row % 2 == 0 else -1.0
        first = 0.0 if sign > 0 else WIDTH
        xs = [first - sign * ramp] + [first + sign * k * WIDTH / (FRAMES - 1) for k in range(FRAMES)]
        xs.append(xs[-1] + sign * ramp)
        dts = [RAMP] + [FRAME] * (FRAMES - 1) + [RAMP]
        for k, x in enumerate(xs):
            positions.append((x, row * STEP))
            times.append(clock)
            moving = 0 < k < len(xs) - 1
            velocities.append((sign * speed if moving else 0.0, 0.0))
            if k < len(dts):
                clock += dts[k]
        clock += TURN
    return np.array(positions), np.array(times), np.array(velocities)


def main(out_dir, machine=None):
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    positions, times, velocities = raster()
    program = pvtc.from_points(positions, times, velocities, axes=("X", "Y"), planner="spline", format="xps")
    report = pvtc.check(program, machine=machine or STAGE)
    print(f"{len(program)} pieces, {program.total_time:.3f} s; peaks:")
    for axis, peaks in report.peaks.items():
        v, a = peaks["velocity"], peaks["acceleration"]
        print(f"  {axis}: |v| {v.value:.3f} mm/s, |a| {a.value:.1f} mm/s^2 (piece {a.piece})")
    if report.exceeded:
        for v in report.violations:
            print(f"  over: {v.axis} {v.quantity} {v.value:.3f} > {v.limit} at piece {v.piece}")
        raise SystemExit("the scan exceeds the stage's limits")
    files = []
    # A row (FRAMES + 2 points) and the step after it are FRAMES + 2 pieces: chunks of
    # whole rows start and end at rest.
    for i, chunk in enumerate(pvtc.stream(program, chunk=ROWS_PER_FILE * (FRAMES + 2))):
        path = out_dir / f"scan_{i:03}.trj"
        chunk.write("xps", path=path)
        files.append(path)
    print(f"wrote {len(files)} XPS trajectory files in {out_dir}")
    return files


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scan", sys.argv[2] if len(sys.argv) > 2 else None)
