#!/usr/bin/python3
"""The settling ellipse's speed, angle and lateral position from examples/ellipse_settling.cpp.

Usage: /usr/bin/python3 examples/plot_ellipse_settling.py DIR [DIR ...] [--out FILE]

Each DIR is one run's output folder (its bodies.csv), labelled by the folder's name. Draws the
settling speed -v_y against t (left), the major axis' angle from the horizontal against the
height of the centre (middle; the ellipse falls from right to left) and the centre's x against
its height (right; the centreline is x = 0.2 cm). Dashed: the values of Xia et al. (2009) that
docs/results.md quotes (terminal speed 1.29-1.30 cm/s, first angle extreme -0.096 pi at
y = 2.17 cm, first lateral extreme x = 0.148 cm at y = 2.16 cm). FILE defaults to
ellipse_settling.png in the first DIR's parent. Needs numpy and matplotlib.
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("dirs", nargs="+")
    p.add_argument("--out")
    a = p.parse_args()
    out = a.out or os.path.join(os.path.dirname(os.path.abspath(a.dirs[0])), "ellipse_settling.png")
    fig, (ax_u, ax_a, ax_x) = plt.subplots(1, 3, figsize=(15, 4.2))
    for d in a.dirs:
        c = np.genfromtxt(os.path.join(d, "bodies.csv"), delimiter=",", names=True)
        label = os.path.basename(os.path.normpath(d))
        angle = np.degrees(np.remainder(c["angle0"] + np.pi / 2, np.pi) - np.pi / 2)
        ax_u.plot(c["t"], -c["vy0"], label=label)
        ax_a.plot(c["y0"], angle, label=label)
        ax_x.plot(c["y0"], c["x0"], label=label)
    ax_u.axhspan(1.29, 1.30, color="k", alpha=0.15, label="Xia et al. terminal")
    ax_a.plot([2.17], [-0.096 * 180], "kx", label="Xia et al. first extreme")
    ax_x.plot([2.16], [0.148], "kx", label="Xia et al. first extreme")
    ax_x.axhline(0.2, color="k", lw=0.5, ls="--")
    ax_a.axhline(0, color="k", lw=0.5, ls="--")
    ax_u.set(xlabel="t (s)", ylabel="settling speed (cm/s)")
    ax_a.set(xlabel="height of the centre y (cm)", ylabel="angle of the major axis (deg)")
    ax_x.set(xlabel="height of the centre y (cm)", ylabel="x (cm)")
    for ax in (ax_a, ax_x):
        ax.invert_xaxis()
    for ax in (ax_u, ax_a, ax_x):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


if __name__ == "__main__":
    main()
