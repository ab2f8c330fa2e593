#!/usr/bin/env bash
# Runs bench_assembly in parts and keeps the console table and the JSON of every run.
#
#   bench/run_assembly.sh assembly   # pattern / kernel / scatter / assemble, 2D and 3D (~2 min)
#   bench/run_assembly.sh lu         # SparseLU, all but the two long cases (~2 min)
#   bench/run_assembly.sh lu-long    # 2D P2/P1 N = 256 (COLAMD) and 3D P2/P1 N = 12 (~6 min, 9.5 GB peak)
#   bench/run_assembly.sh all
#
# Output: build/bench/results/<part>-<date>.{txt,json}. Build first:
#   cmake --preset bench && cmake --build --preset bench --target bench_assembly
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bench/bench/bench_assembly
[[ -x $bin ]] || { echo "build $bin first (see the header of this script)" >&2; exit 1; }
out=build/bench/results
mkdir -p "$out"
stamp=$(date +%Y%m%d-%H%M%S)

run() {  # name filter
  local name=$1 filter=$2
  echo "== $name: --benchmark_filter='$filter'  ($(uptime | sed 's/.*load/load/'))"
  "$bin" --benchmark_filter="$filter" --benchmark_counters_tabular=true \
    --benchmark_out="$out/$name-$stamp.json" --benchmark_out_format=json | tee "$out/$name-$stamp.txt"
}

assembly='/(pattern|kernel|scatter|assemble)/'
lu='P2P1/2D/lu_colamd/(16|32|64|128)/|/lu_amd/|P1P1GLS/2D/lu_colamd/|P2P1/3D/lu_colamd/(4|6|8|10)/|P1P1GLS/3D/lu_colamd/'
lu_long='P2P1/2D/lu_colamd/256/|P2P1/3D/lu_colamd/12/'
case ${1:-all} in
  assembly) run assembly "$assembly" ;;
  lu) run lu "$lu" ;;
  lu-long) run lu-long "$lu_long" ;;
  all) run assembly "$assembly"; run lu "$lu"; run lu-long "$lu_long" ;;
  *) echo "usage: $0 [assembly|lu|lu-long|all]" >&2; exit 2 ;;
esac
