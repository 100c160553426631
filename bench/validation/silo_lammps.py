#!/usr/bin/python3
"""The Beverloo silo's discharges run by LAMMPS from tetrasand's settled fill
(bench/validation/silo_lammps_criteria.md, issue 18).

Usage: bench/validation/silo_lammps.py BIN_DIR OUT [spheres|tetrahedra] [--orifices N]

1. BIN_DIR/tetrasand_validation_runs OUT silo[-spheres]-lammps settles the fill (CPU reference, as the
   `silo` and `silo-spheres` runs do), opens each orifice and writes the state as a LAMMPS deck per
   orifice (OUT/lammps_D8d, _D5d, _D7d, _D6d). Skipped when OUT already holds the decks.
2. Debian's `lmp` (serial) runs each deck, widest orifice first; `--orifices N` stops after N. A deck
   whose log.lammps is complete is not run again, so a stopped run resumes.
3. The discharged mass (dynamic mass below z = -0.05 m, every 2 ms) is fitted as report.py fits
   tetrasand's: W is the slope from 0.1 s on, and k the empty annulus of W^(2/5) linear in D.
   Tetrasand's rates on the same fill come from the committed sphere run
   (bench/validation/silo_spheres_2026-12-04/silo.csv) or from docs/validation.md's silo table.

Writes OUT/silo_lammps.csv (orifice_m,time_s,discharged_kg) and OUT/silo_lammps_summary.md, and prints
the summary. Needs numpy (/usr/bin/python3 on Debian).
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
COARSE_RADIUS = 5e-3  # m, the silo's grain sphere radius (assets/scenes/reference/silo_mankoc.toml)
D_EQ = 2 * COARSE_RADIUS * 4 ** (1 / 3)  # m, volume-equivalent diameter (and the spheres' diameter)
GRAIN_MASS = 2600.0 * 4 * 4.0 / 3.0 * np.pi * COARSE_RADIUS**3  # kg, a grain or its sphere
PUBLISHED_FILL = {"spheres": 0.7085}  # m, settled height of the published sphere run (silo_fill.csv)


def rate(t, m):
    """kg/s: the slope of the discharged mass from 0.1 s on (report.py's fit)."""
    t, m = np.asarray(t), np.asarray(m) - m[0]
    sel = t >= 0.1
    return float(np.polyfit(t[sel], m[sel], 1)[0]) if sel.sum() >= 3 else float("nan")


def beverloo_k(D, W):
    """k (in d) and the standard error of k from W^(2/5) linear in D (exponent 5/2)."""
    D, y = np.asarray(D), np.asarray(W) ** 0.4
    if len(D) < 2:
        return float("nan"), float("nan")
    A = np.vstack([D, np.ones_like(D)]).T
    coef, res, _, _ = np.linalg.lstsq(A, y, rcond=None)
    a, b = coef
    k = -b / a / D_EQ
    if len(D) < 3:
        return float(k), float("nan")
    s2 = float(res[0]) / (len(D) - 2) if len(res) else 0.0
    cov = s2 * np.linalg.inv(A.T @ A)
    grad = np.array([b / a**2, -1 / a]) / D_EQ
    return float(k), float(np.sqrt(grad @ cov @ grad))


def tetrasand_series(shape):
    """{D (m): (t s, discharged kg)} of tetrasand's published run, where its raw file was kept (spheres)."""
    if shape != "spheres":
        return {}
    rows = list(csv.DictReader(open(os.path.join(HERE, "silo_spheres_2026-12-04", "silo.csv"))))
    out = {}
    for D in sorted({float(r["orifice_m"]) for r in rows}):
        sel = [r for r in rows if float(r["orifice_m"]) == D]
        out[D] = (np.array([float(r["time_s"]) for r in sel]), np.array([float(r["discharged"]) for r in sel]) * GRAIN_MASS)
    return out


def tetrasand_rates(shape):
    """{D (m): W (kg/s)} of tetrasand's published run on the same fill."""
    if shape == "spheres":
        return {D: rate(t, m) for D, (t, m) in tetrasand_series(shape).items()}
    text = open(os.path.join(ROOT, "docs", "validation.md")).read()
    section = text[text.index("## Silo discharge against orifice diameter"):text.index("<!-- section: silo-spheres -->")]
    return {float(mm) * 1e-3: float(w) * 1e-3
            for mm, w in re.findall(r"^\| ([\d.]+) \| [\d.]+ \| (\d+) \| \d+ \|$", section, re.M)}


def thermo(log):
    """(time s, discharged kg) rows of a LAMMPS log whose thermo_style is step time atoms v_discharged."""
    t, m, reading = [], [], False
    for line in open(log):
        words = line.split()
        if words[:4] == ["Step", "Time", "Atoms", "v_discharged"]:
            reading = True
            continue
        if reading and words and words[0] == "Loop":
            reading = False
            continue
        if reading and len(words) == 4:
            try:
                t.append(float(words[1]))
                m.append(float(words[3]))
            except ValueError:
                pass
    return np.array(t), np.array(m)


def plot(shape, out, lammps, reference, k, k_ref):
    """OUT/silo_lammps_SHAPE.png: discharged mass against time, and W against D with both fits."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ours = tetrasand_series(shape)
    for i, D in enumerate(sorted(lammps)):
        t, m = lammps[D]
        colour = f"C{i}"
        ax1.plot(t, m - m[0], "--", color=colour, label=f"LAMMPS, D = {D / D_EQ:.0f} d")
        near = [x for x in ours if abs(x - D) < 1e-4]
        if near:
            tt, mm = ours[near[0]]
            ax1.plot(tt, mm - mm[0], "-", color=colour, label=f"tetrasand, D = {D / D_EQ:.0f} d")
    ax1.axvline(0.1, color="grey", ls=":")
    ax1.set_xlabel("time after opening (s)")
    ax1.set_ylabel("discharged mass (kg)")
    ax1.legend(fontsize=7)
    for label, rates, kk, style in (("LAMMPS", {D: rate(*lammps[D]) for D in lammps}, k, "s"),
                                     ("tetrasand", reference, k_ref, "o")):
        D = np.array(sorted(rates))
        W = np.array([rates[x] for x in D])
        a, b = np.polyfit(D, W ** 0.4, 1)
        Dfit = np.linspace(D.min() * 0.9, D.max() * 1.1, 50)
        line = ax2.plot(D * 1e3, W * 1e3, style, label=f"{label}, k = {kk:.2f}")[0]
        ax2.plot(Dfit * 1e3, np.clip(a * Dfit + b, 0, None) ** 2.5 * 1e3, "-", color=line.get_color(), lw=0.8)
    ax2.set_xlabel("orifice diameter D (mm)")
    ax2.set_ylabel("discharge rate W (g/s)")
    ax2.set_title(f"{shape}: the same settled fill, Beverloo fits at 5/2", fontsize=9)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"silo_lammps_{shape}.png"), dpi=110)
    plt.close(fig)


def complete(log):
    return os.path.exists(log) and "Total wall time" in open(log).read()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bin_dir")
    ap.add_argument("out")
    ap.add_argument("shape", nargs="?", default="spheres", choices=["spheres", "tetrahedra"])
    ap.add_argument("--orifices", type=int, default=4, help="run at most this many decks (widest first)")
    args = ap.parse_args()
    out = os.path.abspath(args.out)
    decks_csv = os.path.join(out, "silo_lammps_decks.csv")
    mode = "silo-spheres-lammps" if args.shape == "spheres" else "silo-lammps"
    if not (os.path.exists(decks_csv) and len(list(csv.DictReader(open(decks_csv)))) == 4):
        os.makedirs(out, exist_ok=True)
        subprocess.run([os.path.join(args.bin_dir, "tetrasand_validation_runs"), out, mode], check=True)
    decks = list(csv.DictReader(open(decks_csv)))
    fill = float(next(csv.DictReader(open(os.path.join(out, "silo_fill.csv"))))["fill_m"])
    lines = []
    if args.shape in PUBLISHED_FILL:
        same = abs(fill - PUBLISHED_FILL[args.shape]) < 1e-3
        lines.append(f"- Settled fill {fill * 1e3:.1f} mm against the published {PUBLISHED_FILL[args.shape] * 1e3:.1f} mm: "
                     f"**{'the same fill' if same else 'NOT the same fill: the run is void'}**.")
    measured = {}
    series = []
    for row in decks[: args.orifices]:
        deck = os.path.join(out, row["deck"])
        log = os.path.join(deck, "log.lammps")
        if not complete(log):
            start = time.time()
            print(f"LAMMPS: {row['deck']} ({row['grains']} grains, {row['steps']} steps) ...", file=sys.stderr, flush=True)
            subprocess.run(["lmp", "-in", "in.tetrasand", "-log", "log.lammps", "-screen", "none"], cwd=deck, check=True)
            print(f"LAMMPS: {row['deck']} done in {time.time() - start:.0f} s", file=sys.stderr, flush=True)
        wall = re.search(r"Total wall time: (\S+)", open(log).read()).group(1)
        t, m = thermo(log)
        D = float(row["orifice_m"])
        measured[D] = (rate(t, m), float(m[-1] - m[0]), wall)
        series += [(D, ti, mi) for ti, mi in zip(t, m)]
    with open(os.path.join(out, "silo_lammps.csv"), "w") as f:
        f.write("orifice_m,time_s,discharged_kg\n")
        f.writelines(f"{D:.5f},{t:.5f},{m:.6g}\n" for D, t, m in series)

    reference = tetrasand_rates(args.shape)
    table = ["| D (mm) | D / d | W LAMMPS (g/s) | W tetrasand (g/s) | LAMMPS / tetrasand | LAMMPS wall time |",
             "|---|---|---|---|---|---|"]
    ratios = []
    for D in sorted(measured):
        W, _, wall = measured[D]
        ref = min(reference.items(), key=lambda kv: abs(kv[0] - D))[1]
        ratios.append(W / ref)
        table.append(f"| {D * 1e3:.1f} | {D / D_EQ:.2f} | {W * 1e3:.0f} | {ref * 1e3:.0f} | {W / ref:.3f} | {wall} |")
    Ds = sorted(measured)
    k, sk = beverloo_k(Ds, [measured[D][0] for D in Ds])
    Dr = sorted(reference)
    k_ref, sk_ref = beverloo_k(Dr, [reference[D] for D in Dr])
    lines += [f"- Rates: LAMMPS / tetrasand from {min(ratios):.3f} to {max(ratios):.3f} over {len(ratios)} orifices.",
              f"- k at exponent 5/2 (in d = {D_EQ * 1e3:.1f} mm): LAMMPS {k:.2f} (standard error {sk:.2f}, "
              f"{len(Ds)} orifices), tetrasand {k_ref:.2f} (standard error {sk_ref:.2f})."]
    plot(args.shape, out, {D: (np.array([x[1] for x in series if x[0] == D]), np.array([x[2] for x in series if x[0] == D]))
                           for D in measured}, reference, k, k_ref)
    summary = f"# The {args.shape} silo's discharges in LAMMPS\n\n" + "\n".join(table) + "\n\n" + "\n".join(lines) + "\n"
    with open(os.path.join(out, "silo_lammps_summary.md"), "w") as f:
        f.write(summary)
    print(summary)


if __name__ == "__main__":
    main()
