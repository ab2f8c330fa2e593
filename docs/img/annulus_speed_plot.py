#!/usr/bin/python3
"""Speed against error on the annulus (docs/results.md, "Speed against error (annulus, smooth start, mu = 1)").

    /usr/bin/python3 docs/img/annulus_speed_plot.py docs/img/annulus_speed.csv [out.png]

The CSV is from `annulus speed --csv` (examples/annulus.cpp). Four log-log panels: rows E
against the FD reference (total error: time + space) and against the fine-dt FEM solution on
the same mesh (time error alone); columns wall time and CPU time of the run. One colour per
scheme, solid Newton, dashed semi-implicit; along a line dt = 0.02 ... 0.00125 (left to right).
Default output: docs/img/annulus_speed_error.png.
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "annulus_speed.csv")
dst = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "annulus_speed_error.png")

names = {"MR_AB": "MR/AB", "BDF2_BDF2E": "BDF2/BDF2E", "BDF2_AB": "BDF2/AB", "BDF3_BDF3E": "BDF3/BDF3E", "BSS": "BSS"}
colours = {"MR_AB": "C0", "BDF2_BDF2E": "C1", "BDF2_AB": "C2", "BDF3_BDF3E": "C3", "BSS": "C4"}
series = defaultdict(list)
with open(src, newline="") as f:
    for r in csv.DictReader(f):
        series[(r["scheme"], r["linearisation"])].append(
            (float(r["wall_s"]), float(r["cpu_s"]), float(r["E_fd"]), float(r["E_time"])))

fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), sharex="col")
for (scheme, lin), pts in series.items():
    pts.sort(key=lambda p: p[1])
    style = "-" if lin == "newton" else "--"
    marker = "o" if lin == "newton" else "s"
    label = f"{names.get(scheme, scheme)}, {'Newton' if lin == 'newton' else 'semi-implicit'}"
    for row, e in enumerate((2, 3)):
        for col, t in enumerate((0, 1)):
            axes[row][col].loglog([p[t] for p in pts], [p[e] for p in pts], style, marker=marker, mfc="none",
                                  color=colours.get(scheme, "k"), label=label)
axes[0][0].set_ylabel("E = ||u - u_h||_L2 at T = 0.4 (against FD)")
axes[1][0].set_ylabel("time error (against fine-dt FEM)")
axes[1][0].set_xlabel("wall time of the run (s; shared, loaded machine: noisy)")
axes[1][1].set_xlabel("CPU time of the run (s)")
for ax in axes.flat:
    ax.grid(True, which="both", alpha=0.3)
axes[0][1].legend(fontsize=7, ncol=2)
fig.suptitle("Annulus, smooth start (mu = 1, rho_1 = 1.25), P2/P1, h = 0.08: error against run time")
fig.tight_layout()
fig.savefig(dst, dpi=110)
print("wrote", dst)
