#!/usr/bin/env bash
# Batch scaling: how much faster `pvtc compile DIR --out-dir OUT -j N` is on more cores.
#
#   crates/pvtc/benches/batch.sh [FILES] [LINES] [ROUNDS] [JOBS...]
#   crates/pvtc/benches/batch.sh 200 5000 3 1 2      # the README's figures (the defaults)
#
# Writes FILES deterministic programs of LINES lines (surfacing, pocket and mixed in turn,
# from `cargo run --example generate`) into a temporary folder, then compiles the folder
# ROUNDS times at each `-j` in JOBS, the job counts taking turns so that a machine whose
# speed drifts treats them alike. Prints each wall time, the best per job count and the
# speed-up of each over the first, and checks that one batch output is byte-identical to
# compiling that file alone.
set -euo pipefail

files=${1:-200}
lines=${2:-5000}
rounds=${3:-3}
shift $(( $# < 3 ? $# : 3 ))
jobs=("$@")
[ ${#jobs[@]} -eq 0 ] && jobs=(1 2)

cd "$(dirname "$0")/../../.."
cargo build --release -q -p pvtc --bin pvtc --example generate
pvtc=target/release/pvtc
generate=target/release/examples/generate

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/in"
kinds=(surfacing pocket mixed)
for i in $(seq -w 1 "$files"); do
    "$generate" "${kinds[$((10#$i % 3))]}" "$lines" > "$work/in/p$i.ngc"
done
echo "$files programs of $lines lines, $(du -sh "$work/in" | cut -f1); $(nproc) cores"

declare -A best
for round in $(seq "$rounds"); do
    for j in "${jobs[@]}"; do
        rm -rf "$work/out"
        start=$(date +%s.%N)
        "$pvtc" compile "$work/in" --out-dir "$work/out" -j "$j" 2>/dev/null
        seconds=$(echo "$(date +%s.%N) - $start" | bc)
        printf 'round %s  -j%-3s %6.2f s\n' "$round" "$j" "$seconds"
        if [ -z "${best[$j]:-}" ] || [ "$(echo "$seconds < ${best[$j]}" | bc)" = 1 ]; then
            best[$j]=$seconds
        fi
    done
done

first=${jobs[0]}
for j in "${jobs[@]}"; do
    printf 'best -j%-3s %6.2f s  speed-up over -j%s: %.2fx\n' \
        "$j" "${best[$j]}" "$first" "$(echo "${best[$first]} / ${best[$j]}" | bc -l)"
done

one=$(ls "$work/in" | head -1)
"$pvtc" compile "$work/in/$one" -o "$work/alone.pmac" 2>/dev/null
cmp "$work/alone.pmac" "$work/out/${one%.ngc}.pmac"
echo "batch output of $one is byte-identical to compiling it alone"
