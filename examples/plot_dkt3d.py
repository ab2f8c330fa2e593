#!/usr/bin/python3
"""The 3D drafting, kissing and tumbling pair from examples/dkt3d.cpp's output.

Usage: /usr/bin/python3 examples/plot_dkt3d.py DIR [DIR ...] [--out FILE]

Each DIR is one run's output folder (its bodies.csv), labelled by the folder's name. Draws the
distance between the centres in diameters against t (left, with the issue's kiss criterion
1.005 d), the tilt of the line of centres from the vertical (middle) and the heights of both
centres (right). FILE defaults to dkt3d.png in the first DIR's parent. Needs numpy and
matplotlib.
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
    out = a.out or os.path.join(os.path.dirname(os.path.abspath(a.dirs[0])), "dkt3d.png")
    fig, (ax_d, ax_t, ax_z) = plt.subplots(1, 3, figsize=(15, 4.2))
    for d in a.dirs:
        c = np.genfromtxt(os.path.join(d, "bodies.csv"), delimiter=",", names=True)
        label = os.path.basename(os.path.normpath(d))
        r = np.stack([c["x1"] - c["x0"], c["y1"] - c["y0"], c["z1"] - c["z0"]])
        dist = np.linalg.norm(r, axis=0)
        tilt = np.degrees(np.arccos(np.clip(np.abs(r[2]) / dist, 0, 1)))
        ax_d.plot(c["t"], dist, label=label)
        ax_t.plot(c["t"], tilt, label=label)
        line = ax_z.plot(c["t"], c["z0"], label=label + " leading")[0]
        ax_z.plot(c["t"], c["z1"], "--", color=line.get_color(), label=label + " trailing")
    ax_d.axhline(1.005, color="k", lw=0.5, ls="--", label="1.005 d")
    ax_d.set(xlabel="t", ylabel="distance of the centres / d", ylim=(0.95, 3))
    ax_t.set(xlabel="t", ylabel="tilt of the pair (deg)")
    ax_z.set(xlabel="t", ylabel="height of the centre z")
    for ax in (ax_d, ax_t, ax_z):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


if __name__ == "__main__":
    main()
