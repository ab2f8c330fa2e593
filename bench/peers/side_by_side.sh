#!/usr/bin/env bash
# Side by side: the 2D P2/P1 Stokes matrix on the unit square cut into 2 N^2 triangles, assembled
# by alefsi and by every installed peer in one run, so that the ratios are measured, not quoted.
#
#   bench/peers/side_by_side.sh [N ...]            # default: 64 128 256 512
#   REPS=5 bench/peers/side_by_side.sh 128 256     # repetitions per program (default 3; minimum kept)
#
# Programs (same form 2 mu (D(u), D(v)) - (p, div v) - (q, div u), mu = 1, Dirichlet velocity
# on the whole boundary, lid (1, 0) on top; see the head of each file):
#   alefsi   bench/peers/alefsi_stokes.cpp       compiled here with g++ -O3 -march=native (1 and 2 threads)
#   deal.II  bench/peers/dealii/stokes_p2p1.cc   built with CMake if find_package(deal.II) succeeds
#            (Debian: apt-get install libdeal.ii-dev)
#   FreeFEM  bench/peers/stokes_p2p1.edp         run if FreeFem++ is on the PATH (apt-get install freefem++)
# A peer that is not installed is skipped with a message. Output: a table per N with the CPU
# time (process CPU, the one-core figure) of the pattern build and of the fill, their sum, the
# elements per CPU second, and the wall time of alefsi/deal.II (FreeFEM: CPU only, its clock());
# the load average is printed before each program runs (the machine may be shared: compare CPU
# columns). Everything is also written to build/peers/side_by_side-<date>.txt.
set -euo pipefail
cd "$(dirname "$0")/../.."
sizes=("$@")
[[ ${#sizes[@]} -gt 0 ]] || sizes=(64 128 256 512)
reps=${REPS:-3}
build=build/peers
mkdir -p "$build"
log="$build/side_by_side-$(date +%Y%m%d-%H%M%S).txt"
raw="$build/side_by_side-raw.txt"
: > "$raw"
load() { uptime | sed 's/.*load average: //'; }
say() { echo "$*" | tee -a "$log"; }

say "# side_by_side.sh $(date -u '+%Y-%m-%d %H:%M UTC'), sizes ${sizes[*]}, REPS=$reps, $(nproc) CPUs"

# --- alefsi ---------------------------------------------------------------------------------
cxx=${CXX:-g++}
if [[ ! -x $build/alefsi_stokes || bench/peers/alefsi_stokes.cpp -nt $build/alefsi_stokes ||
      -n $(find include -newer "$build/alefsi_stokes" -name '*.hpp' -print -quit) ]]; then
  say "building alefsi_stokes ($cxx -O3 -march=native)"
  "$cxx" -std=c++20 -O3 -march=native -DNDEBUG -Iinclude -isystem /usr/include/eigen3 \
    bench/peers/alefsi_stokes.cpp -o "$build/alefsi_stokes"
fi
have_dealii=0
if cmake -S bench/peers/dealii -B "$build/dealii" -DCMAKE_BUILD_TYPE=Release > "$build/dealii-cmake.log" 2>&1; then
  if cmake --build "$build/dealii" > "$build/dealii-build.log" 2>&1; then
    have_dealii=1
  else
    say "deal.II: found but the build failed, skipped (see $build/dealii-build.log)"
  fi
else
  say "deal.II: not installed (find_package(deal.II) failed; apt-get install libdeal.ii-dev), skipped"
fi
have_freefem=0
if command -v FreeFem++ > /dev/null; then
  have_freefem=1
else
  say "FreeFEM: not installed (no FreeFem++ on the PATH; apt-get install freefem++), skipped"
fi

export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
for n in "${sizes[@]}"; do
  say "## N = $n"
  say "load before alefsi (1 thread): $(load)"
  "$build/alefsi_stokes" "$n" "$reps" 1 | tee -a "$raw" >> "$log"
  say "load before alefsi (2 threads): $(load)"
  "$build/alefsi_stokes" "$n" "$reps" 2 | tee -a "$raw" >> "$log"
  if ((have_dealii)); then
    say "load before deal.II: $(load)"
    "$build/dealii/stokes_p2p1_dealii" "$n" "$reps" | tee -a "$raw" >> "$log"
  fi
  if ((have_freefem)); then
    say "load before FreeFEM: $(load)"
    FreeFem++ -nw -v 0 bench/peers/stokes_p2p1.edp -N "$n" -reps "$reps" 2>&1 | grep '^freefem' | tee -a "$raw" >> "$log"
  fi
done
say "load at the end: $(load)"

python3 - "$raw" <<'PY' | tee -a "$log"
import sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
# alefsi / dealii: name N cells unknowns nnz dofs_cpu pattern_cpu fill_cpu pattern_wall fill_wall [threads]
# freefem:         name N cells dofs nnz cpu (pattern + fill)
fill1, tot1 = {}, {}
for r in rows:
    if r[0] == "alefsi" and r[10] == "1":
        fill1[int(r[1])], tot1[int(r[1])] = float(r[7]), float(r[6]) + float(r[7])
print()
print("| program | N | cells | unknowns | nnz | pattern CPU s | fill CPU s | pattern + fill CPU s "
      "| fill el/s (CPU) | pattern + fill el/s (CPU) | fill wall s | CPU time / alefsi's: fill, pattern + fill |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
def ratio(x, ref, n):
    return f"{x / ref[n]:.1f}x" if n in ref else "-"
for r in rows:
    name, n, cells, dofs, nnz = r[0], int(r[1]), int(r[2]), int(r[3]), int(r[4])
    if name == "freefem":
        tot = float(r[5])
        print(f"| FreeFEM | {n} | {cells} | {dofs} | {nnz} | (in fill) | {tot:.4f} | {tot:.4f} | "
              f"{cells / tot:.3g} | {cells / tot:.3g} | | -, {ratio(tot, tot1, n)} |")
        continue
    pat, fill, wfill = float(r[6]), float(r[7]), float(r[9])
    label = "deal.II" if name == "dealii" else f"alefsi, {r[10]} thread{'s' if r[10] != '1' else ''}"
    tot = pat + fill
    print(f"| {label} | {n} | {cells} | {dofs} | {nnz} | {pat:.4f} | {fill:.4f} | {tot:.4f} | "
          f"{cells / fill:.3g} | {cells / tot:.3g} | {wfill:.4f} | {ratio(fill, fill1, n)}, {ratio(tot, tot1, n)} |")
print()
print("unknowns: alefsi after eliminating the fixed DOFs; deal.II all DOFs (constrained rows keep a")
print("diagonal entry); FreeFEM all DOFs (Dirichlet rows kept, tgv on the diagonal; its pattern and")
print("fill are one call). Ratios: the program's CPU time over alefsi's (1 thread) for the same N.")
PY
echo "written: $log"
