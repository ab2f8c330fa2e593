#!/usr/bin/python3
"""Plots of the annulus case (docs/results.md, section "Annulus").

    /usr/bin/python3 docs/img/annulus_plot.py fig7.csv [table1.csv [table1_damped.csv]]

fig7.csv   from `annulus fig7 --csv`: t* against I^ (FD reference line, FEM markers)
           -> docs/img/annulus_fig7.png
table1.csv from `annulus table1 --csv`: E against dt per scheme, with the paper's values
           -> docs/img/annulus_table1.png
table1_damped.csv from `annulus table1 --damped-start M --csv`: with it, the figure has two
           panels, E against the FD reference (left) and the time error against the fine-dt
           FEM solution (right), the damped start solid, the multistep start of table1.csv
           dotted, the paper's values dashed (x)
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


def table1_two_starts(plain_path, damped_path):
    plain, damped = rows(plain_path), rows(damped_path)
    names = {"MR_AB": "MR/AB", "BDF2_BDF2E": "BDF2/BDF2E", "BDF2_AB": "BDF2/AB", "BDF3_BDF3E": "BDF3/BDF3E",
             "BSS": "BSS"}
    colours = {"MR_AB": "C0", "BDF2_BDF2E": "C1", "BDF2_AB": "C2", "BDF3_BDF3E": "C3", "BSS": "C4"}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), sharex=True)
    for s in dict.fromkeys(x["scheme"] for x in plain + damped):
        c = colours.get(s, "k")
        for ax, key in zip(axes, ("E_fd", "E_time")):
            for rr, style, tag in ((damped, "o-", "damped start"), (plain, "s:", "multistep start")):
                sub = [x for x in rr if x["scheme"] == s]
                if sub:
                    ax.loglog([float(x["dt"]) for x in sub], [float(x[key]) for x in sub], style, color=c, mfc="none",
                              label=f"{names.get(s, s)}, {tag}")
        paper = [(float(x["dt"]), float(x["paper_E"])) for x in plain + damped if x["scheme"] == s and x["paper_E"]]
        paper = sorted(dict(paper).items())
        if paper:
            axes[0].loglog(*zip(*paper), "x--", color=c, label=f"{names.get(s, s)}, paper")
    dts = sorted({float(x["dt"]) for x in damped})
    if dts:
        for p, y0 in ((1, 3e-3), (2, 3e-4), (3, 3e-5)):
            axes[1].loglog(dts, [y0 * (d / dts[-1]) ** p for d in dts], "k-", lw=0.6, alpha=0.5)
            axes[1].annotate(f"order {p}", (dts[-1], y0 * (dts[-1] / dts[-1]) ** p), fontsize=7, alpha=0.7)
    axes[0].set_ylabel(r"$E = \|u - u_h\|_{L^2}$ at $t = 0.8$, against FD (time + space)")
    axes[1].set_ylabel("against the fine-dt FEM solution (time error)")
    for ax in axes:
        ax.set_xlabel(r"$\Delta t$")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=6, ncol=2)
    fig.suptitle("Annulus, Table 1 set-up (mu = 0.01, impulsive start)")
    fig.tight_layout()
    out = os.path.join(here, "annulus_table1.png")
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    fig7(sys.argv[1])
    if len(sys.argv) > 3:
        table1_two_starts(sys.argv[2], sys.argv[3])
    elif len(sys.argv) > 2:
        table1(sys.argv[2])
