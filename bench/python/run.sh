#!/usr/bin/env bash
# The speed of the Python package against the CLI (issue 43): `pvtc.plan` of the
# 10^6-line `generate surfacing` program against `pvtc compile --format json` of it, in
# one run, best of RUNS (default 3), with peak RSS. Builds the release binary, and
# installs the package as the README says (`pip install ./crates/pvtc-py`, a release
# build) into a virtual environment of its own (target/pvtc-py/release-venv).
#
#   bench/python/run.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
cargo build --release -q -p pvtc --bin pvtc --example generate
venv=target/pvtc-py/release-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q numpy
"$venv/bin/pip" install -q --force-reinstall --no-deps ./crates/pvtc-py
dir=${PVTC_BENCH_DIR:-$(mktemp -d)}
[ -s "$dir/lines.ngc" ] || target/release/examples/generate surfacing 1000000 > "$dir/lines.ngc"
"$venv/bin/python" bench/python/speed.py target/release/pvtc "$dir/lines.ngc" "$runs"
