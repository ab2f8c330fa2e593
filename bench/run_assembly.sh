#!/usr/bin/env bash
# Runs bench_assembly in parts, each benchmark repeated, and keeps the console table, the JSON
# and a summary with the *minimum* over the repetitions (the machine is shared: the minimum is
# the least disturbed run).
#
#   bench/run_assembly.sh assembly   # Stokes: pattern / kernel / kernel_quad / scatter / assemble(_t2), 2D and 3D
#   bench/run_assembly.sh ns         # Navier-Stokes Jacobian: ns_newton(_kernel|_t2), ns_semi, 2D and 3D
#   bench/run_assembly.sh threads    # 1 against 2 threads: assemble(_t2), ns_newton(_t2), 2D and 3D
#                                    # (needs an idle machine to mean anything: see the load printed)
#   bench/run_assembly.sh pattern    # pattern build (constructor + take_pattern; and the rebuild after a
#                                    # remesh, repattern) next to one assembly (the fill), 2D and 3D
#   bench/run_assembly.sh lu         # SparseLU, all but the two long cases (~2 min)
#   bench/run_assembly.sh lu-long    # 2D P2/P1 N = 256 (COLAMD) and 3D P2/P1 N = 12 (~6 min, 9.5 GB peak)
#   bench/run_assembly.sh all
#   REPS=5 BIN=build/asm-bench/bench/bench_assembly bench/run_assembly.sh assembly 'P2P1/2D'
#   bench/run_assembly.sh custom 'P2P1/3D/(kernel|assemble)/(8|16)/'   # any filter, REPS repetitions
#
# An optional second argument, a name prefix without the trailing slash ('P2P1/2D', '3D'),
# restricts the part to those benchmarks.
# REPS (default 3): repetitions of every assembly benchmark (lu parts: 1).
# Output: build/bench/results/<part>-<date>.{txt,json,min.txt}. Build first:
#   cmake --preset bench && cmake --build --preset bench --target bench_assembly
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN:-build/bench/bench/bench_assembly}
[[ -x $bin ]] || { echo "build $bin first (see the header of this script)" >&2; exit 1; }
out=${OUT:-build/bench/results}
mkdir -p "$out"
stamp=$(date +%Y%m%d-%H%M%S)
reps=${REPS:-3}

run() {  # name filter repetitions
  local name=$1 filter=$2 r=$3
  echo "== $name: --benchmark_filter='$filter' --benchmark_repetitions=$r  ($(uptime | sed 's/.*load/load/'))"
  "$bin" --benchmark_filter="$filter" --benchmark_counters_tabular=true --benchmark_repetitions="$r" \
    --benchmark_out="$out/$name-$stamp.json" --benchmark_out_format=json | tee "$out/$name-$stamp.txt"
  echo "== done ($(uptime | sed 's/.*load/load/'))"
  summary "$out/$name-$stamp.json" | tee "$out/$name-$stamp.min.txt"
}

# Minimum over the repetitions of wall and CPU time per benchmark; rates from the minima.
summary() {
  python3 - "$1" <<'PY'
import json, sys, collections
d = json.load(open(sys.argv[1]))
runs = collections.OrderedDict()
for b in d["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    runs.setdefault(b["run_name"], []).append(b)
print(f"{'benchmark (min over repetitions)':34s} {'reps':>4s} {'wall ms':>10s} {'CPU ms':>10s} {'el/s wall':>10s} {'el/s CPU':>10s} {'GF/s wall':>9s} {'GF/s CPU':>9s}")
for name, bs in runs.items():
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[bs[0]["time_unit"]]
    wall = min(b["real_time"] for b in bs) * scale
    cpu = min(b["cpu_time"] for b in bs) * scale
    cells = bs[0].get("cells", 0)
    flop = bs[0].get("flop/el", 0)
    gf = f"{cells * flop / wall * 1e-9:9.2f} {cells * flop / cpu * 1e-9:9.2f}" if flop else ""
    short = name.split("/min_time")[0].split("/iterations")[0]
    print(f"{short:34s} {len(bs):4d} {wall * 1e3:10.2f} {cpu * 1e3:10.2f} {cells / wall:10.3e} {cells / cpu:10.3e} {gf}")
PY
}

stokes='/(pattern|kernel|kernel_quad|scatter|assemble|assemble_t2)/'
ns='/(ns_newton|ns_newton_kernel|ns_newton_kernel_quad|ns_newton_t2|ns_semi)/'
threads='/(assemble|assemble_t2|ns_newton|ns_newton_t2)/'
pattern='/(pattern|repattern|assemble)/'
lu='P2P1/2D/lu_colamd/(16|32|64|128)/|/lu_amd/|P1P1GLS/2D/lu_colamd/|P2P1/3D/lu_colamd/(4|6|8|10)/|P1P1GLS/3D/lu_colamd/'
lu_long='P2P1/2D/lu_colamd/256/|P2P1/3D/lu_colamd/12/'
extra=${2:-}
with() { [[ -n $extra ]] && echo "($extra).*$1" || echo "$1"; }
case ${1:-all} in
  assembly) run assembly "$(with "$stokes")" "$reps" ;;
  ns) run ns "$(with "$ns")" "$reps" ;;
  threads) run threads "$(with "$threads")" "$reps" ;;
  pattern) run pattern "$(with "$pattern")" "$reps" ;;
  lu) run lu "$(with "$lu")" 1 ;;
  lu-long) run lu-long "$(with "$lu_long")" 1 ;;
  custom) run custom "${2:?custom needs a filter}" "$reps" ;;
  all) run assembly "$stokes" "$reps"; run ns "$ns" "$reps"; run lu "$lu" 1; run lu-long "$lu_long" 1 ;;
  *) echo "usage: $0 [assembly|ns|threads|pattern|lu|lu-long|all] [name-prefix] | custom <filter>" >&2; exit 2 ;;
esac
