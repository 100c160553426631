#!/usr/bin/python3
"""Spring heap against LAMMPS (docs/validation.md; criteria in bench/validation/spring_heap_criteria.md,
written before the first run).

The pour of assets/scenes/reference/coarse_pile.toml (300 grains, mu = 0.5) with viscous and with spring
friction on tetrasand's CPU reference, and on LAMMPS through `tetrasand export lammps` (linear_nohistory,
mindlin, and mindlin's deck with linear_history at the reference contact's k_t); every heap's angle by the
two measures of the criteria.

Usage: bench/validation/spring_heap.py BUILD_BIN_DIR WORK_DIR [RUN ...] [--set KEY=VALUE ...]
  RUN: tetrasand_viscous tetrasand_spring lammps_viscous lammps_mindlin lammps_linear_history (default: these),
       lammps_mindlin_rescale lammps_mindlin_force
  --set KEY=VALUE adds KEY = VALUE to the scene's [simulation] table for every run (a controlled run);
  --scene KEY=VALUE replaces the scene file's first line `KEY = ...` (e.g. gamma_s=8.0, seed=12).
Prints one line per run and a markdown table at the end; writes WORK_DIR/spring_heap.json.
"""
import json
import math
import os
import re
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
from sim_peers import read_dump_frames, read_ply_bodies, repose_angle, run  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCENE = os.path.join(ROOT, "assets", "scenes", "reference", "coarse_pile.toml")
RADIUS = 5.0e-3  # m, the pile's sphere radius
BOUND = RADIUS * (1 + math.sqrt(6) / 2)  # bounding radius of a tetrahedron of touching spheres
RUNS = ["tetrasand_viscous", "tetrasand_spring", "lammps_viscous", "lammps_mindlin", "lammps_linear_history"]
# Further LAMMPS variants of the mindlin deck (criteria, addendum 2): run name -> tangential model.
VARIANTS = {"lammps_mindlin_rescale": "mindlin_rescale", "lammps_mindlin_force": "mindlin/force"}


def scene_text(tangential, sim_sets, material_sets):
    text = open(SCENE).read()
    extra = "".join(f"{k} = {v}\n" for k, v in sim_sets) + f'tangential = "{tangential}"\n'
    text = text.replace("[simulation]\n", "[simulation]\n" + extra, 1)
    text = text.replace("[output]\nevery = 500\n", "[output]\nevery = 500\nply = true\n", 1)  # the final state
    for k, v in material_sets:
        text, n = re.subn(rf"^{k} = .*$", f"{k} = {v}", text, count=1, flags=re.M)
        if n != 1:
            sys.exit(f"spring_heap: key {k} not in {SCENE}")
    return text


def test_angle(xyz):
    """tests/sim/granular_physics_test.cpp's angle_of_repose: highest grain top (centre + bounding radius)
    per bin of two bounding radii about the centroid, fitted from bin 1 out to where the top is two
    bounding radii high."""
    axis = xyz[:, :2].mean(axis=0)
    bin_ = 2 * BOUND
    top = np.zeros(64)
    k = (np.linalg.norm(xyz[:, :2] - axis, axis=1) / bin_).astype(int)
    for kk, z in zip(k, xyz[:, 2]):
        if kk < len(top):
            top[kk] = max(top[kk], z + BOUND)
    ks = []
    for kk in range(1, len(top)):
        if top[kk] <= 2 * BOUND:
            break
        ks.append(kk)
    if len(ks) < 3:
        return 0.0
    x = (np.array(ks) + 0.5) * bin_
    return float(np.degrees(np.arctan(-np.polyfit(x, top[ks], 1)[0])))


def reference_kt(scene_file):
    """LAMMPS mindlin's k_t = 8 G* sqrt(R* delta) at the export's reference contact (one grain resting on
    another: R* = r / 2, delta = (m g / k_n)^(2/3)), from the scene's material."""
    text = open(scene_file).read()
    e = float(re.search(r"^E = (.*)$", text, re.M).group(1))
    nu = float(re.search(r"^nu = (.*)$", text, re.M).group(1))
    rho = float(re.search(r"^density = (.*)$", text, re.M).group(1))
    e_star = e / (2 * (1 - nu * nu))
    g = e / (2 * (1 + nu))
    g_star = 1 / (2 * (2 - nu) / g)
    r_star = RADIUS / 2
    mass = 4 * rho * 4 / 3 * math.pi * RADIUS ** 3  # four touching (non-overlapping) spheres
    delta = (mass * 9.81 / (4 / 3 * e_star * math.sqrt(r_star))) ** (2 / 3)
    return 8 * g_star * math.sqrt(r_star * delta), delta


def tetrasand_run(bin_dir, scene_file, out):
    wall, text = run([os.path.join(bin_dir, "tetrasand"), "sim", scene_file, "-o", out, "--backend", "cpu"])
    plys = sorted(f for f in os.listdir(out) if f.startswith("particles_") and f.endswith(".ply"))
    _, xyz = read_ply_bodies(os.path.join(out, plys[-1]))
    m = re.search(r": (\d+) steps of ([0-9.e+-]+) s", text)
    return xyz[-300:], wall, dict(steps=int(m.group(1)), dt=float(m.group(2))) if m else {}, text


def lammps_run(bin_dir, scene_file, deck, linear_history=None, variant=None):
    run([os.path.join(bin_dir, "tetrasand"), "export", "lammps", scene_file, "-o", deck])
    if variant is not None:
        path = os.path.join(deck, "in.tetrasand")
        text, n = re.subn(r"tangential mindlin ", f"tangential {variant} ", open(path).read())
        if n == 0:
            sys.exit("spring_heap: no mindlin in the exported deck")
        open(path, "w").write(text)
    if linear_history is not None:
        path = os.path.join(deck, "in.tetrasand")
        text = open(path).read()
        text, n = re.subn(r"tangential mindlin (\S+) ", f"tangential linear_history {linear_history:.6g} ", text)
        if n == 0:
            sys.exit("spring_heap: no mindlin in the exported deck")
        open(path, "w").write(text)
    wall, _ = run(["lmp", "-in", "in.tetrasand", "-log", "log.lammps", "-screen", "none"], cwd=deck)
    _, xyz = read_dump_frames(os.path.join(deck, "final.dump"))[-1]
    coeffs = [l for l in open(os.path.join(deck, "in.tetrasand")) if l.startswith("pair_coeff")]
    return xyz, wall, dict(pair_coeff=coeffs), ""


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    bin_dir, work = os.path.abspath(args[0]), os.path.abspath(args[1])
    rest = args[2:]
    sim_sets, material_sets, runs = [], [], []
    i = 0
    while i < len(rest):
        if rest[i] in ("--set", "--scene"):
            k, v = rest[i + 1].split("=", 1)
            (sim_sets if rest[i] == "--set" else material_sets).append((k, v))
            i += 2
        else:
            runs.append(rest[i])
            i += 1
    runs = runs or RUNS
    os.makedirs(work, exist_ok=True)
    scenes = {}
    for t in ("viscous", "spring"):
        scenes[t] = os.path.join(work, f"pile_{t}.toml")
        open(scenes[t], "w").write(scene_text(t, sim_sets, material_sets))
    kt, delta = reference_kt(scenes["spring"])
    results = {}
    for name in runs:
        start = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
        code, model = name.split("_", 1)
        scene_file = scenes["viscous" if model == "viscous" else "spring"]
        out = os.path.join(work, name)
        if code == "tetrasand":
            xyz, wall, info, _ = tetrasand_run(bin_dir, scene_file, out)
        else:
            xyz, wall, info, _ = lammps_run(bin_dir, scene_file, out, kt if model == "linear_history" else None,
                                            VARIANTS.get(name))
        if len(xyz) != 300:
            sys.exit(f"spring_heap: {name}: {len(xyz)} grains in the final state, 300 expected")
        a = repose_angle(xyz, ring_width=RADIUS)
        b = test_angle(xyz)
        results[name] = dict(start=start, wall_s=wall, angle_a=a, angle_b=b, height_mm=1e3 * float(xyz[:, 2].max()),
                             **info)
        print(f"{name}: A {a:.1f} deg, B {b:.1f} deg, top centre {results[name]['height_mm']:.1f} mm, "
              f"{wall:.0f} s ({start})", flush=True)
    results["_settings"] = dict(sim_sets=sim_sets, material_sets=material_sets, linear_history_kt=kt,
                                reference_overlap=delta, load=os.getloadavg())
    with open(os.path.join(work, "spring_heap.json"), "w") as f:
        json.dump(results, f, indent=1)
    print("\n| run | angle A (deg) | angle B (deg) | highest centre (mm) | wall (s) |\n|---|---|---|---|---|")
    for name in runs:
        r = results[name]
        print(f"| {name} | {r['angle_a']:.1f} | {r['angle_b']:.1f} | {r['height_mm']:.1f} | {r['wall_s']:.0f} |")


if __name__ == "__main__":
    main()
