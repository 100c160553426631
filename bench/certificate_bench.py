#!/usr/bin/python3
"""Coverage certificate benchmark: its cost against the probe pass it sits beside, and the criterion
that no body anywhere reports c <= r while an independent probe check finds a deeper hole.

For each count, `tetrasand sample MESH --count N` makes the body (its rounds steered by the
certificate; the run's own certificate and probe times come from its report), then
tetrasand_bench_certificate runs, in one process on that body: the certificate (GPU) and the 1M-probe
pass (CPU, all cores) side by side, and an independent 10M-probe check with another seed. Criteria
(written before the runs: bench/certificate_criteria.md, quoted in docs/benchmarks/certificate.md): every probe lies
within the certified bound, and no probe lies beyond r on a certified body; each body of a count given
to --must-certify (default 200000) is certified; the CPU certifier (same process, all cores) gives the GPU's
verdict and a bound within the floor of its bound (criterion 6). Exit status 1 when one fails.

Usage: bench/certificate_bench.py --tetrasand build-release/bin/tetrasand [--mesh assets/bunny.obj]
       [--counts 1000 10000 100000 200000] [--must-certify 200000] [--independent 10000000] [--csv OUT.csv]
       [--markdown docs/benchmarks/certificate.md --command "scripts/bench.sh certificate"]
--markdown rewrites the section certificate (between `<!-- section: certificate -->` and
`<!-- end: certificate -->`) with this run's table and the reading in bench/certificate_notes.md;
with --cpu-table-only it rewrites only the CPU-against-GPU table inside it (between
`<!-- section: certificate-cpu -->` and `<!-- end: certificate-cpu -->`, `scripts/bench.sh certificate-cpu`);
rows are printed and appended to the CSV as they come, so a stopped run keeps what it measured.
"""
import argparse, csv, json, os, platform, re, subprocess, sys, tempfile, time

FIELDS = ["mesh", "requested", "particles", "sample_s", "rounds", "sample_certificate_s", "sample_passes",
          "sample_probes_s", "certified", "bound_over_r", "lower_over_r", "probes_c_over_r", "independent_c_over_r",
          "certificate_s", "probes_s", "ratio", "evaluated", "uncovered", "levels", "tiles", "margin_over_r",
          "criterion_holds", "cpu_certificate_s", "cpu_certified", "cpu_bound_over_r", "cpu_lower_over_r",
          "cpu_evaluated", "cpu_uncovered", "cpu_levels", "cpu_bound_difference_over_floor", "cpu_agrees",
          "cpu_over_gpu", "load1"]


def run_sample(exe, mesh, count, out, extra):
    cmd = [exe, "sample", mesh, "-o", out, "--count", str(count), *extra]
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - t
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({res.returncode}): {res.stdout}{res.stderr}")
    with open(os.path.join(out, f"sample-{count}.log"), "w") as log:  # the run's report, warnings included
        log.write(res.stdout + res.stderr)
    work = re.search(r"certificate ([0-9.]+) s in ([0-9]+) passes, probes ([0-9.]+) s", res.stdout)
    if not work:
        raise RuntimeError(f"no work line in the report of {' '.join(cmd)}:\n{res.stdout}")
    stem = os.path.splitext(os.path.basename(mesh))[0]
    return os.path.join(out, stem + ".body.json"), seconds, float(work[1]), int(work[2]), float(work[3])


def run_bench(exe, mesh, body, independent):
    cmd = [exe, mesh, body, "--independent", str(independent)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)} failed ({res.returncode}): {res.stderr}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetrasand", required=True)
    ap.add_argument("--bench", help="tetrasand_bench_certificate (default: beside --tetrasand)")
    ap.add_argument("--mesh", default="assets/bunny.obj")
    ap.add_argument("--counts", nargs="+", type=int, default=[1000, 10000, 100000, 200000])
    ap.add_argument("--must-certify", nargs="*", type=int, default=[200000],
                    help="requested counts whose bodies must be certified (criterion 2)")
    ap.add_argument("--independent", type=int, default=10_000_000)
    ap.add_argument("--sample-args", default="", help="extra options for tetrasand sample (e.g. '--sdf-budget-mib 4096')")
    ap.add_argument("--csv")
    ap.add_argument("--markdown")
    ap.add_argument("--command", default="")
    ap.add_argument("--cpu-table-only", action="store_true",
                    help="with --markdown: rewrite only the CPU-against-GPU table of the section")
    args = ap.parse_args()
    bench = args.bench or os.path.join(os.path.dirname(os.path.abspath(args.tetrasand)), "tetrasand_bench_certificate")
    started = time.strftime("%Y-%m-%d")
    load_start = open("/proc/loadavg").read().split()[:3]
    csv_file = open(args.csv, "w", newline="") if args.csv else None
    writer = csv.DictWriter(csv_file, FIELDS) if csv_file else None
    if writer:
        writer.writeheader()
    rows, renderer = [], ""
    tmp = tempfile.mkdtemp(prefix="certificate_bench_")
    label = os.path.splitext(os.path.basename(args.mesh))[0]
    for count in args.counts:
        body, sample_s, cert_s, passes, probes_s = run_sample(args.tetrasand, args.mesh, count, tmp, args.sample_args.split())
        load1 = open("/proc/loadavg").read().split()[0]  # just before the certificates and probes run
        b = run_bench(bench, args.mesh, body, args.independent)
        renderer = b["renderer"]
        rounds = json.load(open(body))["quality"]["injection_rounds"]
        row = {"mesh": label, "requested": count, "particles": b["particles"], "sample_s": sample_s, "rounds": rounds,
               "sample_certificate_s": cert_s, "sample_passes": passes, "sample_probes_s": probes_s,
               "ratio": b["certificate_s"] / b["probes_s"], "cpu_over_gpu": b["cpu_certificate_s"] / b["certificate_s"],
               "load1": float(load1), **{k: b[k] for k in FIELDS if k in b}}
        rows.append(row)
        print(json.dumps(row), f"(report: {tmp}/sample-{count}.log)", flush=True)
        if writer:
            writer.writerow({k: row.get(k, "") for k in FIELDS})
            csv_file.flush()
    if csv_file:
        csv_file.close()
    ok = all(r["criterion_holds"] for r in rows)
    must = [r for r in rows if r["requested"] in args.must_certify]
    certified_ok = all(r["certified"] for r in must)
    cpu_ok = all(r["cpu_agrees"] for r in rows)
    if args.markdown and args.cpu_table_only:
        write_cpu_markdown(args, rows, started, load_start, renderer, cpu_ok)
    elif args.markdown:
        write_markdown(args, rows, started, load_start, renderer, ok, must, certified_ok, cpu_ok)
    print("criterion 1 holds for every body" if ok else "CRITERION 1 FAILED for some body", flush=True)
    if must:
        print("criterion 2 holds" if certified_ok else "CRITERION 2 FAILED: a body is not certified", flush=True)
    print("criterion 6 holds for every body" if cpu_ok else "CRITERION 6 FAILED: the CPU and GPU certificates "
          "disagree on some body", flush=True)
    return 0 if ok and certified_ok and cpu_ok else 1


def table(rows, independent):
    lines = [f"| N | sample s | rounds | certificate in the run: s (passes) | share of the run | probe pass in the run s "
             f"| certified | bound c / r | lower c / r | 1M probes c / r | {independent / 1e6:.0f}M probes c / r "
             "| certificate s | 1M-probe pass s | ratio | sub-triangles | levels | tiles | margin / r |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['particles']} | {r['sample_s']:.1f} | {r['rounds']} | {r['sample_certificate_s']:.2f} "
                     f"({r['sample_passes']}) | {r['sample_certificate_s'] / r['sample_s']:.0%} | {r['sample_probes_s']:.2f} | "
                     f"{'yes' if r['certified'] else 'NO'} | {r['bound_over_r']:.4f} | "
                     f"{r['lower_over_r']:.4f} | {r['probes_c_over_r']:.4f} | {r['independent_c_over_r']:.4f} | "
                     f"{r['certificate_s']:.2f} | {r['probes_s']:.2f} | {r['ratio']:.2f} | {r['evaluated']} | "
                     f"{r['levels']} | {r.get('tiles', 1)} | {r['margin_over_r']:.1e} |")
    return "\n".join(lines)


def verdicts(rows, ok, must, certified_ok):
    one = "holds for every body" if ok else "FAILED"
    if not must:
        two = "not judged (no body of a --must-certify count in this run)"
    else:
        two = "holds" if certified_ok else "FAILED"
        two += " (" + ", ".join(f"{r['particles']} particles: {'certified' if r['certified'] else 'NOT certified'}, "
                                f"bound {r['bound_over_r']:.4f} r" for r in must) + ")"
    return f"This run: criterion 1 **{one}**; criterion 2 **{two}**."


def cpu_table(rows):
    lines = ["| N | load (1 min) | GPU certificate s | CPU certificate s | CPU / GPU | 1M-probe pass s | CPU / probes "
             "| certified GPU, CPU | bound c / r GPU, CPU | (CPU - GPU) / floor | lower c / r GPU, CPU "
             "| sub-triangles GPU, CPU | levels GPU, CPU | agree |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    yes = lambda v: "yes" if v else "NO"
    for r in rows:
        lines.append(f"| {r['particles']} | {r['load1']:.2f} | {r['certificate_s']:.2f} | {r['cpu_certificate_s']:.2f} | "
                     f"{r['cpu_over_gpu']:.2f} | {r['probes_s']:.2f} | {r['cpu_certificate_s'] / r['probes_s']:.2f} | "
                     f"{yes(r['certified'])}, {yes(r['cpu_certified'])} | {r['bound_over_r']:.4f}, "
                     f"{r['cpu_bound_over_r']:.4f} | {r['cpu_bound_difference_over_floor']:+.2f} | "
                     f"{r['lower_over_r']:.4f}, {r['cpu_lower_over_r']:.4f} | {r['evaluated']}, {r['cpu_evaluated']} | "
                     f"{r['levels']}, {r['cpu_levels']} | {yes(r['cpu_agrees'])} |")
    return "\n".join(lines)


def cpu_section(args, rows, started, load_start, load_end, renderer, cpu_ok):
    return f"""<!-- section: certificate-cpu -->
### The CPU certifier beside the GPU one

`{args.command or 'bench/certificate_bench.py'}` ({started}) on {args.mesh}: on each body (made by
`tetrasand sample --count N`), one process runs the GPU certificate, the CPU certifier
(sampler/cpu_coverage_certificate.h, double precision, TBB on all cores) and the sampler's 1M-probe pass
(CPU, all cores), one after the other. Machine {platform.node()} ({platform.machine()}, {os.cpu_count()} cores),
GL renderer: {renderer}; load average {' '.join(load_start)} (1/5/15 min) at the start, {' '.join(load_end)} at the
end, and the 1-minute figure just before each body's certificates in the table. Seconds are one run each, the
certifier's set-up (triangle upload and shaders; the CPU's triangle copy) apart. "(CPU - GPU) / floor": the
bounds' difference in floors r / 64.

{cpu_criteria()}

{verdict_6(cpu_ok)}

{cpu_table(rows)}
<!-- end: certificate-cpu -->"""


def cpu_criteria():
    """Criteria 6 and 7 as bench/certificate_criteria.md states them (from their heading on)."""
    text = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "certificate_criteria.md")).read()
    return text[text.index("**Criteria for the CPU certifier"):].strip()


def verdict_6(cpu_ok):
    return f"This run: criterion 6 **{'holds for every body' if cpu_ok else 'FAILED'}**."


def write_cpu_markdown(args, rows, started, load_start, renderer, cpu_ok):
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    from docs_section import replace_between
    load_end = open("/proc/loadavg").read().split()[:3]
    text = cpu_section(args, rows, started, load_start, load_end, renderer, cpu_ok)
    inner = text.split("\n", 1)[1].rsplit("\n", 1)[0] + "\n"  # between the markers
    replace_between(args.markdown, "<!-- section: certificate-cpu -->\n", "<!-- end: certificate-cpu -->", inner)
    print(f"wrote the CPU certifier table of the certificate section of {args.markdown}")


def write_markdown(args, rows, started, load_start, renderer, ok, must, certified_ok, cpu_ok):
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    from docs_section import replace_between
    load_end = open("/proc/loadavg").read().split()[:3]
    text = f"""## Coverage certificate

`{args.command or 'bench/certificate_bench.py'}` ({started}; bench/certificate_bench.py,
bench/certificate_bench.cpp) on {args.mesh}: `tetrasand sample --count N` makes each body, then one
process on that body runs the certificate (GPU) and the sampler's 1M-probe pass (CPU, all cores) side
by side, and an independent {args.independent:,}-probe check with another seed. Machine
{platform.node()} ({platform.machine()}, {os.cpu_count()} cores), GL renderer: {renderer}; load
average {' '.join(load_start)} (1/5/15 min) at the start, {' '.join(load_end)} at the end.
Ratio = certificate time / 1M-probe pass time on the same body; "certificate in the run" is the wall
time of all the certificate passes of that `sample` run (one per hole-closing round), against its
total time in "sample s".

{open(os.path.join(here, "certificate_criteria.md")).read().split("**Criteria for the CPU certifier")[0].strip()}

{verdicts(rows, ok, must, certified_ok)}

{table(rows, args.independent)}
"""
    notes = os.path.join(here, "certificate_notes.md")
    if os.path.exists(notes):
        text += "\n" + open(notes).read()
    text += "\n" + cpu_section(args, rows, started, load_start, load_end, renderer, cpu_ok) + "\n"
    replace_between(args.markdown, "<!-- section: certificate -->\n", "<!-- end: certificate -->\n", text)
    print(f"wrote the certificate section of {args.markdown}")


if __name__ == "__main__":
    sys.exit(main())
