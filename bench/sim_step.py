#!/usr/bin/env python3
"""The simulation step before and after a change, side by side on this machine (issue 44; reading rules in
bench/sim_step_criteria.md, written before the first run):

  bench/sim_step.py --before DIR --after DIR [--grains 64000,1000000] [--precision float] [--min-steps 3]
                    [--seconds 0] [--out DIR] [--markdown docs/benchmarks/sim.md]

DIR holds a build's tetrasand_bench_sim (the after one is BUILD/bin); a DIR with a shaders/ folder runs with
TETRASAND_SHADER_DIR set to it, so a kept copy of an older build reads its own shaders. Each size runs before,
then after, so load from other jobs falls on both. Writes OUT/sim-step.json, the raw CSVs and --timings
reports, and with --markdown the section sim-step of that file: grain-steps/s of both builds and their
ratio for the GPU pipeline and the CPU reference, and the after build's per-kernel tables.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from docs_section import replace_between  # noqa: E402
from device_bench import kernel_tables  # noqa: E402


def run_bench(build, grains, args, out, label):
    exe = os.path.join(build, "tetrasand_bench_sim")
    env = dict(os.environ)
    if os.path.isdir(os.path.join(build, "shaders")):
        env["TETRASAND_SHADER_DIR"] = os.path.join(build, "shaders")
    table = os.path.join(out, f"{label}-{grains}.csv")
    cmd = [exe, "--grains", str(grains), "--precision", args.precision, "--seconds", str(args.seconds),
           "--min-steps", str(args.min_steps), "--csv", table, "--timings"]
    start = time.perf_counter()
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    open(os.path.join(out, f"{label}-{grains}.timings.txt"), "w").write(res.stderr)
    if res.returncode != 0:
        raise SystemExit(f"sim_step: {' '.join(cmd)} failed ({res.returncode}):\n{res.stderr[-2000:]}")
    rows = list(csv.DictReader(open(table)))
    return {"command": cmd, "wall_s": wall, "rows": rows, "report": res.stderr, "kernels": kernel_tables(res.stderr)}


def ratio_rows(results):
    lines = ["| grains | precision | GPU before | GPU after | GPU ratio | CPU before | CPU after | CPU ratio "
             "| contacts / grain | timed steps GPU / CPU (after) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for b, a in zip(r["before"]["rows"], r["after"]["rows"]):
            gb, ga = float(b["gpu_grain_steps_per_s"]), float(a["gpu_grain_steps_per_s"])
            cb, ca = float(b["cpu_grain_steps_per_s"]), float(a["cpu_grain_steps_per_s"])
            lines.append(f"| {a['grains']} | {a['precision']} | {gb:.3g} | {ga:.3g} | {ga / gb:.2f} | {cb:.3g} | {ca:.3g} "
                         f"| {ca / cb:.2f} | {float(a['contacts_per_grain']):.1f} | {a['gpu_steps']} / {a['cpu_steps']} |")
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
    lines = ["## The simulation step before and after the contact lists", "",
             f"Measured by `bench/sim_step.py` on {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}; GL renderer: "
             f"{renderer}. No NVIDIA GPU was used: every GPU figure here is llvmpipe (software). Before: "
             f"`{args.before}`; after: `{args.after}`. Reading rules written before the run: "
             "[bench/sim_step_criteria.md](../../bench/sim_step_criteria.md). Grain-steps/s on the settled bed; each "
             "size ran before, then after.", ""]
    lines += ratio_rows(results)
    for r in results:
        lines += kernel_rows("Before", r["before"]["kernels"]) + kernel_rows("After", r["after"]["kernels"])
        lines += ["", f"After, {r['grains']} grains, both engines' `--timings` reports:", "", "```",
                  r["after"]["report"].strip(), "```"]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--grains", default="64000,1000000")
    ap.add_argument("--precision", default="float")
    ap.add_argument("--min-steps", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=0)
    ap.add_argument("--out", default="sim-step-out")
    ap.add_argument("--markdown")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    results = []
    for grains in map(int, args.grains.split(",")):
        before = run_bench(args.before, grains, args, args.out, "before")
        after = run_bench(args.after, grains, args, args.out, "after")
        results.append({"grains": grains, "before": before, "after": after})
        print(f"{grains} grains: before {before['wall_s']:.0f} s, after {after['wall_s']:.0f} s", flush=True)
        json.dump(results, open(os.path.join(args.out, "sim-step.json"), "w"), indent=1)
    renderer = results[0]["after"]["rows"][0]["renderer"] if results and results[0]["after"]["rows"] else "?"
    text = section(results, args, renderer)
    print(text)
    if args.markdown:
        replace_between(args.markdown, "<!-- section: sim-step -->\n", "<!-- end: sim-step -->", text)


if __name__ == "__main__":
    main()
