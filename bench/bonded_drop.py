#!/usr/bin/python3
"""docs/validation.md "Bonded particles", criterion 5 (fragmentation): the bonded clay ball of
assets/scenes/validation/bonded_drop.toml thrown onto a rigid floor at four speeds. Prints one table row
per speed (impact energy, broken-bond fraction, fragments, largest fragment's mass fraction), says
whether the criterion holds (the broken fraction rises and the largest fragment's fraction falls with
the impact energy), and plots the fragment mass distributions.
Usage: /usr/bin/python3 bench/bonded_drop.py TETRASAND_BINARY OUT_DIR PNG  (Debian's python3-matplotlib)"""
import csv
import json
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SPEEDS = [0.5, 1.0, 2.0, 4.0]  # m/s, the criterion's four increasing speeds
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "assets", "scenes", "validation", "bonded_drop.toml")


def scene_at(speed, folder):
    """The scene with the ball's velocity set to `speed` downwards and its body path made absolute."""
    text = open(SCENE).read()
    text, n = re.subn(r"^velocity = \[.*\]$", f"velocity = [0.0, 0.0, {-speed}]", text, flags=re.M)
    assert n == 1, "bonded_drop.toml: expected one velocity line"
    body = os.path.join(ROOT, "assets", "bodies", "sphere.body.json")
    text = text.replace('body = "../../bodies/sphere.body.json"', f'body = "{body}"')
    path = os.path.join(folder, f"drop_{speed:g}.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(binary, speed, out):
    os.makedirs(out, exist_ok=True)
    scene = scene_at(speed, out)
    run_dir = os.path.join(out, f"run_{speed:g}")
    summary = subprocess.run([binary, "sim", scene, "-o", run_dir, "--backend", "cpu", "--json"], check=True,
                             capture_output=True, text=True).stdout
    s = json.loads(summary)
    with open(os.path.join(run_dir, "fragments.csv")) as f:
        masses = [float(r["mass_kg"]) for r in csv.DictReader(f)]
    return s, masses


def main():
    binary, out, png = sys.argv[1:4]
    rows = []
    for v in SPEEDS:
        s, masses = run(binary, v, out)
        total = sum(masses)
        bonds = s["bonds"]
        rows.append({"speed": v, "energy": 0.5 * total * v * v, "broken": bonds["broken"] / bonds["at_start"],
                     "fragments": bonds["fragments"], "largest": masses[0] / total, "masses": masses,
                     "total": total, "steps": s["steps"]})
    print("| impact speed [m/s] | impact energy [J] | bonds broken | fragments | largest fragment / ball |")
    print("|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['speed']:g} | {r['energy']:.4g} | {100 * r['broken']:.1f} % | {r['fragments']} | "
              f"{r['largest']:.3f} |")
    broken_rises = all(a["broken"] < b["broken"] for a, b in zip(rows, rows[1:]))
    largest_falls = all(a["largest"] > b["largest"] for a, b in zip(rows, rows[1:]))
    print(f"broken fraction rises with energy: {broken_rises}; largest fragment falls: {largest_falls}; "
          f"criterion 5 {'met' if broken_rises and largest_falls else 'NOT met'}")

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for r in rows:
        fractions = [m / r["total"] for m in r["masses"]]
        ax.loglog(fractions, range(1, len(fractions) + 1), "o-", markersize=3,
                  label=f"{r['speed']:g} m/s ({r['energy']:.2g} J)")
    ax.set_xlabel("fragment mass / ball mass")
    ax.set_ylabel("fragments at least this heavy")
    ax.set_title("Bonded clay ball onto a rigid floor (382 spheres, 1913 bonds of 10 kPa)")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
