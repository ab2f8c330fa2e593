#!/usr/bin/env python3
"""Plots the bodies' time series written by alefsi's run driver (DIR/bodies.csv).

usage: python3 examples/plot_bodies.py DIR [DIR2 ...] [--labels a,b,...] [--out PREFIX]

Writes PREFIX_positions.png (x and y of every body against t), PREFIX_velocities.png
(V1, V2 and w against t) and PREFIX_trajectories.png (the paths in the x-y plane). With
several folders (e.g. three mesh / dt levels) the curves are overlaid. PREFIX defaults to
DIR/dkt. Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(folder):
    with open(f"{folder}/bodies.csv") as f:
        rows = list(csv.DictReader(f))
    cols = {k: [float(r[k]) for r in rows] for k in rows[0]}
    n = sum(1 for k in cols if k.startswith("x") and k[1:].isdigit())
    return cols, n


def main(argv):
    folders, labels, out = [], None, None
    i = 0
    while i < len(argv):
        if argv[i] == "--labels":
            labels = argv[i + 1].split(",")
            i += 2
        elif argv[i] == "--out":
            out = argv[i + 1]
            i += 2
        else:
            folders.append(argv[i])
            i += 1
    if not folders:
        print(__doc__)
        return 2
    labels = labels or folders
    out = out or f"{folders[0]}/dkt"
    data = [read(f) for f in folders]
    styles = ["-", "--", ":", "-."]

    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for (c, n), lab, ls in zip(data, labels, styles * 4):
        for k in range(n):
            ax[0].plot(c["t"], c[f"x{k}"], ls, label=f"body {k} ({lab})")
            ax[1].plot(c["t"], c[f"y{k}"], ls, label=f"body {k} ({lab})")
    ax[0].set_ylabel("x [cm]"), ax[1].set_ylabel("y [cm]")
    for a in ax:
        a.set_xlabel("t [s]"), a.grid(alpha=0.3)
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(f"{out}_positions.png", dpi=120)

    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    for (c, n), lab, ls in zip(data, labels, styles * 4):
        for k in range(n):
            for a, key in zip(ax, ("vx", "vy", "omega")):
                a.plot(c["t"], c[f"{key}{k}"], ls, label=f"body {k} ({lab})")
    for a, name in zip(ax, ("V1 [cm/s]", "V2 [cm/s]", "w [1/s]")):
        a.set_xlabel("t [s]"), a.set_ylabel(name), a.grid(alpha=0.3)
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(f"{out}_velocities.png", dpi=120)

    fig, ax = plt.subplots(figsize=(3.5, 8))
    for (c, n), lab, ls in zip(data, labels, styles * 4):
        for k in range(n):
            ax.plot(c[f"x{k}"], c[f"y{k}"], ls, label=f"body {k} ({lab})")
    ax.set_aspect("equal"), ax.set_xlabel("x [cm]"), ax.set_ylabel("y [cm]"), ax.grid(alpha=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(f"{out}_trajectories.png", dpi=120)
    print(f"wrote {out}_positions.png, {out}_velocities.png, {out}_trajectories.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
