#!/usr/bin/env bash
# Runs every fuzz target (or those named) for SECONDS each (default 60), one after the
# other, each seeded from the shipped samples; prints each target's execution count.
#
#   fuzz/run.sh                 # about a minute per target
#   SECONDS_PER_TARGET=600 fuzz/run.sh gcode dxf
#
# Needs cargo-fuzz (`cargo install cargo-fuzz`); the stable toolchain builds it with
# RUSTC_BOOTSTRAP=1. Crashes land in fuzz/artifacts/<target>/; copy each into
# tests/fuzz-regressions/ with the fix.
set -euo pipefail
cd "$(dirname "$0")"
seconds="${SECONDS_PER_TARGET:-60}"
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(gcode dxf csv json)
export RUSTC_BOOTSTRAP=1
cargo fuzz build -O >/dev/null 2>&1
seed() {
  local target=$1 dir=corpus/$1
  mkdir -p "$dir"
  case $target in
    gcode) cp ../samples/gcode/*.ngc ../tests/bad/*.ngc "$dir"/ 2>/dev/null || true ;;
    dxf) cp ../samples/dxf/*.dxf ../tests/bad/*.dxf "$dir"/ 2>/dev/null || true ;;
    csv) cp ../samples/csv/*.csv ../tests/bad/*.csv "$dir"/ 2>/dev/null || true ;;
    json) cp ../tests/golden/*/*.json "$dir"/ 2>/dev/null || true ;;
  esac
}
for target in "${targets[@]}"; do
  seed "$target"
  log=$(mktemp)
  status=0
  cargo fuzz run -O "$target" "corpus/$target" -- -max_total_time="$seconds" \
    -rss_limit_mb=4096 -timeout=20 >"$log" 2>&1 || status=$?
  done_line=$(grep -E "^Done [0-9]+ runs" "$log" | tail -1 || true)
  echo "$target: ${done_line:-no summary} (exit $status)"
  if [ $status -ne 0 ]; then tail -40 "$log"; fi
  rm -f "$log"
done
