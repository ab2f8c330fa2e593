#!/usr/bin/python3
"""Error against CPU time, fixed dt beside adaptive steps (docs/results.md, "Adaptive steps against a fixed dt").

    /usr/bin/python3 docs/img/fixed_adaptive_plot.py DKT_SUMMARY.csv ANNULUS_SMOOTH.csv ANNULUS_IMPULSIVE.csv [out.png]

DKT_SUMMARY.csv: OUT_DIR/summary.csv of bench/dkt_adaptive.sh (the DKT on one level: the larger
position error of the two disks at t = 0.1 s and the kissing-time error, against a fine fixed-dt
run). The annulus CSVs: `annulus speed --csv` with --tolerances (examples/annulus.cpp; rows with
k = -1 are the adaptive runs): the time error at T against the fine-dt FEM solution. A file
given as "-" is left out. Fixed dt solid with circles, adaptive dashed with triangles; one
colour per scheme (annulus) or per measure (DKT). Default output: docs/img/fixed_adaptive.png.
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
if len(sys.argv) < 4:
    sys.exit(__doc__)
dkt_src, smooth_src, impulsive_src = sys.argv[1:4]
dst = sys.argv[4] if len(sys.argv) > 4 else os.path.join(here, "fixed_adaptive.png")
names = {"BDF2_BDF2E": "BDF2/BDF2E", "BDF2_AB": "BDF2/AB", "BDF3_BDF3E": "BDF3/BDF3E", "MR_AB": "MR/AB", "BSS": "BSS"}
colours = {"MR_AB": "C0", "BDF2_BDF2E": "C1", "BDF2_AB": "C2", "BDF3_BDF3E": "C3", "BSS": "C4"}


def style(adaptive):
    return dict(ls="--" if adaptive else "-", marker="^" if adaptive else "o", mfc="none")


def annulus(ax, src, title):
    series = defaultdict(list)
    with open(src, newline="") as f:
        for r in csv.DictReader(f):
            adaptive = int(r["k"]) < 0
            series[(r["scheme"], r["linearisation"], adaptive)].append((float(r["cpu_s"]), float(r["E_time"])))
    for (scheme, lin, adaptive), pts in sorted(series.items()):
        pts.sort()
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=colours.get(scheme, "k"), **style(adaptive),
                  label=f"{names.get(scheme, scheme)} {lin}, {'adaptive' if adaptive else 'fixed dt'}")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("CPU time of the run (s)")
    ax.set_ylabel("time error at T (L2, against fine-dt FEM)")
    ax.legend(fontsize=7)


def dkt(ax, src):
    rows = list(csv.DictReader(open(src, newline="")))
    for key, label, colour in (("err_t0.1", "position error at t = 0.1 s (cm)", "C0"),
                               ("kiss_err_ms", "kissing-time error (ms)", "C3")):
        for kind in ("fixed", "adaptive"):
            pts = sorted((float(r["cpu_s"]), float(r[key])) for r in rows if r["kind"] == kind)
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=colour, **style(kind == "adaptive"),
                      label=f"{label}, {'adaptive' if kind == 'adaptive' else 'fixed dt'}")
    ax.set_title("DKT, level 2 (against fixed dt = 6.25e-5)", fontsize=10)
    ax.set_xlabel("CPU time of the run (s)")
    ax.set_ylabel("error")
    ax.legend(fontsize=7)


panels = [(src, kind) for src, kind in ((dkt_src, "dkt"), (smooth_src, "smooth"), (impulsive_src, "impulsive"))
          if src != "-"]
fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.6), squeeze=False)
for ax, (src, kind) in zip(axes[0], panels):
    if kind == "dkt":
        dkt(ax, src)
    elif kind == "smooth":
        annulus(ax, src, "Annulus, smooth start (mu = 1, T = 0.4)")
    else:
        annulus(ax, src, "Annulus, impulsive start (Table 1: mu = 0.01, T = 0.8)")
    ax.grid(True, which="both", alpha=0.3)
fig.suptitle("Error against CPU time: fixed dt (solid) and adaptive steps (dashed)")
fig.tight_layout()
fig.savefig(dst, dpi=110)
print("wrote", dst)
