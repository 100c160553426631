#!/usr/bin/python3
"""Plots of the sampler bench (bench/sample_bench.py --csv): tetrasand against Open3D's Poisson-disk
sampling over the particle count (time, covering radius c / r, relative radius rho), and the
sampler's own trade (relaxation steps against c / r and rho over --rounds and --max-iterations).
Usage: /usr/bin/python3 bench/plot_sample.py OUT_DIR a.csv [b.csv ...]  (Debian's python3-matplotlib)
Writes OUT_DIR/sample_vs_open3d.png when the CSVs hold compare rows, OUT_DIR/sample_trade.png when
they hold trade rows."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The sampler's defaults (sampler/sample_mesh.h), starred on the trade plot.
DEFAULT_ROUNDS, DEFAULT_MAX_ITERATIONS = 12, 2000
STYLE = {"tetrasand": ("tab:blue", "o", "tetrasand (llvmpipe)"), "Open3D": ("tab:orange", "s", "Open3D poisson disk")}


def plot_compare(rows, png):
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for mesh in sorted({r["mesh"] for r in rows}):
        for tool, (colour, marker, label) in STYLE.items():
            mine = sorted((r for r in rows if r["mesh"] == mesh and r["tool"] == tool), key=lambda r: int(r["n"]))
            if not mine:
                continue
            n = [int(r["n"]) for r in mine]
            name = f"{label}, {mesh}"
            for ax, key in zip(axes, ("seconds", "c_over_r", "rho")):
                ax.plot(n, [float(r[key]) for r in mine], marker=marker, color=colour, label=name)
    titles = ("time [s]", "covering radius c / r (<= 1: no gaps)", "relative radius rho (higher: more even)")
    for ax, title in zip(axes, titles):
        ax.set_xscale("log")
        ax.set_xlabel("particles N")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_yscale("log")
    axes[1].axhline(1.0, color="grey", lw=0.8, ls="--")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def plot_trade(rows, png):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    caps = sorted({int(r["max_iterations"]) for r in rows})
    colours = plt.cm.viridis([i / max(len(caps) - 1, 1) for i in range(len(caps))])
    for cap, colour in zip(caps, colours):
        mine = sorted((r for r in rows if int(r["max_iterations"]) == cap), key=lambda r: int(r["rounds"]))
        t = [int(r["iterations"]) for r in mine]  # deterministic, unlike time on a shared machine
        for ax, key in zip(axes, ("c_over_r", "rho")):
            ax.plot(t, [float(r[key]) for r in mine], marker="o", color=colour, label=f"--max-iterations {cap}")
            for r, x in zip(mine, t):
                ax.annotate(f"{r['rounds']}", (x, float(r[key])), fontsize=7, xytext=(3, 3), textcoords="offset points")
                if int(r["rounds"]) == DEFAULT_ROUNDS and cap == DEFAULT_MAX_ITERATIONS:
                    ax.scatter([x], [float(r[key])], marker="*", s=220, color="gold", edgecolor="black", zorder=5,
                               label="default (--rounds 12, --max-iterations 2000)")
    mesh = rows[0]["mesh"]
    axes[0].set_title(f"{mesh}, {rows[0]['requested']} particles: c / r (labels: --rounds)")
    axes[1].set_title("relative radius rho")
    axes[0].axhline(1.0, color="grey", lw=0.8, ls="--")
    for ax in axes:
        ax.set_xlabel("relaxation steps, all rounds (times: docs/benchmarks/sampler.md)")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def main(out_dir, paths):
    rows = [r for p in paths for r in csv.DictReader(open(p))]
    compare = [r for r in rows if r["kind"] == "compare"]
    trade = [r for r in rows if r["kind"] == "trade"]
    if compare:
        plot_compare(compare, os.path.join(out_dir, "sample_vs_open3d.png"))
    if trade:
        plot_trade(trade, os.path.join(out_dir, "sample_trade.png"))


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
