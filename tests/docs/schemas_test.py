#!/usr/bin/env python3
"""The published JSON Schemas (docs/schemas/) hold for what tetrasand writes: a body from `sample`, the
bundled bodies `sample` made, and the `--json` reports of `info`, `sdf`, `sample`, `sim`, `export lammps`,
`preview` and `frames`; a body with a key missing or a wrong unit fails its schema, and so does a report with a key
it does not define (so the check can fail). Debian's python3-jsonschema.

  schemas_test.py TETRASAND_BINARY SOURCE_DIR      exit 0 when every check holds
"""
import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile

import jsonschema


def check(ok, what):
    if not ok:
        raise SystemExit(f"schemas_test: {what}")


def validator(source, name):
    folder = os.path.join(source, "docs", "schemas")
    store = {}
    for f in os.listdir(folder):  # the schemas refer to each other by $id
        s = json.load(open(os.path.join(folder, f)))
        jsonschema.Draft202012Validator.check_schema(s)
        store[s["$id"]] = s
    schema = json.load(open(os.path.join(folder, name)))
    resolver = jsonschema.RefResolver(schema["$id"], schema, store=store)
    return jsonschema.Draft202012Validator(schema, resolver=resolver)


def expect_valid(v, document, what):
    errors = sorted(v.iter_errors(document), key=lambda e: list(e.path))
    check(not errors, f"{what}: " + "; ".join(f"{list(e.path)}: {e.message}" for e in errors[:5]))


def run_json(binary, args, cwd):
    res = subprocess.run([binary] + args, capture_output=True, text=True, cwd=cwd)
    check(res.returncode == 0, f"tetrasand {' '.join(args)} exits 0 (got {res.returncode}): {res.stderr[-600:]}")
    return json.loads(res.stdout)


def check_bodies(binary, source, work):
    v = validator(source, "body.schema.json")
    report = run_json(binary, ["sample", os.path.join(source, "assets", "sphere.obj"), "-o", "body", "--count", "150",
                               "--probes", "20000", "--backend", "cpu", "--preview", "--json"], work)
    check("preview" in report["run"]["seconds"], "sample --preview --json times the preview (run.seconds.preview)")
    sample = validator(source, "sample-report.schema.json")
    expect_valid(sample, report, "sample --json")
    check(not sample.is_valid(dict(report, surprise=1)), "a sample report with an unknown key fails its schema")
    body = json.load(open(os.path.join(work, "body", "sphere.body.json")))
    expect_valid(v, body, "sample's sphere.body.json")
    for name in ("cube", "plate"):  # made by sample; piston.body.json is a hand-written prop
        expect_valid(v, json.load(open(os.path.join(source, "assets", "bodies", f"{name}.body.json"))), name)
    for broken, what in ((lambda b: b.pop("mass"), "without its mass"),
                         (lambda b: b["units"].update(length="mm"), "in millimetres"),
                         (lambda b: b["quality"].pop("coverage_certified"), "format 3 without its certificate")):
        damaged = copy.deepcopy(body)
        broken(damaged)
        check(not v.is_valid(damaged), f"a body {what} fails the schema")


def check_reports(binary, source, work):
    scenes = os.path.join(source, "assets", "scenes")
    info = run_json(binary, ["info", os.path.join(source, "assets", "bunny.obj"), "--json"], work)
    expect_valid(validator(source, "info-report.schema.json"), info, "info --json")
    sdf = run_json(binary, ["sdf", os.path.join(source, "assets", "cube.obj"), "-o", "cube.nvdb", "--resolution", "16",
                            "--backend", "cpu", "--json"], work)
    expect_valid(validator(source, "sdf-report.schema.json"), sdf, "sdf --json (CPU)")
    sdf = run_json(binary, ["sdf", os.path.join(source, "assets", "cube.obj"), "-o", "cube.vdb", "--resolution", "16",
                            "--backend", "gpu", "--json"], work)
    expect_valid(validator(source, "sdf-report.schema.json"), sdf, "sdf --json (GPU)")
    sim = run_json(binary, ["sim", os.path.join(scenes, "two_grain_collision.toml"), "-o", "sim", "--duration",
                            "0.0002", "--backend", "cpu", "--json"], work)
    expect_valid(validator(source, "sim-report.schema.json"), sim, "sim --json")
    deck = run_json(binary, ["export", "lammps", os.path.join(scenes, "prop_drop.toml"), "-o", "deck", "--json"], work)
    expect_valid(validator(source, "export-report.schema.json"), deck, "export lammps --json")
    frames = os.path.join(work, "frames")
    os.makedirs(frames)
    check_preview_reports(binary, source, work, os.path.join(frames, "frame_000000.png"))
    shutil.copy(os.path.join(frames, "frame_000000.png"), os.path.join(frames, "frame_000001.png"))
    sheet = run_json(binary, ["frames", frames, "-o", os.path.join(work, "sheet.png"), "--json"], work)
    expect_valid(validator(source, "frames-report.schema.json"), sheet, "frames --json")


def check_preview_reports(binary, source, work, png):
    """preview --json on the CPU (a mesh) and on the GL device (a mesh, the sample's body, a turntable)."""
    v = validator(source, "preview-report.schema.json")
    cpu = run_json(binary, ["preview", os.path.join(source, "assets", "cube.obj"), "-o", png, "--size", "48x32",
                            "--resolution", "16", "--backend", "cpu", "--json"], work)
    expect_valid(v, cpu, "preview --json (CPU)")
    check(cpu["outputs"] == [png] and os.path.isfile(png), f"preview --json names the PNG it wrote: {cpu['outputs']}")
    check(cpu["backend"]["chosen"] == "cpu" and cpu["passes"], "preview --json (CPU) reports its passes")
    check(not v.is_valid(dict(cpu, surprise=1)), "a preview report with an unknown key fails its schema")
    gpu = run_json(binary, ["preview", os.path.join(source, "assets", "sphere.obj"), "--particles",
                            os.path.join(work, "body", "sphere.body.json"), "-o", "turn.png", "--size", "32x32",
                            "--resolution", "16", "--turntable", "2", "--color-by", "particle-distance",
                            "--backend", "gpu", "--json"], work)
    expect_valid(v, gpu, "preview --json (GPU)")
    check(gpu["outputs"] == ["turn_000.png", "turn_001.png"] and all(
        os.path.isfile(os.path.join(work, f)) for f in gpu["outputs"]), f"the turntable's PNGs: {gpu['outputs']}")
    check(gpu["backend"]["chosen"] == "gpu" and gpu["passes"] and gpu["drawn"]["particles"]["count"] > 0,
          "preview --json (GPU) reports its passes and the body's particles")


def main():
    binary, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    with tempfile.TemporaryDirectory() as work:
        check_bodies(binary, source, work)
        check_reports(binary, source, work)
    print("schemas_test: body.json and the info, sdf, sample, sim, export, preview and frames reports meet docs/schemas/")


if __name__ == "__main__":
    main()
