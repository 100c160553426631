#!/usr/bin/python3
"""Sample fixed costs by relaxation backend (issue 16): `tetrasand sample --backend cpu` against
`--backend gpu` against Open3D's sample_points_poisson_disk(N, init_factor=5) on one mesh, interleaved
run by run so the three see the same machine load.

Each repetition runs, in this order, tetrasand --backend cpu, Open3D, tetrasand --backend gpu (Open3D at
the particle count tetrasand's CPU run produced). Every point set is measured the same way by
bench/sample_bench.py's quality(): rho = min NN / d_hex, CV of NN distances, covering radius c over one
shared set of area-uniform probes, c / r with r tetrasand's radius. tetrasand's stage seconds come from
`--json`'s run.seconds; CPU seconds of each run are the process's user + system time.

Usage: bench/sample_backend_bench.py --tetrasand build-test/bin/tetrasand [--mesh assets/bunny.obj]
       [--counts 1000 10000] [--repeat 3] [--single-counts 100000] [--csv OUT.csv] [--extra ARG ...]
--single-counts: counts run once (no repetition), after the others.
Prints a markdown table of medians and every run's figures.
"""
import argparse, csv, os, platform, resource, statistics, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sample_bench import ensure_open3d, quality, read_ply_points, renderer, run_sample  # noqa: E402

STAGES = ["context", "load", "plan", "sdf", "setup", "relaxation", "projection", "certificate", "injection",
          "probes", "thin_features", "body", "write", "total"]


def children_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def run_tetrasand(exe, mesh, count, backend, out, extra):
    cpu0 = children_cpu()
    load = float(open("/proc/loadavg").read().split()[0])
    body, seconds, _ = run_sample(exe, mesh, count, out, ["--backend", backend, *extra])
    points = read_ply_points(os.path.join(out, os.path.splitext(os.path.basename(mesh))[0] + ".particles.ply"))
    return {"tool": f"tetrasand --backend {backend}", "seconds": seconds, "cpu_seconds": children_cpu() - cpu0,
            "load": load, "points": points, "radius": body["particle_radius"], "n": body["particle_count"],
            "iterations": body["quality"]["iterations"], "rounds": body["quality"]["injection_rounds"],
            "converged": body["quality"]["converged"], "certified": body["quality"]["coverage_certified"],
            "bound_over_r": body["quality"]["covering_bound_over_r"], "relax_backend": body["run"].get("relax_backend"),
            "certificate_backend": body["run"].get("certificate_backend"),
            "stages": {k: body["run"]["seconds"].get(k, 0.0) for k in STAGES}}


def run_open3d(mesh, count):
    load = float(open("/proc/loadavg").read().split()[0])
    t, c = time.perf_counter(), time.process_time()
    import numpy as np
    points = np.asarray(mesh.sample_points_poisson_disk(count, init_factor=5).points)
    return {"tool": "Open3D", "seconds": time.perf_counter() - t, "cpu_seconds": time.process_time() - c,
            "load": load, "points": points, "n": len(points)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetrasand", required=True)
    ap.add_argument("--mesh", default="assets/bunny.obj")
    ap.add_argument("--counts", nargs="*", type=int, default=[1000, 10000])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--single-counts", nargs="*", type=int, default=[])
    ap.add_argument("--probes", type=int, default=1_000_000)
    ap.add_argument("--extra", nargs="*", default=[], help="more tetrasand sample arguments")
    ap.add_argument("--backends", nargs="+", choices=["cpu", "gpu"], default=["cpu", "gpu"],
                    help="tetrasand backends to run (gpu on llvmpipe at 1M takes most of an hour)")
    ap.add_argument("--csv")
    args = ap.parse_args()
    ensure_open3d()
    import numpy as np
    import open3d as o3d
    o3d.utility.random.seed(7)
    mesh = o3d.io.read_triangle_mesh(args.mesh)
    probes = np.asarray(mesh.sample_points_uniformly(args.probes).points)
    tmp = tempfile.mkdtemp(prefix="sample_backend_bench_")
    print(f"{time.strftime('%Y-%m-%d %H:%M:%S %Z')}; machine {platform.node()} ({platform.machine()}, "
          f"{os.cpu_count()} cores); GL: {renderer(args.tetrasand)}; Open3D {o3d.__version__}; "
          f"load average at the start {' '.join(open('/proc/loadavg').read().split()[:3])}", flush=True)
    rows = []
    plan = [(n, args.repeat) for n in args.counts] + [(n, 1) for n in args.single_counts]
    for count, repeat in plan:
        n_open3d = None
        for rep in range(repeat):
            for tool in args.backends[:1] + ["open3d"] + args.backends[1:]:  # Open3D takes the first run's count
                if tool == "open3d":
                    r = run_open3d(mesh, n_open3d)
                    radius = rows[-1]["radius"]
                else:
                    r = run_tetrasand(args.tetrasand, args.mesh, count, tool, os.path.join(tmp, tool), args.extra)
                    radius = r["radius"]
                    n_open3d = n_open3d or r["n"]
                q = quality(r.pop("points"), mesh, probes, radius)
                r.update(q, count=count, rep=rep, radius=radius)
                rows.append(r)
                print(f"  N {count} rep {rep}: {r['tool']}: {r['seconds']:.2f} s wall, {r['cpu_seconds']:.2f} s CPU, "
                      f"load {r['load']:.1f}; rho {q['rho']:.3f}, CV {q['cv']:.3f}, c/r {q['c_over_r']:.3f}"
                      + (f", certified {r['certified']} (bound {r['bound_over_r']:.4f} r), {r['iterations']} "
                         f"iterations, relax {r['relax_backend']}, certificate {r['certificate_backend']}, stages "
                         + ", ".join(f"{k} {v:.2f}" for k, v in r["stages"].items() if v >= 0.005)
                         if "stages" in r else ""), flush=True)
    print(f"load average at the end {' '.join(open('/proc/loadavg').read().split()[:3])}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            fields = ["count", "rep", "tool", "n", "seconds", "cpu_seconds", "load", "rho", "cv", "c_over_r",
                      "c_over_dhex", "phi_over_r", "certified", "bound_over_r", "iterations", "rounds"] + \
                     [f"stage_{k}" for k in STAGES]
            w = csv.DictWriter(f, fields, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow({**r, **{f"stage_{k}": v for k, v in r.get("stages", {}).items()}})
    print()
    print("| N | tool | runs | time s (median) | / Open3D | CPU s | load (1 min) | rho | CV | c / r | certified (bound c / r) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for count, _ in plan:
        mine = [r for r in rows if r["count"] == count]
        o3d_median = statistics.median(r["seconds"] for r in mine if r["tool"] == "Open3D")
        for tool in [f"tetrasand --backend {b}" for b in args.backends] + ["Open3D"]:
            rs = [r for r in mine if r["tool"] == tool]
            med = lambda k: statistics.median(r[k] for r in rs)  # noqa: E731
            cert = "" if tool == "Open3D" else ", ".join(
                f"{'yes' if r['certified'] else 'NO'} ({r['bound_over_r']:.4f})" for r in rs)
            print(f"| {rs[0]['n']} | {tool} | {len(rs)} | {med('seconds'):.2f} | {med('seconds') / o3d_median:.2f} | "
                  f"{med('cpu_seconds'):.2f} | {min(r['load'] for r in rs):.1f}-{max(r['load'] for r in rs):.1f} | "
                  f"{med('rho'):.3f} | {med('cv'):.3f} | {med('c_over_r'):.3f} | {cert} |")
    print()
    print("| stage (median, s) | " + " | ".join(f"{c} {b}" for c, _ in plan for b in args.backends) + " |")
    print("|---|" + "---|" * (len(args.backends) * len(plan)))
    for k in STAGES:
        cells = []
        for count, _ in plan:
            for b in args.backends:
                rs = [r for r in rows if r["count"] == count and r["tool"] == f"tetrasand --backend {b}"]
                cells.append(f"{statistics.median(r['stages'][k] for r in rs):.3f}")
        print(f"| {k} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
