#!/usr/bin/env python3
"""VTK's own readers (Debian python3-vtk9) open what tetrasand writes for ParaView: a short prop drop with
[output] vtp, its particles.pvd listing every .vtp with its time, each .vtp read by vtkXMLPolyDataReader
with a vertex per particle and the point arrays of scene/vtk_files.h; and a body's NAME.particles.vtp
from `sample` (--fill, so surface and interior), its points those of the PLY.

  vtk_read_test.py TETRASAND_BINARY SOURCE_DIR      exit 0 when every check holds
"""
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import vtk  # python3-vtk9 (scripts/deps.sh)

ARRAYS = {"radius": 1, "body": 1, "motion": 1, "body_particles": 1, "velocity": 3, "angular_velocity": 3,
          "orientation": 4, "body_centre": 3}


def check(ok, what):
    if not ok:
        raise SystemExit(f"vtk_read_test: {what}")


def run_prop_drop(binary, source, work):
    text = open(os.path.join(source, "assets", "scenes", "prop_drop.toml")).read()
    check("[output]\n" in text, "prop_drop.toml has an [output] table")
    text = text.replace("[output]\n", "[output]\nvtp = true\n", 1)
    scene = os.path.join(work, "prop_drop_vtp.toml")
    open(scene, "w").write(text.replace('"../', f'"{source}/assets/').replace("'../", f"'{source}/assets/"))
    out = os.path.join(work, "out")
    res = subprocess.run([binary, "sim", scene, "-o", out, "--backend", "cpu", "--duration", "0.01"],
                         capture_output=True, text=True, cwd=os.path.join(source, "assets", "scenes"))
    check(res.returncode == 0, f"sim exits 0 (got {res.returncode}): {res.stderr[-800:]}")
    return out


def check_vtp(path, time):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    data = reader.GetOutput()
    n = data.GetNumberOfPoints()
    check(n > 0 and data.GetNumberOfVerts() == n, f"{path}: a vertex cell per point ({n} points)")
    points = data.GetPointData()
    for name, components in ARRAYS.items():
        a = points.GetArray(name)
        check(a is not None and a.GetNumberOfComponents() == components and a.GetNumberOfTuples() == n,
              f"{path}: point array {name} with {components} components")
    for i in range(n):
        q = points.GetArray("orientation").GetTuple4(i)
        check(abs(math.sqrt(sum(c * c for c in q)) - 1) < 1e-9, f"{path}: unit orientation at {i}")
    stored = data.GetFieldData().GetArray("TimeValue").GetValue(0)
    check(abs(stored - time) <= 1e-12 * max(1.0, abs(time)), f"{path}: TimeValue {stored} is the .pvd's {time}")
    speeds = [math.dist(points.GetArray("velocity").GetTuple3(i), (0, 0, 0)) for i in range(n)]
    sizes = {int(points.GetArray("body_particles").GetValue(i)) for i in range(n)}
    return max(speeds), sizes


def check_body_vtp(binary, source, work):
    res = subprocess.run([binary, "sample", os.path.join(source, "assets", "sphere.obj"), "-o", "body", "--count", "150",
                          "--probes", "20000", "--backend", "cpu", "--fill"], capture_output=True, text=True, cwd=work)
    check(res.returncode == 0, f"sample exits 0: {res.stderr[-600:]}")
    vtp = vtk.vtkXMLPolyDataReader()
    vtp.SetFileName(os.path.join(work, "body", "sphere.particles.vtp"))
    vtp.Update()
    ply = vtk.vtkPLYReader()
    ply.SetFileName(os.path.join(work, "body", "sphere.particles.ply"))
    ply.Update()
    body, points = vtp.GetOutput(), ply.GetOutput()
    n = body.GetNumberOfPoints()
    check(n == points.GetNumberOfPoints() and body.GetNumberOfVerts() == n, f"the body's .vtp: {n} vertex cells")
    check(all(body.GetPoint(i) == points.GetPoint(i) for i in range(n)), "the .vtp's points are the PLY's")
    surface = body.GetPointData().GetArray("surface")
    flags = {int(surface.GetValue(i)) for i in range(n)}
    check(flags == {0, 1}, f"surface and interior particles marked: {flags}")
    check(body.GetPointData().GetArray("normal").GetNumberOfComponents() == 3, "normals")


def main():
    binary, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    with tempfile.TemporaryDirectory() as work:
        out = run_prop_drop(binary, source, work)
        collection = ET.parse(os.path.join(out, "particles.pvd")).getroot()
        check(collection.get("type") == "Collection", "particles.pvd is a VTK collection")
        entries = [(float(d.get("timestep")), d.get("file")) for d in collection.iter("DataSet")]
        vtps = sorted(f for f in os.listdir(out) if f.endswith(".vtp"))
        check([f for _, f in entries] == vtps, f"the collection lists every .vtp in order ({len(vtps)} files)")
        check(all(a < b for (a, _), (b, _) in zip(entries, entries[1:])), "times increase")
        fastest, sizes = 0.0, set()
        for time, name in entries:
            speed, body_sizes = check_vtp(os.path.join(out, name), time)
            fastest, sizes = max(fastest, speed), sizes | body_sizes
        check(fastest > 0, "some particle moves")
        check(4 in sizes and any(s > 4 for s in sizes), f"grains (4 particles) and a prop (more): {sorted(sizes)}")
        check_body_vtp(binary, source, work)
    print(f"vtk_read_test: {len(entries)} outputs read by VTK {vtk.vtkVersion.GetVTKVersion()}")


if __name__ == "__main__":
    main()
