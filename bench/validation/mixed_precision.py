#!/usr/bin/env python3
"""The agreement decks' heap and silo in mixed precision against full double on the GPU pipeline
(issue 44, item 4; criterion in docs/benchmarks/sim.md "Mixed precision", written before the run):

  bench/validation/mixed_precision.py RUN_DIR

RUN_DIR holds what `tetrasand_validation_runs RUN_DIR mixed[-heap|-silo] double|full-double [SEEDS]` wrote:
mixed_heap_{double,full-double}_seedN.csv (grain centres of each settled heap, one per pour seed) and
mixed_silo_{double,full-double}.csv (grains discharged against time, per fill seed). Prints a markdown table:
the heap's mean angle of repose over the pours and the silo's mean discharge rate over the fills in each
precision, their difference against the agreement's tolerances (3 deg, 10 %), and the pour-to-pour and
fill-to-fill scatter (max - min) in each precision, the yardstick for the differences.
Exits 1 when a file is missing, naming it.
"""
import glob
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import GRAIN_MASS, discharge_rate, repose_angle  # noqa: E402

PRECISIONS = ("double", "full-double")
ANGLE_TOLERANCE = 3.0  # deg, the agreement's (and LAMMPS's) heap tolerance
RATE_TOLERANCE = 0.10  # relative, the agreement's discharge tolerance


def need(run, name):
    path = os.path.join(run, name)
    if not os.path.exists(path):
        raise SystemExit(f"mixed_precision: {path} is missing; write it with "
                         "`tetrasand_validation_runs RUN_DIR mixed-heap|mixed-silo double|full-double`")
    return path


def heap_angles(run, precision):
    files = glob.glob(os.path.join(run, f"mixed_heap_{precision}_seed*.csv"))
    if not files:
        need(run, f"mixed_heap_{precision}_seed11.csv")
    return {int(re.search(r"seed(\d+)\.csv$", f).group(1)): repose_angle(np.loadtxt(f, delimiter=",", skiprows=1))
            for f in files}


def silo_rates(path):
    s = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    seeds = sorted(set(int(x) for x in s["seed"]))
    return {k: discharge_rate(s["time_s"][s["seed"] == k], s["discharged"][s["seed"] == k]) for k in seeds}


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    run = sys.argv[1]
    angles = {p: heap_angles(run, p) for p in PRECISIONS}
    angle = {p: float(np.mean(list(a.values()))) for p, a in angles.items()}
    angle_spread = {p: max(a.values()) - min(a.values()) for p, a in angles.items()}
    rates = {p: silo_rates(need(run, f"mixed_silo_{p}.csv")) for p in PRECISIONS}
    mean = {p: float(np.mean(list(r.values()))) for p, r in rates.items()}
    spread = {p: float((max(r.values()) - min(r.values())) / mean[p]) for p, r in rates.items()}
    d_angle = angle["double"] - angle["full-double"]
    d_rate = mean["double"] / mean["full-double"] - 1
    seeds = ", ".join(str(k) for k in rates["double"])
    pours = ", ".join(str(k) for k in sorted(angles["double"]))
    print("| quantity | mixed (`double`) | full double | difference | tolerance | within |")
    print("|---|---|---|---|---|---|")
    print(f"| angle of repose, 400-grain heap (reference/heap.toml, mean of pour seeds {pours}) "
          f"| {angle['double']:.1f} deg "
          f"| {angle['full-double']:.1f} deg | {d_angle:+.1f} deg | {ANGLE_TOLERANCE:.0f} deg "
          f"| {'yes' if abs(d_angle) <= ANGLE_TOLERANCE else 'no'} |")
    print(f"| silo discharge rate, D = 16 mm (reference/silo.toml, mean of fill seeds {seeds}) "
          f"| {mean['double'] * GRAIN_MASS * 1e3:.2f} g/s | {mean['full-double'] * GRAIN_MASS * 1e3:.2f} g/s "
          f"| {100 * d_rate:+.1f} % | {100 * RATE_TOLERANCE:.0f} % | {'yes' if abs(d_rate) <= RATE_TOLERANCE else 'no'} |")
    print()
    print("Pour-to-pour scatter of the angle (max - min over the pours): "
          + ", ".join(f"{p} {angle_spread[p]:.1f} deg" for p in PRECISIONS) + "; per pour, mixed / full double in deg: "
          + ", ".join(f"seed {k}: {angles['double'][k]:.1f} / {angles['full-double'].get(k, float('nan')):.1f}"
                      for k in sorted(angles["double"])))
    print()
    print("Fill-to-fill scatter of the rate (max - min over the fills, of the mean): "
          + ", ".join(f"{p} {100 * spread[p]:.1f} %" for p in PRECISIONS) + "; per fill, mixed / full double in g/s: "
          + ", ".join(f"seed {k}: {rates['double'][k] * GRAIN_MASS * 1e3:.2f} / "
                      f"{rates['full-double'].get(k, float('nan')) * GRAIN_MASS * 1e3:.2f}" for k in rates["double"]))


if __name__ == "__main__":
    main()
