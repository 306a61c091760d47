"""The examples in crates/pvtc-py/examples and the README's Python example run as
written, and give what the CLI gives."""

import importlib.util
import os
import re

import pvtc
from conftest import ROOT, cli


def load(name):
    path = ROOT / "crates/pvtc-py/examples" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_freecad_post_writes_what_the_cli_writes(tmp_path):
    post = load("freecad_post")
    name = "samples/gcode/linuxcnc_helix.ngc"
    machine = "samples/machines/mill.toml"
    out = tmp_path / "helix.pmac"
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        text = post.export([(ROOT / name).read_text()], str(out), f"--tolerance 0.005 --machine {machine} --program 12")
    finally:
        os.chdir(cwd)
    _, want, _ = cli("compile", name, "--tolerance", "0.005", "--machine", machine, "--pmac-program", "12")
    # The header names the source: the file FreeCAD was asked to write.
    assert text.replace(str(out), name).encode() == want
    assert out.read_text() == text


def test_fly_scan_writes_xps_files_that_make_the_whole_scan(tmp_path):
    scan = load("fly_scan")
    files = scan.main(tmp_path)
    assert len(files) == -(-scan.ROWS // scan.ROWS_PER_FILE)
    positions, times, velocities = scan.raster()
    whole = pvtc.from_points(positions, times, velocities, format="xps")
    assert "".join(f.read_text() for f in files) == whole.write()


def test_the_readme_python_example_runs_as_written(tmp_path):
    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks, "the README's Python section has a python block"
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for block in blocks:
            exec(compile(block, "README.md", "exec"), {"__name__": "readme"})
    finally:
        os.chdir(cwd)
