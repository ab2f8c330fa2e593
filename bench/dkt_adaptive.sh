#!/usr/bin/env bash
# Error against cost on the DKT (paper 6.2), fixed dt against adaptive steps, on one mesh level:
# each run's positions at t = 0.1, 0.2, 0.3 s and kissing time against a reference run with a
# small fixed dt on the same initial mesh and with the same GLS tau, beside its steps, wall and
# CPU time
# (docs/results.md, "Adaptive steps against a fixed dt"); the table also goes to OUT_DIR/summary.csv
# (plot: docs/img/fixed_adaptive_plot.py).
# Needs the dkt example built: cmake --preset release && cmake --build --preset release --target dkt
# usage: bench/dkt_adaptive.sh [OUT_DIR] [LEVEL] [T_END]
#   defaults: build/release/output/dkt_adaptive  2  0.3
#   levels (h_body / h_far): 1: 0.04 / 0.3, 2: 0.02 / 0.15, 3: 0.01 / 0.075, 4: 0.005 / 0.0375,
#     5: 0.0025 / 0.01875
#   environment: DTS (fixed steps, default "2e-3 1e-3 5e-4 2.5e-4"), REF_DT (default 6.25e-5),
#     TOLS (adaptive tolerances, default "1e-2 3e-3 1e-3 3e-4 1e-4"), FIRST_DT (the adaptive runs'
#     first step, default 1e-4), OFFSET (cm, default 0.05, as bench/dkt_levels.sh), TAU_DT (the
#     step in the GLS tau of every run, fixed or adaptive, so that all solve one discrete
#     problem; default 1e-3),
#     BUILD_DIR (default build/release), RERUN=0 reuses finished runs.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/release/output/dkt_adaptive}
level=${2:-2}
t_end=${3:-0.3}
dts=${DTS:-2e-3 1e-3 5e-4 2.5e-4}
ref_dt=${REF_DT:-6.25e-5}
tols=${TOLS:-1e-2 3e-3 1e-3 3e-4 1e-4}
first_dt=${FIRST_DT:-1e-4}
offset=${OFFSET:-0.05}
tau_dt=${TAU_DT:-1e-3}
build=${BUILD_DIR:-build/release}
rerun=${RERUN:-1}
declare -A spec=([1]="0.04 0.3" [2]="0.02 0.15" [3]="0.01 0.075" [4]="0.005 0.0375" [5]="0.0025 0.01875")
[[ -n "${spec[$level]:-}" ]] || { echo "unknown level $level (1-5)"; exit 2; }
read -r hb hf <<< "${spec[$level]}"
mkdir -p "$out"
one() {  # name, extra options
  local dir="$out/$1"
  shift
  if [[ "$rerun" == 1 || ! -s "$dir.log" ]] || ! grep -q "^wall" "$dir.log"; then
    echo "== $(basename "$dir"): $*, load $(cut -d' ' -f1-3 /proc/loadavg)"
    OPENBLAS_NUM_THREADS=1 /usr/bin/time -v "$build/examples/dkt" --h-body "$hb" --h-far "$hf" --t-end "$t_end" \
      --offset "$offset" --tau-dt "$tau_dt" --output "$dir" --vtu-every 0 --checkpoint-every 0 "$@" > "$dir.log" \
      2> "$dir.time" ||
      echo "$dir failed"
  fi
}
one "ref_dt$ref_dt" --dt "$ref_dt" --tolerance 0
for dt in $dts; do one "fixed_dt$dt" --dt "$dt" --tolerance 0; done
for tol in $tols; do one "adaptive_tol$tol" --dt "$first_dt" --tolerance "$tol"; done

# --- summary from the logs ---------------------------------------------------------------
python3 - "$out" "$ref_dt" "$dts" "$tols" "$level" <<'EOF'
import math, re, sys
out, ref_dt, dts, tols, level = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4].split(), sys.argv[5]

def parse(name):
    log, tim = open(f"{out}/{name}.log").read(), open(f"{out}/{name}.time").read()
    r = {"name": name}
    m = re.search(r"kissing time \(first minimum of the gap\): ([0-9.]+)", log)
    r["kiss"] = float(m.group(1)) if m else math.nan
    for t, x0, y0, x1, y1 in re.findall(
            r"^t = ([0-9.]+): upper \(([-0-9.]+), ([-0-9.]+)\), lower \(([-0-9.]+), ([-0-9.]+)\)", log, re.M):
        r[round(float(t), 3)] = ((float(x0), float(y0)), (float(x1), float(y1)))
    m = re.search(r"in (\d+) steps \((\d+) rejected\), (\d+) remeshes", log)
    r["steps"], r["rejected"], r["remeshes"] = (int(m.group(i)) for i in (1, 2, 3))
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([0-9.]+)", tim)
    r["wall"] = int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3))
    user = float(re.search(r"User time \(seconds\): ([0-9.]+)", tim).group(1))
    system = float(re.search(r"System time \(seconds\): ([0-9.]+)", tim).group(1))
    r["cpu"] = user + system
    r["rss"] = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", tim).group(1)) / 1024
    return r

def dist(a, b, t):
    if t not in a or t not in b:
        return math.nan
    return max(math.hypot(p[0] - q[0], p[1] - q[1]) for p, q in zip(a[t], b[t]))

ref = parse(f"ref_dt{ref_dt}")
print(f"DKT level {level}, reference: fixed dt {ref_dt} ({ref['steps']} steps, {ref['cpu']:.0f} CPU-s), "
      f"kiss {ref['kiss']:.5f} s")
print("| run | steps (rejected) | remeshes | wall s | CPU s | peak MB | position error t=0.1 | t=0.2 | t=0.3 | kiss error ms |")
print("|---|---|---|---|---|---|---|---|---|---|")
csv = open(f"{out}/summary.csv", "w")
csv.write("run,kind,value,steps,rejected,remeshes,wall_s,cpu_s,peak_mb,err_t0.1,err_t0.2,err_t0.3,kiss_err_ms\n")
for name in [f"fixed_dt{d}" for d in dts] + [f"adaptive_tol{t}" for t in tols]:
    try:
        r = parse(name)
    except (OSError, AttributeError):
        print(f"| {name} | failed |")
        continue
    e = [dist(r, ref, t) for t in (0.1, 0.2, 0.3)]
    print(f"| {name.replace('_', ' ')} | {r['steps']} ({r['rejected']}) | {r['remeshes']} | {r['wall']:.1f} | "
          f"{r['cpu']:.1f} | {r['rss']:.0f} | {e[0]:.1e} | {e[1]:.1e} | {e[2]:.1e} | "
          f"{1e3 * abs(r['kiss'] - ref['kiss']):.3f} |")
    kind, value = name.split("_")
    csv.write(f"{name},{kind},{value.lstrip('dtol')},{r['steps']},{r['rejected']},{r['remeshes']},{r['wall']:.2f},"
              f"{r['cpu']:.2f},{r['rss']:.0f},{e[0]:.3e},{e[1]:.3e},{e[2]:.3e},{1e3 * abs(r['kiss'] - ref['kiss']):.4f}\n")
print(f"wrote {out}/summary.csv")
EOF
