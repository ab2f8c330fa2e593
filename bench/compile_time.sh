#!/usr/bin/env bash
# Compile times of a scene's translation units: min of N runs (user CPU, wall, peak RSS) with the
# release flags (GCC, -O2), interleaved so that the machine's noise falls on every variant alike.
#   bench/compile_time.sh [OTHER_TREE]   (N=3 by default; OTHER_TREE: a checkout to compare,
#                                         e.g. `git worktree add /tmp/base 3070efa`)
# Prints one line per translation unit: examples/dkt.cpp (the program), examples/dkt_flow.cpp
# (the flow and scene set-up, compiled once), the umbrella header alone, the README's program.
set -euo pipefail
N=${N:-3}
here=$(cd "$(dirname "$0")/.." && pwd)
other=${1:-}
F=(-DALEFSI_HAVE_SUITESPARSE -isystem /usr/include/eigen3 -isystem /usr/include/suitesparse -O2 -DNDEBUG
   -std=gnu++20 -DALEFSI_DKT_PAIR=P1P1Gls -DALEFSI_DKT_SCHEME=BDF2_BDF2E -w)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '#include <alefsi/alefsi.hpp>\nint main() {}\n' > "$tmp/umbrella.cpp"
units=()
for tree in "$here" $other; do
  for src in examples/dkt.cpp examples/dkt_flow.cpp UMBRELLA tests/downstream/app.cpp; do
    [ "$src" = UMBRELLA ] && { units+=("$tree|$tmp/umbrella.cpp|umbrella"); continue; }
    [ -f "$tree/$src" ] && units+=("$tree|$tree/$src|$src")
  done
done
declare -A best wall rss
for _ in $(seq "$N"); do
  for u in "${units[@]}"; do
    IFS='|' read -r tree src name <<< "$u"
    /usr/bin/time -f "%U %e %M" -o "$tmp/t" c++ "${F[@]}" -I"$tree/include" -I"$(dirname "$src")" -c "$src" -o "$tmp/o.o"
    read -r cpu w m < "$tmp/t"
    if [ -z "${best[$u]:-}" ] || awk "BEGIN{exit !($cpu < ${best[$u]})}"; then best[$u]=$cpu wall[$u]=$w rss[$u]=$m; fi
  done
done
for u in "${units[@]}"; do
  IFS='|' read -r tree src name <<< "$u"
  printf '%-40s %-28s user %6.2f s  wall %6.2f s  peak %5d MB\n' "$tree" "$name" "${best[$u]}" "${wall[$u]}" $((rss[$u] / 1024))
done
