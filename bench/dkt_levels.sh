#!/usr/bin/env bash
# DKT (paper 6.2) on three mesh / dt levels for BDF2/BDF2E and BDF3/BDF3E: kissing time and
# positions at t = 0.1, 0.2, 0.3 s (docs/results.md). Needs the release build of the examples:
#   cmake --preset release && cmake --build --preset release --target dkt dkt_bdf3
# usage: bench/dkt_levels.sh [OUT_DIR] [T_END] [OFFSET] [EXECUTABLES]
#   defaults: build/release/output/dkt_levels  0.35 (s)  0.001 (cm)  "dkt dkt_bdf3"
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/release/output/dkt_levels}
t_end=${2:-0.35}
offset=${3:-0.001}
exes=${4:-dkt dkt_bdf3}
mkdir -p "$out"
levels=("0.04 0.3 2e-3" "0.02 0.15 1e-3" "0.01 0.075 5e-4")
for exe in $exes; do
  for i in 0 1 2; do
    read -r hb hf dt <<< "${levels[$i]}"
    dir="$out/${exe}_L$((i + 1))"
    /usr/bin/time -v ./build/release/examples/$exe --h-body "$hb" --h-far "$hf" --dt "$dt" --t-end "$t_end" \
      --offset "$offset" --output "$dir" --vtu-every 0 --checkpoint-every 0 > "$dir.log" 2> "$dir.time" ||
      echo "$exe L$((i + 1)) failed"
    echo "== $exe level $((i + 1)): h_body $hb, h_far $hf, dt $dt, offset $offset"
    grep -E "^DKT|kissing|^t = |^wall|^reached" "$dir.log"
    grep -E "Maximum resident" "$dir.time"
  done
done
