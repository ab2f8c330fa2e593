#!/usr/bin/env python3
"""Figures 8-10 of the paper (section 6.4) from examples/squirmer_diffraction's output.

usage: python3 examples/plot_diffraction.py DIR
Reads DIR/alone/bodies.csv (v*) and DIR/kappa_*/bodies.csv; writes DIR/fig8_trajectories.png
(squirmer paths, colour = t), DIR/fig9_angle.png (squirmer angle against t_hat = t v* / R) and
DIR/fig10_passive.png (passive disk x and y against t_hat), in units of R about the passive
disk's start (8, 4). Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

R, X0, Y0 = 0.125, 8.0, 4.0


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main(d):
    alone = read(f"{d}/alone/bodies.csv")
    t, x = alone["t"], alone["x0"]
    i1 = min(range(len(t)), key=lambda i: abs(t[i] - 1))
    i3 = min(range(len(t)), key=lambda i: abs(t[i] - 3))
    v = (x[i3] - x[i1]) / (t[i3] - t[i1])
    runs = sorted(glob.glob(f"{d}/kappa_*/bodies.csv"), key=lambda p: float(p.split("kappa_")[1].split("/")[0]))
    f8, a8 = plt.subplots(figsize=(8, 4))
    f9, a9 = plt.subplots(figsize=(6, 4))
    f10, a10 = plt.subplots(1, 2, figsize=(11, 4))
    for p in runs:
        k = p.split("kappa_")[1].split(os.sep)[0]
        c = read(p)
        th = [ti * v / R for ti in c["t"]]
        sc = a8.scatter([(xi - X0) / R for xi in c["x0"]], [(yi - Y0) / R for yi in c["y0"]], c=c["t"], s=2, cmap="viridis")
        a8.annotate(f"k={k}", ((c["x0"][-1] - X0) / R, (c["y0"][-1] - Y0) / R), fontsize=7)
        a9.plot(th, c["angle0"], label=f"kappa = {k}")
        a10[0].plot(th, [(xi - X0) / R for xi in c["x1"]], label=f"kappa = {k}")
        a10[1].plot(th, [(yi - Y0) / R for yi in c["y1"]], label=f"kappa = {k}")
    a8.add_patch(plt.Circle((0, 0), 1, color="grey", alpha=0.5))
    a8.set_aspect("equal"), a8.set_xlabel("x / R"), a8.set_ylabel("y / R"), a8.grid(alpha=0.3)
    f8.colorbar(sc, ax=a8, label="t [s]")
    a9.set_xlabel("t v* / R"), a9.set_ylabel("squirmer angle [rad]"), a9.grid(alpha=0.3), a9.legend(fontsize=7)
    for a, n in zip(a10, ("x_g^1 / R", "y_g^1 / R")):
        a.set_xlabel("t v* / R"), a.set_ylabel(n), a.grid(alpha=0.3)
    a10[1].legend(fontsize=7)
    for f, n in ((f8, "fig8_trajectories"), (f9, "fig9_angle"), (f10, "fig10_passive")):
        f.tight_layout()
        f.savefig(f"{d}/{n}.png", dpi=120)
    print(f"v* = {v:.4f}; wrote {d}/fig8_trajectories.png, fig9_angle.png, fig10_passive.png")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
