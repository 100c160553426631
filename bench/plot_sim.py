#!/usr/bin/python3
"""The Cundall-number sweep of tetrasand_bench_sim --csv: a log-log plot of grain-steps/s against grains
(GPU pipeline and CPU reference) and the table between `<!-- cundall -->` and `<!-- end cundall -->`
inside the sim section of docs/benchmarks/sim.md (the rest of the section is left as it is).
Usage: /usr/bin/python3 bench/plot_sim.py sweep.csv DOCS_DIR  (Debian's python3-matplotlib)"""
import csv
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from docs_section import replace_between  # noqa: E402


def plot(rows, png):
    n = [int(r["grains"]) for r in rows]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    renderer = rows[0]["renderer"].split(" / ")[0]
    ax.loglog(n, [float(r["gpu_grain_steps_per_s"]) for r in rows], "o-",
              label=f"GPU pipeline ({rows[0]['precision']}, {renderer})")
    ax.loglog(n, [float(r["cpu_grain_steps_per_s"]) for r in rows], "s-",
              label=f"CPU reference (double, TBB, {os.cpu_count()} cores)")
    ax.set_xlabel("grains")
    ax.set_ylabel("grain-steps / s (Cundall number)")
    ax.set_title("Settled bed, r = 1 mm, E = 10 MPa (shared machine: noisy)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def table(rows, command):
    r0 = rows[0]
    lines = [f"`{command}` ({time.strftime('%Y-%m-%d')}; renderer: {r0['renderer']}; "
             f"{os.cpu_count()} cores shared with other engineers' builds, so rates are noisy, read the ratios). "
             f"Scene: the settled bed of `bench/bench_scenes.h` (tile `assets/scenes/reference/bed_tile.toml`, "
             f"1000 grains settled in a 5 cm box, copied side by side), dt = {float(r0['dt_s']) * 1e6:.1f} us, "
             f"{rows[0]['precision']} on the GPU. Memory: GPU = bytes of every buffer of the pipeline "
             "(`GpuStepper::gpu_bytes`); CPU = growth of the process's resident set for the world copy, the "
             "stepper's scratch and its grid (RSS; at small sizes reused heap makes it noisy).", "",
             "| grains | contacts / grain | GPU grain-steps/s | CPU grain-steps/s | GPU / CPU | timed steps GPU / CPU "
             "| GPU bytes / grain | CPU bytes / grain |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {int(r['grains'])} | {float(r['contacts_per_grain']):.1f} | "
                     f"{float(r['gpu_grain_steps_per_s']):.3g} | {float(r['cpu_grain_steps_per_s']):.3g} | "
                     f"{float(r['gpu_over_cpu']):.2f} | {r['gpu_steps']} / {r['cpu_steps']} | "
                     f"{float(r['gpu_bytes_per_grain']):.0f} | {float(r['cpu_bytes_per_grain']):.0f} |")
    lines += ["", "![Cundall number against grains](sim_cundall.png)", ""]
    return "\n".join(lines)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    docs = sys.argv[2]
    command = sys.argv[3] if len(sys.argv) > 3 else "scripts/bench.sh sim"
    os.makedirs(os.path.join(docs, "benchmarks"), exist_ok=True)
    plot(rows, os.path.join(docs, "benchmarks", "sim_cundall.png"))
    replace_between(os.path.join(docs, "benchmarks", "sim.md"), "<!-- cundall -->\n", "<!-- end cundall -->",
                    table(rows, command))


if __name__ == "__main__":
    main()
