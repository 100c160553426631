#!/usr/bin/env python3
"""Whether two `tetrasand sim` output folders of the same scene agree: the same layout and numbering, and
values equal up to the round-off of a changed summation order (issue 44: contact lists and cell order may
change the order of float sums, nothing more). scripts/same-outputs.sh --sim-tolerance calls it for the
sim folders whose bytes differ.

  scripts/sim_outputs_agree.py BASE_DIR HEAD_DIR      exit 0: they agree; 1: they do not, with the reasons

The criteria, written on 2026-12-07 before the first comparison of the contact-list step:
1. Layout and numbering, exactly: the same file names; PLY headers equal but for the time comment, the
   same vertex count, and the body and radius of every vertex bit for bit (a particle is the same particle
   in both); CSV files with the same header and row count, metrics.csv's step and time columns equal.
2. Values, at every output: particle positions within 5 % of the mean particle radius at the median and
   their centroid within 5 % of it too (round-off grows in chaotic collisions, so a few grains may part
   ways; the bulk may not); metrics.csv's mechanical energy (translational + rotational + potential) within
   1 % of the largest |energy| of the run, row by row.
"""
import csv
import os
import struct
import sys

POSITION_TOLERANCE = 0.05  # of the mean particle radius
ENERGY_TOLERANCE = 0.01    # of the largest |mechanical energy| of the run


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = [l for l in data[:end].decode().splitlines() if not l.startswith("comment")]
    count = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
    rows = list(struct.iter_unpack("<ffffI", data[end:end + 20 * count]))
    return header, rows


def median(values):
    s = sorted(values)
    return s[len(s) // 2] if s else 0.0


def compare_ply(a, b, name):
    (ha, ra), (hb, rb) = read_ply(a), read_ply(b)
    if ha != hb or len(ra) != len(rb):
        return [f"{name}: header or vertex count differs"]
    if any(x[3:] != y[3:] for x, y in zip(ra, rb)):
        return [f"{name}: a particle's body or radius differs (numbering changed)"]
    if not ra:
        return []
    radius = sum(x[3] for x in ra) / len(ra)
    moved = [sum((x[k] - y[k]) ** 2 for k in range(3)) ** 0.5 for x, y in zip(ra, rb)]
    centroid = sum(((sum(x[k] for x in ra) - sum(y[k] for y in rb)) / len(ra)) ** 2 for k in range(3)) ** 0.5
    bad = []
    if median(moved) > POSITION_TOLERANCE * radius:
        bad.append(f"{name}: median particle displacement {median(moved) / radius:.3g} radii > {POSITION_TOLERANCE}")
    if centroid > POSITION_TOLERANCE * radius:
        bad.append(f"{name}: centroids {centroid / radius:.3g} radii apart > {POSITION_TOLERANCE}")
    return bad


def compare_metrics(a, b, name):
    ra, rb = list(csv.DictReader(open(a))), list(csv.DictReader(open(b)))
    if len(ra) != len(rb) or (ra and ra[0].keys() != rb[0].keys()):
        return [f"{name}: header or row count differs"]
    energy_keys = [k for k in ("kinetic_translational_J", "kinetic_rotational_J", "potential_J") if ra and k in ra[0]]
    bad = []
    for x, y in zip(ra, rb):
        for k in ("step", "time_s"):
            if k in x and x[k] != y[k]:
                bad.append(f"{name}: {k} {x[k]} against {y[k]}")
    if energy_keys:
        ea = [sum(float(r[k]) for k in energy_keys) for r in ra]
        eb = [sum(float(r[k]) for k in energy_keys) for r in rb]
        scale = max(max(abs(e) for e in ea + eb), 1e-300)
        worst = max(abs(x - y) for x, y in zip(ea, eb)) / scale
        if worst > ENERGY_TOLERANCE:
            bad.append(f"{name}: mechanical energy differs by {worst:.3g} of its largest value > {ENERGY_TOLERANCE}")
    return bad


def compare_csv(a, b, name):
    ra, rb = open(a).read().splitlines(), open(b).read().splitlines()
    if not ra or not rb or ra[0] != rb[0]:
        return [f"{name}: header differs"]
    return [] if name.startswith("contacts_") else ([f"{name}: row count differs"] if len(ra) != len(rb) else [])


def agree(base, head):
    files_a = sorted(os.listdir(base))
    files_b = sorted(os.listdir(head))
    if files_a != files_b:
        return [f"file names differ: {sorted(set(files_a) ^ set(files_b))}"]
    bad = []
    for name in files_a:
        a, b = os.path.join(base, name), os.path.join(head, name)
        if open(a, "rb").read() == open(b, "rb").read():
            continue
        if name.endswith(".ply"):
            bad += compare_ply(a, b, name)
        elif name == "metrics.csv":
            bad += compare_metrics(a, b, name)
        elif name.endswith(".csv"):
            bad += compare_csv(a, b, name)
        elif name.endswith(".png"):
            continue  # frames follow the particles, compared above
        else:
            bad.append(f"{name}: differs (no tolerance applies to it)")
    return bad


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    bad = agree(sys.argv[1], sys.argv[2])
    for line in bad:
        print(f"{sys.argv[2]}: {line}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
