#!/usr/bin/python3
"""The device run of issue 16: SDF, sampler, sim and preview benchmarks in one call of at most 8 minutes,
each part under its own time cap, into one results file; and the report that turns that file into the
NVIDIA sections of docs/benchmarks/device.md. scripts/device-bench.sh is the entry point (it unpacks the carried
bundle on the device machine first); by hand:
  bench/device_bench.py run --bin BUILD/bin --out DIR [--quick] [--meshes DIR] [--only sdf,sim]
                            [--budget S] [--caps sim=60,preview=20]
  bench/device_bench.py report DIR/device-bench.json --markdown docs/benchmarks/device.md [--baseline HERE.json]
`run` writes DIR/device-bench.json (rewritten after every part, so a call stopped at its limit keeps the
parts it finished) and DIR/device-bench.md (the sections `report` would write). Standard library only:
the device machine's python3 is not Debian's."""
import argparse
import csv
import json
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import tarfile
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import sdf_report  # noqa: E402
from docs_section import replace_between  # noqa: E402
from sample_bench import resolve_mesh, run_sample  # noqa: E402

SCHEMA = "tetrasand-device-bench/1"
# In order of value: the first gets its time first. selftest first: the GPU kernels' agreement tests
# on the device, because timings of kernels that compute wrong are worth nothing (2026-12-04: PNanoVDB's
# root walk read every voxel as the background on NVIDIA while every llvmpipe test passed).
PARTS = ["selftest", "sdf", "sampler", "sim", "preview"]

# Sizes of each part: the full run (issue 16) and --quick (tiny, so the chain runs on llvmpipe here).
SIZES = {
    "full": {
        "selftest": "full",
        "sdf": {"meshes": ["knot1", "armadillo", "icosphere:8"], "resolutions": [256, 512, 1024, 2048]},
        "sampler": {"mesh": "bunny", "counts": [10_000, 100_000, 1_000_000]},
        # bench/sim_step_criteria.md: at least 10 timed GPU steps a size; 4M once more in the other
        # precision order ("repeat"), so a one-off stall shows as two 4M rows that disagree.
        "sim": {"grains": [64_000, 1_000_000, 4_000_000], "precisions": ["float", "double"], "seconds": 1.0,
                "min_steps": 10, "cpu_min_steps": 2, "repeat": {"grains": [4_000_000], "precisions": ["double", "float"]},
                "kernel_grains": [64_000, 1_000_000, 4_000_000], "kernel_seconds": 0.5},
        "preview": {"mesh": "bunny", "size": 1024, "resolution": 1024, "particles": 1_000_000, "repeat": 3},
    },
    "quick": {
        "selftest": "quick",
        "sdf": {"meshes": ["knot1", "icosphere:2"], "resolutions": [16, 24]},
        "sampler": {"mesh": "bunny", "counts": [400, 600]},
        "sim": {"grains": [1000], "precisions": ["float", "double"], "seconds": 0.1,
                "min_steps": 10, "cpu_min_steps": 2, "repeat": {"grains": [1000], "precisions": ["double", "float"]},
                "kernel_grains": [1000], "kernel_seconds": 0.05},
        "preview": {"mesh": "bunny", "size": 96, "resolution": 32, "particles": 2000, "repeat": 1},
    },
}
# Time caps (s). Full: 460 s of parts in a call of at most 8 minutes (unpacking and `devices` take the
# rest); time a part leaves unused goes to the parts after it. Quick: loose, for 2 loaded cores.
CAPS = {"full": {"selftest": 60, "sdf": 150, "sampler": 80, "sim": 130, "preview": 50},
        "quick": {"selftest": 200, "sdf": 90, "sampler": 90, "sim": 150, "preview": 120}}
# The selftest: test executables and the GoogleTest filters of their GPU-against-host tests (the full
# set on the device; --quick a few, since each new kernel compiles for tens of seconds on llvmpipe).
SELFTESTS = {
    "full": [("tetrasand_gpu_tests", "GpuContext.*:GpuQueue.*:Graphics.*:GpuGrid.*:GpuLayouts.*:HostSync.*"),
             # Not PnanovdbsRootKeyAndWalkMatchTheHostGrid: it shows the driver's miscompiled 64-bit root key
             # itself, which the reads no longer use (the flat root table; ReadsNeverDependOnPnanovdbsRootWalk
             # and the grids past 4096 voxels a side are the checks).
             ("tetrasand_sdf_tests", "SparseFieldTest.*:SparseFieldPast4096Test.*:ScanConvert.*:ComputeScan.*:GpuBrickPairs.*"
                                     ":*LeafField*:PrismModel.*"
                                     "-SparseFieldTest.PnanovdbsRootKeyAndWalkMatchTheHostGrid"),
             ("tetrasand_sampler_tests", "Relaxer.*:CoverageCertificate.*:Meshes/CpuAgainstGpu.*"),
             ("tetrasand_sim_tests", "GpuStepperTest.*:GpuCpuAgreement.*"),
             ("tetrasand_preview_tests", "PreviewRenderer.*:PreviewGolden.*:PreviewComputePasses.*")],
    "quick": [("tetrasand_gpu_tests", "GpuLayouts.*"),
              ("tetrasand_sdf_tests", "SparseFieldTest.ReadsNeverDependOnPnanovdbsRootWalk")],
}
TEST_BINARIES = [exe for exe, _ in SELFTESTS["full"]]
# The sampler part times the GPU path whatever `--backend auto` would pick (issue 43: the scan, the field kept
# on the GPU and the relaxation on it), after the selftest has checked the sparse field's reads there.
SAMPLER_GPU_PATH = ["--backend", "gpu", "--sdf-backend", "gpu"]
BINARIES = {"selftest": "tetrasand_gpu_tests", "sdf": "tetrasand_bench_sdf", "sampler": "tetrasand", "sim": "tetrasand_bench_sim",
            "preview": "tetrasand_bench_preview"}


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def tail(text, lines=15):
    return "\n".join(text.strip().splitlines()[-lines:])


def run_capped(cmd, cap, log):
    """Runs `cmd` in its own process group for at most `cap` s, stdout and stderr to `log`.out / .err.
    Returns (exit code or None on timeout, seconds, stdout, stderr)."""
    start = time.perf_counter()
    with open(log + ".out", "w") as out, open(log + ".err", "w") as err:
        p = subprocess.Popen(cmd, stdout=out, stderr=err, start_new_session=True)
        try:
            rc = p.wait(timeout=max(cap, 0.1))
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            rc = None
    return rc, time.perf_counter() - start, open(log + ".out").read(), open(log + ".err").read()


def outcome(rc, stderr):
    """The part's status and error text from its process's exit."""
    if rc is None:
        return "timeout", "stopped at its time cap"
    return ("ok", "") if rc == 0 else ("error", f"exit status {rc}: {tail(stderr)}")


def kernel_tables(text):
    """The per-kernel tables `tetrasand_bench_sim --timings` prints to stderr, one per size:
    {grains: [{kernel, calls, ms, share}]} (the `total` row left out)."""
    tables, grains = {}, None
    for line in text.splitlines():
        head = re.match(r"^(\d+) grains:$", line)
        if re.match(r"^\d+ grains, CPU reference:$", line):
            grains = None  # the CPU reference's report (lists, no kernels) is not a GPU table
        row = re.match(r"^(\S+)\s+(\d+)\s+([\d.]+)\s+([\d.]+)%$", line)
        if head:
            grains = head.group(1)
            tables[grains] = []
        elif row and grains is not None:
            tables[grains].append({"kernel": row.group(1), "calls": int(row.group(2)), "ms": float(row.group(3)),
                                   "share": float(row.group(4))})
    return tables


def csv_rows(path):
    return list(csv.DictReader(open(path))) if os.path.exists(path) else []


class Run:
    """One `run`: where the binaries, meshes and work files are, the sizes, and the results so far."""

    def __init__(self, args):
        self.bin, self.work, self.meshes = args.bin, tempfile.mkdtemp(prefix="device-bench."), args.meshes
        self.kind = "quick" if args.quick else "full"
        self.sizes = SIZES[self.kind]
        os.environ["TETRASAND_SOURCE_DIR"] = ROOT  # the bench scenes are read from this tree

    def exe(self, part):
        path = os.path.join(self.bin, BINARIES[part])
        if not os.access(path, os.X_OK):
            raise FileNotFoundError(f"{path}: no such executable (build it, or run `scripts/device-bench.sh prepare`)")
        return path

    def mesh(self, name):
        """A case's mesh: icosphere:S as it is, bunny from assets/, CGAL's from --meshes or the Debian tarball."""
        if name.startswith("icosphere:"):
            return name
        if name == "bunny":
            return os.path.join(ROOT, "assets", "bunny.obj")
        carried = os.path.join(self.meshes or "", name + ".off")
        return carried if self.meshes and os.path.exists(carried) else resolve_mesh(name, self.work)

    def selftest(self, cap):
        """Each test executable under what is left of the cap; a missing one (a bundle packed without the
        tests) is recorded as such. The part is an error when any test failed, with the names."""
        rows, start, failed = [], time.perf_counter(), []
        for exe, pattern in SELFTESTS[self.sizes["selftest"]]:
            path, left = os.path.join(self.bin, exe), cap - (time.perf_counter() - start)
            if not os.access(path, os.X_OK):
                rows.append({"binary": exe, "filter": pattern, "status": "missing"})
                continue
            if left <= 0:
                rows.append({"binary": exe, "filter": pattern, "status": "not run (part cap reached)"})
                continue
            report = os.path.join(self.work, exe + ".json")
            rc, secs, out, err = run_capped([path, f"--gtest_filter={pattern}", f"--gtest_output=json:{report}"],
                                            left, os.path.join(self.work, exe))
            tests = [(f"{suite['name']}.{t['name']}", t.get("failures", []))
                     for suite in (json.load(open(report)).get("testsuites", []) if os.path.exists(report) else [])
                     for t in suite.get("testsuite", [])]
            bad = [name for name, failures in tests if failures]
            status = "timeout" if rc is None else ("ok" if rc == 0 else "failed")
            failed += bad or ([f"{exe} ({status})"] if status != "ok" else [])
            rows.append({"binary": exe, "filter": pattern, "status": status, "seconds": round(secs, 2),
                         "tests": len(tests), "failed": bad,
                         "messages": {name: tail(f[0].get("failure", ""), 6) for name, f in tests if f},
                         "output_tail": tail(out + err, 20) if status != "ok" else ""})
        missing = [r["binary"] for r in rows if r["status"] == "missing"]
        if len(missing) == len(rows):
            raise FileNotFoundError(f"no test executable in {self.bin} (prepare packs them from a build with tests)")
        err = "failed: " + ", ".join(failed) if failed else ""
        return (1 if failed else 0), time.perf_counter() - start, err, {"rows": rows}

    def sdf(self, cap):
        s = self.sizes["sdf"]
        paths = {m: self.mesh(m) for m in s["meshes"]}
        # Every mesh at one resolution before any at the next: a cap cuts the largest grids, not a mesh.
        cases = [f"{paths[m]}@{r}" for r in s["resolutions"] for m in s["meshes"]]
        table = os.path.join(self.work, "sdf.csv")
        cmd = [self.exe("sdf"), *cases, "--csv", table]
        rc, secs, _, err = run_capped(cmd, cap, os.path.join(self.work, "sdf"))
        planned = [f"{paths[m]}@{','.join(map(str, s['resolutions']))}" for m in s["meshes"]]
        return rc, secs, err, {"command": cmd, "planned": planned, "rows": csv_rows(table)}

    def sampler(self, cap):
        s = self.sizes["sampler"]
        exe, mesh, rows, start = self.exe("sampler"), self.mesh(s["mesh"]), [], time.perf_counter()
        rc, err = 0, ""
        for count in s["counts"]:
            left = cap - (time.perf_counter() - start)
            if rc != 0 or left <= 0:
                rows.append({"count": count, "status": "not run (part cap reached or an earlier count failed)"})
                continue
            out = os.path.join(self.work, f"sample-{count}")
            try:
                body, secs, timings = run_sample(exe, mesh, count, out, ["--timings", *SAMPLER_GPU_PATH], timeout=left)
                q, run = body["quality"], body.get("run", {})
                field = run.get("sdf", {}) if isinstance(run.get("sdf"), dict) else {}
                rows.append({"count": count, "status": "ok", "seconds": secs, "particles": body["particle_count"],
                             "radius_m": body["particle_radius"], "iterations": q["iterations"],
                             "converged": q["converged"], "injection_rounds": q["injection_rounds"],
                             "relaxation_s": q["seconds"], "relative_radius": q["relative_radius"], "cv": q["cv"],
                             "covering_over_r": q["covering_over_r"], "scan": run.get("scan", ""),
                             "relax_backend": run.get("relax_backend", ""),
                             "sdf_s": run.get("seconds", {}).get("sdf"),
                             "field_readback_bytes": field.get("readback_bytes"),
                             "band_voxels": field.get("band_voxels"), "timings": timings})
            except subprocess.TimeoutExpired:
                rc = None
                rows.append({"count": count, "status": "timeout"})
            except (RuntimeError, KeyError, ValueError) as e:
                rc, err = 1, str(e)
                rows.append({"count": count, "status": "error", "error": tail(str(e))})
            shutil.rmtree(out, ignore_errors=True)
        return rc, time.perf_counter() - start, err, {"mesh": s["mesh"], "rows": rows}

    def sim(self, cap):
        # tetrasand_bench_sim builds GpuStepper and CpuStepper itself (bench/sim_bench.cpp): the GPU
        # pipeline is timed on every device, whatever `tetrasand sim --backend auto` would pick there.
        s = self.sizes["sim"]
        table = os.path.join(self.work, "sim.csv")
        steps = ["--seconds", str(s["seconds"]), "--min-steps", str(s["min_steps"]), "--cpu-min-steps", str(s["cpu_min_steps"])]
        cmd = [self.exe("sim"), "--grains", ",".join(map(str, s["grains"])), "--precision", ",".join(s["precisions"]),
               *steps, "--csv", table]
        rc, secs, _, err = run_capped(cmd, cap, os.path.join(self.work, "sim"))
        result = {"command": cmd, "planned_grains": s["grains"], "rows": csv_rows(table)}
        left = cap - secs
        if rc == 0 and left > 5:
            again = os.path.join(self.work, "sim-repeat.csv")
            rcmd = [self.exe("sim"), "--grains", ",".join(map(str, s["repeat"]["grains"])), "--precision",
                    ",".join(s["repeat"]["precisions"]), *steps, "--csv", again]
            rrc, rsecs, _, rerr = run_capped(rcmd, left, os.path.join(self.work, "sim-repeat"))
            status, error = outcome(rrc, rerr)
            result["repeat"] = {"command": rcmd, "status": status, "error": error, "rows": csv_rows(again)}
            secs += rsecs
        # Then, with what the cap leaves, where a float step's GPU time goes (timer queries, read at the
        # end) at the large sizes: a separate run, so the queries do not touch the rates above. On the
        # first device run 4M grains stepped 130x slower than 1M; this names the kernel.
        left = cap - secs
        if rc == 0 and left > 5:
            kcmd = [self.exe("sim"), "--grains", ",".join(map(str, s["kernel_grains"])), "--precision", "float",
                    "--seconds", str(s["kernel_seconds"]), "--timings"]
            krc, ksecs, _, kerr = run_capped(kcmd, left, os.path.join(self.work, "sim-kernels"))
            status, error = outcome(krc, kerr)
            result["kernels"] = {"command": kcmd, "status": status, "error": error, "tables": kernel_tables(kerr)}
            secs += ksecs
        return rc, secs, err, result

    def preview(self, cap):
        s = self.sizes["preview"]
        cmd = [self.exe("preview"), self.mesh(s["mesh"]), "--size", str(s["size"]), "--resolution",
               str(s["resolution"]), "--particles", str(s["particles"]), "--repeat", str(s["repeat"])]
        rc, secs, out, err = run_capped(cmd, cap, os.path.join(self.work, "preview"))
        # The bench runs both GPU paths (raster draws, compute kernels) in one process; each table's
        # header names its path, and its rows follow.
        rows, path = [], ""
        for line in out.splitlines():
            header = re.match(r"^\| image .*--gpu-path (\w+) \|", line)
            row = re.match(r"^\| ([^|]+?) \| ([\d.]+) \| ([\d.]+) \|$", line)
            if header:
                path = header.group(1)
            elif row:
                rows.append({"image": row[1], "path": path, "first_s": float(row[2]), "median_s": float(row[3])})
        scene = next((l for l in out.splitlines() if l.startswith("mesh ")), "")
        return rc, secs, err, {"command": cmd, "sizes": s, "scene": scene, "rows": rows, "output": out}


def machine(bin_dir, system_env):
    """Date, cores, CPU and the GL device `tetrasand devices` picks (GL_RENDERER / GL_VERSION)."""
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    info = {"date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "host": platform.node(),
            "cores": os.cpu_count(), "cpu": cpu, "gl_renderer": "", "gl_version": "", "gl_device": ""}
    try:
        res = subprocess.run([os.path.join(bin_dir, "tetrasand"), "devices"], capture_output=True, text=True, timeout=60)
        info["devices"] = res.stdout + res.stderr
        chosen = re.search(r"^chosen: device (\d+): (.*)$", res.stdout, re.M)
        if chosen:
            info["gl_device"] = chosen.group(2)
            block = res.stdout.split(f"device {chosen.group(1)}: ", 1)[1]
            info["gl_renderer"] = re.search(r"renderer: (.*)", block).group(1).strip()
            info["gl_version"] = re.search(r"version:\s+(.*)", block).group(1).strip()
    except (OSError, subprocess.TimeoutExpired, AttributeError) as e:
        info["devices"] = f"tetrasand devices failed: {e}"
    smi = shutil.which("nvidia-smi")
    try:
        if smi:
            res = subprocess.run([smi, "--query-gpu=name,driver_version,memory.total", "--format=csv,noheader"],
                                 capture_output=True, text=True, env=system_env, timeout=30)
            info["nvidia_smi"] = res.stdout.strip()
    except (OSError, subprocess.TimeoutExpired) as e:
        info["nvidia_smi_error"] = str(e)
    return info


def parse_caps(text):
    caps = {}
    for item in filter(None, (text or "").split(",")):
        part, _, value = item.partition("=")
        if part not in PARTS:
            raise SystemExit(f"--caps: unknown part {part!r} (parts: {', '.join(PARTS)})")
        caps[part] = float(value)
    return caps


def run_part(r, part, cap):
    """One part's record: status (ok, timeout, error), seconds, its cap, its rows and how it ran."""
    record = {"cap_s": round(cap, 1)}
    if cap <= 0:
        return dict(record, status="timeout", seconds=0.0, error="no time left in the call's budget")
    try:
        rc, secs, err, data = getattr(r, part)(cap)
        status, error = outcome(rc, err)
        return dict(record, **data, status=status, seconds=round(secs, 2), error=error, stderr_tail=tail(err, 30))
    except (OSError, KeyError, tarfile.TarError) as e:  # a missing executable or mesh, a broken tarball: this part's error
        return dict(record, status="error", seconds=0.0, error=str(e))


def run(args):
    r = Run(args)
    only = args.only.split(",") if args.only else PARTS
    unknown = [p for p in only if p not in PARTS]
    if unknown:
        raise SystemExit(f"--only: unknown part(s) {', '.join(unknown)} (parts: {', '.join(PARTS)})")
    caps = dict(CAPS[r.kind], **parse_caps(args.caps))
    args.budget = args.budget or (450.0 if args.quick else 470.0)
    os.makedirs(args.out, exist_ok=True)
    system_env = dict(os.environ)
    if args.libs:  # the children's, not this interpreter's: the loader read its path at start-up
        os.environ["LD_LIBRARY_PATH"] = os.pathsep.join(filter(None, [args.libs, os.environ.get("LD_LIBRARY_PATH")]))
    results = {"schema": SCHEMA, "kind": r.kind, "command": " ".join(sys.argv), "machine": machine(args.bin, system_env),
               "budget_s": args.budget, "parts": {}}
    json_path = os.path.join(args.out, "device-bench.json")
    deadline, slack = time.perf_counter() + args.budget, 0.0
    print(f"device-bench: {results['machine']['gl_device'] or 'no GL device found'}; work files in {r.work}", flush=True)
    for part in PARTS:
        cap = min(caps[part] + slack, deadline - time.perf_counter())
        record = run_part(r, part, cap) if part in only else {"status": "skipped", "error": "not in --only"}
        slack = max(cap - record.get("seconds", cap), 0.0)  # what this part left goes to the next
        results["parts"][part] = record
        if part in only:
            print(f"device-bench: {part}: {record['status']} in {record['seconds']:.1f} s (cap {record['cap_s']} s)"
                  + (f": {record['error']}" if record["error"] else ""), flush=True)
        write_atomically(json_path, json.dumps(results, indent=1) + "\n")
    ran = [text for part, text in sections(results).items() if results["parts"][part]["status"] != "skipped"]
    write_atomically(os.path.join(args.out, "device-bench.md"), "\n\n".join(ran) + "\n")
    print(f"device-bench: wrote {json_path} and device-bench.md", flush=True)
    shutil.rmtree(r.work, ignore_errors=True)


# --- the markdown: one section per part, headed by the machine, GPU, driver and date ---

def provenance(res, part):
    m, p = res["machine"], res["parts"].get(part, {"status": "not in this results file"})
    gl = m.get("nvidia_smi") or m["gl_renderer"] or "unknown GPU"
    label = "" if "NVIDIA" in m["gl_renderer"] else (
        " **Not an NVIDIA GPU**: this run's GL device is the one named here (a test of the script, not a figure "
        "of the GPU's).")
    sizes = " (the --quick sizes: a test of the chain, not a benchmark)" if res["kind"] == "quick" else ""
    return (f"Device run of {m['date'][:10]} (`scripts/device-bench.sh run`, bench/device_bench.py){sizes}: GPU "
            f"{gl}, GL_RENDERER `{m['gl_renderer']}`, GL_VERSION (driver) `{m['gl_version']}`; CPU side "
            f"{m['cores']} cores ({m['cpu']}). Part status: **{p['status']}**"
            + (f" after {p['seconds']:.0f} s of its {p['cap_s']:.0f} s cap" if "seconds" in p else "")
            + (f" ({p['error'].splitlines()[0]})" if p.get("error") else "") + "." + label)


def selftest_section(res):
    p = res["parts"].get("selftest", {})
    lines = ["### GPU self-test on an NVIDIA GPU", "", provenance(res, "selftest"), "",
             "The GPU kernels' agreement tests (GoogleTest, from the build the bundle was packed from) run on the "
             "device before any timing: kernels that compute wrong make their timings worthless.", ""]
    rows = p.get("rows", [])
    if rows:
        lines += ["| executable | filter | status | tests | failed | s |", "|---|---|---|---|---|---|"]
        lines += [f"| {r['binary']} | `{r['filter']}` | {r['status']} | {r.get('tests', '')} "
                  f"| {', '.join(r.get('failed', [])) or '-'} | {r.get('seconds', '')} |" for r in rows]
    messages = [(name, text) for r in rows for name, text in r.get("messages", {}).items()]
    for name, text in messages[:6]:
        lines += ["", f"`{name}`:", "", "```", text, "```"]
    return "\n".join(lines)


def sdf_section(res):
    p = res["parts"]["sdf"]
    lines = ["### SDF on an NVIDIA GPU", "", provenance(res, "sdf"), "",
             "Same program and columns as [section SDF](sdf.md#sdf) (`tetrasand_bench_sdf`): GPU scan conversion against the "
             "CPU exact SDF and OpenVDB `meshToLevelSet`, both on the device machine's cores, errors against exact.",
             ""]
    rows = p.get("rows", [])
    if rows:
        lines += sdf_report.table(rows) + [""]
    gone = sdf_report.missing_cases(p.get("planned", []), rows)
    if gone:
        lines += ["Not run (planned, no row above): " + "; ".join(gone) + ".", ""]
    if rows:
        lines += ["What the numbers say (computed from the rows above):"] + sdf_report.findings(rows)
    return "\n".join(lines)


def sampler_section(res, baseline=None):
    p = res["parts"]["sampler"]
    here = {r["count"]: r for r in (baseline or {}).get("parts", {}).get("sampler", {}).get("rows", [])
            if r.get("status") == "ok"}
    lines = ["### Sampling on an NVIDIA GPU", "", provenance(res, "sampler"), "",
             f"`tetrasand sample {p.get('mesh', 'bunny')} --count N --json --timings {' '.join(SAMPLER_GPU_PATH)}`, "
             "whole command's wall time. The quality columns are the sampler's own figures (body.json `quality`); "
             "scan, SDF s and field read-back are its `run` figures (`run.scan`, `run.seconds.sdf`, "
             "`run.sdf.readback_bytes`: 0 when the field stayed on the GPU between scan and relaxation).", ""]
    if here:
        b = baseline["machine"]
        lines += [f"Baseline (a different machine): the same run on {b['gl_renderer']}, {b['cores']} cores, "
                  f"{b['date'][:10]}; speed-up = baseline time / this run's time.", ""]
    lines += ["| N requested | N | time s | scan | SDF s | field read-back bytes | relaxation s | iterations | converged "
              "| rho | CV | c / r" + (" | baseline s | speed-up |" if here else " |"),
              "|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|---|" if here else "")]
    for r in p.get("rows", []):
        if r["status"] != "ok":
            lines.append(f"| {r['count']} | {r['status']} |" + " |" * (11 + 2 * bool(here)))
            continue
        sdf_s = f"{r['sdf_s']:.2f}" if r.get("sdf_s") is not None else "n/r"
        readback = r.get("field_readback_bytes")
        row = (f"| {r['count']} | {r['particles']} | {r['seconds']:.2f} | {r.get('scan') or 'n/r'} | {sdf_s} "
               f"| {readback if readback is not None else 'n/r'} | {r['relaxation_s']:.2f} | {r['iterations']} "
               f"| {r['converged']} | {r['relative_radius']:.3f} | {r['cv']:.3f} | {r['covering_over_r']:.3f} |")
        if here:
            b = here.get(r["count"])
            row += f" {b['seconds']:.2f} | {b['seconds'] / r['seconds']:.1f} |" if b else " n/r | n/r |"
        lines.append(row)
    timed = [r for r in p.get("rows", []) if r.get("timings")]
    if timed:
        lines += ["", f"Per-kernel GPU times at N = {timed[-1]['count']} (`--timings`):", "", "```",
                  timed[-1]["timings"], "```"]
    return "\n".join(lines)


def sim_section(res):
    p = res["parts"]["sim"]
    rows = p.get("rows", [])
    lines = ["### Simulation on an NVIDIA GPU", "", provenance(res, "sim"), "",
             "Cundall number (grain time steps per second) of `tetrasand_bench_sim` on the settled bed of "
             "[section Simulation](sim.md#simulation), GPU pipeline in float and in double against the CPU reference (double, TBB on the "
             "device machine's cores; measured once per size).", ""]
    if rows:
        lines += ["| grains | GPU precision | contacts / grain | GPU grain-steps/s | CPU grain-steps/s | GPU / CPU "
                  "| timed steps GPU / CPU | GPU bytes / grain |", "|---|---|---|---|---|---|---|---|"]
    repeat = p.get("repeat", {})
    for r in rows + [dict(x, precision=x["precision"] + " (repeat, other order)") for x in repeat.get("rows", [])]:
        lines.append(f"| {r['grains']} | {r['precision']} | {float(r['contacts_per_grain']):.1f} "
                     f"| {float(r['gpu_grain_steps_per_s']):.3g} | {float(r['cpu_grain_steps_per_s']):.3g} "
                     f"| {float(r['gpu_over_cpu']):.2f} | {r['gpu_steps']} / {r['cpu_steps']} "
                     f"| {float(r['gpu_bytes_per_grain']):.0f} |")
    if repeat and repeat.get("status") != "ok":
        lines += ["", f"The repeat run in the other precision order: {repeat.get('status')}"
                  + (f": {repeat['error']}" if repeat.get("error") else "") + "."]
    done = {int(r["grains"]) // 1000 for r in rows}
    gone = [g for g in p.get("planned_grains", []) if g // 1000 not in done]
    if gone:
        lines += ["", "Not run (planned, no row above): " + ", ".join(map(str, gone)) + " grains."]
    k = p.get("kernels")
    if k:
        lines += ["", f"Where a float step's GPU time goes: `{' '.join(os.path.basename(c) for c in k['command'])}` "
                  f"(a separate run with timer queries, read at the end; status {k['status']}"
                  + (f": {k['error']}" if k["error"] else "") + ")."]
        for grains, table in k["tables"].items():
            steps = max((t["calls"] for t in table if t["kernel"] == "sim/contact_forces.comp"), default=0)
            lines += ["", f"{grains} grains, {steps} steps:", "", "| kernel | calls | ms | share | ms per step |",
                      "|---|---|---|---|---|"]
            lines += [f"| {t['kernel']} | {t['calls']} | {t['ms']:.2f} | {t['share']:.1f} % "
                      f"| {t['ms'] / steps if steps else float('nan'):.3f} |" for t in table]
    return "\n".join(lines)


def preview_section(res):
    p = res["parts"]["preview"]
    s = p.get("sizes", {})
    lines = ["### Preview on an NVIDIA GPU", "", provenance(res, "preview"), ""]
    if s:
        lines += [f"`tetrasand_bench_preview {s['mesh']} --size {s['size']} --resolution {s['resolution']} --particles "
                  f"{s['particles']} --repeat {s['repeat']}` ([section Preview](preview.md#preview)). {p.get('scene', '')}", ""]
    if p.get("rows"):
        lines += [f"| image {s['size']}^2 | --gpu-path | first render s | median of {s['repeat']} s |",
                  "|---|---|---:|---:|"]
        lines += [f"| {r['image']} | {r.get('path') or 'raster'} | {r['first_s']:.3f} | {r['median_s']:.3f} |"
                  for r in p["rows"]]
    return "\n".join(lines)


def sections(res, baseline=None):
    return {"selftest": selftest_section(res), "sdf": sdf_section(res), "sampler": sampler_section(res, baseline), "sim": sim_section(res),
            "preview": preview_section(res)}


def load_results(path):
    res = json.load(open(path))
    if res.get("schema") != SCHEMA:
        raise SystemExit(f"{path}: not a device-bench results file (schema {res.get('schema')!r}, expected {SCHEMA})")
    for part in PARTS:  # a file from before a part existed: that part counts as not run
        res["parts"].setdefault(part, {"status": "skipped", "error": "no record in this results file"})
    return res


def report(args):
    res = load_results(args.results)
    renderer = res["machine"]["gl_renderer"]
    if not args.allow_test and (res["kind"] != "full" or "NVIDIA" not in renderer):
        raise SystemExit(f"{args.results}: a {res['kind']} run on {renderer or 'no GL device'}, not a full run on an "
                         "NVIDIA GPU; the NVIDIA sections are for those (--allow-test writes it anyway)")
    baseline = load_results(args.baseline) if args.baseline else None
    for part, text in sections(res, baseline).items():
        if res["parts"][part]["status"] == "skipped":
            continue  # a partial run leaves the sections it did not run as they are
        replace_between(args.markdown, f"<!-- section: nvidia-{part} -->\n", f"<!-- end: nvidia-{part} -->", text + "\n")
        print(f"wrote section nvidia-{part} of {args.markdown}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="verb", required=True)
    r = sub.add_parser("run", help="run the parts, write DIR/device-bench.json and .md")
    r.add_argument("--bin", required=True, help="folder of tetrasand and the bench executables")
    r.add_argument("--out", required=True)
    r.add_argument("--libs", help="folder of carried shared libraries, put first on the benchmarks' library path")
    r.add_argument("--meshes", help="folder of knot1.off and armadillo.off (else CGAL's Debian tarball)")
    r.add_argument("--quick", action="store_true", help="tiny sizes: the whole chain in a few minutes on llvmpipe")
    r.add_argument("--only", help="comma-separated parts to run (others are recorded as skipped)")
    r.add_argument("--caps", help="part=seconds,... overriding the time caps")
    r.add_argument("--budget", type=float, help="seconds for all parts together (default 470; --quick 450)")
    p = sub.add_parser("report", help="write the NVIDIA sections of docs/benchmarks/device.md from a results file")
    p.add_argument("results")
    p.add_argument("--markdown", default=os.path.join(ROOT, "docs", "benchmarks", "device.md"))
    p.add_argument("--baseline", help="a results file of the same sizes run here (llvmpipe), for speed-ups")
    p.add_argument("--allow-test", action="store_true", help="also write a --quick or non-NVIDIA run (tests)")
    args = ap.parse_args()
    run(args) if args.verb == "run" else report(args)


if __name__ == "__main__":
    main()
