#!/usr/bin/env python3
"""Writes the oedometer's piston, assets/bodies/piston.body.json and piston.particles.ply: a flat disc
of fixed spheres (radius 2 mm on a hexagonal lattice 3 mm apart, radius 46 mm, centres in z = 0), so a
servo-driven kinematic prop covers the 40 mm cylinder of assets/scenes/validation/oedometer.toml. A
hand-written body: only the physical keys the simulator reads (no sampling provenance or quality).
Mass and inertia are a steel disc 4 mm thick (a kinematic prop never uses them).
Usage: piston_body.py ASSETS_BODIES_DIR"""
import json
import math
import os
import struct
import sys

RADIUS = 0.046        # m, disc
PARTICLE = 0.002      # m, sphere radius
SPACING = 0.003       # m, lattice
THICKNESS = 0.004     # m, for mass and inertia only
DENSITY = 7800.0      # kg/m^3


def lattice():
    rows = int(RADIUS / (SPACING * math.sqrt(3) / 2)) + 1
    points = []
    for j in range(-rows, rows + 1):
        y = j * SPACING * math.sqrt(3) / 2
        shift = SPACING / 2 if j % 2 else 0.0
        for i in range(-rows - 1, rows + 2):
            x = i * SPACING + shift
            if math.hypot(x, y) <= RADIUS:
                points.append((x, y, 0.0))
    return points


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    points = lattice()
    # The centre of mass at the origin exactly: the lattice is symmetric, but float sums are not.
    cx = sum(p[0] for p in points) / len(points)
    cy = sum(p[1] for p in points) / len(points)
    points = [(x - cx, y - cy, z) for x, y, z in points]
    header = ("ply\nformat binary_little_endian 1.0\ncomment tetrasand particles: metres, mesh coordinates\n"
              f"element vertex {len(points)}\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
    with open(os.path.join(out, "piston.particles.ply.tmp"), "wb") as f:
        f.write(header.encode())
        for p in points:
            f.write(struct.pack("<3f", *p))
    os.replace(os.path.join(out, "piston.particles.ply.tmp"), os.path.join(out, "piston.particles.ply"))
    volume = math.pi * RADIUS ** 2 * THICKNESS
    mass = DENSITY * volume
    side = mass * (3 * RADIUS ** 2 + THICKNESS ** 2) / 12
    body = {
        "format_version": 1,
        "units": {"length": "m", "mass": "kg", "time": "s"},
        "particle_radius": PARTICLE,
        "particle_count": len(points),
        "particles": "piston.particles.ply",
        "density": DENSITY,
        "mass": mass,
        "volume": volume,
        "center_of_mass": [0.0, 0.0, 0.0],
        "inertia": [[side, 0.0, 0.0], [0.0, side, 0.0], [0.0, 0.0, mass * RADIUS ** 2 / 2]],
    }
    with open(os.path.join(out, "piston.body.json.tmp"), "w") as f:
        json.dump(body, f, indent=2)
        f.write("\n")
    os.replace(os.path.join(out, "piston.body.json.tmp"), os.path.join(out, "piston.body.json"))
    print(f"piston: {len(points)} spheres")


if __name__ == "__main__":
    main()
