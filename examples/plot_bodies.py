#!/usr/bin/env python3
"""Plots the bodies' time series written by alefsi's run driver (DIR/bodies.csv).

usage: python3 examples/plot_bodies.py DIR [DIR2 ...] [--labels a,b,...] [--out PREFIX]
                                      [--differences] [--spread DIR_A,DIR_B,LABEL ...]

Writes PREFIX_positions.png (x and y of every body against t), PREFIX_velocities.png
(V1, V2 and w against t), PREFIX_trajectories.png (the paths in the x-y plane) and
PREFIX_steps.png (dt against t, remeshes marked). With
several folders (e.g. mesh / dt levels) the curves are overlaid. PREFIX defaults to
DIR/dkt. With --differences also PREFIX_differences.png: for each pair of successive folders
the largest distance between the positions of a body in the two runs against t (log scale),
plus one dashed curve per --spread DIR_A,DIR_B,LABEL (e.g. two runs of one level on
different initial meshes). Needs matplotlib (Debian: python3-matplotlib).
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


def distance(a, b):
    """t and max over bodies of |X_a(t) - X_b(t)|, at the times of run a inside run b's range
    (b linearly interpolated in t)."""
    (ca, n), (cb, _) = a, b
    tb = cb["t"]
    ts, ds, j = [], [], 0
    for i, t in enumerate(ca["t"]):
        if t < tb[0] or t > tb[-1]:
            continue
        while j + 1 < len(tb) and tb[j + 1] < t:
            j += 1
        k = min(j + 1, len(tb) - 1)
        w = 0.0 if k == j else (t - tb[j]) / (tb[k] - tb[j])
        d = 0.0
        for m in range(n):
            xb = cb[f"x{m}"][j] + w * (cb[f"x{m}"][k] - cb[f"x{m}"][j])
            yb = cb[f"y{m}"][j] + w * (cb[f"y{m}"][k] - cb[f"y{m}"][j])
            d = max(d, ((ca[f"x{m}"][i] - xb) ** 2 + (ca[f"y{m}"][i] - yb) ** 2) ** 0.5)
        ts.append(t), ds.append(max(d, 1e-12))
    return ts, ds


def main(argv):
    folders, labels, out, differences, spreads = [], None, None, False, []
    i = 0
    while i < len(argv):
        if argv[i] == "--differences":
            differences = True
            i += 1
        elif argv[i] == "--spread":
            spreads.append(argv[i + 1].split(","))
            i += 2
        elif argv[i] == "--labels":
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

    # the steps: dt against t (adaptive runs vary it; remeshes marked)
    fig, ax = plt.subplots(figsize=(6.5, 3.5))
    for (c, _), lab, ls in zip(data, labels, styles * 4):
        ax.semilogy(c["t"], c["dt"], ls, label=lab)
        rt = [t for t, r in zip(c["t"], c["remeshed"]) if r > 0]
        rd = [d for d, r in zip(c["dt"], c["remeshed"]) if r > 0]
        ax.semilogy(rt, rd, "k.", ms=3)
    ax.set_xlabel("t [s]"), ax.set_ylabel("dt [s] (dots: remeshes)"), ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(f"{out}_steps.png", dpi=120)
    print(f"wrote {out}_steps.png")

    if differences:
        fig, ax = plt.subplots(figsize=(6.5, 4))
        for (a, la), (b, lb) in zip(zip(data, labels), zip(data[1:], labels[1:])):
            ax.semilogy(*distance(a, b), label=f"{la} -> {lb}")
        for sp in spreads:
            ax.semilogy(*distance(read(sp[0]), read(sp[1])), "--", label=sp[2] if len(sp) > 2 else sp[1])
        ax.set_xlabel("t [s]"), ax.set_ylabel("max over bodies |X_a - X_b| [cm]"), ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(f"{out}_differences.png", dpi=120)
        print(f"wrote {out}_differences.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
