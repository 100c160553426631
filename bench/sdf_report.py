#!/usr/bin/python3
"""Writes section `sdf` of docs/benchmarks/sdf.md from tetrasand_bench_sdf --csv output (one or more CSV
files, e.g. runs split over time), so every figure in it comes from the rows given. Called by
`scripts/bench.sh sdf`; also usable by hand:
  /usr/bin/python3 bench/sdf_report.py --markdown docs/benchmarks/sdf.md --renderer "..." \
      --command "scripts/bench.sh sdf ..." [--planned CASE ...] [--load "..."] [--png-name NAME] a.csv [b.csv ...]
CASE is MESH@R1,R2 as given to the bench; planned cases missing from the CSV are listed as not run."""
import argparse
import csv
import os
import time


def load_rows(paths):
    rows, seen = [], set()
    for path in paths:
        for r in csv.DictReader(open(path)):
            key = (r["mesh"], int(r["resolution"]))
            if key in seen:  # the later file wins: a rerun replaces an earlier row
                rows = [x for x in rows if (x["mesh"], int(x["resolution"])) != key]
            seen.add(key)
            rows.append(r)
    order = {}
    for r in rows:
        order.setdefault(r["mesh"], len(order))
    rows.sort(key=lambda r: (order[r["mesh"]], int(r["resolution"])))
    return rows


def short(mesh):
    return mesh if mesh.startswith("icosphere:") else os.path.splitext(os.path.basename(mesh))[0]


def missing_cases(planned, rows):
    have = {(r["mesh"], int(r["resolution"])) for r in rows}
    out = []
    for case in planned:
        mesh, _, res = case.rpartition("@")
        gone = [int(x) for x in res.split(",") if (short(mesh), int(x)) not in have]
        if gone:
            out.append(f"{short(mesh)} at {', '.join(map(str, gone))}")
    return out


def f(x, fmt):
    return format(float(x), fmt) if x not in ("", None) else "n/r"


def has_compute(rows):
    """Whether the rows carry the compute path's columns (CSV files written before issue 43 do not)."""
    return bool(rows) and all(r.get("compute_s") not in ("", None) for r in rows)


def table(rows):
    compute = has_compute(rows)
    head = ("| mesh | triangles | grid | band voxels | slabs | peak GPU MiB | geometry s | CPU exact s | OpenVDB s "
            "| exact / geometry | OpenVDB / geometry | geometry vs exact mean / max (voxels) | geometry wrong signs "
            "| OpenVDB vs exact mean / p99 / max (voxels) | OpenVDB wrong signs |")
    if compute:
        head += (" compute s | OpenVDB / compute | geometry / compute | compute vs exact mean / max (voxels) "
                 "| compute wrong signs | compute band = geometry band |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        g, e, v = float(r["gpu_s"]), float(r["exact_s"]), float(r["openvdb_s"])
        line = (
            f"| {r['mesh']} | {r['triangles']} | {r['nx']}x{r['ny']}x{r['nz']} ({r['resolution']}) | {r['band_voxels']} "
            f"| {r['slabs']} | {f(r['peak_gpu_mib'], '.1f')} | {g:.2f} | {e:.2f} | {v:.2f} | {e / g:.2f} | {v / g:.2f} "
            f"| {f(r['gpu_mean'], '.1e')} / {f(r['gpu_max'], '.1e')} | {r['gpu_wrong_signs']} "
            f"| {f(r['openvdb_mean'], '.4f')} / {f(r['openvdb_p99'], '.3f')} / {f(r['openvdb_max'], '.3f')} "
            f"| {r['openvdb_wrong_signs']} |")
        if compute:
            c = float(r["compute_s"])
            same = "yes" if r["compute_band_voxels"] == r["band_voxels"] else f"no ({r['compute_band_voxels']})"
            line += (f" {c:.2f} | {v / c:.2f} | {g / c:.2f} | {f(r['compute_mean'], '.1e')} / "
                     f"{f(r['compute_max'], '.1e')} | {r['compute_wrong_signs']} | {same} |")
        lines.append(line)
    return lines


def findings(rows):
    """Bullets whose every number is computed from `rows`."""
    num = lambda r, k: float(r[k])
    worst_gpu = max(rows, key=lambda r: num(r, "gpu_max"))
    gpu_signs = sum(int(r["gpu_wrong_signs"]) for r in rows)
    vdb_means = [num(r, "openvdb_mean") for r in rows]
    vdb_p99 = max(rows, key=lambda r: num(r, "openvdb_p99"))
    vdb_signs = [int(r["openvdb_wrong_signs"]) for r in rows]
    closer = sum(num(r, "gpu_max") < num(r, "openvdb_max") and num(r, "gpu_mean") < num(r, "openvdb_mean") for r in rows)
    out = [f"- **Accuracy.** The geometry path's largest error against exact is {num(worst_gpu, 'gpu_max'):.1e} voxel "
           f"({worst_gpu['mesh']} at {worst_gpu['resolution']}), with {gpu_signs} wrong signs over all {len(rows)} "
           f"runs. OpenVDB's mean error is {min(vdb_means):.1e} to {max(vdb_means):.1e} voxel, its p99 up to "
           f"{num(vdb_p99, 'openvdb_p99'):.3f} voxel ({vdb_p99['mesh']} at {vdb_p99['resolution']}), with "
           f"{min(vdb_signs)} to {max(vdb_signs)} wrong signs per run. The geometry path's field is closer to exact than "
           f"OpenVDB's (mean and max) in {closer} of {len(rows)} runs."]
    speed = [f"{mesh} ({rs[0]['triangles']} triangles): exact / geometry {time_ratios(rs, 'exact_s', 'gpu_s')}; "
             f"OpenVDB / geometry {time_ratios(rs, 'openvdb_s', 'gpu_s', at=False)}" for mesh, rs in rows_by_mesh(rows)]
    out.append("- **Speed** (time ratios; above 1 the geometry path is faster): " + "; ".join(speed) + ".")
    if has_compute(rows):
        out += compute_findings(rows)
    mem = [r for r in rows if r["peak_gpu_mib"] not in ("", None)]
    if mem:
        big = max(mem, key=lambda r: int(r["nx"]) * int(r["ny"]) * int(r["nz"]))
        out.append(f"- **Memory.** The largest grid, {big['nx']}x{big['ny']}x{big['nz']} ({big['mesh']} at "
                   f"{big['resolution']}), ran in {big['slabs']} z-slabs with peak GPU memory {float(big['peak_gpu_mib']):.0f} "
                   f"MiB (slab render target plus geometry buffers) for {int(big['band_voxels']):,} band voxels; "
                   "the host holds one slab's readback and the sparse level set.")
    return out


def rows_by_mesh(rows):
    """(mesh, its rows) in the order the meshes first appear."""
    for mesh in dict.fromkeys(r["mesh"] for r in rows):
        yield mesh, [r for r in rows if r["mesh"] == mesh]


def time_ratios(rs, top, bottom, at=True):
    """"a / b at R, ..." of two time columns over rows `rs`."""
    return ", ".join(f"{float(r[top]) / float(r[bottom]):.2f}" + (f" at {r['resolution']}" if at else "") for r in rs)


def compute_findings(rows):
    """The compute scan conversion's bullets (issue 43), every number from `rows`."""
    num = lambda r, k: float(r[k])
    worst = max(rows, key=lambda r: num(r, "compute_max"))
    signs = sum(int(r["compute_wrong_signs"]) for r in rows)
    same = sum(r["compute_band_voxels"] == r["band_voxels"] for r in rows)
    out = [f"- **Compute path.** Largest error against exact {num(worst, 'compute_max'):.1e} voxel ({worst['mesh']} at "
           f"{worst['resolution']}), {signs} wrong signs over all {len(rows)} runs; the same band voxel count as the "
           f"geometry path in {same} of {len(rows)} runs."]
    speed = [f"{mesh}: geometry / compute {time_ratios(rs, 'gpu_s', 'compute_s')}; "
             f"OpenVDB / compute {time_ratios(rs, 'openvdb_s', 'compute_s', at=False)}" for mesh, rs in rows_by_mesh(rows)]
    out.append("- **Compute speed** (above 1 the compute path is faster): " + "; ".join(speed) + ".")
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--markdown", help="docs/benchmarks/sdf.md to rewrite (section sdf)")
    ap.add_argument("--renderer", default="unknown")
    ap.add_argument("--command", default="scripts/bench.sh sdf")
    ap.add_argument("--planned", nargs="*", default=[])
    ap.add_argument("--load", default="")
    ap.add_argument("--png-name", default="sdf_error_vs_time.png")
    ap.add_argument("--notes", help="a markdown file appended to the section (hand-written explanations)")
    a = ap.parse_args()
    rows = load_rows(a.csv)
    if not rows:
        raise SystemExit("sdf_report: no rows in " + ", ".join(a.csv))
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    software = "llvmpipe" in a.renderer or "softpipe" in a.renderer
    lines = ["## SDF", "",
             f"Measured by `bench/sdf_bench.cpp` (`scripts/bench.sh sdf`) on {os.cpu_count()} cores ({cpu}), "
             f"{time.strftime('%Y-%m-%d')}, GL renderer {a.renderer}."
             + (" **No NVIDIA GPU was used**: every GPU figure here is Mesa's software rasteriser on the CPU cores, "
                "which the CPU paths share, so read the ratios, not the absolute seconds." if software else "")
             + (f" Load average: {a.load}." if a.load else ""), "",
             "For each mesh and resolution (voxels along the longest side, band half-width 3 voxels, automatic "
             "padding), one run builds the field four ways: tetrasand's GPU scan conversion by its geometry-shader path and "
             "by its compute path (`sdf::scan_convert`, "
             "wall time from upload to the flood-filled OpenVDB level set), the CPU exact SDF (`sdf::exact_sdf_grid`: "
             "CGAL AABB tree, double precision, TBB on all cores, tree build included) and OpenVDB's "
             "`tools::meshToLevelSet` (TBB, all cores). The three approximate paths are compared with exact over every "
             "voxel either has in its band (errors in voxels).", "",
             "```", a.command, "```", ""]
    lines += table(rows)
    lines.append("")
    gone = missing_cases(a.planned, rows)
    if gone:
        lines += ["Not run (planned, no row above): " + "; ".join(gone) + ".", ""]
    lines += [f"![SDF error against exact distance versus time]({a.png_name})", "", "What the numbers say:"]
    lines += findings(rows)
    if a.notes:
        lines += [""] + open(a.notes).read().rstrip("\n").split("\n")
    text = "\n".join(lines) + "\n"
    print(text)
    if a.markdown:
        doc = open(a.markdown).read()
        start, end = "<!-- section: sdf -->\n", "<!-- end: sdf -->"
        if start not in doc or end not in doc:
            raise SystemExit(f"{a.markdown}: markers of section sdf not found")
        i, j = doc.index(start) + len(start), doc.index(end)
        tmp = a.markdown + ".tmp"
        with open(tmp, "w") as out:
            out.write(doc[:i] + text + doc[j:])
        os.replace(tmp, a.markdown)


if __name__ == "__main__":
    main()
