"""The speed of `pvtc.plan` against the CLI's JSON compile of the same program, in one run
(issue 43): the best wall time of each over RUNS runs, and peak RSS.

    bench/python/run.sh [RUNS]

Run by run.sh with the release wheel installed; argv: the pvtc binary, the program,
the runs."""

import resource
import subprocess
import sys
import time
import warnings

import pvtc


def cli_run(binary, program, out):
    """Wall seconds of `pvtc compile PROGRAM --format json -o OUT`, and its peak RSS in
    KiB (from /usr/bin/time: a fork of this process would count the arrays held here)."""
    start = time.perf_counter()
    subprocess.run(
        ["/usr/bin/time", "-f", "%M", "-o", out + ".rss", binary, "compile", program, "--format", "json", "-o", out],
        check=True,
        stderr=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - start
    with open(out + ".rss") as f:
        return wall, int(f.read().split()[-1])


def main(binary, program, runs):
    cli_best, py_best = float("inf"), float("inf")
    cli_rss = 0
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for _ in range(runs):
        wall, rss = cli_run(binary, program, program + ".json")
        cli_best, cli_rss = min(cli_best, wall), max(cli_rss, rss)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.perf_counter()
            planned = pvtc.plan(program, format="json")
            py_best = min(py_best, time.perf_counter() - start)
        arrays = sum(a.nbytes for a in (planned.t, planned.p, planned.v, planned.line, planned.contour))
        pieces = len(planned)
        del planned
    py_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(f"pieces: {pieces}, arrays: {arrays / 2**20:.1f} MiB")
    print(f"pvtc compile --format json: best {cli_best:.3f} s, peak RSS {cli_rss / 1024:.1f} MiB")
    print(
        f"pvtc.plan(format='json'):   best {py_best:.3f} s, peak RSS {py_rss / 1024:.1f} MiB "
        f"({base / 1024:.1f} MiB before: Python and numpy; {(py_rss - base) / 1024:.1f} MiB more)"
    )
    print(f"ratio of the best times, plan / compile: {py_best / cli_best:.3f}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 3)
