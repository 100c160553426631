#!/usr/bin/python3
"""Sampler benchmark: tetrasand sample against Open3D's sample_points_poisson_disk (sample elimination,
Yuksel 2015) at equal particle counts on the same meshes, in one run, plus the sampler's own trade
(hole-closing rounds against time and covering radius).

Every figure is measured here, the same way for both samplers: relative radius rho = min NN / d_hex,
CV of NN distances, covering radius c over one shared set of area-uniform probes (default 1M), c / r
with r the radius tetrasand chose for that count (so c / r <= 1 means the spheres of that radius cover
the surface), and the largest distance of a sample from the mesh (Open3D unsigned distance).

Usage: bench/sample_bench.py --tetrasand build-test/bin/tetrasand [--counts 1000 10000] [--meshes ...]
       [--csv OUT.csv] [--no-trade | --no-compare] [--trade trefoil cube --trade-count 1000
       --trade-rounds 0 1 3 12 --trade-iterations 100 2000]
--csv writes every row (kind = compare or trade) for bench/plot_sample.py.
--markdown docs/benchmarks/sampler.md rewrites its section sampler (between `<!-- section: sampler -->` and
`<!-- end: sampler -->`) with this run's tables, its plots (docs/benchmarks/sample_*.png) and the
reading in bench/sample_notes.md; scripts/bench.sh sample does that.
Installs Debian's python3-open3d when it is missing (root only), as the peers note says.
"""
import argparse, csv, json, os, platform, shutil, subprocess, sys, tarfile, tempfile, time

CSV_FIELDS = ["kind", "mesh", "requested", "n", "tool", "rounds", "max_iterations", "iterations", "injection_rounds",
              "seconds", "rho", "cv", "c_over_r", "c_over_dhex", "phi_over_r"]


class CsvOut:
    """Rows appended and flushed as they come, so a long run that is stopped keeps what it measured."""
    def __init__(self, path):
        self.file = open(path, "w", newline="") if path else None
        self.writer = csv.DictWriter(self.file, CSV_FIELDS, extrasaction="ignore") if path else None
        if self.writer:
            self.writer.writeheader()

    def close(self):
        if self.file:
            self.file.close()

    def row(self, **values):
        if self.writer:
            self.writer.writerow(values)
            self.file.flush()


def ensure_open3d():
    try:
        import open3d  # noqa: F401
    except ImportError:
        if os.geteuid() != 0:
            sys.exit("python3-open3d is missing: run  apt-get install -y python3-open3d python3-scipy")
        subprocess.run(["apt-get", "install", "-y", "python3-open3d", "python3-scipy"], check=True)


def read_ply_points(path):
    import numpy as np
    with open(path, "rb") as f:
        n, props = 0, 0
        while True:
            line = f.readline().decode().strip()
            if line.startswith("element vertex"):
                n = int(line.split()[2])
            elif line.startswith("property"):
                props += 1
            elif line == "end_header":
                break
        data = np.frombuffer(f.read(4 * n * props), dtype="<f4").reshape(n, props)
    return data[:, :3].astype(float)


def quality(points, mesh, probes, radius):
    import numpy as np
    import open3d as o3d
    from scipy.spatial import cKDTree
    area = mesh.get_surface_area()
    n = len(points)
    d_hex = (2.0 * area / (3.0 ** 0.5 * n)) ** 0.5
    tree = cKDTree(points)
    nn = tree.query(points, k=2)[0][:, 1]
    c = tree.query(probes, k=1)[0].max()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    phi = scene.compute_distance(o3d.core.Tensor(points.astype(np.float32))).numpy().max()
    return {"n": n, "rho": nn.min() / d_hex, "cv": nn.std() / nn.mean(), "c_over_r": c / radius,
            "c_over_dhex": c / d_hex, "phi_over_r": phi / radius}


def run_sample(exe, mesh_path, count, out, extra=(), timeout=None):
    """`tetrasand sample --json`: (body.json summary, wall seconds, what it printed after the JSON, e.g.
    --timings' table). Raises RuntimeError on failure, subprocess.TimeoutExpired past `timeout` s."""
    cmd = [exe, "-q", "sample", mesh_path, "-o", out, "--count", str(count), "--json", *extra]
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    seconds = time.perf_counter() - t
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {res.stdout}{res.stderr}")
    body, end = json.JSONDecoder().raw_decode(res.stdout, res.stdout.index("{"))
    return body, seconds, res.stdout[end:].strip()


def run_tetrasand(exe, mesh_path, count, out, extra=()):
    body, seconds, tail = run_sample(exe, mesh_path, count, out, extra)
    if tail:  # e.g. --timings' stage table, when --tetrasand-args asked for it
        print(tail, flush=True)
    stem = os.path.splitext(os.path.basename(mesh_path))[0]
    return body, read_ply_points(os.path.join(out, stem + ".particles.ply")), seconds


def renderer(exe):
    res = subprocess.run([exe, "devices"], capture_output=True, text=True)
    lines = [l.strip() for l in res.stdout.splitlines() if "renderer" in l.lower() or "chosen" in l.lower()]
    return "; ".join(lines) or res.stdout.strip().splitlines()[-1]


def resolve_mesh(name, tmp):
    if os.path.exists(name):
        return name
    if os.path.exists(f"assets/{name}.obj"):
        return f"assets/{name}.obj"
    member = f"data/meshes/{name}.off"
    with tarfile.open("/usr/share/doc/libcgal-dev/data.tar.gz") as tar:
        tar.extract(member, tmp)
    return os.path.join(tmp, member)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetrasand", required=True)
    ap.add_argument("--meshes", nargs="+", default=["assets/bunny.obj", "knot1", "bear"])
    ap.add_argument("--counts", nargs="+", type=int, default=[1000])
    ap.add_argument("--large", nargs="*", default=["assets/bunny.obj", "knot1"], help="meshes also run at --large-count")
    ap.add_argument("--large-count", type=int, default=10000)
    ap.add_argument("--probes", type=int, default=1_000_000)
    ap.add_argument("--trade", nargs="*", default=["trefoil"], help="meshes for the sampler's own trade")
    ap.add_argument("--trade-count", type=int, default=1000)
    ap.add_argument("--trade-rounds", nargs="+", type=int, default=[0, 1, 3, 12])
    ap.add_argument("--trade-iterations", nargs="+", type=int, default=[2000],
                    help="--max-iterations of the relaxation (needs a tetrasand that has the option)")
    ap.add_argument("--no-compare", action="store_true", help="only the trade")
    ap.add_argument("--no-trade", action="store_true", help="only the comparison with Open3D")
    ap.add_argument("--tetrasand-args", default="",
                    help="more options for the compared `tetrasand sample` runs, e.g. \"--timings\" (printed after each run)")
    ap.add_argument("--criteria", action="store_true",
                    help="exit 1 unless every tetrasand body meets issue 15's targets: c / r <= 1, rho >= 0.75, CV <= 0.05")
    ap.add_argument("--csv", help="also write every row to this CSV")
    ap.add_argument("--markdown", help="rewrite the sampler section of this markdown file (docs/benchmarks/sampler.md)")
    ap.add_argument("--command", default="", help="the command line to quote in the markdown section")
    args = ap.parse_args()
    if args.markdown and not args.csv:
        args.csv = os.path.join(tempfile.mkdtemp(prefix="sample_bench_csv_"), "sample.csv")
    out = CsvOut(args.csv)
    report = []  # the markdown lines of this run, in order

    def say(line=""):
        print(line, flush=True)
        report.append(line)

    ensure_open3d()
    import numpy as np
    import open3d as o3d
    o3d.utility.random.seed(7)  # Open3D 0.16's samplers draw from this global generator
    tmp = tempfile.mkdtemp(prefix="sample_bench_")
    started = time.strftime("%Y-%m-%d")
    load_start = open("/proc/loadavg").read().split()[:3]
    gl = renderer(args.tetrasand)
    print(f"machine: {platform.node()} {platform.machine()}, {os.cpu_count()} cores; GL: {gl}")
    print(f"Open3D {o3d.__version__}; probes per figure: {args.probes}\n")
    jobs = [] if args.no_compare else [(m, n) for m in args.meshes for n in args.counts]
    jobs += [] if args.no_compare else [(m, args.large_count) for m in args.large]
    missed = []  # tetrasand bodies below the --criteria targets
    if jobs:
        say("| mesh | N | tool | time s | ratio | rho | CV | c / r | c / d_hex | max phi / r |")
        say("|---|---|---|---|---|---|---|---|---|---|")
    for name, count in jobs:
        path = resolve_mesh(name, tmp)
        mesh = o3d.io.read_triangle_mesh(path)
        probes = np.asarray(mesh.sample_points_uniformly(args.probes).points)
        body, ours, t_ours = run_tetrasand(args.tetrasand, path, count, os.path.join(tmp, "out"),
                                           args.tetrasand_args.split())
        r = body["particle_radius"]
        t = time.perf_counter()
        theirs = np.asarray(mesh.sample_points_poisson_disk(body["particle_count"], init_factor=5).points)
        t_theirs = time.perf_counter() - t
        label = os.path.splitext(os.path.basename(path))[0]
        for tool, pts, secs in (("tetrasand", ours, t_ours), ("Open3D", theirs, t_theirs)):
            q = quality(pts, mesh, probes, r)
            if tool == "tetrasand" and not (q["c_over_r"] <= 1.0 and q["rho"] >= 0.75 and q["cv"] <= 0.05):
                missed.append(f"{os.path.basename(path)} at {count}: c / r {q['c_over_r']:.3f}, rho {q['rho']:.3f}, "
                              f"CV {q['cv']:.3f}")
            say(f"| {label} | {q['n']} | {tool} | {secs:.2f} | {secs / t_theirs:.2f} | {q['rho']:.3f} | {q['cv']:.3f} | "
                f"{q['c_over_r']:.3f} | {q['c_over_dhex']:.3f} | {q['phi_over_r']:.1e} |")
            out.row(kind="compare", mesh=label, requested=count, tool=tool, seconds=secs, **q,
                    iterations=body["quality"]["iterations"] if tool == "tetrasand" else "",
                    injection_rounds=body["quality"]["injection_rounds"] if tool == "tetrasand" else "")

    for name in [] if args.no_trade else args.trade:
        path = resolve_mesh(name, tmp)
        mesh = o3d.io.read_triangle_mesh(path)
        probes = np.asarray(mesh.sample_points_uniformly(args.probes).points)
        label = os.path.splitext(os.path.basename(path))[0]
        say()
        say(f"Sampler trade on {label}, {args.trade_count} particles requested, `--rounds` against `--max-iterations`:")
        say()
        say("| rounds | max iterations | N | iterations | injection rounds | time s | rho | CV | c / r |")
        say("|---|---|---|---|---|---|---|---|---|")
        for iterations in args.trade_iterations:
            for rounds in args.trade_rounds:
                extra = ["--rounds", str(rounds)]
                if iterations != 2000:
                    extra += ["--max-iterations", str(iterations)]
                body, ours, secs = run_tetrasand(args.tetrasand, path, args.trade_count, os.path.join(tmp, "trade"), extra)
                q = quality(ours, mesh, probes, body["particle_radius"])
                bq = body["quality"]
                say(f"| {rounds} | {iterations} | {q['n']} | {bq['iterations']} | {bq['injection_rounds']} | {secs:.2f} | "
                    f"{q['rho']:.3f} | {q['cv']:.3f} | {q['c_over_r']:.3f} |")
                out.row(kind="trade", mesh=label, requested=args.trade_count, tool="tetrasand", rounds=rounds,
                        max_iterations=iterations, iterations=bq["iterations"], injection_rounds=bq["injection_rounds"],
                        seconds=secs, **q)
    shutil.rmtree(tmp, ignore_errors=True)
    if args.markdown:
        out.close()
        write_markdown(args, report, started, load_start, gl, o3d.__version__)
    if args.criteria:
        for m in missed:
            print(f"sample: below the targets (c / r <= 1, rho >= 0.75, CV <= 0.05): {m}", file=sys.stderr)
        print("sample: every tetrasand body meets the targets" if not missed else "sample: targets missed")
        if missed:
            sys.exit(1)


def write_markdown(args, report, started, load_start, gl, open3d_version):
    """The sampler section of docs/benchmarks/sampler.md from this run: how it ran, its tables, plots, notes."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    from docs_section import replace_between
    figures = os.path.dirname(os.path.abspath(args.markdown))  # the plots lie beside the page
    os.makedirs(figures, exist_ok=True)
    subprocess.run(["/usr/bin/python3", os.path.join(here, "plot_sample.py"), figures, args.csv], check=True)
    plots = []
    if not args.no_compare:
        plots.append("![tetrasand and Open3D against the particle count](sample_vs_open3d.png)")
    if not args.no_trade and args.trade:
        plots.append("![sampler trade: covering radius and rho against relaxation steps](sample_trade.png)")
    load_end = open("/proc/loadavg").read().split()[:3]
    notes = os.path.join(here, "sample_notes.md")
    gpu_note = ("**No NVIDIA GPU was used**: tetrasand's GPU work ran on Mesa's llvmpipe, on the same CPU cores as "
                "Open3D, so read the ratios, not the seconds.\n" if "llvmpipe" in gl else "")
    text = f"""## Sampling

`{args.command or 'bench/sample_bench.py'}` ({started}; bench/sample_bench.py): `tetrasand sample --count N`
against Open3D {open3d_version} `sample_points_poisson_disk(N, init_factor=5)` (sample elimination, Yuksel
2015) on the same mesh at the count tetrasand produced, in one run. Machine {platform.node()}
({platform.machine()}, {os.cpu_count()} cores), GL renderer of tetrasand's GPU work: {gl}; load average
{' '.join(load_start)} (1/5/15 min) at the start, {' '.join(load_end)} at the end. Both point sets are
measured by the script the same way: rho = min NN / d_hex, CV of NN distances, covering radius c over
one shared set of {args.probes:,} area-uniform probes, c / r with r the radius tetrasand chose for that
count (c / r <= 1: spheres of that radius cover the whole surface), and the largest distance from the
mesh (Open3D's float32 unsigned distance). Ratio = time / Open3D's time; tetrasand's time is the whole
command (mesh load, validation, SDF scan conversion, relaxation, projection, coverage passes, outputs).
{gpu_note}
""" + "\n".join(report) + "\n\n" + "\n\n".join(plots) + "\n"
    if os.path.exists(notes):
        text += "\n" + open(notes).read()
    replace_between(args.markdown, "<!-- section: sampler -->\n", "<!-- end: sampler -->\n", text)
    print(f"wrote the sampler section of {args.markdown}")


if __name__ == "__main__":
    main()
