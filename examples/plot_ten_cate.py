#!/usr/bin/python3
"""ten Cate et al. (2002)'s figure of the settling sphere from examples/ten_cate.cpp's output.

Usage: /usr/bin/python3 examples/plot_ten_cate.py DIR [DIR ...] [--out FILE]

Each DIR is one run's output folder (its bodies.csv); its label is the folder's name (e.g.
E4L1: case E4, level 1). Draws the settling speed -v_z against t (left) with the measured
largest speeds of the four oils as dashed lines, the height of the sphere's bottom above the
floor against t (middle), and the landing: that height where it is below 2 mm, with the
collision range a / 10 (right). FILE defaults to ten_cate.png in the first DIR's parent.
Needs numpy and matplotlib (Debian: python3-matplotlib).
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

RADIUS = 0.0075  # m
MEASURED = {"E1": 0.0360, "E2": 0.0572, "E3": 0.0873, "E4": 0.1222}  # u_max, m/s (table 1)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("dirs", nargs="+")
    p.add_argument("--out")
    a = p.parse_args()
    out = a.out or os.path.join(os.path.dirname(os.path.abspath(a.dirs[0])), "ten_cate.png")
    fig, (ax_u, ax_z, ax_l) = plt.subplots(1, 3, figsize=(15, 4.2))
    for d in a.dirs:
        c = np.genfromtxt(os.path.join(d, "bodies.csv"), delimiter=",", names=True)
        label = os.path.basename(os.path.normpath(d))
        ax_u.plot(c["t"], -c["vz0"], label=label)
        ax_z.plot(c["t"], 1e3 * (c["z0"] - RADIUS), label=label)
        low = 1e3 * c["gap0"] < 2
        if low.any():
            first = np.argmax(low)
            ax_l.plot(c["t"][first:] - c["t"][first], 1e3 * c["gap0"][first:], label=label)
    for case, u in MEASURED.items():
        ax_u.axhline(u, ls="--", lw=0.8, color="0.5")
        ax_u.text(0.0, u, f" {case} measured", va="bottom", fontsize=7, color="0.4")
    ax_u.set_xlabel("t (s)")
    ax_u.set_ylabel("settling speed $-v_z$ (m/s)")
    ax_z.set_xlabel("t (s)")
    ax_z.set_ylabel("bottom of the sphere above the floor (mm)")
    ax_l.axhline(1e3 * RADIUS / 10, ls="--", lw=0.8, color="0.5")
    ax_l.text(0.0, 1e3 * RADIUS / 10, " collision range a / 10", va="bottom", fontsize=7, color="0.4")
    ax_l.set_xlabel("t - t(gap = 2 mm) (s)")
    ax_l.set_ylabel("gap to the floor (mm)")
    ax_l.set_ylim(0, 2.2)
    for ax in (ax_u, ax_z, ax_l):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    main()
