#!/usr/bin/python3
"""Every default against the trade tables (issue 17): applies the rules of bench/defaults_criteria.md
to the tables already in the benchmark pages (docs/benchmarks/*.md) and docs/validation.md, runs the trades no
table held
(the sampler's SDF voxel, `sdf --band`, `sample`'s default count, and what a radius map would buy on
the dino), plots each trade with its default marked, and writes the section between
`<!-- section: defaults -->` and `<!-- end: defaults -->` of docs/benchmarks/defaults.md.

Usage: /usr/bin/python3 bench/defaults.py TETRASAND DOCS_DIR [--work DIR] [--repeats N] [--quick]
       [--only voxel,band,count,radius-map]
(Debian's python3-matplotlib). Each run's rows are kept in docs/benchmarks/defaults.json, so --only
reruns some trades and carries the others' last rows (with their own dates) into the section.
Exit 1 when a default fails its rule."""
import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from docs_section import replace_between  # noqa: E402

DEFAULT_STYLE = dict(marker="*", s=260, color="gold", edgecolor="black", zorder=5, label="default")
TRADES = ("voxel", "band", "count", "radius-map")
# The benchmark pages whose tables the rules read, in the order the one docs/benchmarks.md had them (a table's
# first match is the current one; docs/benchmarks/history.md, with the older tables, is left out).
PAGES = ("sdf", "sampler", "certificate", "preview", "sim", "defaults", "device", "round-trips")
# `sample`'s default count and the sweep around it (bench/defaults_criteria.md, addendum).
DEFAULT_COUNT = 8000  # sampler/sample_mesh.cpp's kDefaultCount (4000 until the sweep of 2026-12-03 picked 8000)
COUNTS = (1000, 2000, 4000, 8000, 16000)
COUNT_MESHES = ("bunny", "trefoil", "knot1", "bear", "dino")
CAVEATS_ALLOWED = ("dino",)  # its claws taper to 2.6 mm: no count of the sweep resolves them
VERDICT_RANK = {"not usable": 0, "usable with caveats": 1, "body OK": 2}


# ---- the tables already in the docs -------------------------------------------------------------

def markdown_table(doc, header_start):
    """Rows (lists of cell strings) of the first table whose header line starts with `header_start`."""
    lines = doc.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(header_start):
            rows = []
            for row in lines[i + 2:]:
                if not row.startswith("|"):
                    break
                rows.append([c.strip() for c in row.strip().strip("|").split("|")])
            return rows
    raise SystemExit(f"docs: no table starting with {header_start!r}")


def first_number(cell):
    m = re.search(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", cell)
    return float(m.group()) if m else None


def energy_rows(doc):
    """(E, dt / bound, [cpu, float, double] energy error, [cpu, float, double] overlap / r)."""
    out = []
    for r in markdown_table(doc, "| E (Pa) | dt / bound | dt (us) | energy error"):
        out.append((float(r[0]), float(r[1]), [float(x) for x in r[3].split("/")], [float(x) for x in r[4].split("/")]))
    return out


def restitution_rows(doc):
    """(dt / bound, forward Euler e or None, symplectic e or None)."""
    out = []
    for r in markdown_table(doc, "| dt / bound | steps per contact | restitution, forward Euler"):
        fwd = first_number(r[2]) if re.match(r"^\d", r[2]) else None
        sym = first_number(r[3]) if re.match(r"^\d", r[3]) else None
        out.append((float(r[0]), fwd, sym))
    return out


def sampler_trade_rows(doc):
    """(rounds, max iterations, iterations, seconds, c / r)."""
    return [(int(r[0]), int(r[1]), int(r[3]), float(r[5]), float(r[8]))
            for r in markdown_table(doc, "| rounds | max iterations | N | iterations")]


def tsuji_spread(validation):
    """The Tsuji restitution's largest distance from 0.65 over the measured speeds, from docs/validation.md."""
    m = re.search(r"Tsuji e within ([0-9.]+) of ([0-9.]+) from ([0-9.]+) to ([0-9.]+) m/s", validation)
    if not m:
        raise SystemExit("docs/validation.md: the Tsuji restitution sentence was not found")
    return float(m.group(1)), float(m.group(2)), float(m.group(3)), float(m.group(4))


# ---- the new runs --------------------------------------------------------------------------------

def resolve_mesh(name, tmp):
    if os.path.exists(name):
        return name
    member = f"data/meshes/{name}.off"
    with tarfile.open("/usr/share/doc/libcgal-dev/data.tar.gz") as tar:
        tar.extract(member, tmp)
    return os.path.join(tmp, member)


def run(cmd):
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - t
    if res.returncode not in (0,):
        raise SystemExit(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stdout}{res.stderr}")
    return res.stdout, seconds


def sample_json(exe, mesh, out, extra):
    text, seconds = run([exe, "-q", "sample", mesh, "-o", out, "--json", *extra])
    body, _ = json.JSONDecoder().raw_decode(text, text.index("{"))
    return body, seconds


def voxel_trade(exe, meshes, work, repeats):
    """Rows: mesh, voxel / r, seconds (median), c / r, certified, bound / r, rho, converged."""
    rows = []
    for name, mesh in meshes:
        out = os.path.join(work, f"voxel-{name}")
        body, _ = sample_json(exe, mesh, out, [])
        r = body["particle_radius"]
        for factor in (1.0, 0.5, 0.25):
            times, q = [], None
            for _ in range(repeats):
                b, s = sample_json(exe, mesh, out, ["--voxel", f"{factor * r:.9g}"])
                times.append(s)
                q = b["quality"]
                assert abs(b["particle_radius"] - r) <= 1e-9 * r, "the radius must not follow the voxel"
            rows.append(dict(mesh=name, voxel_over_r=factor, n=b["particle_count"], seconds=statistics.median(times),
                             c_over_r=q["covering_over_r"], certified=bool(q.get("coverage_certified")),
                             bound_over_r=q.get("covering_bound_over_r"), rho=q["relative_radius"],
                             converged=bool(q["converged"])))
            print(f"defaults: {name} voxel {factor} r: {rows[-1]}", flush=True)
    return rows


def band_trade(exe, mesh, resolutions, bands, work, repeats):
    """Rows: resolution, band, seconds (median of the scan), band voxels, peak GPU MiB, max error vs exact [voxels]."""
    rows = []
    for res in resolutions:
        for band in bands:
            times = []
            for _ in range(repeats):
                # --backend gpu: the scan conversion's band trade (plain sdf takes the CPU path on llvmpipe).
                text, _ = run([exe, "-q", "sdf", mesh, "-o", os.path.join(work, "band.vdb"), "--resolution", str(res),
                               "--band", str(band), "--json", "--backend", "gpu"])
                fig = json.loads(text[text.index("{"):])
                times.append(fig["scan_seconds"])
            text, _ = run([exe, "-q", "sdf", mesh, "-o", os.path.join(work, "band.vdb"), "--resolution", str(res),
                           "--band", str(band), "--compare-openvdb"])
            err = max_gpu_error(text)
            rows.append(dict(resolution=res, band=band, seconds=statistics.median(times), band_voxels=fig["band_voxels"],
                             peak_mib=fig["scan_peak_gpu_bytes"] / 1048576.0, nanovdb_mib=fig["nanovdb_bytes"] / 1048576.0,
                             max_error=err))
            print(f"defaults: band {band} at {res}: {rows[-1]}", flush=True)
    return rows


def max_gpu_error(text):
    """The largest |GPU - exact| in voxels from `sdf --compare-openvdb`'s comparison."""
    # The table's row: "tetrasand GPU vs exact  VOXELS  MEAN  P99  MAX  SIGNS".
    for line in text.splitlines():
        if line.startswith("tetrasand GPU vs exact"):
            values = line[len("tetrasand GPU vs exact"):].split()
            return float(values[3])
    raise SystemExit("sdf --compare-openvdb: no 'tetrasand ... exact ... max' line in\n" + text)


def count_trade(exe, meshes, counts, work):
    """`sample --count N` on each mesh: rows of mesh, count, particles, radius, seconds, verdict and figures."""
    rows = []
    for name, mesh in meshes:
        for count in counts:
            body, seconds = sample_json(exe, mesh, os.path.join(work, f"count-{name}-{count}"), ["--count", str(count)])
            q, thin = body["quality"], body["thin_features"]
            rows.append(dict(mesh=name, count=count, n=body["particle_count"], radius=body["particle_radius"],
                             seconds=seconds, verdict=body["verdict"], certified=bool(q.get("coverage_certified")),
                             bound_over_r=q.get("covering_bound_over_r"), rho=q["relative_radius"], cv=q["cv"],
                             converged=bool(q["converged"]), thin_share=thin["area_share"],
                             thin_regions=thin["region_count"]))
            print(f"defaults: {name} --count {count}: {rows[-1]}", flush=True)
    return rows


def read_off(path):
    """Vertices and triangles of an OFF or COFF file (colours ignored, polygons fanned)."""
    lines = [l.split("#")[0].split() for l in open(path)]
    lines = [l for l in lines if l]
    if not lines[0][0].endswith("OFF"):
        raise SystemExit(f"{path}: not an OFF file")
    counts = lines[0][1:] if len(lines[0]) > 1 else lines[1]
    first = 1 if len(lines[0]) > 1 else 2
    nv, nf = int(counts[0]), int(counts[1])
    verts = [tuple(float(w) for w in l[:3]) for l in lines[first:first + nv]]
    tris = []
    for l in lines[first + nv:first + nv + nf]:
        idx = [int(w) for w in l[1:1 + int(l[0])]]
        tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1)]
    return verts, tris


def triangle_area(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    x = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * (x[0] ** 2 + x[1] ** 2 + x[2] ** 2) ** 0.5


def inside(p, box_min, box_max, pad=0.0):
    return all(box_min[k] - pad <= p[k] <= box_max[k] + pad for k in range(3))


def ply_positions(path):
    """x, y, z of every vertex of a binary little-endian PLY of float properties (the body's particles)."""
    import struct
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    count = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    props = [l.split()[2] for l in header if l.startswith("property float")]
    stride = 4 * len(props)
    return [struct.unpack_from("<fff", data, end + stride * i) for i in range(count)]


def body_positions(out):
    ply = [f for f in os.listdir(out) if f.endswith(".particles.ply")]
    return ply_positions(os.path.join(out, ply[0]))


def radius_map_trade(exe, mesh, work):
    """What a two-radius body would buy on `mesh` (bench/defaults_criteria.md, addendum): (a) the default
    body; (b) the global radius resolving 90 % of every listed thin region, run; the global radius resolving
    every listed region in full, estimated by N ~ 1 / r^2; (c) the two-radius bodies, estimated from the thin
    area share; with the area figures checked against the mesh and run (b)'s particles."""
    out_a, out_b = os.path.join(work, "map-default"), os.path.join(work, "map-small")
    a, seconds_a = sample_json(exe, mesh, out_a, [])
    thin = a["thin_features"]
    listed = thin["regions"]
    r0, n0, share = a["particle_radius"], a["particle_count"], thin["area_share"]
    r_most = min(g["mostly_resolving_radius"] for g in listed if g["mostly_resolving_radius"] > 0)
    r_all = min(g["resolving_radius"] for g in listed if g["resolving_radius"] > 0)
    b, seconds_b = sample_json(exe, mesh, out_b, ["--radius", f"{r_most:.6g}"])
    nb = b["particle_count"]
    # The mesh's own areas: the whole surface, and the triangles lying in the listed regions' boxes (an
    # upper bound of the regions' area: each region's box holds all its triangles, perhaps others too).
    verts, tris = read_off(mesh)
    areas = [triangle_area(verts[i], verts[j], verts[k]) for i, j, k in tris]
    total = sum(areas)
    boxed = [0.0] * len(listed)
    for t, (i, j, k) in enumerate(tris):
        for g, region in enumerate(listed):
            if all(inside(verts[v], region["box_min"], region["box_max"], 1e-9) for v in (i, j, k)):
                boxed[g] += areas[t]
    listed_share = sum(g["area_share"] for g in listed)
    # Run (b)'s particles in the listed boxes against the share of the surface those boxes hold.
    positions = body_positions(out_b)
    in_boxes = sum(1 for p in positions if any(inside(p, g["box_min"], g["box_max"], 1e-9) for g in listed))
    expected_in_boxes = nb * sum(boxed) / total
    two_most = n0 * (1 - share) + n0 * share * (r0 / r_most) ** 2
    two_all = n0 * (1 - share) + n0 * share * (r0 / r_all) ** 2
    global_all = nb * (r_most / r_all) ** 2
    row = dict(
        default=dict(radius=r0, n=n0, seconds=seconds_a, verdict=a["verdict"], thin_share=share,
                     thin_regions=thin["region_count"], listed=len(listed), listed_share=listed_share),
        small=dict(radius=r_most, n=nb, seconds=seconds_b, verdict=b["verdict"],
                   thin_share=b["thin_features"]["area_share"], thin_regions=b["thin_features"]["region_count"],
                   rho=b["quality"]["relative_radius"], bound_over_r=b["quality"].get("covering_bound_over_r")),
        r_all=r_all, global_all_estimate=global_all, two_radius_most=two_most, two_radius_all=two_all,
        mesh_area=total, thin_area=share * total, listed_area=listed_share * total, boxed_area=sum(boxed),
        small_in_boxes=in_boxes, small_in_boxes_expected=expected_in_boxes)
    print(f"defaults: radius map: {row}", flush=True)
    return row


def per_particle_radii(root):
    """Whether the body format (body/particle_body.h) and the sim's particles (sim/world.h) carry one radius
    per particle: a vector of radii in the struct, where the format has one `particle_radius`."""
    body = open(os.path.join(root, "body", "particle_body.h")).read()
    world = open(os.path.join(root, "sim", "world.h")).read()
    body_has = re.search(r"std::vector<(float|double)>\s+\w*radi", body) is not None
    world_part = world[world.index("struct Particles"):]
    world_has = re.search(r"std::vector<(float|double)>\s+radius;", world_part[:world_part.index("};")]) is not None
    return body_has, world_has


# ---- rules ---------------------------------------------------------------------------------------

def count_rule(rows, default_at_run=DEFAULT_COUNT):
    """The count bench/defaults_criteria.md's addendum picks: the smallest count of the sweep at which every
    mesh is body OK (those in CAVEATS_ALLOWED: no worse than caveats) and no larger count gives any mesh a
    better verdict. Returns (count or None, evidence, met: the pick is DEFAULT_COUNT, the present default);
    the evidence names the default the sweep ran against when it was another."""
    meshes = list(dict.fromkeys(r["mesh"] for r in rows))
    counts = sorted({r["count"] for r in rows})
    rank = {(r["mesh"], r["count"]): VERDICT_RANK[r["verdict"]] for r in rows}

    def good_enough(mesh, count):
        return rank[(mesh, count)] >= (1 if mesh in CAVEATS_ALLOWED else 2)

    def saturated(mesh, count):
        return all(rank[(mesh, count)] >= rank[(mesh, k)] for k in counts if k > count)

    picks = [c for c in counts if all(good_enough(m, c) and saturated(m, c) for m in meshes)]
    pick = picks[0] if picks else None
    letter = {2: "OK", 1: "caveats", 0: "not usable"}
    evidence = "; ".join(f"{m}: " + ", ".join(f"{c} {letter[rank[(m, c)]]}" for c in counts) for m in meshes)
    evidence += f" (rule picks: {pick if pick else 'none'}; default {DEFAULT_COUNT}"
    if default_at_run != DEFAULT_COUNT:
        evidence += f", changed from {default_at_run} after this run"
    evidence += ")"
    return pick, evidence, pick == DEFAULT_COUNT


def radius_map_rule(row, body_radii, world_radii):
    """(measures well, runs end to end, evidence) for the radius map (bench/defaults_criteria.md, addendum)."""
    small_n, default_n, two = row["small"]["n"], row["default"]["n"], row["two_radius_most"]
    measures = two <= 0.25 * small_n and two <= 4 * default_n
    evidence = (f"two-radius body for 90 % of every listed region: about {two:.0f} particles = "
                f"{two / small_n:.2f} of the global radius's {small_n} (rule <= 0.25) and {two / default_n:.2f}x "
                f"the default's {default_n} (rule <= 4); per-particle radii: body format {body_radii}, "
                f"sim world {world_radii}")
    return measures, body_radii and world_radii, evidence


def verdicts(energy, restitution, trade, tsuji, voxels, bands, counts=None, radius_map=None, radii=(False, False),
             count_default_at_run=DEFAULT_COUNT):
    """(default, evidence, met) rows, each rule as bench/defaults_criteria.md states it."""
    v = []
    at1 = [r for r in restitution if r[0] == 1]
    sym1 = at1[0][2] if at1 else None
    fwd1 = at1[0][1] if at1 else None
    e_target = 0.65
    sym_ok = sym1 is not None and abs(sym1 - e_target) <= 0.02 * e_target
    drift = [r[2][0] for r in energy if r[1] == 1]  # the CPU reference's, the model's own figure
    drift_gpu = [max(r[2]) for r in energy if r[1] == 1]
    v.append(("sim `dt = \"auto\"` (dt / bound = 1)",
              f"symplectic restitution {sym1} at dt / bound = 1 (target 0.65 +- 2 %); energy drift at dt / bound = 1: "
              f"{', '.join(f'{d:.2e}' for d in drift)} (CPU), at most {max(drift_gpu):.2e} on any backend (rule: < 1e-2)",
              sym_ok and max(drift_gpu) < 1e-2))
    fwd_ok = fwd1 is not None and abs(fwd1 - e_target) <= 0.02 * e_target
    v.append(("integrator symplectic Euler (scene files)",
              f"restitution at dt / bound = 1: symplectic {sym1}, forward Euler {fwd1} (target 0.65 +- 2 %)",
              sym_ok and not fwd_ok))
    ratios = []
    for e, f, err, ovl in energy:
        if f == 1:
            ratios.append((e, err[1] / err[2], ovl[1] / ovl[2]))
    v.append(("GPU precision float",
              "float / double at dt / bound = 1: " + "; ".join(
                  f"E = {e:.0e}: drift {a:.2f}, overlap {b:.2f}" for e, a, b in ratios) + " (rule: each <= 1.5)",
              all(a <= 1.5 and b <= 1.5 for _, a, b in ratios)))
    spread, e0, vmin, vmax = tsuji
    v.append(("normal damping Tsuji",
              f"restitution within {spread} of {e0} from {vmin} to {vmax} m/s (docs/validation.md); rule: change "
              f"<= 2 % ({0.02 * e0:.3f}) between 0.1 and 10 m/s", spread <= 0.02 * e0 and vmin <= 0.1 and vmax >= 10))
    v.append(("tangential model viscous",
              "docs/benchmarks/sim.md (Bulk behaviour) and assets/scenes/README.md state the creep and name "
              "`tangential = \"spring\"`; checked by this script's text search", None))
    default_rows = [r for r in trade if r[0] == 12]
    reach = [r for r in trade if r[4] <= 1.0]
    smallest = min(reach, key=lambda r: r[0]) if reach else None
    rounds_ok = bool(default_rows) and default_rows[0][4] <= 1.0 and smallest is not None and \
        default_rows[0][3] <= smallest[3] * 1.2
    v.append(("sampler `--rounds 12`",
              f"c / r {default_rows[0][4] if default_rows else '-'} in {default_rows[0][3] if default_rows else '-'} s at 12; "
              f"the fewest rounds reaching c / r <= 1: {smallest[0] if smallest else '-'} in "
              f"{smallest[3] if smallest else '-'} s (rule: c / r <= 1, time within 20 %)", rounds_ok))
    capped = [r for r in trade if r[2] >= r[1]]
    v.append(("sampler `--max-iterations 2000`",
              f"iterations used {', '.join(str(r[2]) for r in trade)} of {trade[0][1]} (rule: every run below the cap)",
              not capped))
    if voxels:
        ok = True
        notes = []
        for mesh in sorted({r["mesh"] for r in voxels}):
            by = {r["voxel_over_r"]: r for r in voxels if r["mesh"] == mesh}
            half, quarter, one = by[0.5], by[0.25], by[1.0]
            good = half["certified"] and half["c_over_r"] <= 1 and abs(half["rho"] - quarter["rho"]) <= 0.02
            coarse_good = one["certified"] and one["c_over_r"] <= 1 and abs(one["rho"] - quarter["rho"]) <= 0.02
            faster = one["seconds"] < 0.8 * half["seconds"]
            ok = ok and good and not (coarse_good and faster)
            notes.append(f"{mesh}: r / 2 certified {half['certified']}, c / r {half['c_over_r']:.3f}, rho {half['rho']:.3f} "
                         f"(r / 4: {quarter['rho']:.3f}), {half['seconds']:.1f} s; r: certified {one['certified']}, "
                         f"c / r {one['c_over_r']:.3f}, rho {one['rho']:.3f}, {one['seconds']:.1f} s")
        v.append(("sampler voxel r / 2", "; ".join(notes), ok))
    if bands:
        ok = True
        notes = []
        for res in sorted({r["resolution"] for r in bands}):
            by = {r["band"]: r for r in bands if r["resolution"] == res}
            t = by[3]["seconds"] / by[1]["seconds"]
            m = by[3]["peak_mib"] / by[1]["peak_mib"]
            err = max(r["max_error"] for r in by.values())
            ok = ok and t <= 1.5 and m <= 1.5 and err < 1e-3
            notes.append(f"at {res}: band 3 / band 1 time {t:.2f}, peak GPU memory {m:.2f}, largest error {err:.1e} voxel")
        v.append(("`sdf --band 3`", "; ".join(notes) + " (rule: <= 1.5, <= 1.5, < 1e-3)", ok))
    if counts:
        _, evidence, met = count_rule(counts, count_default_at_run)
        v.append((f"`sample` count {DEFAULT_COUNT} (radius unset)", evidence, met))
    if radius_map:
        measures, end_to_end, evidence = radius_map_rule(radius_map, *radii)
        # Offering it is what the rule decides; "met" here means the present choice (not offered) is right.
        v.append(("no radius map (one radius per body)", evidence + f"; measures well: {measures}, runs end to end: "
                  f"{end_to_end}, so offer it: {measures and end_to_end}", not (measures and end_to_end)))
    return v


def benchmark_pages(docs):
    """The text of the benchmark pages under DOCS/benchmarks/, one after the other (see PAGES)."""
    return "\n".join(open(os.path.join(docs, "benchmarks", f"{page}.md")).read() for page in PAGES)


def tangential_documented(root):
    scenes = open(os.path.join(root, "assets", "scenes", "README.md")).read()
    bench = benchmark_pages(os.path.join(root, "docs"))
    return ("creep" in scenes.lower() or "creep" in bench.lower()) and 'tangential = "spring"' in (scenes + bench)


# ---- plots ---------------------------------------------------------------------------------------

def plot(energy, restitution, trade, voxels, bands, counts, radius_map, png):
    import matplotlib  # only here: the rules (and their test) need no plotting library

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(15, 12.5))
    ax = axes[0][0]
    for e in sorted({r[0] for r in energy}):
        sel = sorted((r for r in energy if r[0] == e), key=lambda r: r[1])
        ax.loglog([r[1] for r in sel], [r[2][0] for r in sel], "o-", label=f"E = {e:.0e} Pa (CPU)")
    ax.scatter([1] * len([r for r in energy if r[1] == 1]), [r[2][0] for r in energy if r[1] == 1], **DEFAULT_STYLE)
    ax.set(xlabel="dt / automatic bound", ylabel="energy drift / drop energy", title="time step (default: auto = 1)")
    ax.legend(fontsize=7)
    ax = axes[0][1]
    f = [r[0] for r in restitution if r[1] is not None]
    ax.semilogx(f, [r[1] for r in restitution if r[1] is not None], "s-", label="forward Euler")
    ax.semilogx([r[0] for r in restitution if r[2] is not None], [r[2] for r in restitution if r[2] is not None], "o-",
                label="symplectic Euler")
    ax.axhspan(0.65 * 0.98, 0.65 * 1.02, color="green", alpha=0.15, label="0.65 +- 2 %")
    ax.scatter([1], [r[2] for r in restitution if r[0] == 1], **DEFAULT_STYLE)
    ax.set(xlabel="dt / automatic bound", ylabel="restitution", title="integrator (default: symplectic)")
    ax.legend(fontsize=7)
    ax = axes[0][2]
    es = [r for r in energy if r[1] == 1]
    x = range(len(es))
    ax.bar([i - 0.2 for i in x], [r[2][1] for r in es], 0.4, label="GPU float")
    ax.bar([i + 0.2 for i in x], [r[2][2] for r in es], 0.4, label="GPU double")
    ax.scatter([i - 0.2 for i in x], [r[2][1] for r in es], **DEFAULT_STYLE)
    ax.set_xticks(list(x))
    ax.set_xticklabels([f"E = {r[0]:.0e}" for r in es])
    ax.set(ylabel="energy drift at dt = bound", title="precision (default: float)")
    ax.legend(fontsize=7)
    ax = axes[1][0]
    ax.plot([r[0] for r in trade], [r[4] for r in trade], "o-", label="c / r")
    ax.axhline(1.0, color="grey", ls="--", lw=0.8)
    ax.scatter([r[0] for r in trade if r[0] == 12], [r[4] for r in trade if r[0] == 12], **DEFAULT_STYLE)
    ax2 = ax.twinx()
    ax2.plot([r[0] for r in trade], [r[3] for r in trade], "s:", color="tab:red", label="time s")
    ax2.set_ylabel("time s", color="tab:red")
    ax.set(xlabel="--rounds", ylabel="c / r (trefoil, 1000)", title="hole-closing rounds (default: 12)")
    ax = axes[1][1]
    if voxels:
        for mesh in sorted({r["mesh"] for r in voxels}):
            sel = sorted((r for r in voxels if r["mesh"] == mesh), key=lambda r: r["voxel_over_r"])
            ax.semilogx([r["voxel_over_r"] for r in sel], [r["c_over_r"] for r in sel], "o-", label=f"{mesh} c / r")
            ax.semilogx([r["voxel_over_r"] for r in sel], [r["rho"] for r in sel], "s--", label=f"{mesh} rho")
            d = [r for r in sel if r["voxel_over_r"] == 0.5]
            ax.scatter([0.5, 0.5], [d[0]["c_over_r"], d[0]["rho"]], **DEFAULT_STYLE)
        ax.set(xlabel="SDF voxel / r", title="sampler voxel (default: r / 2)")
        ax.legend(fontsize=7)
    ax = axes[1][2]
    if bands:
        for res in sorted({r["resolution"] for r in bands}):
            sel = sorted((r for r in bands if r["resolution"] == res), key=lambda r: r["band"])
            ax.plot([r["band"] for r in sel], [r["seconds"] for r in sel], "o-", label=f"scan s, {res}^3")
            d = [r for r in sel if r["band"] == 3]
            ax.scatter([3], [d[0]["seconds"]], **DEFAULT_STYLE)
        ax.set(xlabel="--band [voxels]", ylabel="scan conversion s", title="sdf band (default: 3)")
        ax.legend(fontsize=7)
    if counts:
        plot_counts(axes[2][0], axes[2][1], counts)
    if radius_map:
        plot_radius_map(axes[2][2], radius_map)
    handles = [h for h in axes[0][0].collections[:1]]
    fig.legend(handles, ["default"], loc="upper right")
    fig.suptitle("Defaults (gold stars) on the trade curves; top row and rounds from the tables of docs/benchmarks/*.md")
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)


def plot_counts(verdict_ax, time_ax, counts):
    """`sample --count`: each mesh's verdict and time against the count, the default starred."""
    meshes = list(dict.fromkeys(r["mesh"] for r in counts))
    for k, mesh in enumerate(meshes):
        sel = sorted((r for r in counts if r["mesh"] == mesh), key=lambda r: r["count"])
        shift = 0.06 * (k - (len(meshes) - 1) / 2)  # side by side, not on top of each other
        ranks = [VERDICT_RANK[r["verdict"]] + shift for r in sel]
        verdict_ax.semilogx([r["count"] for r in sel], ranks, "o-", label=mesh)
        time_ax.loglog([r["count"] for r in sel], [r["seconds"] for r in sel], "o-", label=mesh)
        d = [r for r in sel if r["count"] == DEFAULT_COUNT]
        if d:
            star = {**DEFAULT_STYLE, "label": "_nolegend_"}
            verdict_ax.scatter([DEFAULT_COUNT], [VERDICT_RANK[d[0]["verdict"]] + shift], **star)
            time_ax.scatter([DEFAULT_COUNT], [d[0]["seconds"]], **star)
    verdict_ax.set_yticks([0, 1, 2])
    verdict_ax.set_yticklabels(["not usable", "caveats", "body OK"])
    verdict_ax.set_ylim(-0.5, 2.5)
    verdict_ax.set(xlabel="sample --count", title=f"sample count: verdict (default: {DEFAULT_COUNT})")
    verdict_ax.legend(fontsize=7)
    time_ax.set(xlabel="sample --count", ylabel="wall s (one run, shared cores)", title="sample count: time")
    time_ax.legend(fontsize=7)


def plot_radius_map(ax, m):
    """Particles of the dino's bodies: default, global small radius (run, and the full one estimated), and the
    two-radius bodies (estimated)."""
    bars = [("default\n(run)", m["default"]["n"], False), ("global r 90 %\n(run)", m["small"]["n"], False),
            ("global r all\n(estimate)", m["global_all_estimate"], True),
            ("two radii 90 %\n(estimate)", m["two_radius_most"], True),
            ("two radii all\n(estimate)", m["two_radius_all"], True)]
    for i, (name, n, estimate) in enumerate(bars):
        ax.bar(i, n, color="tab:grey" if estimate else "tab:blue", hatch="//" if estimate else None)
    ax.set_yscale("log")
    ax.set_xticks(range(len(bars)))
    ax.set_xticklabels([b[0] for b in bars], fontsize=7)
    ax.set(ylabel="particles", title=f"dino: what a radius map would cost (default body: {m['default']['n']})")


# ---- the section ---------------------------------------------------------------------------------

def run_line(name, meta):
    return (f"{name}: {meta['started']} on {meta['node']} ({meta['cores']} cores), renderer {meta['renderer']}, "
            f"load average {meta['load_start']} at the start, {meta['load_end']} at the end")


def section(v, trades, runs):
    """The section's markdown: the verdicts, the plot, each trade's table, each trade's run."""
    yes = lambda m: "**met**" if m else ("**not met**" if m is not None else "-")  # noqa: E731
    voxels, bands, counts, radius_map = (trades.get(t) for t in TRADES)
    lines = [
        "## Defaults", "",
        "`scripts/bench.sh defaults` (bench/defaults.py; rules in bench/defaults_criteria.md, committed before the "
        "runs). The first rows apply the rules to tables that were already in these docs (their rules were written "
        "with the tables in view: a check of consistency, not a blind test); the others are new runs, each trade on "
        "the date below (`--only` reruns some and carries the others' rows from docs/benchmarks/defaults.json). "
        "**No NVIDIA GPU was used.**", ""]
    lines += [f"- {run_line(t, runs[t])}" for t in TRADES if t in runs]
    lines += ["", "| default | evidence | rule |", "|---|---|---|"]
    for name, evidence, met in v:
        lines.append(f"| {name} | {evidence} | {yes(met)} |")
    lines += ["", "![defaults on the trade curves](defaults.png)", ""]
    if voxels:
        lines += ["Sampler voxel (default particle count, radius unset; median of "
                  f"{runs['voxel']['repeats']} runs each):", "",
                  "| mesh | voxel / r | N | time s | c / r (1M probes) | certified | bound / r | rho | converged |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for r in voxels:
            mark = " (default)" if r["voxel_over_r"] == 0.5 else ""
            bound = f"{r['bound_over_r']:.3f}" if r["bound_over_r"] is not None else "-"
            lines.append(f"| {r['mesh']} | {r['voxel_over_r']:g}{mark} | {r['n']} | {r['seconds']:.2f} | "
                         f"{r['c_over_r']:.3f} | {r['certified']} | {bound} | {r['rho']:.3f} | {r['converged']} |")
        lines.append("")
    if bands:
        lines += [f"`sdf --band` on knot1 (scan conversion time, median of {runs['band']['repeats']}; errors against "
                  "the exact SDF from `--compare-openvdb`):", "",
                  "| grid | band | scan s | band voxels | peak GPU MiB | NanoVDB MiB | largest error vs exact (voxels) |",
                  "|---|---|---|---|---|---|---|"]
        for r in bands:
            mark = " (default)" if r["band"] == 3 else ""
            lines.append(f"| {r['resolution']} | {r['band']}{mark} | {r['seconds']:.2f} | {r['band_voxels']} | "
                         f"{r['peak_mib']:.1f} | {r['nanovdb_mib']:.1f} | {r['max_error']:.1e} |")
        lines.append("")
    if counts:
        lines += count_table(counts)
    if radius_map:
        lines += radius_map_table(radius_map, runs["radius-map"].get("default_count", DEFAULT_COUNT))
    return "\n".join(lines)


def count_table(counts):
    lines = ["`sample MESH --count N` (radius unset; one run each, wall seconds of the whole command; thin share: "
             "the thin features' share of the surface area):", "",
             "| mesh | --count | N | r (m) | time s | verdict | certified bound c / r | rho | CV | converged | "
             "thin share | thin regions |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in counts:
        mark = " (default)" if r["count"] == DEFAULT_COUNT else ""
        bound = f"{r['bound_over_r']:.3f}" if r["bound_over_r"] is not None else "-"
        lines.append(f"| {r['mesh']} | {r['count']}{mark} | {r['n']} | {r['radius']:.4g} | {r['seconds']:.1f} | "
                     f"{r['verdict']} | {bound} | {r['rho']:.3f} | {r['cv']:.3f} | {r['converged']} | "
                     f"{100 * r['thin_share']:.2f} % | {r['thin_regions']} |")
    return lines + [""]


def radius_map_table(m, default_count):
    d, s = m["default"], m["small"]
    return [
        f"A radius map on CGAL's dino (a: the default body, radius unset, when the default count was {default_count}; "
        "b: the smallest `mostly_resolving_radius` of the "
        f"{d['listed']} thin regions the report lists, {100 * d['listed_share']:.2f} % of the area of "
        f"{100 * d['thin_share']:.2f} % in {d['thin_regions']} regions; run b's time is one run):", "",
        "| body | radius (m) | particles | time s | verdict | thin share | thin regions |", "|---|---|---|---|---|---|---|",
        f"| a. default (run) | {d['radius']:.4g} | {d['n']} | {d['seconds']:.1f} | {d['verdict']} | "
        f"{100 * d['thin_share']:.2f} % | {d['thin_regions']} |",
        f"| b. global radius resolving 90 % of every listed region (run) | {s['radius']:.4g} | {s['n']} | "
        f"{s['seconds']:.1f} | {s['verdict']} | {100 * s['thin_share']:.2f} % | {s['thin_regions']} |",
        f"| b'. global radius resolving every listed region (estimate: b x (r_b / r)^2) | {m['r_all']:.4g} | "
        f"{m['global_all_estimate']:.0f} | - | - | - | - |",
        f"| c. two radii: b's radius on the thin area, a's elsewhere (estimate) | {s['radius']:.4g} / {d['radius']:.4g} | "
        f"{m['two_radius_most']:.0f} | - | - | - | - |",
        f"| c'. two radii: the radius of b' on the thin area, a's elsewhere (estimate) | {m['r_all']:.4g} / {d['radius']:.4g} | "
        f"{m['two_radius_all']:.0f} | - | - | - | - |", "",
        f"Area check against the mesh (areas summed from the .off file): surface {m['mesh_area']:.4g} m^2, so the "
        f"thin share is {m['thin_area']:.4g} m^2 and the listed regions' {m['listed_area']:.4g} m^2; the triangles "
        f"lying in the listed regions' boxes hold {m['boxed_area']:.4g} m^2 (at least the regions' own area). Run b "
        f"has {m['small_in_boxes']} particles in those boxes, against {m['small_in_boxes_expected']:.0f} from its "
        "particles spread evenly by area.", ""]


# ---- keeping each trade's rows between runs -------------------------------------------------------

def carried_over(doc, record):
    """Each trade's last rows and run: from docs/benchmarks/defaults.json, or (before that file existed) the
    voxel and band tables of the section itself, with the run figures of its first line."""
    if os.path.exists(record):
        saved = json.load(open(record))
        return saved["trades"], saved["runs"]
    trades, runs = {}, {}
    head = re.search(r"`scripts/bench.sh defaults` \((.*?);.*? on (\S+) \((\d+) cores\), renderer (.*?), "
                     r"load average (.*?) at the start, (.*?) at the end", doc)
    meta = dict(started=head.group(1), node=head.group(2), cores=int(head.group(3)), renderer=head.group(4),
                load_start=head.group(5), load_end=head.group(6), repeats=2) if head else None
    try:
        rows = markdown_table(doc, "| mesh | voxel / r | N | time s |")
        trades["voxel"] = [dict(mesh=r[0], voxel_over_r=float(r[1].split()[0]), n=int(r[2]), seconds=float(r[3]),
                                c_over_r=float(r[4]), certified=r[5] == "True",
                                bound_over_r=None if r[6] == "-" else float(r[6]), rho=float(r[7]),
                                converged=r[8] == "True") for r in rows]
        rows = markdown_table(doc, "| grid | band | scan s |")
        trades["band"] = [dict(resolution=int(r[0]), band=int(r[1].split()[0]), seconds=float(r[2]),
                               band_voxels=int(r[3]), peak_mib=float(r[4]), nanovdb_mib=float(r[5]),
                               max_error=float(r[6])) for r in rows]
        if meta:
            runs["voxel"], runs["band"] = dict(meta), dict(meta)
    except SystemExit:
        pass
    return trades, runs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("exe")
    ap.add_argument("docs")
    ap.add_argument("--work", default=None)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="small meshes and sizes: a check that the script runs")
    ap.add_argument("--only", default=",".join(TRADES),
                    help="the trades to run, of " + ", ".join(TRADES) + "; the others' last rows are carried over")
    args = ap.parse_args()
    only = [t for t in args.only.split(",") if t]
    if any(t not in TRADES for t in only):
        raise SystemExit(f"--only: each of {args.only!r} must be one of {', '.join(TRADES)}")
    root = os.path.dirname(os.path.abspath(args.docs.rstrip("/")))
    bench_md = os.path.join(args.docs, "benchmarks", "defaults.md")
    record = os.path.join(args.docs, "benchmarks", "defaults.json")
    doc = benchmark_pages(args.docs)
    validation = open(os.path.join(args.docs, "validation.md")).read()
    trades, runs = carried_over(doc, record)
    renderer = subprocess.run([args.exe, "devices"], capture_output=True, text=True).stdout.strip().splitlines()
    renderer = next((l.strip() for l in renderer if "chosen" in l.lower()), renderer[-1] if renderer else "?")
    work = args.work or tempfile.mkdtemp(prefix="ts-defaults-")
    os.makedirs(work, exist_ok=True)
    knot1 = resolve_mesh("knot1", work)
    for trade in only:
        meta = dict(started=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), node=platform.node(),
                    cores=os.cpu_count(), renderer=renderer, load_start=" ".join(f"{x:.2f}" for x in os.getloadavg()),
                    repeats=args.repeats if trade in ("voxel", "band") else 1, default_count=DEFAULT_COUNT)
        if trade == "voxel":
            meshes = [("knot1", knot1)] if args.quick else [("knot1", knot1),
                                                            ("bunny", os.path.join(root, "assets", "bunny.obj"))]
            trades[trade] = voxel_trade(args.exe, meshes, work, args.repeats)
        elif trade == "band":
            trades[trade] = band_trade(args.exe, knot1, [64] if args.quick else [128, 256], [1, 2, 3, 5], work,
                                       args.repeats)
        elif trade == "count":
            names = ("trefoil", "knot1") if args.quick else COUNT_MESHES
            meshes = [(n, os.path.join(root, "assets", f"{n}.obj") if n in ("bunny", "trefoil") else resolve_mesh(n, work))
                      for n in names]
            trades[trade] = count_trade(args.exe, meshes, (1000, 2000, 4000) if args.quick else COUNTS, work)
        elif trade == "radius-map":
            trades[trade] = radius_map_trade(args.exe, resolve_mesh("dino", work), work)
        meta["load_end"] = " ".join(f"{x:.2f}" for x in os.getloadavg())
        runs[trade] = meta
    energy, restitution, trade = energy_rows(doc), restitution_rows(doc), sampler_trade_rows(doc)
    v = verdicts(energy, restitution, trade, tsuji_spread(validation), trades.get("voxel"), trades.get("band"),
                 trades.get("count"), trades.get("radius-map"), per_particle_radii(root),
                 runs.get("count", {}).get("default_count", DEFAULT_COUNT))
    v = [(n, e, tangential_documented(root) if m is None else m) for n, e, m in v]
    os.makedirs(os.path.join(args.docs, "benchmarks"), exist_ok=True)
    plot(energy, restitution, trade, trades.get("voxel"), trades.get("band"), trades.get("count"),
         trades.get("radius-map"), os.path.join(args.docs, "benchmarks", "defaults.png"))
    replace_between(bench_md, "<!-- section: defaults -->\n", "<!-- end: defaults -->", section(v, trades, runs))
    tmp = record + ".tmp"
    with open(tmp, "w") as f:
        json.dump(dict(trades=trades, runs=runs), f, indent=1)
    os.replace(tmp, record)
    for name, evidence, met in v:
        print(f"defaults: {'met' if met else 'NOT MET'}: {name}: {evidence}")
    return 0 if all(m for _, _, m in v) else 1


if __name__ == "__main__":
    sys.exit(main())
