"""GPU and host memory of the SDF against resolution: the sparse NanoVDB field the sampler and the
preview read now, against the dense 3D textures they held before (RGBA32F for the sampler, R32F for
the preview). Runs `tetrasand sdf MESH --resolution N -o OUT.nvdb --json` per mesh and resolution,
writes section sparse of docs/benchmarks/sdf.md and docs/benchmarks/sparse_memory.png.

usage: sparse_memory.py TETRASAND MESH[,...] RESOLUTION[,...] --markdown DOCS.md --plot PNG
       [--rows ROWS.json [--keep]]
       sparse_memory.py --report-only --rows ROWS.json --markdown DOCS.md --plot PNG
--rows writes every row's raw figures (the command's JSON, wall time, peak resident memory, when it ran)
to ROWS.json; with --keep the rows already in ROWS.json for a mesh and N not run this time are kept
(marked with their own run's time in the table), so one large N can be added without rerunning the rest.
--report-only runs nothing: it writes the section and the plot from ROWS.json as it stands.
--add-row ROW.json (with --report-only) first adds rows made by hand to ROWS.json: the JSON of a
`tetrasand sdf --json` run plus the keys run() adds (name, resolution, measured_utc, load_at_start,
peak_rss_bytes). A row whose "backend" is "cpu" (the exact CPU path, which scans nothing and reads
nothing back) shows "-" for the scan's columns, is plotted hollow and is left out of the read-back
criterion; it is how grids the GPU path cannot take on this machine enter the plot.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from docs_section import replace_between  # noqa: E402

MIB = 1048576.0


def run(binary, mesh, resolution, work):
    out = os.path.join(work, f"{os.path.basename(mesh)}.{resolution}.nvdb")
    # --backend gpu: the scan converter, named so that no default can swap in the exact CPU path.
    cmd = [binary, "sdf", mesh, "--resolution", str(resolution), "-o", out, "--json", "--backend", "gpu"]
    start = time.time()
    stamp = time.strftime("%Y-%m-%d %H:%M", time.gmtime(start))
    load = open("/proc/loadavg").read().split()[0]
    # Output to files and os.wait4 on this one child: its own peak resident memory (ru_maxrss, KiB),
    # which getrusage(RUSAGE_CHILDREN) would mix with every earlier child's.
    with open(os.path.join(work, "stdout"), "w+") as so, open(os.path.join(work, "stderr"), "w+") as se:
        child = subprocess.Popen(cmd, stdout=so, stderr=se)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        so.seek(0)
        se.seek(0)
        stdout, stderr = so.read(), se.read()
    if child.returncode != 0:
        print(f"sparse: {' '.join(cmd)} failed ({child.returncode}): {stderr.strip()}", file=sys.stderr)
        return None
    row = json.loads(stdout)
    if row.get("backend") != "gpu":
        raise SystemExit(f"sparse: {' '.join(cmd)} ran backend {row.get('backend')!r}, not the GPU scan converter")
    row["wall_seconds"] = time.time() - start
    row["peak_rss_bytes"] = usage.ru_maxrss * 1024
    row["measured_utc"] = stamp
    row["load_at_start"] = load
    row["resolution"] = resolution
    row["name"] = os.path.splitext(os.path.basename(mesh))[0]
    os.remove(out)
    return row


def table(rows):
    lines = ["| mesh | N | grid | band voxels | dense RGBA32F [MiB] | dense R32F [MiB] | NanoVDB on GPU [MiB] | "
             "GPU B / band voxel | read back [MiB] | dense read-back [MiB] | host B / band voxel | scan peak GPU [MiB] | s | "
             "host peak RSS [MiB] | run (UTC) |",
             "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        if r.get("backend") == "cpu":
            lines.append(cpu_row(r))
            continue
        dims = r["grid"]["dims"]
        voxels = dims[0] * dims[1] * dims[2]
        peak = f"{r['peak_rss_bytes'] / MIB:,.0f}" if r.get("peak_rss_bytes") else "-"
        lines.append(
            f"| {r['name']} | {r['resolution']} | {dims[0]} x {dims[1]} x {dims[2]} | {r['band_voxels']:,} | "
            f"{16 * voxels / MIB:,.1f} | {4 * voxels / MIB:,.1f} | {r['nanovdb_bytes'] / MIB:,.2f} | "
            f"{r['nanovdb_bytes_per_band_voxel']:.2f} | {r['readback_bytes'] / MIB:,.2f} | {16 * voxels / MIB:,.1f} | "
            f"{r['host_bytes_per_band_voxel']:.2f} | {r['scan_peak_gpu_bytes'] / MIB:,.1f} | {r['total_seconds']:.2f} | "
            f"{peak} | {r['measured_utc']}, load {r['load_at_start']} |")
    return "\n".join(lines)


def cpu_row(r):
    """A row built by the exact CPU path: the field's memory, no scan, no read-back."""
    dims = r["grid"]["dims"]
    voxels = dims[0] * dims[1] * dims[2]
    peak = f"{r['peak_rss_bytes'] / MIB:,.0f}" if r.get("peak_rss_bytes") else "-"
    return (f"| {r['name']} (cpu) | {r['resolution']} | {dims[0]} x {dims[1]} x {dims[2]} | {r['band_voxels']:,} | "
            f"{16 * voxels / MIB:,.1f} | {4 * voxels / MIB:,.1f} | {r['nanovdb_bytes'] / MIB:,.2f} | "
            f"{r['nanovdb_bytes_per_band_voxel']:.2f} | - | - | {r['host_bytes_per_band_voxel']:.2f} | - | "
            f"{r['total_seconds']:.2f} | {peak} | {r['measured_utc']}, load {r['load_at_start']} |")


def growth(rows):
    """Per mesh, NanoVDB bytes and dense bytes from each resolution to the next (per doubling)."""
    out = []
    by_mesh = {}
    for r in rows:
        by_mesh.setdefault(r["name"], []).append(r)
    for name, rs in by_mesh.items():
        rs.sort(key=lambda r: r["resolution"])
        for a, b in zip(rs, rs[1:]):
            doublings = math.log2(b["resolution"] / a["resolution"])
            sparse = (b["nanovdb_bytes"] / a["nanovdb_bytes"]) ** (1 / doublings)
            va = math.prod(a["grid"]["dims"])
            vb = math.prod(b["grid"]["dims"])
            dense = (vb / va) ** (1 / doublings)
            out.append((name, a["resolution"], b["resolution"], sparse, dense))
    return out


def plot(rows, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    by_mesh = {}
    for r in rows:
        by_mesh.setdefault(r["name"], []).append(r)
    for name, rs in by_mesh.items():
        rs.sort(key=lambda r: r["resolution"])
        n = [r["resolution"] for r in rs]
        line, = ax.loglog(n, [r["nanovdb_bytes"] / MIB for r in rs], "o-", label=f"{name}: sparse NanoVDB (now)")
        cpu = [r for r in rs if r.get("backend") == "cpu"]
        if cpu:  # hollow: built by the exact CPU path
            ax.loglog([r["resolution"] for r in cpu], [r["nanovdb_bytes"] / MIB for r in cpu], "o", mfc="white",
                      color=line.get_color(), label=f"{name}: sparse, exact CPU path")
        ax.loglog(n, [16 * math.prod(r["grid"]["dims"]) / MIB for r in rs], "s--", alpha=0.6,
                  label=f"{name}: dense RGBA32F (before)")
    ax.set_xlabel("voxels along the longest side N")
    ax.set_ylabel("GPU memory of the SDF [MiB]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    tmp = png + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, png)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("binary", nargs="?")
    p.add_argument("meshes", nargs="?")
    p.add_argument("resolutions", nargs="?")
    p.add_argument("--markdown", required=True)
    p.add_argument("--plot", required=True)
    p.add_argument("--renderer", default="")
    p.add_argument("--command", default="")
    p.add_argument("--rows", help="write every row's raw figures to this JSON file")
    p.add_argument("--keep", action="store_true", help="keep the rows already in --rows for a mesh and N not run now")
    p.add_argument("--report-only", action="store_true", help="run nothing; write the section from --rows")
    p.add_argument("--add-row", action="append", default=[], help="with --report-only: add this hand-made row first")
    a = p.parse_args()
    if (a.keep or a.report_only) and not a.rows:
        raise SystemExit("sparse: --keep and --report-only need --rows")
    if not a.report_only and not (a.binary and a.meshes and a.resolutions):
        raise SystemExit("sparse: TETRASAND MESH[,...] RESOLUTION[,...] are needed unless --report-only")
    rows = json.load(open(a.rows)) if a.report_only else []
    if a.add_row and not a.report_only:
        raise SystemExit("sparse: --add-row needs --report-only")
    for path in a.add_row:
        new = json.load(open(path))
        rows = [r for r in rows if (r["name"], r["resolution"], r.get("backend")) !=
                (new["name"], new["resolution"], new.get("backend"))] + [new]
    if a.add_row:
        order = {}
        for r in rows:
            order.setdefault(r["name"], len(order))
        rows.sort(key=lambda r: (order[r["name"]], r["resolution"]))
        tmp = a.rows + ".tmp"
        with open(tmp, "w") as f:
            json.dump(rows, f, indent=1)
        os.replace(tmp, a.rows)
    with tempfile.TemporaryDirectory() as work:
        for mesh in [] if a.report_only else a.meshes.split(","):
            for n in (int(x) for x in a.resolutions.split(",")):
                print(f"sparse: {os.path.basename(mesh)} at {n}", file=sys.stderr)
                r = run(a.binary, mesh, n, work)
                if r:
                    rows.append(r)
                    print(json.dumps(r), file=sys.stderr)  # the raw figures, kept in the run's log
    if not rows:
        raise SystemExit("sparse: no run finished")
    if a.keep and not a.report_only and os.path.exists(a.rows):
        ran = {(r["name"], r["resolution"]) for r in rows}
        kept = [r for r in json.load(open(a.rows)) if (r["name"], r["resolution"]) not in ran]
        rows = kept + rows
        order = {}
        for r in rows:
            order.setdefault(r["name"], len(order))
        rows.sort(key=lambda r: (order[r["name"]], r["resolution"]))
    if a.rows and not a.report_only:
        tmp = a.rows + ".tmp"
        with open(tmp, "w") as f:
            json.dump(rows, f, indent=1)
        os.replace(tmp, a.rows)
    plot(rows, a.plot)
    g = growth(rows)
    renderer = rows[0].get("renderer", a.renderer)
    runs = sorted({r["measured_utc"][:10] for r in rows if "measured_utc" in r})
    text = [f"\nMeasured {', '.join(runs) or time.strftime('%Y-%m-%d')} with `{a.command}` on **{renderer}**, "
            + ("" if a.report_only else f"load average {open('/proc/loadavg').read().split()[0]} at the end; ")
            + "each row's start time and load in its last column. Band 3 voxels, `--backend gpu` (the scan converter), except rows "
            "marked (cpu): the exact CPU path (`--backend cpu`), added by hand (`--add-row`), hollow in the plot. Host peak RSS: the whole "
            "`tetrasand sdf` process's peak resident memory (`ru_maxrss`).\n",
            table(rows), "",
            "Growth per doubling of N (from each resolution to the next):", "",
            "| mesh | from N | to N | sparse NanoVDB x | dense box x |", "|---|---:|---:|---:|---:|"]
    text += [f"| {m} | {x} | {y} | {s:.2f} | {d:.2f} |" for m, x, y, s, d in g]
    text += ["", "![GPU memory of the SDF against resolution](sparse_memory.png)", ""]
    replace_between(a.markdown, "<!-- sparse results -->\n", "<!-- end sparse results -->", "\n".join(text))
    for r in rows:
        print(f"{r['name']} {r['resolution']}: {r['band_voxels']} band voxels, {r['nanovdb_bytes'] / MIB:.2f} MiB sparse")
    # The criteria stated in docs/benchmarks/sdf.md before the run.
    ok = all(s <= 4.5 for m, x, y, s, d in g if x >= 256)
    ok = ok and all(r["readback_bytes"] <= 21 * r["band_voxels"] + 64 * (r.get("slabs") or 0)
                    for r in rows if r.get("backend") != "cpu")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
