#!/usr/bin/python3
"""Every default against the trade tables (issue 17): applies the rules of bench/defaults_criteria.md
to the tables already in docs/benchmarks.md and docs/validation.md, runs the two trades no table held
(the sampler's SDF voxel, `sdf --band`), plots each trade with its default marked, and writes the
section between `<!-- section: defaults -->` and `<!-- end: defaults -->` of docs/benchmarks.md.

Usage: /usr/bin/python3 bench/defaults.py TETRASAND DOCS_DIR [--work DIR] [--repeats N] [--quick]
(Debian's python3-matplotlib). Exit 1 when a default fails its rule."""
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
                text, _ = run([exe, "-q", "sdf", mesh, "-o", os.path.join(work, "band.vdb"), "--resolution", str(res),
                               "--band", str(band), "--json"])
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


# ---- rules ---------------------------------------------------------------------------------------

def verdicts(energy, restitution, trade, tsuji, voxels, bands):
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
              "docs/benchmarks.md (Bulk behaviour) and assets/scenes/README.md state the creep and name "
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
    return v


def tangential_documented(root):
    scenes = open(os.path.join(root, "assets", "scenes", "README.md")).read()
    bench = open(os.path.join(root, "docs", "benchmarks.md")).read()
    return ("creep" in scenes.lower() or "creep" in bench.lower()) and 'tangential = "spring"' in (scenes + bench)


# ---- plots ---------------------------------------------------------------------------------------

def plot(energy, restitution, trade, voxels, bands, png):
    import matplotlib  # only here: the rules (and their test) need no plotting library

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
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
    handles = [h for h in axes[0][0].collections[:1]]
    fig.legend(handles, ["default"], loc="upper right")
    fig.suptitle("Defaults (gold stars) on the trade curves; top row and rounds from the tables of docs/benchmarks.md")
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)


# ---- the section ---------------------------------------------------------------------------------

def section(args, v, voxels, bands, renderer, started, load_start, load_end):
    yes = lambda m: "**met**" if m else ("**not met**" if m is not None else "-")  # noqa: E731
    lines = [
        "## Defaults", "",
        f"`scripts/bench.sh defaults` ({started}; bench/defaults.py; rules in bench/defaults_criteria.md, committed "
        "before the run). The first rows apply the rules to tables that were already in these docs (their rules were "
        "written with the tables in view: a check of consistency, not a blind test); the last two rows are new runs "
        f"on {platform.node()} ({os.cpu_count()} cores), renderer {renderer}, load average {load_start} at the start, "
        f"{load_end} at the end. **No NVIDIA GPU was used.**", "",
        "| default | evidence | rule |", "|---|---|---|"]
    for name, evidence, met in v:
        lines.append(f"| {name} | {evidence} | {yes(met)} |")
    lines += ["", "![defaults on the trade curves](benchmarks/defaults.png)", ""]
    if voxels:
        lines += ["Sampler voxel (default particle count, radius unset; median of "
                  f"{args.repeats} runs each):", "",
                  "| mesh | voxel / r | N | time s | c / r (1M probes) | certified | bound / r | rho | converged |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for r in voxels:
            mark = " (default)" if r["voxel_over_r"] == 0.5 else ""
            bound = f"{r['bound_over_r']:.3f}" if r["bound_over_r"] is not None else "-"
            lines.append(f"| {r['mesh']} | {r['voxel_over_r']:g}{mark} | {r['n']} | {r['seconds']:.2f} | "
                         f"{r['c_over_r']:.3f} | {r['certified']} | {bound} | {r['rho']:.3f} | {r['converged']} |")
        lines.append("")
    if bands:
        lines += [f"`sdf --band` on knot1 (scan conversion time, median of {args.repeats}; errors against the exact SDF "
                  "from `--compare-openvdb`):", "",
                  "| grid | band | scan s | band voxels | peak GPU MiB | NanoVDB MiB | largest error vs exact (voxels) |",
                  "|---|---|---|---|---|---|---|"]
        for r in bands:
            mark = " (default)" if r["band"] == 3 else ""
            lines.append(f"| {r['resolution']} | {r['band']}{mark} | {r['seconds']:.2f} | {r['band_voxels']} | "
                         f"{r['peak_mib']:.1f} | {r['nanovdb_mib']:.1f} | {r['max_error']:.1e} |")
        lines.append("")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("exe")
    ap.add_argument("docs")
    ap.add_argument("--work", default=None)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="one mesh, one grid: a check that the script runs")
    args = ap.parse_args()
    root = os.path.dirname(os.path.abspath(args.docs.rstrip("/")))
    bench_md = os.path.join(args.docs, "benchmarks.md")
    doc = open(bench_md).read()
    validation = open(os.path.join(args.docs, "validation.md")).read()
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    load_start = " ".join(f"{x:.2f}" for x in os.getloadavg())
    renderer = subprocess.run([args.exe, "devices"], capture_output=True, text=True).stdout.strip().splitlines()
    renderer = next((l.strip() for l in renderer if "chosen" in l.lower()), renderer[-1] if renderer else "?")
    work = args.work or tempfile.mkdtemp(prefix="ts-defaults-")
    os.makedirs(work, exist_ok=True)
    knot1 = resolve_mesh("knot1", work)
    meshes = [("knot1", knot1)] if args.quick else [("knot1", knot1), ("bunny", os.path.join(root, "assets", "bunny.obj"))]
    voxels = voxel_trade(args.exe, meshes, work, args.repeats)
    bands = band_trade(args.exe, knot1, [64] if args.quick else [128, 256], [1, 2, 3, 5], work, args.repeats)
    energy, restitution, trade = energy_rows(doc), restitution_rows(doc), sampler_trade_rows(doc)
    v = verdicts(energy, restitution, trade, tsuji_spread(validation), voxels, bands)
    v = [(n, e, tangential_documented(root) if m is None else m) for n, e, m in v]
    os.makedirs(os.path.join(args.docs, "benchmarks"), exist_ok=True)
    plot(energy, restitution, trade, voxels, bands, os.path.join(args.docs, "benchmarks", "defaults.png"))
    load_end = " ".join(f"{x:.2f}" for x in os.getloadavg())
    text = section(args, v, voxels, bands, renderer, started, load_start, load_end)
    replace_between(bench_md, "<!-- section: defaults -->\n", "<!-- end: defaults -->", text)
    with open(os.path.join(work, "defaults.json"), "w") as f:
        json.dump(dict(voxels=voxels, bands=bands, verdicts=v), f, indent=1)
    for name, evidence, met in v:
        print(f"defaults: {'met' if met else 'NOT MET'}: {name}: {evidence}")
    return 0 if all(m for _, _, m in v) else 1


if __name__ == "__main__":
    sys.exit(main())
