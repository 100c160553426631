#!/usr/bin/env python3
"""Creep of a settled pile on the GPU pipeline: viscous friction (thesis eq. 3.28) against the spring
(static friction) model. Too slow for CI on llvmpipe (tests/sim/gpu_stepper_test.cpp checks a single
grain on an incline instead); run by hand:

    bench/sim_spring_creep.py --tetrasand build-test/bin/tetrasand [--cpu] [--out DIR]

300 grains of 5 mm spheres (E = 1 MPa, mu = 0.5) are poured on a rough floor and settle for 1.6 s;
the grains' mean and largest displacement over the next second is printed in sphere radii, with the
slot overflows of the spring run. The scene is the one of GranularPhysics.SettledPileWith* (CPU).
"""
import argparse
import pathlib
import struct
import subprocess
import sys
import tempfile

RADIUS = 5e-3  # m
DT = 1.5e-4    # s, below the automatic bound of this scene
SETTLE = 1.6   # s
WATCH = 1.0    # s

# The coarse pile shared with tests/sim/granular_physics_test.cpp; this script sets its own
# [simulation] and [output] (a longer run at a fixed dt, symplectic Euler, one friction model).
REFERENCE = pathlib.Path(__file__).resolve().parents[1] / "assets" / "scenes" / "reference" / "coarse_pile.toml"
RUN = """
[simulation]
duration = {duration}
dt = {dt}
integrator = "symplectic"
tangential = "{tangential}"

[output]
every = {every}
ply = true
"""


def pile_scene(duration: float, tangential: str, every: int) -> str:
    text = REFERENCE.read_text()
    return text[: text.index("[simulation]")] + RUN.format(duration=duration, dt=DT, tangential=tangential,
                                                            every=every)


def grain_centres(ply: pathlib.Path):
    """Mean position of each 4-sphere body in a tetrasand particle PLY (float x y z radius, uint body)."""
    data = ply.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    count = int(next(l for l in data[:end].decode().splitlines() if l.startswith("element vertex")).split()[2])
    bodies = {}
    for i in range(count):
        x, y, z, _, body = struct.unpack_from("<ffffI", data, end + 20 * i)
        bodies.setdefault(body, []).append((x, y, z))
    return {b: tuple(sum(c[k] for c in p) / 4 for k in range(3)) for b, p in bodies.items() if len(p) == 4}


def creep(tetrasand: str, tangential: str, cpu: bool, out: pathlib.Path):
    every = round(SETTLE / DT)
    scene = out / f"pile_{tangential}.toml"
    scene.write_text(pile_scene(SETTLE + WATCH, tangential, every))
    command = [tetrasand, "sim", str(scene), "-o", str(out / tangential)] + ["--backend", "cpu" if cpu else "gpu"]
    run = subprocess.run(command, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{run.stdout}{run.stderr}")
    dumps = sorted((out / tangential).glob("particles_*.ply"))
    settled, later = grain_centres(dumps[1]), grain_centres(dumps[-1])
    moved = [sum((later[b][k] - settled[b][k]) ** 2 for k in range(3)) ** 0.5 / RADIUS for b in settled]
    overflows = next((l for l in run.stdout.splitlines() if l.startswith("spring slots")), "")
    return sum(moved) / len(moved), max(moved), len(moved), overflows, run.stdout.splitlines()[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tetrasand", default="build-test/bin/tetrasand")
    parser.add_argument("--cpu", action="store_true", help="the CPU reference instead of the GPU pipeline")
    parser.add_argument("--out", help="keep the runs here (default: a temporary folder)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(args.out or tmp)
        out.mkdir(parents=True, exist_ok=True)
        print(f"| friction | grains | mean creep over {WATCH:g} s (radii) | largest (radii) | run |")
        print("|---|---|---|---|---|")
        for tangential in ("viscous", "spring"):
            mean, largest, grains, overflows, summary = creep(args.tetrasand, tangential, args.cpu, out)
            print(f"| {tangential} | {grains} | {mean:.3g} | {largest:.3g} | {summary} {overflows} |")


if __name__ == "__main__":
    main()
