#!/usr/bin/python3
"""Kills `tetrasand sample -o DIR` itself (SIGKILL) over an existing body at random moments, then
checks that DIR holds the old pair or the new pair, whole (issue 20: "a body is replaced only as a
whole, also under SIGKILL"). The test suite kills `body::write_body` in a forked child 200 times
(tests/body/); this runs the real command, which a test cannot afford 200 times on llvmpipe.

Each trial: DIR holds the old body (one `sample` run); a second `sample` with another particle count
replaces it and is killed after a delay; then `tetrasand preview --particles DIR/NAME.body.json` (16x16 pixels) reads the
body through `body::read_body`, as `sim` and `export` do (finishing an interrupted replacement first), and the files must be
the old pair byte for byte, or the new pair: its PLY byte for byte and its JSON equal to a reference
run's but for the wall-time figures. Nothing else may be left in DIR (no temporary file, no journal).
A third of the kills come after a delay uniform over the whole run; two thirds aim at the write
itself: the first hidden temporary file of the new body is awaited (polled every 0.2 ms), then the
kill follows after a delay uniform in [0, --write-window] (as the suite's test spreads its kills over
write_body's window).

Usage: /usr/bin/python3 bench/kill_sample.py TETRASAND [--trials N] [--mesh M] [--csv F]
Exit 1 when any trial finds anything else."""
import argparse
import csv
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

TIMING_KEYS = {"seconds"}


def sample(exe, mesh, out, count):
    cmd = [exe, "-q", "sample", mesh, "-o", out, "--count", str(count)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({res.returncode}): {res.stdout}{res.stderr}")


def pair(out, stem):
    with open(os.path.join(out, stem + ".body.json"), "rb") as f:
        j = f.read()
    with open(os.path.join(out, stem + ".particles.ply"), "rb") as f:
        p = f.read()
    return j, p


def without_timings(json_bytes):
    def strip(v):
        if isinstance(v, dict):
            return {k: strip(x) for k, x in v.items() if k not in TIMING_KEYS}
        if isinstance(v, list):
            return [strip(x) for x in v]
        return v
    return strip(json.loads(json_bytes))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("exe")
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--mesh", default=os.path.join(os.path.dirname(__file__), "..", "assets", "trefoil.obj"))
    ap.add_argument("--old-count", type=int, default=500)
    ap.add_argument("--new-count", type=int, default=1500)
    ap.add_argument("--seed", type=int, default=20261203)
    ap.add_argument("--write-window", type=float, default=0.02, help="s after the first temporary file")
    ap.add_argument("--csv")
    args = ap.parse_args()
    stem = os.path.splitext(os.path.basename(args.mesh))[0]
    work = tempfile.mkdtemp(prefix="ts-kill-sample-")
    ref_old, ref_new = os.path.join(work, "old"), os.path.join(work, "new")
    sample(args.exe, args.mesh, ref_old, args.old_count)
    t0 = time.perf_counter()
    sample(args.exe, args.mesh, ref_new, args.new_count)
    duration = time.perf_counter() - t0
    old = pair(ref_old, stem)
    new = pair(ref_new, stem)
    # Determinism check: a second reference run must give the same PLY, or "new pair" cannot be told.
    again = os.path.join(work, "again")
    sample(args.exe, args.mesh, again, args.new_count)
    if pair(again, stem)[1] != new[1] or without_timings(pair(again, stem)[0]) != without_timings(new[0]):
        sys.exit("kill_sample: two uninterrupted runs of the new body differ; the check needs a deterministic sampler")
    rng = random.Random(args.seed)
    counts = {"old": 0, "new": 0, "bad": 0}
    rows = []
    target = os.path.join(work, "trial")
    for i in range(args.trials):
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(ref_old, target)
        mode = "run" if i % 3 == 0 else "write"
        delay = rng.uniform(0, 1.1 * duration) if mode == "run" else rng.uniform(0, args.write_window)
        proc = subprocess.Popen([args.exe, "-q", "sample", args.mesh, "-o", target, "--count", str(args.new_count)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if mode == "write":
            while proc.poll() is None and not any(f.startswith(".") for f in os.listdir(target)):
                time.sleep(0.0002)
        try:
            proc.wait(timeout=delay)
            killed = False
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGKILL)
            proc.wait()
            killed = True
        left_before = sorted(f for f in os.listdir(target) if f.startswith("."))
        res = subprocess.run([args.exe, "-q", "preview", "--particles", os.path.join(target, stem + ".body.json"),
                              "-o", os.path.join(work, "read.png"), "--size", "16x16"], capture_output=True, text=True)
        files = sorted(os.listdir(target))
        expected = sorted(f for f in os.listdir(ref_old))
        state = "bad"
        why = ""
        if res.returncode != 0:
            why = f"preview exit {res.returncode}: {res.stderr.strip()[:200]}"
        elif files != expected:
            why = f"files {files}, expected {expected}"
        else:
            j, p = pair(target, stem)
            if (j, p) == old:
                state = "old"
            elif p == new[1] and without_timings(j) == without_timings(new[0]):
                state = "new"
            else:
                why = "a pair that is neither the old one nor the new one"
        counts[state] += 1
        rows.append(dict(trial=i, mode=mode, delay_s=f"{delay:.4f}", killed=killed, state=state,
                         hidden_files_before_read=len(left_before), why=why))
        if state == "bad":
            print(f"kill_sample: trial {i}: {why}", flush=True)
        if (i + 1) % 20 == 0:
            print(f"kill_sample: {i + 1}/{args.trials}: {counts}", flush=True)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    interrupted = sum(1 for r in rows if r["hidden_files_before_read"])
    for mode in ("run", "write"):
        mine = [r for r in rows if r["mode"] == mode]
        print(f"kill_sample: kills {mode}: {len(mine)} trials, killed {sum(r['killed'] for r in mine)}, old pair "
              f"{sum(r['state'] == 'old' for r in mine)}, new pair {sum(r['state'] == 'new' for r in mine)}, neither "
              f"{sum(r['state'] == 'bad' for r in mine)}, temporary files or a journal left "
              f"{sum(1 for r in mine if r['hidden_files_before_read'])}")
    print(f"kill_sample: {args.trials} trials, uninterrupted run {duration:.2f} s: old pair {counts['old']}, new pair "
          f"{counts['new']}, neither {counts['bad']}; {interrupted} trials left temporary files or a journal that the "
          f"next read finished or removed")
    shutil.rmtree(work, ignore_errors=True)
    return 1 if counts["bad"] else 0


if __name__ == "__main__":
    sys.exit(main())
