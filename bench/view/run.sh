#!/usr/bin/env bash
# The HTML view of a program of 10^6 lines (issue 44): `pvtc plot -o FILE.html` of the
# surfacing program (10^6 G1 chords, 1.57·10^6 pieces under bench/toppra/machine.toml),
# the time to write the page and its size, then the page opened in headless Chromium
# (crates/pvtc/tests/view.rs, `a_large_programs_page_opens`): the time from opening it to
# drawn, the browser's processor time, and the page script's own times.
#
#   bench/view/run.sh [RUNS]          (RUNS: openings of the page; default 3)
#
# Needs chromium on the PATH (apt-get install chromium). Set PVTC_BENCH_DIR to keep the
# inputs and the page.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
cargo build --release -q -p pvtc --bin pvtc --example generate
dir=${PVTC_BENCH_DIR:-$(mktemp -d)}
mkdir -p "$dir"
[ -s "$dir/s1000000.ngc" ] || target/release/examples/generate surfacing 1000000 > "$dir/s1000000.ngc"
/usr/bin/time -f 'plot: %e s wall, %M KB peak RSS' \
    target/release/pvtc plot "$dir/s1000000.ngc" --machine bench/toppra/machine.toml \
    -o "$dir/s1000000.html" 2> "$dir/plot.err" || { cat "$dir/plot.err"; exit 1; }
grep '^plot:' "$dir/plot.err"
echo "page: $(stat -c %s "$dir/s1000000.html") bytes"
for _ in $(seq "$runs"); do
    PVTC_VIEW_PROGRAM="$dir/s1000000.html" cargo test -q -p pvtc --test view \
        -- --ignored --nocapture a_large_programs_page_opens 2>&1 | grep '^pieces'
done
