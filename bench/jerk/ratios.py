#!/usr/bin/env python3
"""Motion time of every sample under samples/machines/mill.toml against the same machine
without max_jerk, plain and on a 1 ms grid (JSON, and PMAC text read back).

Usage: python3 bench/jerk/ratios.py [PVTC] [SAMPLE...]   (PVTC: target/release/pvtc)
Prints one row per sample: the five times in seconds, the three ratios against the machine
without max_jerk, and the PMAC text's own total against the JSON's on 1 ms ("pmac/json").
"""
import json, os, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def samples():
    out = []
    for d, ext in (("samples/gcode", ".ngc"), ("samples/dxf", ".dxf")):
        for name in sorted(os.listdir(os.path.join(ROOT, d))):
            if name.endswith(ext) and "binary" not in name:
                out.append(os.path.join(d, name))
    return out


def machine_without_jerk(tmp):
    text = open(os.path.join(ROOT, "samples/machines/mill.toml")).read()
    path = os.path.join(tmp, "mill_no_jerk.toml")
    with open(path, "w") as f:
        f.write("\n".join(l for l in text.splitlines() if "max_jerk" not in l) + "\n")
    return path


def compile_time(pvtc, sample, machine, quantum, fmt, tmp):
    out = os.path.join(tmp, "out." + fmt)
    args = [pvtc, "compile", os.path.join(ROOT, sample), "--machine", machine,
            "--format", fmt, "-o", out]
    if sample.endswith(".dxf"):
        args += ["--feed", "6000"]
    if quantum:
        args += ["--quantize", quantum]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        return None
    text = open(out).read()
    if fmt == "json":
        doc = json.loads(text)
        return sum(s["t"] for c in doc["contours"] for s in c["segments"])
    return sum(float(l[2:].split()[0]) / 1000.0 for l in text.splitlines() if l.startswith("TA"))


def main():
    pvtc = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "target/release/pvtc")
    chosen = sys.argv[2:] or samples()
    with tempfile.TemporaryDirectory() as tmp:
        mill = os.path.join(ROOT, "samples/machines/mill.toml")
        free = machine_without_jerk(tmp)
        print(f"{'sample':40} {'free':>8} {'jerk':>8} {'free 1ms':>9} {'jerk 1ms':>9} {'pmac 1ms':>9} {'plain':>6} {'1ms':>6} {'pmac':>6} {'pmac/json':>9}")
        for s in chosen:
            t = [compile_time(pvtc, s, m, q, f, tmp) for m, q, f in (
                (free, None, "json"), (mill, None, "json"),
                (free, "1ms", "json"), (mill, "1ms", "json"), (mill, "1ms", "pmac"))]
            fmt = lambda x: f"{x:8.3f}" if x is not None else "  failed"
            ratio = lambda a, b: f"{a / b:6.2f}" if a and b else "     -"
            same = f"{t[4] / t[3]:9.4f}" if t[3] and t[4] else "        -"
            print(f"{s:40} {fmt(t[0])} {fmt(t[1])} {fmt(t[2]):>9} {fmt(t[3]):>9} {fmt(t[4]):>9} "
                  f"{ratio(t[1], t[0])} {ratio(t[3], t[2])} {ratio(t[4], t[2])} {same}", flush=True)


if __name__ == "__main__":
    main()
