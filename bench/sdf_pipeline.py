#!/usr/bin/python3
"""The geometry-shader scan conversion's pipeline statistics against the prism model (issue 43), as the
markdown table of docs/benchmarks/sdf.md, section "Geometry path: pipeline statistics against the prism
model". Runs `tetrasand sdf MESH --backend gpu --scan geometry --timings --json` per case (the counts come
from GL_ARB_pipeline_statistics_query; sdf/prism_model.h is the model) and prints one row each:
  /usr/bin/python3 bench/sdf_pipeline.py --exe build/bin/tetrasand knot1@64,128 armadillo@128 ...
MESH is a file, or a CGAL demo mesh's name (libcgal-demo's data tarball, as the sampler benches take it)."""
import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sample_bench import resolve_mesh  # noqa: E402


def run_case(exe, mesh, resolution, work):
    out = os.path.join(work, "field.vdb")
    cmd = [exe, "-q", "sdf", mesh, "-o", out, "--backend", "gpu", "--scan", "geometry", "--resolution",
           str(resolution), "--timings", "--json"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({res.returncode}): {res.stdout}{res.stderr}")
    figures, _ = json.JSONDecoder().raw_decode(res.stdout, res.stdout.index("{"))
    if not figures.get("pipeline"):
        raise SystemExit(f"{' '.join(cmd)}: no pipeline statistics (the device has no such queries?)")
    return figures


def row(name, resolution, f):
    p, band = f["pipeline"], f["band_voxels"]
    return (f"| {name} | {f['triangles']} | {resolution} | {band} | {p['geometry_invocations']} "
            f"| {p['model_invocations']} | {p['drawn_prisms']} | {p['geometry_primitives']} "
            f"| {p['geometry_primitives'] / max(p['model_primitives'], 1):.4f} | {p['fragments']} "
            f"| {p['fragments'] / max(p['model_prism_volume_voxels'], 1e-9):.3f} "
            f"| {p['model_prism_volume_voxels'] / max(band, 1):.1f} | {p['fragments'] / max(band, 1):.2f} "
            f"| {p['geometry_primitives'] / max(f['triangles'], 1):.1f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="+", help="MESH@R1,R2,...")
    ap.add_argument("--exe", default="build-release/bin/tetrasand")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="sdf-pipeline.")
    print("| mesh | triangles | resolution | band voxels | GS invocations | instances asked | prisms drawn "
          "| primitives emitted "
          "| / model | fragments | / prism volume | prism voxels / band voxel | fragments / band voxel "
          "| primitives / triangle |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in a.cases:
        mesh, _, resolutions = case.rpartition("@")
        path = resolve_mesh(mesh, work)
        for r in map(int, resolutions.split(",")):
            print(row(os.path.splitext(os.path.basename(mesh))[0], r, run_case(a.exe, path, r, work)), flush=True)


if __name__ == "__main__":
    main()
