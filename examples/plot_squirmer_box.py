#!/usr/bin/env python3
"""The speed of a squirmer swimming the length of a box (examples/squirmer_box.cpp) against the
height of its centre, one curve per run folder, with the fresh steady solves as markers and the
unbounded speed as a line.

    python3 examples/plot_squirmer_box.py DIR [DIR2 ...] [--labels "level 1,level 1.5"] [--out FILE]

Reads DIR/speed.csv: the track (t, z, Vz/U, |Vxy|/U, |w| a/U, slip flux removed / U), a blank
line, then the references (z, steady Vz/U, the run's Vz/U there). Writes FILE (default
DIR/squirmer_box.png).
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read_speed(folder):
    track, refs = [], []
    rows = track
    with open(os.path.join(folder, "speed.csv")) as f:
        for row in csv.reader(f):
            if not row:
                continue
            if row[0] == "t":
                rows = track
                continue
            if row[0] == "reference_z":
                rows = refs
                continue
            rows.append([float(v) for v in row])
    return track, refs


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folders", nargs="+")
    p.add_argument("--labels", default="")
    p.add_argument("--out", default="")
    a = p.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(os.path.normpath(d)) for d in a.folders]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    for folder, label in zip(a.folders, labels):
        track, refs = read_speed(folder)
        z = [r[1] for r in track]
        line, = top.plot(z, [r[2] for r in track], label=label)
        if refs:
            top.plot([r[0] for r in refs], [r[1] for r in refs], "o", mfc="none", color=line.get_color())
        bottom.semilogy(z, [max(r[3], 1e-8) for r in track], color=line.get_color())
        bottom.semilogy(z, [max(r[4], 1e-8) for r in track], "--", color=line.get_color())
    top.axhline(1, color="k", lw=0.8, ls=":")
    top.set_ylabel("$V_z / U$  ($U = 2 B_1 / 3$, unbounded)")
    top.legend(title="run (markers: fresh steady solves)")
    bottom.set_xlabel("height of the centre $z$ (in $d$)")
    bottom.set_ylabel("$|V_{xy}| / U$ (solid)\n$|\\omega| a / U$ (dashed)")
    fig.tight_layout()
    out = a.out or os.path.join(a.folders[0], "squirmer_box.png")
    fig.savefig(out, dpi=130)
    print("wrote", out)


if __name__ == "__main__":
    main()
