#!/usr/bin/env bash
# Streaming on a time grid and under a jerk limit (issue 26): the surfacing program of
# 10^5 and 10^6 lines compiled into PMAC text on every route the path planner takes,
# wall time and peak RSS of each, and each route's time against the default compile's.
#
#   bench/stream/run.sh [RUNS]        (RUNS: runs per row, the best time kept; default 3)
#
# Routes: PMAC's default (the 1 ms grid, no machine file: streams), `--quantize off`
# (streams), `samples/machines/mill.toml` without its `max_jerk` lines on 1 ms (held
# whole: the surfacing lines are shorter than a stopping distance), `mill.toml` as JSON
# (jerk limit, no grid) and `mill.toml --quantize 1ms` (both stream: a window under a
# jerk limit is cut at its stop horizon, across the short lines); their 10^6 rows are
# left out unless BIG=1. Set PVTC_BENCH_DIR to keep inputs.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
cargo build --release -q -p pvtc --bin pvtc --example generate
bin=target/release
dir=${PVTC_BENCH_DIR:-$(mktemp -d)}
mkdir -p "$dir"
mill=samples/machines/mill.toml
grep -v max_jerk "$mill" > "$dir/mill_no_jerk.toml"
for n in 100000 1000000; do
    [ -s "$dir/s$n.ngc" ] || "$bin/examples/generate" surfacing "$n" > "$dir/s$n.ngc"
done

# Of `runs` runs: the best wall time and the largest peak RSS, "seconds KB".
measure() {
    local best= rss=0 t m
    for _ in $(seq "$runs"); do
        rm -f "$dir/out"
        /usr/bin/time -f '%e %M' -o "$dir/time" sh -c "$1" > /dev/null 2>&1
        read -r t m < "$dir/time"
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then best=$t; fi
        [ "$m" -gt "$rss" ] && rss=$m
    done
    echo "$best $rss"
}

echo "| lines | route | wall (best of $runs) | against the default | peak RSS |"
echo "| --- | --- | --- | --- | --- |"
for n in 100000 1000000; do
    file="$dir/s$n.ngc"
    base=
    for route in "-o $dir/out" "--quantize off -o $dir/out" \
        "--machine $dir/mill_no_jerk.toml --quantize 1ms -o $dir/out" \
        "--machine $mill --format json -o $dir/out" \
        "--machine $mill --quantize 1ms -o $dir/out"; do
        if [ "$n" = 1000000 ] && [ "${BIG:-0}" != 1 ] && [[ "$route" == *--machine* ]]; then
            continue
        fi
        read -r t rss <<< "$(measure "$bin/pvtc compile $file $route")"
        [ -z "$base" ] && base=$t
        awk -v n="$n" -v r="$route" -v t="$t" -v b="$base" -v rss="$rss" -v dir="$dir/" \
            'BEGIN{gsub(dir, "", r); printf "| %s | `%s` | %.2f s | %.2f | %.1f MiB |\n",
            n, r, t, t / b, rss / 1024}'
    done
done
