#!/usr/bin/python3
"""docs/validation.md "Bonded particles", criterion 2 (energy): the bonded `--fill` ball of
assets/scenes/validation/bonded_spin.toml (no gravity, no damping, no contact, bonds too strong to break)
launched and spun, its kinetic plus bond energy over 10^4 steps at the bonds' time-step bound. Runs the
scene with outputs every 50 steps instead of 500 (the physics is the same; only the rows are denser),
prints the largest relative energy error, says whether it is within the criterion's 0.5 %, and plots the
error against time.
Usage: /usr/bin/python3 bench/bonded_energy.py TETRASAND_BINARY OUT_DIR PNG [--engines cpu,gpu-double,gpu-float]
       (Debian's python3-matplotlib; default: the CPU reference only). Exits 1 when an engine misses 0.5 %."""
import argparse
import csv
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "assets", "scenes", "validation", "bonded_spin.toml")
TOLERANCE = 0.005  # the criterion's 0.5 %


def dense_scene(folder):
    """The scene with outputs every 50 steps and its body path made absolute."""
    text = open(SCENE).read()
    text, n = re.subn(r"^every = 500$", "every = 50", text, flags=re.M)
    assert n == 1, "bonded_spin.toml: expected one 'every = 500' line"
    body = os.path.join(ROOT, "assets", "bodies", "sphere.body.json")
    text = text.replace('body = "../../bodies/sphere.body.json"', f'body = "{body}"')
    path = os.path.join(folder, "bonded_spin_dense.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


ENGINES = {"cpu": ("CPU reference", ["--backend", "cpu"]),
           "gpu-double": ("GPU pipeline, double", ["--backend", "gpu", "--precision", "double"]),
           "gpu-float": ("GPU pipeline, float", ["--backend", "gpu", "--precision", "float"])}


def energy_error(binary, scene, run, options):
    """(times, relative errors, steps, start energy) of one run of the scene."""
    subprocess.run([binary, "sim", scene, "-o", run] + options, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(run, "metrics.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if any(int(r["contacts"]) or int(r["bonds_broken"]) for r in rows):
        sys.exit(f"bonded_energy: {run}: a contact or a broken bond in the run; the criterion needs neither")
    time = [float(r["time_s"]) for r in rows]
    total = [float(r["kinetic_translational_J"]) + float(r["kinetic_rotational_J"]) + float(r["elastic_J"])
             for r in rows]
    return time, [(e - total[0]) / total[0] for e in total], int(rows[-1]["step"]), total[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("out")
    ap.add_argument("png")
    ap.add_argument("--engines", default="cpu", help="comma-separated: " + ", ".join(ENGINES))
    args = ap.parse_args()
    engines = args.engines.split(",")
    for name in engines:
        if name not in ENGINES:
            sys.exit(f"bonded_energy: --engines: '{name}' is none of {', '.join(ENGINES)}")
    os.makedirs(args.out, exist_ok=True)
    scene = dense_scene(args.out)
    fig, ax = plt.subplots(figsize=(7, 4))
    print("| engine | steps | start energy | largest error | criterion 2 (0.5 %) |\n|---|---|---|---|---|")
    all_met = True
    for name in engines:
        label, options = ENGINES[name]
        time, error, steps, start = energy_error(args.binary, scene, os.path.join(args.out, name), options)
        worst = max(error, key=abs)
        met = abs(worst) <= TOLERANCE
        all_met = all_met and met
        print(f"| {label} | {steps} | {start:.6g} J | {100 * worst:+.4f} % | {'met' if met else 'not met'} |")
        ax.plot([1e3 * t for t in time], [100 * e for e in error], lw=1.2, label=f"{label}, {steps} steps")
    ax.axhline(100 * TOLERANCE, color="grey", ls="--", lw=0.8, label="criterion 2: 0.5 %")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("(kinetic + bond energy) / start - 1 (%)")
    ax.set_title("bonded --fill ball spun and shaken, no damping or contact (bonded_spin.toml)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    tmp = args.png + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, args.png)
    return 0 if all_met else 1


if __name__ == "__main__":
    sys.exit(main())
