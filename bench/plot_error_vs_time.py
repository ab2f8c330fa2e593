#!/usr/bin/python3
"""Plots error against wall time for the five ALE schemes (bench_ale_step error).

    /tmp/bench_ale_step error --csv docs/img/error_vs_time.csv
    /usr/bin/python3 bench/plot_error_vs_time.py [docs/img/error_vs_time.csv [docs/img/error_vs_time.png]]

Use Debian's /usr/bin/python3 (python3-matplotlib). One panel per element pair; one line per
scheme (colour) and linearisation (solid: Newton, dashed: semi-implicit); the points along a
line are dt = T/10 ... T/320 (left to right: more steps, more time).
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

src = sys.argv[1] if len(sys.argv) > 1 else "docs/img/error_vs_time.csv"
dst = sys.argv[2] if len(sys.argv) > 2 else src.rsplit(".", 1)[0] + ".png"

series = defaultdict(list)  # (pair, scheme, lin) -> [(wall, err, steps)]
pairs, schemes = [], []
with open(src, newline="") as f:
    for row in csv.DictReader(f):
        key = (row["pair"], row["scheme"], row["linearisation"])
        series[key].append((float(row["wall_s"]), float(row["err_u_l2"]), int(row["steps"])))
        if row["pair"] not in pairs:
            pairs.append(row["pair"])
        if row["scheme"] not in schemes:
            schemes.append(row["scheme"])

colours = dict(zip(schemes, ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]))
markers = dict(zip(schemes, ["o", "s", "^", "D", "v"]))
styles = {"Newton": "-", "semi-implicit": "--"}

fig, axes = plt.subplots(1, len(pairs), figsize=(6.2 * len(pairs), 5.2), squeeze=False)
for ax, pair in zip(axes[0], pairs):
    for scheme in schemes:
        for lin, ls in styles.items():
            pts = sorted(series.get((pair, scheme, lin), []), key=lambda p: p[2])
            if not pts:
                continue
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], ls, color=colours[scheme], marker=markers[scheme],
                      markersize=4.5, markerfacecolor="none" if lin != "Newton" else colours[scheme],
                      label=f"{scheme}, {lin}")
    ax.set_title(f"2D {pair}, 4 x 4 mesh, dt = T/10 .. T/320")
    ax.set_xlabel("wall time of the whole run (s)")
    ax.set_ylabel(r"$\|u(T) - u_h\|_{L^2}$")
    ax.grid(True, which="major", alpha=0.5)
    ax.grid(True, which="minor", alpha=0.15)
handles, labels = axes[0][0].get_legend_handles_labels()
fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8.5, frameon=False)
fig.suptitle("ALE Navier-Stokes, manufactured solution (time error only): error vs wall time\n"
             "solid / filled: Newton (tol 1e-12); dashed / open: semi-implicit (one linear solve per step)",
             fontsize=10.5)
fig.tight_layout(rect=(0, 0.09, 1, 1))
fig.savefig(dst, dpi=130)
print("wrote", dst)
