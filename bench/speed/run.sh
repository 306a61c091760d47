#!/usr/bin/env bash
# The speed benchmark of issue 22: the default compile (`path` planner, PMAC text) of
# three generated programs, against the `gcode` crate's parse of the same file in the
# same run, with MB/s of input and peak RSS on every output route.
#
#   bench/speed/run.sh [RUNS]        (RUNS: runs per row, the best time kept; default 3)
#
# Inputs (crates/pvtc/examples/generate): 10^6 straight lines (`surfacing`), 10^6 lines
# with one arc in ten (`arcs`), `pocket 100000`. Set PVTC_BENCH_DIR to keep them.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
cargo build --release -q -p pvtc --bin pvtc --example generate --example gcode_parse
bin=target/release
dir=${PVTC_BENCH_DIR:-$(mktemp -d)}
mkdir -p "$dir"
for input in "surfacing 1000000 lines" "arcs 1000000 arcs" "pocket 100000 pocket"; do
    set -- $input
    [ -s "$dir/$3.ngc" ] || "$bin/examples/generate" "$1" "$2" > "$dir/$3.ngc"
done

# best TIME and largest RSS (KB) of `runs` runs of a shell command: "seconds KB"
measure() {
    local best= rss=0 t m
    for _ in $(seq "$runs"); do
        rm -f "$dir/out.pmac"
        /usr/bin/time -f '%e %M' -o "$dir/time" sh -c "$1" > /dev/null 2>&1
        read -r t m < "$dir/time"
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then best=$t; fi
        [ "$m" -gt "$rss" ] && rss=$m
    done
    echo "$best $rss"
}

echo "| input | MB | route | time (best of $runs) | MB/s | peak RSS | time / gcode parse |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for name in lines arcs pocket; do
    file="$dir/$name.ngc"
    mb=$(awk "BEGIN{printf \"%.1f\", $(stat -c %s "$file") / 1e6}")
    read -r parse parse_rss <<< "$(measure "$bin/examples/gcode_parse $file")"
    for route in "-o $dir/out.pmac" "-o /dev/null" "| cat > /dev/null"; do
        read -r t rss <<< "$(measure "$bin/pvtc compile $file $route")"
        awk -v n="$name" -v mb="$mb" -v r="$route" -v t="$t" -v rss="$rss" -v p="$parse" \
            -v dir="$dir/" 'BEGIN{sub(dir, "", r); printf "| %s | %s | `%s` | %.2f s | %.0f | %.1f MiB | %.2f |\n",
            n, mb, r, t, mb / t, rss / 1024, t / p}'
    done
    awk -v n="$name" -v mb="$mb" -v t="$parse" -v rss="$parse_rss" \
        'BEGIN{printf "| %s | %s | gcode crate parse | %.2f s | %.0f | %.1f MiB | 1.00 |\n",
        n, mb, t, mb / t, rss / 1024}'
done
