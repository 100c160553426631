#!/usr/bin/python3
"""Repose magnitude (issue 18; docs/validation.md "Repose magnitude (issue 18)"; criteria in
bench/validation/repose_criteria.md, written before the first run).

The 3,000-grain heap of the "Angle of repose against friction" section at mu = 0.5, built as
validation_runs.cpp's repose() builds it, with one factor changed per run (the thesis's gamma_s, the
grain's edge / radius, spring friction, mu, the heap size, the pour seed), on tetrasand's CPU
reference, and the same deck on LAMMPS through `tetrasand export lammps`. Every heap's angle is the
one report.py gives those heaps (sim_peers.repose_angle, 10 mm rings about x = y = 0).

Usage: bench/validation/repose_sweep.py BUILD_BIN_DIR WORK_DIR [RUN ...] [--plot PNG] [--plot-only]
  RUN: a name of RUNS below (default: all, in the criteria's order). A run already in WORK_DIR/results.json
  is not run again, so the sweep can be resumed; --plot PNG plots what results.json then holds, and with
  --plot-only nothing is run.
Prints one line per run and a markdown table; writes WORK_DIR/results.json (atomically).
"""
import json
import os
import re
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from spring_heap import test_angle  # noqa: E402
from sim_peers import centres, read_dump_frames, read_ply_bodies, repose_angle, run  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCENE = os.path.join(ROOT, "assets", "scenes", "reference", "coarse_pile.toml")
RADIUS = 5.0e-3  # m, the pile's sphere radius
D_EQ = 2 * RADIUS * 4 ** (1 / 3)  # m, report.py's COARSE_D_EQ (mass of four whole spheres, whatever the edge)
RING = 2 * RADIUS  # m, the ring width report.py uses for these heaps
BASE_GRAINS = 3000

# name -> (code, what the run changes from the baseline: a dict of the edits scene_text() knows)
RUNS = {
    "base": ("tetrasand", {}),
    "lammps_base": ("lammps", {}),
    "gamma_s10": ("tetrasand", {"gamma_s": 10.0}),
    "edge1.0": ("tetrasand", {"edge": 1.0}),
    "spring": ("tetrasand", {"tangential": "spring"}),
    "mu1.0": ("tetrasand", {"mu": 1.0}),
    "base_seed12": ("tetrasand", {"seed": 12}),
    "edge1.5": ("tetrasand", {"edge": 1.5}),
    "grains6000": ("tetrasand", {"grains": 6000}),
    "lammps_gamma_s10": ("lammps", {"gamma_s": 10.0}),
    # Added after run 1 (criteria, addendum): the baseline with 3 s more at rest.
    "base_long": ("tetrasand", {"rest": 4.0}),
    # Added after gamma_s10 (criteria, addendum 2): the baseline at gamma_s10's automatic step.
    "base_dt_g10": ("tetrasand", {"dt": 6.0033156060896112e-05}),
}


def replace_once(text, old, new):
    if text.count(old) != 1:
        sys.exit(f"repose_sweep: expected one '{old.strip()}' in {SCENE}")
    return text.replace(old, new)


def scene_text(edits):
    """validation_runs.cpp repose()'s heap (3,000 grains, 1,000 grains/s, 16 cm box 5-30 cm up, 0.8 m
    floor, 4 s, symplectic Euler) with `edits` applied."""
    grains = edits.get("grains", BASE_GRAINS)
    pour_s = grains / 1000.0
    rest_s = edits.get("rest", 1.0)
    t = open(SCENE).read()
    t = replace_once(t, "min = [-0.04, -0.04, 0.05]", "min = [-0.08, -0.08, 0.05]")
    t = replace_once(t, "max = [0.04, 0.04, 0.22]", "max = [0.08, 0.08, 0.30]")
    t = replace_once(t, "count = 300\n", f"count = {grains}\n")
    t = replace_once(t, "rate = 400.0", "rate = 1000.0")
    t = replace_once(t, "size = [0.3, 0.3]", "size = [0.8, 0.8]")
    sim = f'duration = {pour_s + rest_s}\nintegrator = "symplectic"\n'
    if "dt" in edits:
        sim += f'dt = {edits["dt"]!r}\n'
    if "tangential" in edits:
        sim += f'tangential = "{edits["tangential"]}"\n'
    t = replace_once(t, "duration = 1.6\n", sim)
    t = replace_once(t, "[output]\nevery = 500\n", "[output]\nevery = 500\nply = true\n")
    if "gamma_s" in edits:
        t = replace_once(t, "gamma_s = 2.0\n", f"gamma_s = {edits['gamma_s']}\n")
    if "mu" in edits:
        t = replace_once(t, "mu = 0.5\n", f"mu = {edits['mu']}\n")
    if "seed" in edits:
        t = replace_once(t, "seed = 11\n", f"seed = {edits['seed']}\n")
    if "edge" in edits:
        t = replace_once(t, "[grain]\nradius = 5.0e-3\n", f"[grain]\nradius = 5.0e-3\nedge = {edits['edge'] * RADIUS:.6g}\n")
    return t, grains, pour_s + rest_s


def angle_series(out, grains, pour_s):
    """(time, angle, highest centre) of every PLY of run `out` from the end of the pour on: how the heap
    creeps once nothing more lands."""
    plys = sorted(f for f in os.listdir(out) if f.startswith("particles_") and f.endswith(".ply"))
    times = np.atleast_1d(np.genfromtxt(os.path.join(out, "metrics.csv"), delimiter=",", names=True)["time_s"])
    series = []
    for t, ply in zip(times, plys):
        if t >= pour_s and not (series and t == series[-1][0]):  # the last output and the final state may coincide
            xyz = read_ply_bodies(os.path.join(out, ply))[1][-grains:]
            series.append((float(t), repose_angle(xyz, RING), float(xyz[:, 2].max())))
    return series


def tetrasand_run(bin_dir, scene_file, out, grains, duration):
    wall, text = run(["nice", "-n", "15", os.path.join(bin_dir, "tetrasand"), "sim", scene_file, "-o", out,
                      "--backend", "cpu"])
    plys = sorted(f for f in os.listdir(out) if f.startswith("particles_") and f.endswith(".ply"))
    metrics = np.genfromtxt(os.path.join(out, "metrics.csv"), delimiter=",", names=True)
    times = np.atleast_1d(metrics["time_s"])
    if len(times) != len(plys):
        sys.exit(f"repose_sweep: {out}: {len(plys)} PLYs against {len(times)} metrics rows")
    final = read_ply_bodies(os.path.join(out, plys[-1]))[1][-grains:]
    k = int(np.argmin(np.abs(times - (duration - 0.5))))
    earlier = read_ply_bodies(os.path.join(out, plys[k]))[1][-grains:]
    m = re.search(r": (\d+) steps of ([0-9.e+-]+) s", text)
    overflows = int(np.atleast_1d(metrics["spring_overflows"]).sum())
    kinetic = float(np.atleast_1d(metrics["kinetic_translational_J"])[-1])
    series = angle_series(out, grains, grains / 1000.0)
    return final, wall, dict(series=series, steps=int(m.group(1)), dt=float(m.group(2)), angle_earlier=repose_angle(earlier, RING),
                             time_earlier=float(times[k]), spring_overflows=overflows, final_kinetic_J=kinetic)


def lammps_series(deck, grains):
    """(time, angle, highest centre) of every frame of the deck's particles.dump (one frame per [output]
    every steps) once all `grains` are in (fix deposit releases one grain every
    round(1 / (rate dt)) steps, so its pour ends at its own time)."""
    text = open(os.path.join(deck, "in.tetrasand")).read()
    dt = float(re.search(r"^timestep\s+(\S+)", text, re.M).group(1))
    series = []
    # sim_peers.read_dump_frames cannot read the empty frames of a pour's start: the full frames only.
    lines = open(os.path.join(deck, "particles.dump")).read().split("\n")
    for i, line in enumerate(lines):
        if line.startswith("ITEM: TIMESTEP"):
            step, n = int(lines[i + 1]), int(lines[i + 3])
            if n == 4 * grains:
                rows = np.array([l.split() for l in lines[i + 9:i + 9 + n]], dtype=float)
                xyz = centres(rows[:, 1].astype(int), rows[:, 3:6])[1]
                series.append((step * dt, repose_angle(xyz, RING), float(xyz[:, 2].max())))
    return series


def lammps_run(bin_dir, scene_file, deck):
    run([os.path.join(bin_dir, "tetrasand"), "export", "lammps", scene_file, "-o", deck])
    wall, _ = run(["nice", "-n", "15", "lmp", "-in", "in.tetrasand", "-log", "log.lammps", "-screen", "none"], cwd=deck)
    _, xyz = read_dump_frames(os.path.join(deck, "final.dump"))[-1]
    pair = [l.strip() for l in open(os.path.join(deck, "in.tetrasand")) if l.startswith("pair_coeff")]
    return xyz, wall, dict(pair_coeff=pair, series=lammps_series(deck, len(xyz)))


def final_centres(out, code, grains):
    if code == "lammps":
        return read_dump_frames(os.path.join(out, "final.dump"))[-1][1]
    plys = sorted(f for f in os.listdir(out) if f.startswith("particles_") and f.endswith(".ply"))
    return read_ply_bodies(os.path.join(out, plys[-1]))[1][-grains:]


def after_the_fact(xyz):
    """Measures added after the runs (docs label them so): spring_heap's angle B (its bounding radius is
    the touching grain's) and the mean grain-centre height."""
    return dict(angle_b=test_angle(xyz), mean_height_m=float(xyz[:, 2].mean()))


def save_json(path, data):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


def plot(results, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [n for n in RUNS if n in results]
    angles = [results[n]["angle"] for n in names]
    colours = ["tab:orange" if n.startswith("lammps") else "tab:grey" if n.startswith("base") else "tab:blue"
               for n in names]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.5), gridspec_kw=dict(width_ratios=[3, 2]))
    ax.axhspan(30, 40, color="tab:green", alpha=0.15, label="30-40 deg")
    ax.bar(range(len(names)), angles, color=colours)
    for i, n in enumerate(names):
        ax.text(i, angles[i] + 0.4, f"{angles[i]:.1f}", ha="center", fontsize=8)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, rotation=30, ha="right")
    ax.set_ylabel("angle of repose (deg)")
    ax.set_ylim(0, 42)
    ax.set_title("3,000-grain heap (mu 0.5, viscous, edge 2r): one factor changed per bar")
    ax.legend(loc="upper left")
    ax2.axhspan(30, 40, color="tab:green", alpha=0.15)
    for n in names:
        if results[n].get("series"):
            t, a, _ = np.array(results[n]["series"]).T
            ax2.plot(t, a, ".-", label=n)
    ax2.set_xlabel("time (s); each series starts when its pour's last grain is in")
    ax2.set_ylabel("angle of repose (deg)")
    ax2.set_title("angle against time after the pour")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    tmp = png + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, png)


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    bin_dir, work = os.path.abspath(args[0]), os.path.abspath(args[1])
    rest = args[2:]
    png = None
    if "--plot" in rest:
        i = rest.index("--plot")
        png = rest[i + 1]
        del rest[i:i + 2]
    plot_only = "--plot-only" in rest
    if plot_only:
        rest.remove("--plot-only")
    for name in rest:
        if name not in RUNS:
            sys.exit(f"repose_sweep: unknown run '{name}' (known: {' '.join(RUNS)})")
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "results.json")
    results = json.load(open(path)) if os.path.exists(path) else {}
    todo = [] if plot_only else (rest or list(RUNS))
    for name in todo:
        if name in results:
            continue
        code, edits = RUNS[name]
        text, grains, duration = scene_text(edits)
        scene_file = os.path.join(work, f"{name}.toml")
        open(scene_file, "w").write(text)
        start = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
        load = os.getloadavg()
        out = os.path.join(work, name)
        if code == "tetrasand":
            xyz, wall, info = tetrasand_run(bin_dir, scene_file, out, grains, duration)
        else:
            xyz, wall, info = lammps_run(bin_dir, scene_file, out)
        if len(xyz) != grains:
            sys.exit(f"repose_sweep: {name}: {len(xyz)} grains in the final state, {grains} expected")
        angle = repose_angle(xyz, RING)
        height = float(xyz[:, 2].max())
        info.update(after_the_fact(xyz))
        results[name] = dict(code=code, edits=edits, start=start, load_start=load, load_end=os.getloadavg(),
                             wall_s=wall, angle=angle, height_m=height, height_d=height / D_EQ, grains=grains, **info)
        save_json(path, results)
        print(f"{name}: {angle:.1f} deg, H {height * 1e3:.1f} mm = {height / D_EQ:.1f} d, {wall:.0f} s "
              f"({start}, load {load[0]:.1f})", flush=True)
    if png:
        # Runs recorded before the series was added to tetrasand_run get it from their PLYs.
        for name, r in results.items():
            out = os.path.join(work, name)
            if "angle_b" not in r and os.path.isdir(out):
                r.update(after_the_fact(final_centres(out, r["code"], r["grains"])))
            if "series" not in r and os.path.isdir(out):
                r["series"] = (angle_series(out, r["grains"], r["grains"] / 1000.0) if r["code"] == "tetrasand"
                               else lammps_series(out, r["grains"]))
        save_json(path, results)
        plot(results, png)
    print("\n| run | code | change | angle (deg) | angle B (deg) | H (d) | wall (s) |\n|---|---|---|---|---|---|---|")
    for name in RUNS:
        if name in results:
            r = results[name]
            b = f"{r['angle_b']:.1f}" if "angle_b" in r else "-"
            print(f"| {name} | {r['code']} | {r['edits'] or '-'} | {r['angle']:.1f} | {b} | {r['height_d']:.1f} | "
                  f"{r['wall_s']:.0f} |")


if __name__ == "__main__":
    main()
