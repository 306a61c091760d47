#!/usr/bin/env bash
# The speed benchmark of issue 22: the streaming compile (`path` planner, PMAC text,
# `--quantize off`; PMAC's default 1 ms grid, which streams too, is bench/stream) of three
# generated programs, against the `gcode` crate's parse of the same file in the
# same run, with MB/s of input (of wall time, what a compile on several threads is judged
# by, and of CPU time) and peak RSS on every output route.
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

# Of `runs` runs of a shell command: the best wall time, the best CPU time (user +
# system, which a loaded machine inflates less) and the largest RSS: "seconds seconds KB"
measure() {
    local best= cpu= rss=0 t u s m
    for _ in $(seq "$runs"); do
        rm -f "$dir/out.pmac"
        /usr/bin/time -f '%e %U %S %M' -o "$dir/time" sh -c "$1" > /dev/null 2>&1
        read -r t u s m < "$dir/time"
        u=$(awk "BEGIN{print $u + $s}")
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then best=$t; fi
        if [ -z "$cpu" ] || awk "BEGIN{exit !($u < $cpu)}"; then cpu=$u; fi
        [ "$m" -gt "$rss" ] && rss=$m
    done
    echo "$best $cpu $rss"
}

echo "| input | MB | route | wall (best of $runs) | CPU (best) | MB/s (wall) | MB/s (CPU) | peak RSS | CPU / gcode parse CPU |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for name in lines arcs pocket; do
    file="$dir/$name.ngc"
    mb=$(awk "BEGIN{printf \"%.1f\", $(stat -L -c %s "$file") / 1e6}")
    read -r parse parse_cpu parse_rss <<< "$(measure "$bin/examples/gcode_parse $file")"
    for route in "-o $dir/out.pmac" "-o /dev/null" "| cat > /dev/null"; do
        read -r t cpu rss <<< "$(measure "$bin/pvtc compile $file --quantize off $route")"
        awk -v n="$name" -v mb="$mb" -v r="$route" -v t="$t" -v c="$cpu" -v rss="$rss" \
            -v p="$parse_cpu" -v dir="$dir/" 'BEGIN{sub(dir, "", r);
            printf "| %s | %s | `%s` | %.2f s | %.2f s | %.0f | %.0f | %.1f MiB | %.2f |\n",
            n, mb, r, t, c, mb / t, mb / c, rss / 1024, c / p}'
    done
    awk -v n="$name" -v mb="$mb" -v t="$parse" -v c="$parse_cpu" -v rss="$parse_rss" \
        'BEGIN{printf "| %s | %s | gcode crate parse | %.2f s | %.2f s | %.0f | %.0f | %.1f MiB | 1.00 |\n",
        n, mb, t, c, mb / t, mb / c, rss / 1024}'
done
