#!/usr/bin/python3
"""docs/validation.md from the CSV files of tetrasand_validation_runs, with PNG plots (matplotlib).

Usage: bench/validation/report.py RUN_DIR DOCS_DIR
Each section states what the literature expects and whether tetrasand meets it, from the numbers of
this run (nothing is hard-coded but the literature's values and the tolerances).
"""
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
from sim_peers import repose_angle  # noqa: E402  (one definition of the heap's slope for both reports)

RADIUS = 1e-3  # m, grain sphere radius of every run
DENSITY = 2600.0  # kg/m^3
GRAIN_MASS = DENSITY * 4 * 4.0 / 3.0 * np.pi * RADIUS**3  # kg, four full spheres
D_EQ = 2 * RADIUS * 4 ** (1 / 3)  # m, volume-equivalent sphere diameter of a touching tetrahedral grain


def save(fig, docs, name):
    os.makedirs(os.path.join(docs, "validation"), exist_ok=True)
    path = os.path.join(docs, "validation", name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return f"![{name}](validation/{name})"


def restitution(run, docs):
    d = np.genfromtxt(os.path.join(run, "restitution.csv"), delimiter=",", names=True)
    v, et, eh = d["impact_speed_m_s"], d["e_tsuji"], d["e_thesis"]
    tsuji_spread = float(np.max(np.abs(et - 0.65)))
    # Kuwabara & Kono 1987 / Brilliantov 1996: 1 - e ~ v^(1/5) for viscoelastic Hertz (thesis damping).
    slope = np.polyfit(np.log(v), np.log(1 - eh), 1)[0]
    # Schwager & Poeschel 2008: 1 - e = A v^(1/5) - B v^(2/5) + ..., A, B > 0 (leading term: Kuwabara &
    # Kono 1987); the single power law only holds where 1 - e is small.
    basis = np.stack([v ** 0.2, -(v ** 0.4)], axis=1)
    (A, B), *_ = np.linalg.lstsq(basis, 1 - eh, rcond=None)
    residual = float(np.max(np.abs(basis @ np.array([A, B]) - (1 - eh))))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogx(v, et, "o-", label="Tsuji damping")
    ax.semilogx(v, eh, "s-", label="thesis damping (eq. 3.27)")
    ax.axhline(0.65, color="grey", ls=":", label="requested e = 0.65")
    ax.set_xlabel("impact speed (m/s)")
    ax.set_ylabel("coefficient of restitution")
    ax.legend()
    img = save(fig, docs, "restitution.png")
    ok_t, ok_h = tsuji_spread < 0.005, residual < 0.01 and A > 0 and B > 0
    return f"""## Restitution against impact speed

One solid sphere (r = 1 mm, E = 10 MPa, requested e = 0.65) hits a smooth wall head on, no gravity,
200 steps per contact (CPU reference, semi-implicit Euler).

{img}

- Expected: Tsuji damping gives a restitution independent of impact speed (Tsuji et al. 1992);
  the thesis's viscoelastic damping gives 1 - e growing as v^(1/5) at small damping (Kuwabara & Kono
  1987; Brilliantov et al. 1996), more precisely 1 - e = A v^(1/5) - B v^(2/5) + ... with A, B > 0
  (Schwager & Poeschel 2008), and e = 0.65 at its reference speed 1 m/s.
- Measured: Tsuji e within {tsuji_spread:.4f} of 0.65 from {v.min():g} to {v.max():g} m/s
  (**{'meets' if ok_t else 'does not meet'}** it, tolerance 0.005). Thesis damping: e = {eh[np.argmin(np.abs(v - 1))]:.4f}
  at 1 m/s; 1 - e = {A:.3f} v^(1/5) - {B:.3f} v^(2/5) fits every speed within {residual:.4f}
  (**{'meets' if ok_h else 'does not meet'}** it, tolerance 0.01); a single power law over the whole range
  gives v^{slope:.3f}, flatter than 1/5 because 1 - e is not small here.
"""


def repose(run, docs):
    d = np.genfromtxt(os.path.join(run, "repose.csv"), delimiter=",", names=True)
    mu = d["mu"]
    angle = np.array([repose_angle(np.loadtxt(os.path.join(run, f"heap_mu{m:g}.csv"), delimiter=",", skiprows=1))
                      for m in mu])
    rising = bool(np.all(np.diff(angle[:2]) > 0))
    monotonic = bool(np.all(np.diff(angle) > 0))
    saturates = bool(abs(angle[-1] - angle[-2]) < max(3.0, 0.5 * (angle[1] - angle[0])))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(mu, angle, "o-", label="tetrasand (CPU reference, 400 grains)")
    ax.set_xlabel("friction coefficient mu")
    ax.set_ylabel("angle of repose (deg)")
    ax.legend()
    img = save(fig, docs, "repose.png")
    table = "\n".join(f"| {m:g} | {a:.1f} |" for m, a in zip(mu, angle))
    return f"""## Angle of repose against friction

400 grains poured at 1000 grains/s from a 1.6 cm box 3-6 cm above a rough floor (fixed spheres of the
grains' size), no side walls, 0.8 s; angle = slope of the heap's flank (highest grain centre per 2 mm
ring, fitted from the edge of the flat top, above 80 % of the height, out to 20 % of the height).

{img}

| mu | angle (deg) |
|---|---|
{table}

- Expected: the angle rises with sliding friction and levels off above mu ~ 0.5 (Zhou et al. 2002,
  spheres; non-spherical grains stand steeper through interlocking); thesis ch. 7 reports 30-40 deg
  for its tetrahedral grains with thousands of grains.
- Measured: rising from mu = {mu[0]:g} to {mu[1]:g}: **{'yes' if rising else 'no'}**; levelling off
  at the top (last two within 3 deg): **{'yes' if saturates else 'no'}**; rising at every step:
  **{'yes' if monotonic else 'no'}**. A heap of 400 grains is only a few grains high, so
  each angle carries several degrees of noise (one run per point); a meaningful curve needs
  10^4-10^5 grains per heap, a GPU run.
"""


def silo(run, docs):
    d = np.genfromtxt(os.path.join(run, "silo.csv"), delimiter=",", names=True)
    rows = []
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for D in np.unique(d["orifice_m"]):
        s = d[d["orifice_m"] == D]
        t, n = s["time_s"], s["discharged"]
        total = n.max()
        rate = discharge_rate(t, n)  # grains/s
        if np.isnan(rate):
            continue
        rows.append((D, rate * GRAIN_MASS, total))
        ax1.plot(t, n, label=f"D = {D * 1e3:g} mm")
    ax1.set_xlabel("time (s)")
    ax1.set_ylabel("grains discharged")
    ax1.legend()
    D = np.array([r[0] for r in rows])
    W = np.array([r[1] for r in rows])
    grows = bool(np.all(np.diff(W) > 0))
    # Beverloo W = C rho_b sqrt(g) (D - k d)^(5/2): W^(2/5) is linear in D.
    a, b = np.polyfit(D, W ** 0.4, 1)
    k = -b / a / D_EQ
    rho_b = 0.6 * DENSITY
    C = a ** 2.5 / (rho_b * np.sqrt(9.81))
    # Free exponent with k fixed at Beverloo's 1.5 (fitting k and the exponent together on three orifices
    # would fit anything).
    n_exp = np.polyfit(np.log(D - 1.5 * D_EQ), np.log(W), 1)[0]
    Dfit = np.linspace(D.min() * 0.9, D.max() * 1.1, 50)
    ax2.plot(D * 1e3, W * 1e3, "o", label="tetrasand")
    ax2.plot(Dfit * 1e3, np.clip(a * Dfit + b, 0, None) ** 2.5 * 1e3, "-", label=f"Beverloo fit, k = {k:.2f}")
    ax2.set_xlabel("orifice diameter D (mm)")
    ax2.set_ylabel("discharge rate W (g/s)")
    ax2.legend()
    img = save(fig, docs, "silo.png")
    width = 0.040
    cond1 = width > 2.5 * D.max()
    cond2 = width > D.max() + 30 * D_EQ
    table = "\n".join(f"| {x * 1e3:g} | {w * 1e3:.2f} | {int(t)} |" for x, w, t in rows)
    return f"""## Silo discharge against orifice diameter (Beverloo)

A flat-bottomed silo: smooth cylinder of 40 mm diameter, rough plate with a round orifice, 600
grains (d = {D_EQ * 1e3:.2f} mm volume-equivalent) released as a column at t = 0, 0.6 s; rate fitted
from t = 0.15 s (after the column's first fall) while 10-60 % of the grains had left.

{img}

| D (mm) | W (g/s) | grains out |
|---|---|---|
{table}

- Expected: W = C rho_b sqrt(g) (D - k d)^(5/2) with C ~ 0.58 and k ~ 1.5 for spheres (Beverloo et al.
  1961); Mankoc et al. 2007 show the 5/2 law holds only when the silo is wider than 2.5 D and D + 30 d
  and filled above 1.2 widths.
- Measured: with the exponent fixed at 5/2, k = {k:.2f} and C = {C:.2f} (taking rho_b = 0.6 rho);
  with k fixed at 1.5, the free exponent is {n_exp:.2f} (5/2 expected:
  **{'meets' if abs(n_exp - 2.5) < 0.5 else 'does not meet'}** it within 0.5).
- Honestly: this silo does **not** meet Mankoc's conditions (width > 2.5 D: {'yes' if cond1 else 'no'};
  width > D + 30 d = {(D.max() + 30 * D_EQ) * 1e3:.0f} mm: {'yes' if cond2 else 'no'}; the 600 grains
  fill it about 2 widths at the start and drain below 1.2 widths while the rate is measured), and
  three orifices at 4-6 grain diameters cannot test an exponent: the silo empties within 0.3 s, so the
  rate is taken over a few tens of milliseconds right after the column's fall, and the fitted k, C and
  exponent above are no test of the law either way. Rate growing with D:
  **{'yes' if grows else 'no'}**. Testing 5/2 needs a silo of 10^5 grains (width 10 cm, D from 5 to 20 d,
  fill > 12 cm), a GPU run.
"""


def forces(run, docs):
    f = np.loadtxt(os.path.join(run, "contact_forces.csv"), skiprows=1)
    f = f[f > 0]
    fn = f / f.mean()
    bins = np.linspace(0, fn.max(), 30)
    hist, edges = np.histogram(fn, bins=bins, density=True)
    centres = 0.5 * (edges[1:] + edges[:-1])
    tail = (centres > 1) & (hist > 0)
    beta = -np.polyfit(centres[tail], np.log(hist[tail]), 1)[0]
    # exp(-c f^alpha): log(-log(P/P0)) is linear in log f; P0 from the fit of the exponential.
    def sse(alpha):
        x = centres[tail] ** alpha
        p = np.polyfit(x, np.log(hist[tail]), 1)
        return np.sum((np.polyval(p, x) - np.log(hist[tail])) ** 2), p
    alphas = np.linspace(0.5, 3.0, 51)
    errors = [sse(a)[0] for a in alphas]
    alpha = alphas[int(np.argmin(errors))]
    e_exp, p_exp = sse(1.0)
    e_gauss, p_gauss = sse(2.0)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(centres[hist > 0], hist[hist > 0], "o", label=f"tetrasand, {len(f)} contacts")
    x = np.linspace(1, fn.max(), 50)
    ax.semilogy(x, np.exp(np.polyval(p_exp, x)), "-", label=f"exponential tail, beta = {beta:.2f}")
    ax.semilogy(x, np.exp(np.polyval(p_gauss, x ** 2)), "--", label="Gaussian tail")
    ax.set_xlabel("f = F_n / <F_n>")
    ax.set_ylabel("P(f)")
    ax.legend()
    img = save(fig, docs, "contact_forces.png")
    exponential_better = e_exp < e_gauss
    return f"""## Normal contact forces in a resting pile (thesis 7.2)

The grain-grain and grain-floor particle contacts of the mu = 0.5 heap at rest, normal force
magnitudes over their mean.

{img}

- Expected: a plateau or peak near f = 1 and a tail for f > 1 that is exponential, P ~ exp(-beta f) with
  beta ~ 1.5 (Mueth, Jaeger & Nagel 1998), or falls faster, Gaussian-like exp(-c f^2) (van Eerd et al.
  2007, thesis table 7.2) once there are enough contacts.
- Measured: peak below f = 1: **{'yes' if centres[np.argmax(hist)] < 1 else 'no'}**; exponential tail with
  beta = {beta:.2f} ({'within' if 0.75 <= beta <= 2.25 else 'outside'} a factor 1.5 of 1.5); best tail
  exponent alpha = {alpha:.2f} in exp(-c f^alpha); squared log residuals: exponential {e_exp:.2f},
  Gaussian {e_gauss:.2f}, so the {'exponential' if exponential_better else 'Gaussian'} tail fits better
  here. With {len(f)} contacts the tail holds few forces above f = 3 (single counts per bin), too few to
  tell a Gaussian tail from an exponential one; the thesis's distributions came from 10^4-10^5 grains.
"""


def column(run, docs):
    d = np.genfromtxt(os.path.join(run, "column.csv"), delimiter=",", names=True)
    a, n = d["aspect"], d["normalised_runout"]
    order = np.argsort(a)
    a, n, grains = a[order], n[order], int(d["grains"][0])
    rising = bool(np.all(np.diff(n) > 0))
    slope = float(np.polyfit(np.log(a), np.log(n), 1)[0])
    low, high = a < 1.7, a >= 1.7
    slope_high = float(np.polyfit(np.log(a[high]), np.log(n[high]), 1)[0]) if high.sum() >= 2 else float("nan")
    x = np.linspace(min(a.min(), 0.3), max(a.max(), 6), 100)
    lube = np.where(x < 1.7, 1.24 * x, 1.6 * np.sqrt(x))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(a, n, "o-", label=f"tetrasand (CPU reference, {grains} grains, r = 5 mm)")
    ax.loglog(x, lube, "--", color="grey", label="Lube et al. 2004: 1.24 a, 1.6 a^(1/2) above a = 1.7")
    ax.set_xlabel("aspect ratio a = H0 / R0")
    ax.set_ylabel("normalised runout (R_inf - R0) / R0")
    ax.legend(fontsize=7)
    img = save(fig, docs, "column.png")
    table = "\n".join(f"| {r0 * 1e3:.0f} | {h0 * 1e3:.0f} | {ai:.2f} | {ro * 1e3:.0f} | {ni:.2f} | "
                      f"{(1.24 * ai if ai < 1.7 else 1.6 * np.sqrt(ai)):.2f} |"
                      for r0, h0, ai, ro, ni in zip(d["r0_m"][order], d["h0_m"][order], a, d["runout_m"][order], n))
    return f"""## Column collapse: runout against aspect ratio

An axisymmetric column (`assets/scenes/reference/column.toml`: {grains} coarse grains, r = 5 mm, E = 1 MPa,
mu = 0.5, symplectic Euler) settles for 1.2 s inside a smooth cylinder of radius R0 on a rough floor; the
cylinder is then removed and the column spreads for 1.2 s. H0 and R_inf are the 95th percentiles of the
grains' outer extent (height; horizontal distance from the axis) before and after; the cylinder's radius
sets the aspect ratio a = H0 / R0.

{img}

| R0 (mm) | H0 (mm) | a | R_inf (mm) | (R_inf - R0) / R0 | Lube et al. 2004 |
|---|---|---|---|---|---|
{table}

- Expected: (R_inf - R0) / R0 = 1.24 a below a = 1.7 and 1.6 a^(1/2) above (Lube et al. 2004,
  axisymmetric); Lajeunesse et al. 2004 find the same two regimes, linear then sub-linear, with the
  break at a of order 1-3.
- Measured: runout rising with a: **{'yes' if rising else 'no'}**; power law over all runs a^{slope:.2f};
  above a = 1.7: a^{slope_high:.2f} (1/2 expected: **{'close' if abs(slope_high - 0.5) <= 0.15 else 'not close'}**,
  within 0.15); largest gap to Lube's values {np.max(np.abs(n / np.where(a < 1.7, 1.24 * a, 1.6 * np.sqrt(a)) - 1)) * 100:.0f} %.
  This is indicative only: with {grains} grains a column is 4-9 grains across and H0 a handful of grain
  diameters, the exponent above 1.7 rests on {int(high.sum())} columns, and grain size sets the deposit's
  edge, so the exponents are **not tested** by this run. Testing them needs tens of thousands of grains
  per column (the GPU pipeline on an NVIDIA GPU; none was lent to this session, and llvmpipe ran a
  400-grain heap about 16 times slower than the CPU reference). The small version is the test
  `ColumnCollapse.RunoutGrowsWithAspectRatio`.
"""


def discharge_rate(t, n, grains=600):
    """Grains/s fitted after the column's first fall (0.15 s) while 10-60 % of the grains have left."""
    sel = (t >= 0.15) & (n >= 0.1 * grains) & (n <= 0.6 * grains)
    return float(np.polyfit(t[sel], n[sel], 1)[0]) if sel.sum() >= 3 else float("nan")


def agreement(run, docs):
    renderer = open(os.path.join(run, "agreement_renderer.txt")).read().strip()
    heap = {b: repose_angle(np.loadtxt(os.path.join(run, f"agreement_heap_{b}.csv"), delimiter=",", skiprows=1))
            for b in ("cpu", "gpu")}
    s = np.genfromtxt(os.path.join(run, "agreement_silo.csv"), delimiter=",", names=True, dtype=None,
                      encoding="utf-8")
    rate = {b: discharge_rate(s["time_s"][s["backend"] == b], s["discharged"][s["backend"] == b])
            for b in ("cpu", "gpu")}
    bed = np.genfromtxt(os.path.join(run, "agreement_bed.csv"), delimiter=",", names=True, dtype=None,
                        encoding="utf-8")
    mean = {b: bed["mean_height_m"][bed["backend"] == b] for b in ("cpu", "gpu")}
    seed_spread = float((mean["cpu"].max() - mean["cpu"].min()) / mean["cpu"].mean())
    bed_diff = float(mean["gpu"].mean() / mean["cpu"].mean() - 1)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for b, style in (("cpu", "-"), ("gpu", "--")):
        sel = s["backend"] == b
        ax1.plot(s["time_s"][sel], s["discharged"][sel], style,
                 label=f"{'CPU reference' if b == 'cpu' else 'GPU pipeline'}: {rate[b] * GRAIN_MASS * 1e3:.2f} g/s")
        ax2.plot(bed["seed"][bed["backend"] == b], mean[b] * 1e3, "o" if b == "cpu" else "^", ls=style,
                 label="CPU reference" if b == "cpu" else "GPU pipeline")
    ax1.set_xlabel("time (s)")
    ax1.set_ylabel("grains discharged (16 mm orifice)")
    ax1.legend()
    ax2.set_xlabel("fill seed")
    ax2.set_ylabel("settled bed: mean centre height (mm)")
    ax2.legend()
    img = save(fig, docs, "agreement.png")
    ok_heap = abs(heap["gpu"] - heap["cpu"]) <= 3
    ok_silo = abs(rate["gpu"] / rate["cpu"] - 1) <= 0.10
    ok_bed = abs(bed_diff) <= 0.02
    return f"""## GPU pipeline against the CPU reference (long runs, statistics)

The same scenes on the CPU reference (double) and the GPU pipeline (float; renderer {renderer}):
the trajectories part within a few hundred steps (float against double, chaotic contacts), so what must
agree is the statistics. Tolerances were set before the run: heap angle 3 deg (as against LAMMPS),
discharge rate 10 %, bed height 2 % (mean of four fill seeds). The test
`GpuCpuAgreement.SettledBedHeightAgreesWithinThePackingSpread` is the small version.

{img}

| quantity | CPU reference | GPU pipeline | difference | tolerance | within |
|---|---|---|---|---|---|
| angle of repose, 400-grain heap (reference/heap.toml, mu = 0.5) | {heap['cpu']:.1f} deg | {heap['gpu']:.1f} deg | {heap['gpu'] - heap['cpu']:+.1f} deg | 3 deg | {'yes' if ok_heap else 'NO'} |
| silo discharge rate, 600 grains, D = 16 mm (reference/silo.toml) | {rate['cpu'] * GRAIN_MASS * 1e3:.2f} g/s | {rate['gpu'] * GRAIN_MASS * 1e3:.2f} g/s | {(rate['gpu'] / rate['cpu'] - 1) * 100:+.1f} % | 10 % | {'yes' if ok_silo else 'NO'} |
| settled coarse bed (reference/coarse_bed.toml, 120 grains, seeds 1-4): mean centre height | {mean['cpu'].mean() * 1e3:.2f} mm | {mean['gpu'].mean() * 1e3:.2f} mm | {bed_diff * 100:+.2f} % | 2 % | {'yes' if ok_bed else 'NO'} |

- Expected: differences within the run-to-run scatter of each quantity. Seed-to-seed spread of the bed
  on the CPU reference here: {seed_spread * 100:.1f} % (max - min over the four seeds).
- Small systems: a 400-grain heap's angle scatters by a few degrees from pour to pour, and the silo
  rate is fitted over a few tens of milliseconds, so these tolerances are loose; tighter tests need the
  large runs of a real GPU.
"""


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    run, docs = sys.argv[1], sys.argv[2]
    parts = [restitution(run, docs), repose(run, docs), silo(run, docs), forces(run, docs)]
    if os.path.exists(os.path.join(run, "column.csv")):
        parts.append(column(run, docs))
    if os.path.exists(os.path.join(run, "agreement_bed.csv")):
        parts.append(agreement(run, docs))
    header = f"""# Physical validation

Produced by `scripts/bench.sh validation` ({time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPU cores, CPU
reference in double precision; the agreement section also ran the GPU pipeline on Mesa's llvmpipe, no
NVIDIA GPU was used). Each run is sized to finish in about a minute on two
shared cores, which is far below the grain counts the literature's laws are stated for; each section says
what the small run can and cannot show. Tetrahedral grains of four touching spheres, r = 1 mm, quartz
density; E = 1 MPa in the scene runs (a soft sand keeps the time step near 40 us).

The same contact law run by LAMMPS (through `tetrasand export lammps`) settles beds, rebounds grains and
builds heaps like tetrasand does: see the section "Simulation against LAMMPS" of docs/benchmarks.md,
also produced by `scripts/bench.sh`.

Column collapse is run at 400 grains per column only (section below): the exponents of Lube et al. 2004
and Lajeunesse et al. 2004 need tens of thousands of grains per column and a real GPU.
"""
    note = os.path.join(run, "NOTE.md")  # how this run was made, when it was not one plain command
    if os.path.exists(note):
        header += "\n" + open(note).read()
    text = header + "\n" + "\n".join(parts)
    path = os.path.join(docs, "validation.md")
    open(path + ".tmp", "w").write(text)
    os.replace(path + ".tmp", path)
    print(text)


if __name__ == "__main__":
    main()
