#!/usr/bin/env python3
"""The simulation step before and after a change, side by side on this machine (issue 44; reading rules in
bench/sim_step_criteria.md, written before the first run):

  bench/sim_step.py --before DIR --after DIR [--grains 64000,1000000] [--precision float] [--min-steps 3]
                    [--before-min-steps N] [--seconds 0] [--scenes bed,plough] [--plough-speed 0.5]
                    [--after-first] [--out DIR] [--markdown docs/benchmarks/sim.md] [--section sim-step]

DIR holds a build's tetrasand_bench_sim (the after one is BUILD/bin); a DIR with a shaders/ folder runs with
TETRASAND_SHADER_DIR set to it, so a kept copy of an older build reads its own shaders. Each size runs before,
then after (--after-first: after, then before, for a second round), so load from other jobs falls on both. Writes OUT/sim-step.json, the raw CSVs and --timings
reports, and with --markdown the section --section of that file: grain-steps/s of both builds and their
ratio for the GPU pipeline and the CPU reference, and the after build's per-kernel tables.

--scenes picks the scenes of tetrasand_bench_sim --scene: bed (settled, lists built once) and plough (the bed
with a blade driven through it, lists rebuilt every few tens of steps); each size runs every scene, before
then after. For the plough the section adds the list builds' share of the after build's step: the GPU
kernels of a build (the grid's passes and list_build.comp, dispatched indirectly every step and empty
between builds) over all kernel time, and the CPU reference's list-build seconds over its step time. The
before builds have no lists: every step is a build, so --before-min-steps (default --min-steps) may be
smaller there without changing what is averaged. The before build must know --scene (a copy with the
patch bench/sim_step_before_plough.patch).
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from docs_section import replace_between  # noqa: E402
from device_bench import kernel_tables  # noqa: E402


def run_bench(build, grains, args, out, label, scene):
    exe = os.path.join(build, "tetrasand_bench_sim")
    env = dict(os.environ)
    if os.path.isdir(os.path.join(build, "shaders")):
        env["TETRASAND_SHADER_DIR"] = os.path.join(build, "shaders")
    table = os.path.join(out, f"{label}-{scene}-{grains}.csv")
    min_steps = args.before_min_steps if label == "before" and args.before_min_steps else args.min_steps
    cmd = [exe, "--grains", str(grains), "--precision", args.precision, "--seconds", str(args.seconds),
           "--min-steps", str(min_steps), "--csv", table, "--timings"]
    if scene != "bed":  # a build without --scene still measures the bed
        cmd += ["--scene", scene, "--plough-speed", str(args.plough_speed)]
    start = time.perf_counter()
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    open(os.path.join(out, f"{label}-{scene}-{grains}.timings.txt"), "w").write(res.stderr)
    if res.returncode != 0:
        raise SystemExit(f"sim_step: {' '.join(cmd)} failed ({res.returncode}):\n{res.stderr[-2000:]}")
    rows = list(csv.DictReader(open(table)))
    return {"command": cmd, "wall_s": wall, "rows": rows, "report": res.stderr, "kernels": kernel_tables(res.stderr),
            "load": os.getloadavg()}


# GPU kernels that run every step whether or not the lists are rebuilt, and the one-off reorder of the
# bodies in cell order (at the first step, then every resort_every steps); every other kernel in the table is
# a pass of the list build (the grid's counting, scans, scatter and sort, and list_build.comp).
STEP_KERNELS = {"sim/update_particles.comp", "sim/list_decide.comp", "sim/contact_forces.comp",
                "sim/integrate_bodies.comp"}
RESORT_KERNELS = {"sim/resort_keys.comp", "sim/resort_ranges.comp", "sim/resort_particles.comp",
                  "sim/resort_fixup.comp", "sim/gather_rows.comp", "sim/resort_bonds.comp"}


def build_share(result):
    """The list builds in the after build's --timings: {engine: (builds, steps, build time, total time, unit)}."""
    out = {}
    text = result["report"]
    gpu = re.search(r"^contact lists: .*?; (\d+) builds in (\d+) steps", text, re.M)
    tables = list(result["kernels"].values())
    if gpu and tables:
        table = tables[0]
        build = sum(t["ms"] for t in table if t["kernel"] not in STEP_KERNELS | RESORT_KERNELS)
        out["GPU"] = (int(gpu.group(1)), int(gpu.group(2)), build, sum(t["ms"] for t in table), "ms")
    cpu = re.search(r"^contact lists \(CPU reference\): .*?; (\d+) list builds in (\d+) steps", text, re.M)
    cpu_time = re.search(r"time: ([\d.]+) s in list builds", text)
    row = result["rows"][0] if result["rows"] else None
    if cpu and cpu_time and row:
        steps = int(cpu.group(2))
        step_s = float(row["grains"]) / float(row["cpu_grain_steps_per_s"])  # s a timed step
        out["CPU"] = (int(cpu.group(1)), steps, float(cpu_time.group(1)), steps * step_s, "s")
    return out


def share_rows(results):
    lines = ["| grains | scene | engine | list builds | steps | steps per build | build time | all | build share |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for engine, (builds, steps, build, total, unit) in build_share(r["after"]).items():
            lines.append(f"| {r['grains']} | {r['scene']} | {engine} | {builds} | {steps} | "
                         f"{steps / builds if builds else float('nan'):.1f} | {build:.3g} {unit} | {total:.3g} {unit} "
                         f"| {100 * build / total:.1f} % |")
    return lines


def ratio_rows(results):
    lines = ["| grains | scene | precision | GPU before | GPU after | GPU ratio | CPU before | CPU after | CPU ratio "
             "| contacts / grain | timed steps GPU / CPU (before; after) | load average (1 min) before / after |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for b, a in zip(r["before"]["rows"], r["after"]["rows"]):
            gb, ga = float(b["gpu_grain_steps_per_s"]), float(a["gpu_grain_steps_per_s"])
            cb, ca = float(b["cpu_grain_steps_per_s"]), float(a["cpu_grain_steps_per_s"])
            lines.append(f"| {a['grains']} | {r['scene']} | {a['precision']} | {gb:.3g} | {ga:.3g} | {ga / gb:.2f} | {cb:.3g} "
                         f"| {ca:.3g} | {ca / cb:.2f} | {float(a['contacts_per_grain']):.1f} | {b['gpu_steps']} / "
                         f"{b['cpu_steps']}; {a['gpu_steps']} / {a['cpu_steps']} | {r['before']['load'][0]:.1f} / "
                         f"{r['after']['load'][0]:.1f} |")
    return lines


def kernel_rows(label, tables):
    lines = []
    for grains, table in tables.items():
        steps = max((t["calls"] for t in table if t["kernel"] == "sim/contact_forces.comp"), default=0)
        lines += ["", f"{label}, {grains} grains, {steps} steps:", "", "| kernel | calls | ms | share | ms per step |",
                  "|---|---|---|---|---|"]
        lines += [f"| {t['kernel']} | {t['calls']} | {t['ms']:.1f} | {t['share']:.1f} % "
                  f"| {t['ms'] / steps if steps else float('nan'):.2f} |" for t in table]
    return lines


def section(results, args, renderer):
    title = "The simulation step before and after the contact lists"
    if any(r["scene"] != "bed" for r in results):
        title += ": a scene that moves"
    lines = [f"## {title}", "",
             f"Measured by `bench/sim_step.py` on {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}; GL renderer: "
             f"{renderer}. No NVIDIA GPU was used: every GPU figure here is llvmpipe (software). Before: "
             f"`{args.before}`; after: `{args.after}`. Reading rules written before the run: "
             "[bench/sim_step_criteria.md](../../bench/sim_step_criteria.md). Grain-steps/s on the settled bed "
             f"(bed) and the bed with a blade driven through it at {args.plough_speed} m/s (plough); each size and "
             f"scene ran {'after, then before' if args.after_first else 'before, then after'}.", ""]
    lines += ratio_rows(results)
    if any(r["scene"] != "bed" for r in results):
        lines += ["", "The list builds' share of the after build's step (`--timings`; GPU: kernel time, the passes "
                  "of a build against all kernels; CPU reference: list-build seconds against its steps' time):", ""]
        lines += share_rows(results)
    for r in results:
        label = f"{r['scene']}, " if r["scene"] != "bed" else ""
        lines += kernel_rows(f"Before, {label}".rstrip(", "), r["before"]["kernels"])
        lines += kernel_rows(f"After, {label}".rstrip(", "), r["after"]["kernels"])
        lines += ["", f"After, {label}{r['grains']} grains, both engines' `--timings` reports:", "", "```",
                  r["after"]["report"].strip(), "```"]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--grains", default="64000,1000000")
    ap.add_argument("--precision", default="float")
    ap.add_argument("--min-steps", type=int, default=3)
    ap.add_argument("--before-min-steps", type=int, default=0)
    ap.add_argument("--scenes", default="bed")
    ap.add_argument("--plough-speed", type=float, default=0.5)
    ap.add_argument("--section", default="sim-step")
    ap.add_argument("--after-first", action="store_true")
    ap.add_argument("--seconds", type=float, default=0)
    ap.add_argument("--out", default="sim-step-out")
    ap.add_argument("--markdown")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    results = []
    scenes = args.scenes.split(",")
    for scene in scenes:
        if scene not in ("bed", "plough"):
            raise SystemExit(f"sim_step: --scenes: '{scene}' is neither bed nor plough")
    for grains in map(int, args.grains.split(",")):
        for scene in scenes:
            if args.after_first:  # a second round in the other order puts a load trend on the other side
                after = run_bench(args.after, grains, args, args.out, "after", scene)
                before = run_bench(args.before, grains, args, args.out, "before", scene)
            else:
                before = run_bench(args.before, grains, args, args.out, "before", scene)
                after = run_bench(args.after, grains, args, args.out, "after", scene)
            results.append({"grains": grains, "scene": scene, "before": before, "after": after})
            print(f"{grains} grains, {scene}: before {before['wall_s']:.0f} s, after {after['wall_s']:.0f} s "
                  f"(load {before['load'][0]:.1f} / {after['load'][0]:.1f})", flush=True)
            json.dump(results, open(os.path.join(args.out, "sim-step.json"), "w"), indent=1)
    renderer = results[0]["after"]["rows"][0]["renderer"] if results and results[0]["after"]["rows"] else "?"
    text = section(results, args, renderer)
    print(text)
    open(os.path.join(args.out, "sim-step.md"), "w").write(text + "\n")
    if args.markdown:
        replace_between(args.markdown, f"<!-- section: {args.section} -->\n", f"<!-- end: {args.section} -->", text)


if __name__ == "__main__":
    main()
