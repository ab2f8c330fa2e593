#!/usr/bin/env bash
# DKT (paper 6.2) on mesh / dt levels for BDF2/BDF2E and BDF3/BDF3E: kissing time and positions
# at t = 0.1, 0.2, 0.3 s, the changes between successive levels with their ratios, and (with
# several offsets) the spread between runs of one level whose initial meshes differ
# (docs/results.md, "Drafting, kissing and tumbling").
# Needs the examples built, e.g.
#   cmake --preset release && cmake --build --preset release --target dkt dkt_bdf3
# usage: bench/dkt_levels.sh [OUT_DIR] [T_END] [OFFSETS] [EXECUTABLES] [LEVELS]
#   defaults: build/release/output/dkt_levels  0.35 (s)  "0.05" (cm)  "dkt dkt_bdf3"  "1 2 3"
#   levels (h_body / h_far / dt): 1: 0.04 / 0.3 / 2e-3, 2: 0.02 / 0.15 / 1e-3,
#     3: 0.01 / 0.075 / 5e-4, 4: 0.005 / 0.0375 / 2.5e-4 (about 8 min CPU and 0.3 GB per run with
#     the reused factorisations), 5: 0.0025 / 0.01875 / 1.25e-4
#   OFFSETS: the upper disk's shift to the left; the first is the study, further ones (e.g.
#     "0.05 0.050001") only change the initial mesh and measure the spread due to the mesh.
#   environment: BUILD_DIR (default build/release) holds examples/dkt*; SPRING_RANGE (cm,
#     default 0.04) is passed to every run; RERUN=0 reuses finished runs (their .log files).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/release/output/dkt_levels}
t_end=${2:-0.35}
offsets=${3:-0.05}
exes=${4:-dkt dkt_bdf3}
levels=${5:-1 2 3}
build=${BUILD_DIR:-build/release}
spring=${SPRING_RANGE:-0.04}
rerun=${RERUN:-1}
declare -A spec=([1]="0.04 0.3 2e-3" [2]="0.02 0.15 1e-3" [3]="0.01 0.075 5e-4" [4]="0.005 0.0375 2.5e-4" [5]="0.0025 0.01875 1.25e-4")
mkdir -p "$out"
for exe in $exes; do
  for offset in $offsets; do
    for l in $levels; do
      [[ -n "${spec[$l]:-}" ]] || { echo "unknown level $l (1-5)"; exit 2; }
      read -r hb hf dt <<< "${spec[$l]}"
      dir="$out/${exe}_o${offset}_L$l"
      if [[ "$rerun" == 1 || ! -s "$dir.log" ]] || ! grep -q "^wall" "$dir.log"; then
        echo "== $exe L$l (h_body $hb, h_far $hf, dt $dt, offset $offset, spring range $spring), load $(cut -d' ' -f1-3 /proc/loadavg)"
        OPENBLAS_NUM_THREADS=1 /usr/bin/time -v "$build/examples/$exe" --h-body "$hb" --h-far "$hf" --dt "$dt" --tolerance 0 \
          --t-end "$t_end" --offset "$offset" --spring-range "$spring" --output "$dir" --vtu-every 0 \
          --checkpoint-every 0 > "$dir.log" 2> "$dir.time" || echo "$exe L$l offset $offset failed"
      fi
    done
  done
done

# --- summary from the logs ---------------------------------------------------------------
python3 - "$out" "$offsets" "$exes" "$levels" <<'EOF'
import csv, math, re, sys
out, offsets, exes, levels = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), sys.argv[4].split()

def parse(base):
    try:
        log, tim = open(base + ".log").read(), open(base + ".time").read()
    except OSError:
        return None
    r = {"nodes": int(re.search(r": (\d+) nodes", log).group(1))}
    m = re.search(r"kissing time \(first minimum of the gap\): ([0-9.]+)", log)
    r["kiss"] = float(m.group(1)) if m else math.nan
    for t, x0, y0, x1, y1 in re.findall(
            r"^t = ([0-9.]+): upper \(([-0-9.]+), ([-0-9.]+)\), lower \(([-0-9.]+), ([-0-9.]+)\)", log, re.M):
        r[round(float(t), 3)] = ((float(x0), float(y0)), (float(x1), float(y1)))
    try:  # full precision from DIR/bodies.csv (the log rounds to 1e-4): the same positions and kiss
        with open(base + "/bodies.csv") as f:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
        for row in rows:
            for t in (0.1, 0.2, 0.3):
                if abs(row["t"] - t) < 0.5 * row["dt"]:
                    r[t] = ((row["x0"], row["y0"]), (row["x1"], row["y1"]))
        g = [(row["t"], math.hypot(row["x0"] - row["x1"], row["y0"] - row["y1"]) - 0.25) for row in rows]
        for (t0, g0), (t1, g1), (t2, g2) in zip(g, g[1:], g[2:]):  # as examples/dkt.cpp
            if g1 < 0.125 and g1 <= g0 and g2 > g1:
                a, b, fa, fb = t1 - t0, t1 - t2, g1 - g0, g1 - g2
                den = a * fb - b * fa
                r["kiss"] = t1 - (0.5 * (a * a * fb - b * b * fa) / den if den != 0 else 0)
                break
    except (OSError, KeyError, ValueError):
        pass
    m = re.search(r"in (\d+) steps \((\d+) rejected\), (\d+) remeshes, worst quality ([0-9.]+), smallest gap ([-0-9.e+]+)", log)
    if m:
        r.update(steps=int(m.group(1)), rejected=int(m.group(2)), remeshes=int(m.group(3)),
                 q=float(m.group(4)), gap=float(m.group(5)))
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([0-9.]+)", tim)
    if wall:
        h, mi, s = wall.groups()
        r["wall"] = 3600 * int(h or 0) + 60 * int(mi) + float(s)
    cpu = [float(v) for v in re.findall(r"(?:User|System) time \(seconds\): ([0-9.]+)", tim)]
    r["cpu"] = sum(cpu) if cpu else math.nan
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", tim)
    r["rss"] = int(m.group(1)) / 1024 if m else math.nan
    return r

def dist(a, b, t):  # largest displacement of the two disks between runs a and b at time t
    if t not in a or t not in b:
        return math.nan
    return max(math.hypot(a[t][k][0] - b[t][k][0], a[t][k][1] - b[t][k][1]) for k in (0, 1))

times = (0.1, 0.2, 0.3)
for exe in exes:
    runs = {o: {l: parse(f"{out}/{exe}_o{o}_L{l}") for l in levels} for o in offsets}
    for o in offsets:
        print(f"\n{exe}, offset {o}: level | nodes | kissing t | upper (x, y), lower (x, y) at "
              "t = 0.1 / 0.2 / 0.3 | remeshes | worst q | min gap | wall / CPU s | RSS MB")
        for l in levels:
            r = runs[o][l]
            if r is None:
                print(f"  L{l}: missing"); continue
            pos = " / ".join(f"({r[t][0][0]:.4f}, {r[t][0][1]:.4f}), ({r[t][1][0]:.4f}, {r[t][1][1]:.4f})"
                             if t in r else "-" for t in times)
            print(f"  L{l} | {r['nodes']} | {r['kiss']:.4f} | {pos} | {r.get('remeshes', '-')} | "
                  f"{r.get('q', math.nan):.3f} | {r.get('gap', math.nan):.1e} | "
                  f"{r.get('wall', math.nan):.0f} / {r['cpu']:.0f} | {r['rss']:.0f}")
    o = offsets[0]
    print(f"\n{exe}, offset {o}: change between successive levels (kissing t in s; positions: the "
          "larger displacement of the two disks, cm) and ratio to the previous change")
    prev = None
    for a, b in zip(levels, levels[1:]):
        ra, rb = runs[o][a], runs[o][b]
        if ra is None or rb is None:
            continue
        d = [abs(ra["kiss"] - rb["kiss"])] + [dist(ra, rb, t) for t in times]
        ratio = "" if prev is None else "  ratios " + " ".join(f"{p / c:.1f}" if c > 0 else "-" for p, c in zip(prev, d))
        print(f"  L{a}->L{b}: kiss {d[0]:.1e}, x(0.1) {d[1]:.1e}, x(0.2) {d[2]:.1e}, x(0.3) {d[3]:.1e}{ratio}")
        prev = d
    if len(offsets) > 1:
        print(f"{exe}: spread within a level (runs with offsets {' '.join(offsets[1:])} against {o}: "
              "only the initial mesh differs)")
        for l in levels:
            for o2 in offsets[1:]:
                ra, rb = runs[o][l], runs[o2][l]
                if ra is None or rb is None:
                    continue
                d = [abs(ra["kiss"] - rb["kiss"])] + [dist(ra, rb, t) for t in times]
                same = " (the same initial mesh: identical runs)" if all(v == 0 for v in d if v == v) else ""
                print(f"  L{l} ({o2}): kiss {d[0]:.1e}, " +
                      ", ".join(f"x({t}) {v:.1e}" for t, v in zip(times, d[1:])) + same)
EOF
