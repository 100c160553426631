#!/usr/bin/python3
"""Simulation against LAMMPS, side by side in one run (docs/benchmarks/sim.md, section peers-sim).

The same scenes run on tetrasand's CPU reference (`tetrasand sim --backend cpu`), its GPU pipeline
(`tetrasand sim --backend gpu`, on whatever EGL device is there: llvmpipe without a GPU) and LAMMPS
(`tetrasand export lammps` + Debian's `lmp`, serial and `mpirun -np 2`), with the same material,
time step and duration. Reported: grain-steps per second as ratios to LAMMPS serial (process wall
time, start-up included, the same for every code) and the physical outcome:
  bed      300 grains settling in a smooth 2 cm box: mean grain-centre height (tolerance 4 %)
  bounce   one spinless, nearly spherical grain dropped 4 mm: rebound apex (tolerance 2 %)
  heap     400 grains poured onto a rough floor: angle of repose (tolerance 3 degrees; CPU and LAMMPS)
(assets/scenes/reference/{bed,bounce,heap}.toml).

Usage: bench/peers/sim_peers.py BUILD_BIN_DIR WORK_DIR [--markdown FILE] [--no-gpu]
"""
import os
import re
import struct
import subprocess
import sys
import time

import numpy as np

# The scenes, shared with tests/export/lammps_deck_test.cpp and bench/validation.
REFERENCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "assets", "scenes", "reference")


def read_ply_bodies(path):
    """Grain centres (mean of each dynamic body's particles) from a tetrasand particles PLY."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    n = int(re.search(r"element vertex (\d+)", header).group(1))
    rec = np.frombuffer(data[end:end + n * 20], dtype=np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                                                ("r", "<f4"), ("body", "<u4")]))
    return centres(rec["body"], np.stack([rec["x"], rec["y"], rec["z"]], axis=1).astype(float))


def centres(ids, xyz):
    order = np.argsort(ids, kind="stable")
    ids, xyz = ids[order], xyz[order]
    uniq, start, counts = np.unique(ids, return_index=True, return_counts=True)
    sums = np.add.reduceat(xyz, start, axis=0)
    return uniq, sums / counts[:, None]


def read_dump_frames(path):
    """Frames of a LAMMPS dump `id mol type x y z radius`: per frame (mol ids, molecule centres)."""
    frames = []
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: NUMBER OF ATOMS"):
            n = int(lines[i + 1])
            rows = np.array([l.split() for l in lines[i + 7:i + 7 + n]], dtype=float).reshape(n, -1)
            frames.append(centres(rows[:, 1].astype(int), rows[:, 3:6]))
            i += 7 + n
        else:
            i += 1
    return frames


def frozen_free(uniq, xyz, grains):
    """tetrasand PLYs hold rough-wall particles too: keep the last `grains` bodies (dynamic ones come last)."""
    return xyz[-grains:] if grains else xyz


def run(cmd, cwd=None, env=None):
    start = time.monotonic()
    p = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.monotonic() - start
    if p.returncode != 0:
        sys.exit(f"sim_peers: {' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-3000:]}")
    return wall, p.stdout


def tetrasand(bin_dir, scene, out, gpu):
    cmd = [os.path.join(bin_dir, "tetrasand"), "sim", scene, "-o", out] + (["--backend", "gpu"] if gpu else ["--backend", "cpu"])
    wall, text = run(cmd)
    m = re.search(r": (\d+) steps of ([0-9.e+-]+) s, (\d+) grains, .*grain-steps/s, (.*)\)\n", text)
    steps, grains, device = int(m.group(1)), int(m.group(3)), m.group(4)
    plys = sorted(f for f in os.listdir(out) if f.startswith("particles_") and f.endswith(".ply"))
    return dict(wall=wall, steps=steps, grains=grains, device=device, plys=[os.path.join(out, f) for f in plys])


def lammps(bin_dir, scene, deck, ranks):
    run([os.path.join(bin_dir, "tetrasand"), "export", "lammps", scene, "-o", deck])
    cmd = ["lmp", "-in", "in.tetrasand", "-log", "log.lammps", "-screen", "none"]
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + cmd
    wall, _ = run(cmd, cwd=deck)
    log = open(os.path.join(deck, "log.lammps")).read()
    version = re.search(r"LAMMPS \((.*?)\)", log).group(1)
    steps = sum(int(s) for s in re.findall(r"Loop time of [0-9.e+-]+ on \d+ procs for (\d+) steps", log))
    return dict(wall=wall, steps=steps, version=version, deck=deck)


def bed_height(xyz):
    return float(np.mean(xyz[:, 2]))


def rebound_apex(z, radius=1e-3):
    """Highest centre height after the first floor contact, above the resting height `radius`."""
    low = int(np.argmin(z[: len(z) // 2]))
    return float(np.max(z[low:low + 400]) - radius), float(z[0] - radius)


def repose_angle(xyz, ring_width=2e-3):
    """Slope of a heap's flank: the highest grain centre per ring (2 mm wide for the 1 mm grains; about a
    grain radius), fitted from the last ring above 80 % of the heap's height outwards to the first ring
    below 20 % (not the flat top, not the scattered grains around it)."""
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    ring = (r / ring_width).astype(int)
    top = np.zeros(ring.max() + 1)
    np.maximum.at(top, ring, xyz[:, 2])
    h = top.max()
    first = int(np.nonzero(top > 0.8 * h)[0].max())
    below = np.nonzero(top[first:] < 0.2 * h)[0]
    last = first + (int(below[0]) if len(below) else len(top) - first)
    x = (np.arange(len(top)) + 0.5) * ring_width
    if last - first < 2:
        return float("nan")
    slope = np.polyfit(x[first:last], top[first:last], 1)[0]
    return float(np.degrees(np.arctan(-slope)))


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    bin_dir, work = args[0], args[1]
    markdown = args[args.index("--markdown") + 1] if "--markdown" in args else None
    gpu = "--no-gpu" not in args
    os.makedirs(work, exist_ok=True)
    scenes = {name: os.path.join(REFERENCE, name + ".toml") for name in ("bed", "heap", "bounce")}
    # The same bounce under forward Euler (the thesis integrator), for information.
    bounce = open(scenes["bounce"]).read()
    if 'integrator = "symplectic"' not in bounce:
        sys.exit(f"sim_peers: {scenes['bounce']}: expected integrator = \"symplectic\"")
    scenes["bounce_euler"] = os.path.join(work, "bounce_euler.toml")
    open(scenes["bounce_euler"], "w").write(bounce.replace('integrator = "symplectic"', 'integrator = "euler"'))

    rows, physics = [], []
    # Bed: speed and settled height, every code.
    bed = {}
    bed["CPU reference"] = tetrasand(bin_dir, scenes["bed"], os.path.join(work, "bed_cpu"), gpu=False)
    if gpu:
        bed["GPU pipeline"] = tetrasand(bin_dir, scenes["bed"], os.path.join(work, "bed_gpu"), gpu=True)
    bed["LAMMPS serial"] = lammps(bin_dir, scenes["bed"], os.path.join(work, "bed_lammps"), 1)
    bed["LAMMPS mpirun -np 2"] = lammps(bin_dir, scenes["bed"], os.path.join(work, "bed_lammps2"), 2)
    grains = bed["CPU reference"]["grains"]
    heights = {}
    for name, r in bed.items():
        if "plys" in r:
            heights[name] = bed_height(frozen_free(*read_ply_bodies(r["plys"][-1]), grains))
        else:
            heights[name] = bed_height(read_dump_frames(os.path.join(r["deck"], "final.dump"))[-1][1])
        r["rate"] = r["steps"] * grains / r["wall"]
    base = bed["LAMMPS serial"]["rate"]
    for name, r in bed.items():
        rows.append((name, r.get("device", "CPU, LAMMPS " + r.get("version", "")), r["rate"], r["rate"] / base,
                     r["wall"]))
    ref = heights["LAMMPS serial"]
    for name, h in heights.items():
        physics.append(("bed: mean grain-centre height", name, f"{h * 1e3:.3f} mm", f"{(h / ref - 1) * 100:+.1f} %",
                        "4 %", abs(h / ref - 1) <= 0.04))

    # Bounce: rebound apex of a spinless grain (symplectic and forward Euler against velocity Verlet).
    lb = lammps(bin_dir, scenes["bounce"], os.path.join(work, "bounce_lammps"), 1)
    z_l = np.array([f[1][0, 2] for f in read_dump_frames(os.path.join(lb["deck"], "particles.dump"))])
    apex_l, drop = rebound_apex(z_l)
    physics.append(("bounce: rebound apex", "LAMMPS serial", f"{apex_l * 1e3:.4f} mm (e = {np.sqrt(apex_l / drop):.4f})",
                    "reference", "", True))
    for name, scene in [("CPU reference, symplectic Euler", "bounce"), ("CPU reference, forward Euler", "bounce_euler")]:
        r = tetrasand(bin_dir, scenes[scene], os.path.join(work, scene + "_cpu"), gpu=False)
        z = np.array([read_ply_bodies(p)[1][0, 2] for p in r["plys"]])
        apex, _ = rebound_apex(z)
        # Forward Euler is shown for information: it is not the integrator LAMMPS has.
        symplectic = scene == "bounce"
        physics.append(("bounce: rebound apex", name, f"{apex * 1e3:.4f} mm (e = {np.sqrt(apex / drop):.4f})",
                        f"{(apex / apex_l - 1) * 100:+.2f} %", "2 %" if symplectic else "(informative)",
                        abs(apex / apex_l - 1) <= 0.02 if symplectic else None))

    # Heap: angle of repose, CPU reference and LAMMPS.
    hc = tetrasand(bin_dir, scenes["heap"], os.path.join(work, "heap_cpu"), gpu=False)
    hl = lammps(bin_dir, scenes["heap"], os.path.join(work, "heap_lammps"), 1)
    a_c = repose_angle(frozen_free(*read_ply_bodies(hc["plys"][-1]), hc["grains"]))
    a_l = repose_angle(read_dump_frames(os.path.join(hl["deck"], "final.dump"))[-1][1])
    physics.append(("heap: angle of repose", "LAMMPS serial", f"{a_l:.1f} deg", "reference", "", True))
    physics.append(("heap: angle of repose", "CPU reference", f"{a_c:.1f} deg", f"{a_c - a_l:+.1f} deg", "3 deg",
                    abs(a_c - a_l) <= 3))

    cpu_model = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    lines = ["## Simulation against LAMMPS", "",
             f"Measured by `scripts/bench.sh peers-sim` (bench/peers/sim_peers.py) on {os.cpu_count()} cores "
             f"({cpu_model}), {time.strftime('%Y-%m-%d')}; GL renderer of the GPU run: "
             f"{bed['GPU pipeline']['device'] if gpu else 'not run'}. "
             "No NVIDIA GPU was used: every GPU figure here is Mesa's llvmpipe (software).", "",
             f"Same scene, same material (E = 1 MPa, nu = 0.3, e = 0.5, mu = 0.5, gamma_s = 0.1 N s/m), same dt "
             f"({bed['CPU reference']['steps']} steps over 0.4 s), {grains} grains settling in a smooth 2 cm box. "
             "LAMMPS runs the deck written by `tetrasand export lammps`. Rates are process wall time (start-up "
             "included) for all codes; the CPU reference uses TBB on every core, LAMMPS serial one core and "
             "`mpirun -np 2` two. The machine is shared with other jobs, so read the ratios, not the absolute "
             "figures.", "",
             "| code | device | grain-steps/s | ratio to LAMMPS serial | wall s |", "|---|---|---|---|---|"]
    for name, device, rate, ratio, wall in rows:
        lines.append(f"| {name} | {device} | {rate:.3g} | {ratio:.2f} | {wall:.1f} |")
    lines += ["", "Physical outcome (tolerances stated before the run):", "",
              "| quantity | code | value | vs LAMMPS | tolerance | within |", "|---|---|---|---|---|---|"]
    for q, name, value, diff, tol, ok in physics:
        lines.append(f"| {q} | {name} | {value} | {diff} | {tol} | {'-' if ok is None else 'yes' if ok else 'NO'} |")
    lines += ["",
              "Notes: the bounce is a grain of four coincident spheres (edge 1 um) dropped without spin, so it "
              "measures the normal contact law alone; LAMMPS's Tsuji polynomial is not the Hertz oscillator's, so "
              "the deck hands LAMMPS the restitution whose polynomial value equals tetrasand's damping strength "
              "(handing it e = 0.6 as is rebounds 1.9 times as high). Forward Euler (the thesis integrator, "
              "tetrasand's default) gains energy in each contact and rebounds higher than velocity Verlet at the "
              "same dt; symplectic Euler agrees. The heap uses LAMMPS's own random pour sites (fix deposit), so its "
              "grains are not the same grains, only the same statistics."]
    text = "\n".join(lines) + "\n"
    print(text)
    if markdown:
        doc = open(markdown).read()
        start, end = "<!-- section: peers-sim -->\n", "<!-- end: peers-sim -->"
        i, j = doc.index(start) + len(start), doc.index(end)
        tmp = markdown + ".tmp"
        open(tmp, "w").write(doc[:i] + text + doc[j:])
        os.replace(tmp, markdown)
    return 0 if all(p[-1] is not False for p in physics) else 1


if __name__ == "__main__":
    sys.exit(main())
