#!/usr/bin/python3
"""CTest checks of scripts/device-bench.sh on llvmpipe, at the --quick sizes (label device-bench):
  device_bench_test.py quick BUILD_DIR    the whole chain: every part recorded, each ok with rows
  device_bench_test.py report BUILD_DIR   `report` on quick's results, into a copy of docs/benchmarks/device.md
  device_bench_test.py caps BUILD_DIR     a part past its cap is stopped and recorded, the next still runs,
                                          a missing executable is that part's error, not the run's
Exit status 0 when every check holds; each failed check is printed."""
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "device-bench.sh")
DOCS = os.path.join(ROOT, "docs", "benchmarks", "device.md")
PARTS = ["selftest", "sdf", "sampler", "sim", "preview"]
failures = []


def check(ok, what):
    print(("ok:   " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def device_bench(*args):
    res = subprocess.run([SCRIPT, *args], capture_output=True, text=True)
    print(res.stdout + res.stderr)
    check(res.returncode == 0, f"device-bench.sh {' '.join(args)} exits 0 (got {res.returncode})")


def quick_dir(build):
    return os.path.join(build, "device-bench-quick")


def quick(build):
    out = quick_dir(build)
    shutil.rmtree(out, ignore_errors=True)
    device_bench("run", "--quick", "--build-dir", build, "--out", out)
    res = json.load(open(os.path.join(out, "device-bench.json")))
    m = res["machine"]
    check(res["kind"] == "quick", "the results say they are of the --quick sizes")
    check(bool(m["gl_renderer"]) and bool(m["gl_version"]), f"GL_RENDERER and GL_VERSION recorded: {m['gl_device']}")
    check(len(m["date"]) == 20 and m["cores"] == os.cpu_count(), f"date and cores recorded: {m['date']}")
    for part in PARTS:
        p = res["parts"].get(part, {})
        check(p.get("status") == "ok", f"{part}: status ok (got {p.get('status')}: {p.get('error')})")
        check(len(p.get("rows", [])) > 0, f"{part}: has rows")
        check(0 < p.get("seconds", 0) <= p.get("cap_s", 0), f"{part}: took {p.get('seconds')} s within its cap")
    selftest = res["parts"]["selftest"]["rows"]
    check(all(r["status"] == "ok" and r["tests"] > 0 and not r["failed"] for r in selftest),
          f"selftest: every test executable ran its GPU tests and passed ({selftest})")
    sdf = res["parts"]["sdf"]["rows"]
    check(len(sdf) == 4 and all(int(r["gpu_wrong_signs"]) == 0 for r in sdf), "sdf: 2 meshes x 2 grids, no wrong sign")
    check(all(int(r["compute_wrong_signs"]) == 0 and r["compute_band_voxels"] == r["band_voxels"] for r in sdf),
          "sdf: both scan paths timed, the compute path with no wrong sign and the geometry path's band")
    sim = res["parts"]["sim"]["rows"]
    check(sorted(r["precision"] for r in sim) == ["double", "float"], "sim: a float and a double row")
    kernels = res["parts"]["sim"].get("kernels", {})
    table = kernels.get("tables", {}).get("1000", [])
    check(kernels.get("status") == "ok" and any(t["kernel"] == "sim/contact_forces.comp" and t["calls"] > 0 for t in table)
          and abs(sum(t["share"] for t in table) - 100) < 1, f"sim: the per-kernel table of the 1000-grain float run ({kernels})")
    sampler = res["parts"]["sampler"]["rows"]
    # The GPU path on every device (SAMPLER_GPU_PATH), llvmpipe included.
    check(all(r["status"] == "ok" and r["relax_backend"] == "gpu" and "sampler/relax.comp" in r["timings"]
              and r["scan"] in ("compute", "geometry") for r in sampler),
          "sampler: every count ok on the GPU path (scan, relaxation kernels), with their timings")
    preview = res["parts"]["preview"]["rows"]
    check(sorted((r["path"], r["image"].split()[0]) for r in preview)
          == sorted((p, k) for p in ("raster", "compute") for k in ("SDF", "2000", "hybrid:")),
          "preview: SDF, impostor and hybrid rows by both GPU paths")
    md = open(os.path.join(out, "device-bench.md")).read()
    check(all(f"### {t} on an NVIDIA GPU" in md for t in ("GPU self-test", "SDF", "Sampling", "Simulation", "Preview")),
          "device-bench.md has the five sections")


def report(build):
    results = os.path.join(quick_dir(build), "device-bench.json")
    res = json.load(open(results))
    before = hashlib.sha256(open(DOCS, "rb").read()).hexdigest()
    tmp = tempfile.mkdtemp(prefix="device-bench-report.")
    copy = os.path.join(tmp, "device.md")
    shutil.copy(DOCS, copy)
    refused = subprocess.run([SCRIPT, "report", results, "--markdown", copy], capture_output=True, text=True)
    check(refused.returncode != 0 and "--allow-test" in refused.stderr and open(copy).read() == open(DOCS).read(),
          "a quick llvmpipe run is refused without --allow-test, the file left as it was")
    device_bench("report", results, "--markdown", copy, "--allow-test")
    doc, original = open(copy).read(), open(DOCS).read()
    check(hashlib.sha256(open(DOCS, "rb").read()).hexdigest() == before, "docs/benchmarks/device.md itself is untouched")
    for part in PARTS:
        start, end = f"<!-- section: nvidia-{part} -->\n", f"<!-- end: nvidia-{part} -->"
        body = doc[doc.index(start) + len(start):doc.index(end)]
        check(res["machine"]["gl_renderer"] in body and res["machine"]["date"][:10] in body,
              f"nvidia-{part}: names the GL renderer and the date")
        check("Not an NVIDIA GPU" in body, f"nvidia-{part}: an llvmpipe run is labelled as not NVIDIA")
    check("| knot1 | 6400 |" in doc and "| 1000 | double |" in doc, "the SDF and sim rows are in their sections")
    check("| sim/contact_forces.comp |" in doc, "the sim section has the per-kernel table")
    outside = lambda text: text.split("<!-- section: nvidia-selftest -->")[0]
    check(outside(doc) == outside(original), "the text before the NVIDIA sections is unchanged")
    device_bench("report", results, "--markdown", copy, "--allow-test", "--baseline", results)
    sampler = open(copy).read().split("<!-- section: nvidia-sampler -->")[1].split("<!-- end: nvidia-sampler -->")[0]
    check("| baseline s | speed-up |" in sampler and "| 1.0 |" in sampler,
          "--baseline adds the baseline's time and the speed-up (1.0 against itself)")
    shutil.rmtree(tmp)


# A stand-in test executable whose GoogleTest report has one failed test, as a GPU that computes wrong gives.
FAILING_TESTS = """#!/bin/sh
for a in "$@"; do case "$a" in --gtest_output=json:*) report=${a#--gtest_output=json:} ;; esac; done
cat > "$report" <<'JSON'
{"testsuites": [{"name": "SparseFieldTest", "testsuite": [
  {"name": "ReadsNeverDependOnPnanovdbsRootWalk", "failures": [{"failure": "voxel 1 2 3: 0.24 != -0.12"}]},
  {"name": "OffTheGridIsTheOutsideBackgroundAndTheGradientIsTheNormal"}]}]}
JSON
exit 1
"""


def caps(build):
    """selftest with a failing test executable: an error naming the test, the rest still run; sdf
    stopped at a 0.5 s cap, sampler still run, sim without its executable: an error record."""
    tmp = tempfile.mkdtemp(prefix="device-bench-caps.")
    fake = os.path.join(tmp, "bin")
    os.makedirs(fake)
    for exe in ("tetrasand", "tetrasand_bench_sdf"):
        os.symlink(os.path.join(build, "bin", exe), os.path.join(fake, exe))
    failing = os.path.join(fake, "tetrasand_sdf_tests")
    with open(failing, "w") as f:
        f.write(FAILING_TESTS)
    os.chmod(failing, 0o755)
    out = os.path.join(tmp, "out")
    res = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "device_bench.py"), "run", "--quick", "--bin",
                          fake, "--out", out, "--only", "selftest,sdf,sampler,sim", "--caps", "selftest=0.3,sdf=0.5"],
                         capture_output=True, text=True)
    print(res.stdout + res.stderr)
    parts = json.load(open(os.path.join(out, "device-bench.json")))["parts"]
    rows = {r["binary"]: r for r in parts["selftest"].get("rows", [])}
    check(parts["selftest"]["status"] == "error"
          and "SparseFieldTest.ReadsNeverDependOnPnanovdbsRootWalk" in parts["selftest"]["error"],
          f"selftest: an error naming the failed test ({parts['selftest'].get('error')})")
    check(rows.get("tetrasand_gpu_tests", {}).get("status") == "missing"
          and rows.get("tetrasand_sdf_tests", {}).get("failed") == ["SparseFieldTest.ReadsNeverDependOnPnanovdbsRootWalk"]
          and "0.24 != -0.12" in json.dumps(rows.get("tetrasand_sdf_tests", {}).get("messages")),
          "selftest: the missing executable recorded as missing, the failed test with its message")
    check(parts["sdf"]["status"] == "timeout" and parts["sdf"]["seconds"] < 5,
          f"sdf: recorded as timeout after {parts['sdf'].get('seconds')} s")
    check(parts["sampler"]["status"] == "ok", f"sampler: still ran after the timeout ({parts['sampler']['status']})")
    check(parts["sim"]["status"] == "error" and "tetrasand_bench_sim" in parts["sim"]["error"],
          f"sim: error naming the missing executable ({parts['sim']['error']})")
    check(parts["preview"]["status"] == "skipped", "preview: skipped (not in --only)")
    shutil.rmtree(tmp)


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("quick", "report", "caps"):
        sys.exit(__doc__)
    {"quick": quick, "report": report, "caps": caps}[sys.argv[1]](os.path.abspath(sys.argv[2]))
    sys.exit(1 if failures else 0)
