"""A FreeCAD-style post-processor: G-code text in, a PMAC motion program out, planned
by pvtc with the path planner within the machine's limits.

FreeCAD calls a post-processor module's ``export(objectslist, filename, argstring)``;
each Path object's G-code is ``obj.Path.toGCode()``. This module keeps that shape, and
``post()`` is the part that works on text, so it runs without FreeCAD too:

    python crates/pvtc-py/examples/freecad_post.py samples/gcode/square.ngc out.pmac \\
        "--tolerance 0.005 --machine samples/machines/mill.toml --program 12"
"""

import argparse
import shlex
import sys
import warnings

import pvtc

TOOLTIP = "PMAC PVT motion program, planned by pvtc"

parser = argparse.ArgumentParser(prog="pvtc_post", add_help=False)
parser.add_argument("--tolerance", type=float, default=None, help="path tolerance, mm")
parser.add_argument("--machine", default=None, help="machine TOML with the axis limits")
parser.add_argument("--program", type=int, default=1, help="PMAC program number")
parser.add_argument("--coord", type=int, default=None, help="PMAC coordinate system")


def post(gcode, argstring="", name="<FreeCAD>"):
    """The PMAC program for ``gcode``, planned with the options in ``argstring``."""
    args = parser.parse_args(shlex.split(argstring))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", pvtc.PvtcWarning)
        program = pvtc.plan(pvtc.Text(gcode, name=name), tolerance=args.tolerance, machine=args.machine)
    for w in caught:
        print(f"pvtc: {w.message}", file=sys.stderr)
    return program.write("pmac", pmac_program=args.program, pmac_coord=args.coord)


def export(objectslist, filename, argstring=""):
    """FreeCAD's entry point: the G-code of every object, posted into ``filename``."""
    gcode = "".join(obj if isinstance(obj, str) else obj.Path.toGCode() for obj in objectslist)
    try:
        text = post(gcode, argstring, name=filename)
    except pvtc.CompileError as error:
        for d in error.diagnostics:
            print(f"{d.path}:{d.line}:{d.column}: {d.message} [{d.code}]", file=sys.stderr)
        raise
    with open(filename, "w") as out:
        out.write(text)
    return text


if __name__ == "__main__":
    source, target = sys.argv[1], sys.argv[2]
    with open(source) as f:
        export([f.read()], target, sys.argv[3] if len(sys.argv) > 3 else "")
    print(f"wrote {target}")
