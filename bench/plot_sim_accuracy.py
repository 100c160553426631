#!/usr/bin/python3
"""The E / dt / precision trade of tetrasand_bench_sim_accuracy: plots and the table between
`<!-- accuracy -->` and `<!-- end accuracy -->` inside the sim section of docs/benchmarks/sim.md.
Usage: /usr/bin/python3 bench/plot_sim_accuracy.py RUN_DIR DOCS_DIR  (Debian's python3-matplotlib)"""
import csv
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
sys.path.insert(0, os.path.join(here, "peers"))
from docs_section import replace_between  # noqa: E402
from sim_peers import repose_angle  # noqa: E402  (the heap slope of every report)

STYLE = {"cpu": ("s", "CPU reference (double)"), "gpu-float": ("o", "GPU float"), "gpu-double": ("^", "GPU double")}


def energy_plot(rows, png):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    moduli = sorted({float(r["E_Pa"]) for r in rows})
    colours = dict(zip(moduli, ["tab:blue", "tab:orange", "tab:green", "tab:red"]))
    for backend, (marker, label) in STYLE.items():
        for e in moduli:
            sel = sorted((r for r in rows if r["backend"] == backend and float(r["E_Pa"]) == e),
                         key=lambda r: float(r["dt_factor"]))
            if not sel:
                continue
            f = [float(r["dt_factor"]) for r in sel]
            lab = f"{label}, E = {e:.0e} Pa"
            axes[0].loglog(f, [max(float(r["max_energy_error"]), 1e-12) for r in sel], marker=marker, ls="-",
                           color=colours[e], alpha=0.8, label=lab)
            axes[1].loglog(f, [float(r["max_overlap_ratio"]) for r in sel], marker=marker, ls="-",
                           color=colours[e], alpha=0.8, label=lab)
    axes[0].set_ylabel("largest |energy drift| / potential energy of the drop")
    axes[1].set_ylabel("largest overlap / r")
    for ax in axes:
        ax.set_xlabel("dt / automatic bound")
        ax.grid(True, which="both", alpha=0.3)
        ax.axvline(1.0, color="gold", lw=2, zorder=0, label="default: dt = \"auto\" (the bound)")
    axes[0].legend(fontsize=6)
    fig.suptitle("No-dissipation box, 100 grains, symplectic Euler (the scene default)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def pile_plot(rows, png):
    fig, ax = plt.subplots(figsize=(6, 4))
    labels = []
    for i, r in enumerate(rows):
        marker, label = STYLE[r["backend"]]
        ax.plot(i, r["angle"], marker=marker, color="tab:blue" if float(r["dt_factor"]) == 1 else "tab:orange")
        labels.append(f"{r['backend']}\nE={float(r['E_Pa']):.0e}\ndt={r['dt_factor']}x")
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels(labels, fontsize=6)
    ax.set_ylabel("angle of repose (degrees)")
    ax.set_title("150-grain heap on a rough floor (blue: dt = bound, orange: 2 x)")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def section(run, energy, pile, renderer):
    lines = [f"`scripts/bench.sh sim-accuracy` ({time.strftime('%Y-%m-%d')}; bench/sim_accuracy.cpp; renderer "
             f"{renderer}; {os.cpu_count()} shared cores). Tsuji damping; `bound` is the "
             "automatic step of each E (`min(t_c/20, 0.2 t_R, m_t/gamma_s)`). GPU double is GLSL fp64 on the same "
             "device.", ""]
    if energy:
        lines += ["No-dissipation box (`assets/scenes/reference/elastic_box.toml`: 100 grains, restitution 1, mu = 0, "
                  "gamma_s = 0, dropped into a smooth 2 cm box, 0.08 s, symplectic Euler). Energy error = the largest drift of "
                  "kinetic + potential + Hertz spring energy (sampled 400 times, springs evaluated by the CPU "
                  "reference on each backend's state) over the drop's potential energy; overlap = largest over every "
                  "step.", "",
                  "| E (Pa) | dt / bound | dt (us) | energy error CPU / GPU float / GPU double "
                  "| largest overlap / r CPU / GPU float / GPU double |", "|---|---|---|---|---|"]
        keys = sorted({(float(r["E_Pa"]), float(r["dt_factor"])) for r in energy})
        for e, f in keys:
            by = {r["backend"]: r for r in energy if float(r["E_Pa"]) == e and float(r["dt_factor"]) == f}
            err = " / ".join(f"{float(by[b]['max_energy_error']):.2e}" if b in by else "-" for b in STYLE)
            ovl = " / ".join(f"{float(by[b]['max_overlap_ratio']):.4f}" if b in by else "-" for b in STYLE)
            dt = float(next(iter(by.values()))["dt_s"]) * 1e6
            lines.append(f"| {e:.0e} | {f:g} | {dt:.2f} | {err} | {ovl} |")
        lines += ["", "![energy error and overlap against dt](sim_accuracy_energy.png)", ""]
    if pile:
        lines += ["Heap (`assets/scenes/reference/heap.toml` with 150 grains on a 6 cm rough floor, 0.5 s; mu = 0.5, "
                  "e = 0.5, viscous friction, forward Euler as the scene sets it): angle of repose fitted on the flank as in the peers and validation reports; overlap "
                  "= largest at the outputs (every 50 steps). A 150-grain heap's angle scatters by a few degrees "
                  "from one pour to the next, so only differences beyond that mean anything.", "",
                  "| E (Pa) | dt / bound | backend | steps | angle of repose (deg) | largest overlap / r | wall s |",
                  "|---|---|---|---|---|---|---|"]
        for r in pile:
            lines.append(f"| {float(r['E_Pa']):.0e} | {r['dt_factor']} | {r['backend']} | {r['steps']} | "
                         f"{r['angle']:.1f} | {float(r['max_overlap_ratio_at_outputs']):.4f} | {r['seconds']} |")
        lines += ["", "![angle of repose per run](sim_accuracy_pile.png)", ""]
    return "\n".join(lines)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    run, docs = sys.argv[1], sys.argv[2]
    os.makedirs(os.path.join(docs, "benchmarks"), exist_ok=True)
    energy = pile = None
    if os.path.exists(os.path.join(run, "energy.csv")):
        energy = list(csv.DictReader(open(os.path.join(run, "energy.csv"))))
        energy_plot(energy, os.path.join(docs, "benchmarks", "sim_accuracy_energy.png"))
    if os.path.exists(os.path.join(run, "pile.csv")):
        pile = list(csv.DictReader(open(os.path.join(run, "pile.csv"))))
        for r in pile:
            xyz = np.loadtxt(os.path.join(run, r["heap_file"]), delimiter=",", skiprows=1)
            r["angle"] = repose_angle(xyz)
        pile_plot(pile, os.path.join(docs, "benchmarks", "sim_accuracy_pile.png"))
    renderer = open(os.path.join(run, "renderer.txt")).read().strip()
    replace_between(os.path.join(docs, "benchmarks", "sim.md"), "<!-- accuracy -->\n", "<!-- end accuracy -->",
                    section(run, energy, pile, renderer))


if __name__ == "__main__":
    main()
