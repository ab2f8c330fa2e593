#!/usr/bin/python3
"""Plots of the annulus case (docs/results.md, section "Annulus").

    /usr/bin/python3 docs/img/annulus_plot.py fig7.csv [table1.csv]

fig7.csv   from `annulus fig7 --csv`: t* against I^ (FD reference line, FEM markers)
           -> docs/img/annulus_fig7.png
table1.csv from `annulus table1 --csv`: E against dt per scheme, with the paper's values
           -> docs/img/annulus_table1.png
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def fig7(path):
    r = rows(path)
    ih = [float(x["I_hat"]) for x in r]
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(ih, [float(x["tstar_fd"]) for x in r], "-", label="FD reference (CN, N = 2000)")
    ax.loglog(ih, [float(x["tstar_fem"]) for x in r], "o", mfc="none", label="FEM, free inner cylinder (MR/AB)")
    ax.set_xlabel(r"$\hat I = \rho_1 / 64$")
    ax.set_ylabel(r"$\hat t^*$ ($\hat\omega = 1/2$)")
    ax.set_title("Annulus, Figure 7 set-up")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = os.path.join(here, "annulus_fig7.png")
    fig.savefig(out, dpi=120)
    print("wrote", out)


def table1(path):
    r = rows(path)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for i, s in enumerate(dict.fromkeys(x["scheme"] for x in r)):
        sub = [x for x in r if x["scheme"] == s]
        dt = [float(x["dt"]) for x in sub]
        line, = ax.loglog(dt, [float(x["E_fd"]) for x in sub], "o-", label=s + " (ours)")
        paper = [(float(x["dt"]), float(x["paper_E"])) for x in sub if x["paper_E"]]
        if paper:
            ax.loglog(*zip(*paper), "x--", color=line.get_color(), label=s + " (paper)")
    ax.set_xlabel(r"$\Delta t$")
    ax.set_ylabel(r"$E = \|u - u_h\|_{L^2}$ at $t = 0.8$")
    ax.set_title("Annulus, Table 1 set-up")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(here, "annulus_table1.png")
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    fig7(sys.argv[1])
    if len(sys.argv) > 2:
        table1(sys.argv[2])
