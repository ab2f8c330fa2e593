#!/usr/bin/python3
"""Figures 3 and 4 of the paper (section 6.1) from the output of examples/sphere_squirmer.cpp.

Usage: /usr/bin/python3 examples/plot_sphere_squirmer.py DIR [--out OUTDIR]

Reads DIR/plane_{translation,squirmer}_{far,near}.csv (velocity sampled on z = 0) and
DIR/decay.csv (|u| against r), writes OUTDIR/sphere_squirmer_streamlines.png (Figure 3:
streamlines on the plane z = 0, sedimentation-like case left, squirmer right, whole box on top,
the near field below, coloured by log10 |u|) and OUTDIR/sphere_squirmer_decay.png (Figure 4:
|u| against r / R, log-log, with r^-1, r^-2, r^-3 slopes). OUTDIR defaults to DIR.
Needs numpy and matplotlib (Debian: python3-matplotlib).
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

R = 0.25


def read_plane(path):
    d = np.genfromtxt(path, delimiter=",", names=True)
    n = int(round(np.sqrt(len(d))))
    x = d["x"].reshape(n, n)[0, :]
    y = d["y"].reshape(n, n)[:, 0]
    return x, y, d["ux"].reshape(n, n), d["uy"].reshape(n, n)


def streamlines(ax, path, title):
    x, y, ux, uy = read_plane(path)
    speed = np.hypot(ux, uy)
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = np.log10(np.where(speed > 0, speed, np.nan))
    ax.pcolormesh(x / R, y / R, logs, shading="auto", cmap="viridis", vmin=-7, vmax=0)
    ux = np.nan_to_num(ux)
    uy = np.nan_to_num(uy)
    ax.streamplot(x / R, y / R, ux, uy, density=1.3, color="w", linewidth=0.6, arrowsize=0.6)
    ax.add_patch(plt.Circle((0, 0), 1, color="0.3"))
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x / R", fontsize=8)
    ax.set_ylabel("y / R", fontsize=8)
    ax.tick_params(labelsize=7)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    out = a.out or a.dir
    os.makedirs(out, exist_ok=True)

    # Figure 3
    fig, axes = plt.subplots(2, 2, figsize=(8, 7.2))
    for col, (case, name) in enumerate([("translation", "sedimentation-like"), ("squirmer", "squirmer")]):
        streamlines(axes[0, col], os.path.join(a.dir, f"plane_{case}_far.csv"), name + ", whole box")
        streamlines(axes[1, col], os.path.join(a.dir, f"plane_{case}_near.csv"), name + ", near field")
    sm = plt.cm.ScalarMappable(cmap="viridis", norm=matplotlib.colors.Normalize(-7, 0))
    fig.colorbar(sm, ax=axes, shrink=0.6, label="log10 |(u_x, u_y)| on z = 0")
    fig.savefig(os.path.join(out, "sphere_squirmer_streamlines.png"), dpi=80)
    plt.close(fig)

    # Figure 4
    d = np.genfromtxt(os.path.join(a.dir, "decay.csv"), delimiter=",", names=True)
    r = d["r"] / R
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for case, colour in [("translation", "C0"), ("squirmer", "C3")]:
        if case + "_mean" not in d.dtype.names:
            continue
        ax.loglog(r, d[case + "_mean"], "-", color=colour, lw=2, label=case + ", mean over 200 directions")
        ax.loglog(r, d[case + "_px"], "--", color=colour, lw=1, label=case + ", along +x")
        ax.loglog(r, d[case + "_py"], ":", color=colour, lw=1, label=case + ", along +y")
    r0 = 3.0
    for k, style in [(1, "k-"), (2, "k--"), (3, "k:")]:
        rr = np.array([r0, min(100.0, r.max())])
        ax.loglog(rr, 0.3 * (rr / r0) ** (-k), style, lw=0.8, alpha=0.7, label=f"r^-{k}")
    ax.set_xlabel("r / R")
    ax.set_ylabel("|u|  (cm/s)")
    ax.set_title(f"Decay of |u| (walls at {r.max() / 0.95:.0f} R)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    ax.set_ylim(1e-7, 1)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "sphere_squirmer_decay.png"), dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main()
