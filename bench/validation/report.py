#!/usr/bin/python3
"""docs/validation.md from the CSV files of tetrasand_validation_runs, with PNG plots (matplotlib).

Usage: bench/validation/report.py RUN_DIR DOCS_DIR [--only column]
(--only column: only the column-collapse section, from RUN_DIR/column.csv, which may hold the columns of
more than one run with a `source` column; see bench/validation/column_criteria.md)
Each section states what the literature expects and whether tetrasand meets it, from the numbers of
this run (nothing is hard-coded but the literature's values and the tolerances).
"""
import os
import re
import sys
import time
from collections import namedtuple

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
from sim_peers import repose_angle  # noqa: E402  (one definition of the heap's slope for both reports)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from docs_section import replace_between  # noqa: E402

RADIUS = 1e-3  # m, grain sphere radius of the restitution run and the agreement runs
DENSITY = 2600.0  # kg/m^3
GRAIN_MASS = DENSITY * 4 * 4.0 / 3.0 * np.pi * RADIUS**3  # kg, four full spheres
D_EQ = 2 * RADIUS * 4 ** (1 / 3)  # m, volume-equivalent sphere diameter of a touching tetrahedral grain
COARSE_RADIUS = 5e-3  # m, grain sphere radius of the repose, silo and column-collapse runs
COARSE_D_EQ = 2 * COARSE_RADIUS * 4 ** (1 / 3)  # m
COARSE_GRAIN_MASS = DENSITY * 4 * 4.0 / 3.0 * np.pi * COARSE_RADIUS**3  # kg
# m: centre to sphere centre (edge 2r times sqrt(3/8)) plus r, as sim/grain.cpp
BOUNDING_RADIUS = 2 * COARSE_RADIUS * np.sqrt(3 / 8) + COARSE_RADIUS


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
    grains = int(d["grains"][0])
    angle = np.array([repose_angle(np.loadtxt(os.path.join(run, f"heap_mu{m:g}.csv"), delimiter=",", skiprows=1),
                                   ring_width=2 * COARSE_RADIUS) for m in mu])
    rising = bool(np.all(np.diff(angle[:2]) > 0))
    monotonic = bool(np.all(np.diff(angle) > 0))
    saturates = bool(abs(angle[-1] - angle[-2]) < max(3.0, 0.5 * (angle[1] - angle[0])))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(mu, angle, "o-", label=f"tetrasand (CPU reference, {grains} grains, r = 5 mm)")
    ax.set_xlabel("friction coefficient mu")
    ax.set_ylabel("angle of repose (deg)")
    ax.legend()
    img = save(fig, docs, "repose.png")
    table = "\n".join(f"| {m:g} | {a:.1f} |" for m, a in zip(mu, angle))
    heap_height = float(np.loadtxt(os.path.join(run, f"heap_mu{mu[-1]:g}.csv"), delimiter=",", skiprows=1)[:, 2].max())
    return f"""## Angle of repose against friction

{grains} coarse grains (r = 5 mm, E = 1 MPa, e = 0.5, viscous Coulomb-capped friction, symplectic Euler;
`assets/scenes/reference/coarse_pile.toml` scaled up from its 300 grains) poured at 1,000 grains/s from
a 16 cm x 16 cm box 5-30 cm above a rough floor (fixed spheres of the grains' size), no side walls,
4 s (3 s of pouring, 1 s at rest); angle = slope of the heap's flank (highest grain centre per 10 mm
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
  **{'yes' if monotonic else 'no'}**. Each heap is {heap_height * 1e3:.0f} mm high at mu = {mu[-1]:g}, about
  {heap_height / COARSE_D_EQ:.0f} grain diameters; one pour per point, so each angle still carries a degree or
  two of pour-to-pour scatter. The viscous tangential model lets a heap creep (issue 6 measured it);
  with `tangential = "spring"` heaps stand at rest instead.
"""


def round_rim_sites(D, plate_radius=COARSE_RADIUS):
    """(x, y) of the rim spheres scene/scene_world.cpp round_hole_rim puts around a hole of diameter D."""
    circle = D / 2 + plate_radius
    count = max(3, int(np.ceil(2 * np.pi * circle / plate_radius)))
    angle = 2 * np.pi * np.arange(count) / count
    return circle * np.cos(angle), circle * np.sin(angle)


def orifice_open_diameter(D, rim, plate_radius=COARSE_RADIUS, cell=2e-4):
    """Diameter (m) of the disc whose area is the hole's, for the hole validation_runs.cpp cuts into the
    rough plate (touching spheres on a square lattice, centres within D/2 + r of the axis removed; with
    `rim`, lined by the ring of round_rim_sites): the area, seen from above, farther than r from every
    remaining sphere centre and connected to the axis."""
    from scipy import ndimage
    spacing = 2 * plate_radius
    reach = D / 2 + 3 * spacing
    sites = np.arange(-np.ceil(reach / spacing), np.ceil(reach / spacing) + 1) * spacing
    X, Y = np.meshgrid(sites, sites)
    keep = np.hypot(X, Y) >= D / 2 + plate_radius
    xs, ys = list(X[keep]), list(Y[keep])
    if rim:
        rx, ry = round_rim_sites(D, plate_radius)
        xs += list(rx)
        ys += list(ry)
    g = np.arange(-reach, reach, cell)
    GX, GY = np.meshgrid(g, g)
    free = np.ones(GX.shape, bool)
    for x, y in zip(xs, ys):
        free &= (GX - x) ** 2 + (GY - y) ** 2 > plate_radius ** 2
    labels, _ = ndimage.label(free)
    hole = labels == labels[len(g) // 2, len(g) // 2]
    return float(np.sqrt(4 * hole.sum() * cell * cell / np.pi))


def silo(run, docs):
    d = np.genfromtxt(os.path.join(run, "silo.csv"), delimiter=",", names=True)
    info = np.genfromtxt(os.path.join(run, "silo_fill.csv"), delimiter=",", names=True)
    width, fill, grains = float(info["width_m"]), float(info["fill_m"]), int(info["grains"])
    runs_file = os.path.join(run, "silo_runs.csv")
    runs = np.atleast_1d(np.genfromtxt(runs_file, delimiter=",", names=True)) if os.path.exists(runs_file) else None
    rim = runs is not None and "rim_spheres" in runs.dtype.names  # runs before the round rim cut a ragged hole
    removed = runs["removed_on_rim"].astype(int) if rim else np.array([0])
    rows = []
    before = []
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for D in np.unique(d["orifice_m"]):
        s = d[d["orifice_m"] == D]
        t, n = s["time_s"], s["discharged"]
        # Grains already below the plate at the first sample (2 ms, too soon to fall 5 cm through the
        # orifice) got past the plate during the fill's fall; every copy holds the same ones.
        before.append(int(n[0]))
        n = n - n[0]
        # Steady rate: after the first 0.1 s (the arch above the new orifice breaking up).
        sel = t >= 0.1
        rate, _ = np.polyfit(t[sel], n[sel], 1) if sel.sum() >= 3 else (np.nan, 0)
        rows.append((D, rate * COARSE_GRAIN_MASS, int(n.max())))
        ax1.plot(t, n, label=f"D = {D * 1e3:.0f} mm = {D / COARSE_D_EQ:.2f} d")
    ax1.axvline(0.1, color="grey", ls=":")
    ax1.set_xlabel("time after opening (s)")
    ax1.set_ylabel("grains discharged")
    ax1.legend(fontsize=8)
    D = np.array([r[0] for r in rows])
    W = np.array([r[1] for r in rows])
    grows = bool(np.all(np.diff(W) > 0))
    # Beverloo W = C rho_b sqrt(g) (D - k d)^(5/2): W^(2/5) is linear in D.
    a, b = np.polyfit(D, W ** 0.4, 1)
    k = -b / a / COARSE_D_EQ
    packing = grains * COARSE_GRAIN_MASS / DENSITY / (np.pi * (width / 2) ** 2 * fill)
    rho_b = packing * DENSITY
    C = a ** 2.5 / (rho_b * np.sqrt(9.81))
    linear_residual = float(np.max(np.abs(np.polyval([a, b], D) - W ** 0.4) / W ** 0.4))
    # Free exponent with k fixed at Beverloo's 1.5 (fitting k and the exponent together on four
    # orifices would fit almost anything).
    n_exp = float(np.polyfit(np.log(D - 1.5 * COARSE_D_EQ), np.log(W), 1)[0])
    n_exp_k0 = float(np.polyfit(np.log(D), np.log(W), 1)[0])  # informative, not a criterion
    widening = np.array([orifice_open_diameter(x, rim) - x for x in D]) / COARSE_D_EQ
    a_open, b_open = np.polyfit(D + widening * COARSE_D_EQ, W ** 0.4, 1)
    k_open = -b_open / a_open / COARSE_D_EQ
    Dfit = np.linspace(D.min() * 0.9, D.max() * 1.1, 50)
    ax2.plot(D * 1e3, W * 1e3, "o", label="tetrasand (CPU reference)")
    ax2.plot(Dfit * 1e3, np.clip(a * Dfit + b, 0, None) ** 2.5 * 1e3, "-", label=f"Beverloo fit, k = {k:.2f}, C = {C:.2f}")
    ax2.set_xlabel("orifice diameter D (mm)")
    ax2.set_ylabel("discharge rate W (g/s)")
    ax2.legend(fontsize=8)
    img = save(fig, docs, "silo.png")
    cond1 = width > 2.5 * D.max()
    cond2 = width > D.max() + 30 * COARSE_D_EQ
    cond3 = fill > 1.2 * width
    out_max = max(r[2] for r in rows)
    conforming = cond1 and cond2 and cond3
    leaked = (f"; {max(before)} grains that got past the plate (through or around it) during the fill's fall (already below it "
              f"when the orifice opens) are not counted" if max(before) else "")
    if rim:
        opening = (f"The plate's particles within D/2 + r of the axis are taken away and a ring of its spheres "
                   f"(centres on a circle of D/2 + r, at most r apart) lines the hole, so the opening is a disc of D: "
                   f"its open area is that of a disc {widening.min():+.3f} to {widening.max():+.3f} d wider. Grains "
                   f"resting in the lattice hollows where a rim sphere now stands ({removed.min()}-{removed.max()} per "
                   f"orifice, against {int(min(r[2] for r in rows))}+ discharged) are taken out before the discharge starts.")
        orifice_note = (f"With the orifice now a disc of D, the empty annulus at 5/2 is k = {k:.2f} d "
                        f"(Beverloo's is about 1.5 d for spheres). The round rim was added after a run whose "
                        f"lattice-edge orifice missed the criterion above, so this pass was not met blind.")
    else:
        opening = ("The plate's particles within D/2 + r of the axis are taken away (no rim: the lattice's edge "
                   "is ragged).")
        orifice_note = (f"The orifice cut from the lattice has the open area of a disc {widening.min():.2f}-"
                        f"{widening.max():.2f} d wider than D; against that diameter the fit at 5/2 gives "
                        f"k = {k_open:.2f}.")
    table = "\n".join(f"| {x * 1e3:.1f} | {x / COARSE_D_EQ:.2f} | {w * 1e3:.0f} | {t} |" for x, w, t in rows)
    return f"""## Silo discharge against orifice diameter (Beverloo)

A flat-bottomed silo sized to the conditions of Mankoc et al. 2007
(`assets/scenes/reference/silo_mankoc.toml`): {grains} coarse grains (r = 5 mm spheres,
d = {COARSE_D_EQ * 1e3:.1f} mm volume-equivalent, E = 1 MPa, mu = 0.5, symplectic Euler) settled for
{float(info["settle_s"]):.2f} s in a smooth cylinder {width * 1e3:.0f} mm across on a closed rough plate. The fill
falls as a lattice about 4 m onto the plate; from the moment its top grain would land, the settling
is damped (velocities decay with a 0.05 s time constant) until 99 % of the grains move slower than
2 cm/s or the fill height stays within 0.3 % for 0.1 s. Each orifice then opens in a copy of that
settled fill and the silo discharges, undamped, for 0.35 s; the rate W is the slope of the discharged
mass from 0.1 s on. {opening}
Grains 5 cm below the plate leave the simulation{leaked}. CPU reference, dt = {float(info["dt_s"]) * 1e6:.0f} us.

{img}

| D (mm) | D / d | W (g/s) | grains out in 0.35 s |
|---|---|---|---|
{table}

- Size conditions (Mankoc et al. 2007): width {width * 1e3:.0f} mm > 2.5 D = {2.5 * D.max() * 1e3:.0f} mm:
  **{'yes' if cond1 else 'no'}**; > D + 30 d = {(D.max() + 30 * COARSE_D_EQ) * 1e3:.0f} mm: **{'yes' if cond2 else 'no'}**;
  fill {fill * 1e3:.0f} mm > 1.2 widths = {1.2 * width * 1e3:.0f} mm: **{'yes' if cond3 else 'no'}** (it drops by
  at most {out_max / grains * fill * 1e3:.0f} mm during a run).
- Expected: W = C rho_b sqrt(g) (D - k d)^(5/2) with C ~ 0.58 and k ~ 1.5 for spheres (Beverloo et al.
  1961; k grows for angular grains, 2-3 for sand); the rate grows with D.
- Measured: rate growing with D: **{'yes' if grows else 'no'}**. With the exponent fixed at 5/2,
  W^(2/5) is linear in D within {linear_residual * 100:.1f} % and gives k = {k:.2f} and C = {C:.2f}
  (rho_b = {packing:.2f} rho, the settled fill's); with k fixed at 1.5 the free exponent is
  {n_exp:.2f} (5/2 expected: **{'meets' if abs(n_exp - 2.5) < 0.5 else 'does not meet'}** it within 0.5,
  the tolerance set before the run). Informative, not a criterion (added after a run with the
  lattice-edge orifice found k ~ 0): with k fixed at 0 the free exponent is {n_exp_k0:.2f}. {orifice_note}
- The same fit in other grain sizes (issue 18; informative, added after the run): the empty annulus is
  k d = {k * COARSE_D_EQ * 1e3:.1f} mm whatever the unit; over the sphere diameter 2 r = {2 * COARSE_RADIUS * 1e3:.0f} mm it is
  k = {k * COARSE_D_EQ / (2 * COARSE_RADIUS):.2f}, over the grain's bounding diameter {2 * BOUNDING_RADIUS * 1e3:.1f} mm k = {k * COARSE_D_EQ / (2 * BOUNDING_RADIUS):.2f}.
  Beverloo's k ~ 1.5 is for spheres of diameter d; the same silo with spheres (below) gives k = 0.28.
- What it can show: {'the silo meets all three size conditions, so the 5/2 law is the one to expect; ' if conforming else 'the silo does not meet every size condition, so the fit is no test of the law; '}
  the orifices span {D.min() / COARSE_D_EQ:.0f}-{D.max() / COARSE_D_EQ:.0f} d (the width, {width / COARSE_D_EQ:.0f} d, bounds D
  through D + 30 d; a tetrahedron is {2 * BOUNDING_RADIUS / COARSE_D_EQ:.1f} d across, so 4 d is under three grains and
  near clogging), so the exponent's lever arm is short: it is sensitive to k, which is why it is reported
  at Beverloo's k = 1.5 and with k fitted at 5/2.
"""


def tail_fits(fn):
    """Fits to the tail (f > 1) of the distribution of normalised forces fn: beta of exp(-beta f),
    the best alpha of exp(-c f^alpha), and the squared log residuals of alpha = 1 and 2, over
    histogram bins holding at least 5 forces (so single counts do not steer the tail)."""
    bins = np.arange(0, fn.max() + 0.2, 0.2)
    counts, edges = np.histogram(fn, bins=bins)
    hist = counts / (len(fn) * np.diff(edges))
    centres = 0.5 * (edges[1:] + edges[:-1])
    tail = (centres > 1) & (counts >= 5)

    def sse(alpha):
        x = centres[tail] ** alpha
        p = np.polyfit(x, np.log(hist[tail]), 1)
        return float(np.sum((np.polyval(p, x) - np.log(hist[tail])) ** 2)), p

    alphas = np.linspace(0.5, 3.0, 51)
    alpha = float(alphas[int(np.argmin([sse(a)[0] for a in alphas]))])
    e_exp, p_exp = sse(1.0)
    e_gauss, p_gauss = sse(2.0)
    return {"centres": centres, "hist": hist, "counts": counts, "beta": float(-p_exp[0]), "alpha": alpha,
            "e_exp": e_exp, "e_gauss": e_gauss, "p_exp": p_exp, "p_gauss": p_gauss,
            "peak": float(centres[int(np.argmax(hist))]), "above3": int((fn > 3).sum()), "n": len(fn)}


# m: the height of the plate's sphere centres (reference/silo_mankoc.toml: tops at z = 0, r = 5 mm). A
# grain sphere touching the plate below this plane has sunk into a gap of the plate's lattice.
PLATE_CENTRE_Z = -COARSE_RADIUS


def lodged_in_plate(base):
    """Base contacts of grain spheres lodged in the plate: contact point below the plane of the plate's
    sphere centres, so the grain's sphere is pressed into a gap of the lattice from the sides (a solid
    base, like the carbon paper's, has no gaps)."""
    return base["z_m"] < PLATE_CENTRE_Z


# One settled fill's normal forces, each over its reference. base: over the fill's mean base force (as
# the carbon paper under Mueth et al.'s cylinder measures them); on_plate: the base contacts without those
# lodged in the plate, over their own mean; bulk: over the mean of its 5 cm layer (the load grows with
# depth); grain: each grain's vertical load on the floor over their mean (None in files without a grain
# column); lodged_contacts and lodged_grains: how many base contacts and grains are lodged in the plate.
FillForces = namedtuple("FillForces", "base on_plate bulk grain lodged_contacts lodged_grains")


def normalised_forces(file):
    """The normal forces of one settled fill's contact-force CSV, as FillForces."""
    d = np.genfromtxt(file, delimiter=",", names=True)
    d = d[d["normal_force_N"] > 0]
    base = d[d["base"] == 1]
    bulk = d[d["base"] == 0]
    lodged = lodged_in_plate(base)
    on_plate = base["normal_force_N"][~lodged]
    lodged_grains = len(np.unique(base["grain"][lodged])) if "grain" in d.dtype.names else None
    layer = np.floor(bulk["z_m"] / 0.05).astype(int)
    layer_mean = {k: bulk["normal_force_N"][layer == k].mean() for k in np.unique(layer)}
    per_grain = None  # each grain's vertical load on the floor over their mean (files with a grain column)
    if "grain" in d.dtype.names:
        _, which = np.unique(base["grain"].astype(np.int64), return_inverse=True)
        load = np.bincount(which, weights=base["fz_N"])
        load = load[load > 0]
        per_grain = load / load.mean()
    return FillForces(base["normal_force_N"] / base["normal_force_N"].mean(), on_plate / on_plate.mean(),
                      bulk["normal_force_N"] / np.array([layer_mean[k] for k in layer]), per_grain,
                      int(lodged.sum()), lodged_grains)


def force_fills(run):
    """(label, grains, fill height m, contact-force file) of every settled fill in the run: the silo's,
    and the extra piles of `tetrasand_validation_runs OUT forces`."""
    fills = []
    if os.path.exists(os.path.join(run, "contact_forces.csv")):
        info = np.genfromtxt(os.path.join(run, "silo_fill.csv"), delimiter=",", names=True)
        fills.append(("silo fill (seed 17)", int(info["grains"]), float(info["fill_m"]),
                      os.path.join(run, "contact_forces.csv")))
    extra = os.path.join(run, "forces_fills.csv")
    if os.path.exists(extra):
        for r in np.atleast_1d(np.genfromtxt(extra, delimiter=",", names=True)):
            fills.append((f"pile, seed {int(r['seed'])}", int(r["grains"]), float(r["fill_m"]),
                          os.path.join(run, f"contact_forces_seed{int(r['seed'])}.csv")))
    return fills


# One settled fill's tail fits (tail_fits dicts; grain: per-grain base loads, None where not recorded) and
# its contacts lodged in the plate (FillForces).
FillFits = namedtuple("FillFits", "label grains height base on_plate bulk grain lodged_contacts lodged_grains")


def forces(run, docs):
    fills = force_fills(run)
    per_fill = []
    pooled = {"base": [], "on_plate": [], "bulk": [], "grain": []}
    for label, grains, height, file in fills:
        f = normalised_forces(file)
        for name in pooled:
            if getattr(f, name) is not None:
                pooled[name].append(getattr(f, name))
        per_fill.append(FillFits(label, grains, height, tail_fits(f.base), tail_fits(f.on_plate), tail_fits(f.bulk),
                                 tail_fits(f.grain) if f.grain is not None else None, f.lodged_contacts,
                                 f.lodged_grains))
    fits = {name: tail_fits(np.concatenate(v)) for name, v in pooled.items() if v}
    fig, ax = plt.subplots(figsize=(6.5, 4.2))

    def plot_histogram(t, fmt, label, **style):
        keep = t["counts"] > 0  # empty bins have no logarithm
        ax.semilogy(t["centres"][keep], t["hist"][keep], fmt, label=label, **style)

    tail = lambda t: f"best tail exp(-c f^{t['alpha']:.2f})"
    for name, fmt in (("bulk", "o"), ("base", "s")):
        plot_histogram(fits[name], fmt, f"{name}, {len(fills)} fills: {fits[name]['n']} contacts, {tail(fits[name])}", ms=4)
    plot_histogram(fits["on_plate"], "s", f"base without contacts lodged in the plate: {fits['on_plate']['n']}, "
                   f"{tail(fits['on_plate'])}", ms=6, mfc="none", color="black", lw=0.8)
    if "grain" in fits:
        plot_histogram(fits["grain"], "^", f"base load per grain: {fits['grain']['n']} grains, {tail(fits['grain'])}", ms=4)
    for p in per_fill:
        plot_histogram(p.base, "-", f"base, {p.label}", lw=0.6, alpha=0.6)
    t = fits["bulk"]
    x = np.linspace(1, t["centres"][t["counts"] >= 5].max(), 50)
    ax.semilogy(x, np.exp(np.polyval(t["p_exp"], x)), "-", color="grey", label=f"bulk, exponential tail, beta = {t['beta']:.2f}")
    ax.semilogy(x, np.exp(np.polyval(t["p_gauss"], x ** 2)), "--", color="grey", label="bulk, Gaussian tail")
    ax.set_xlabel("f = F_n / <F_n>")
    ax.set_ylabel("P(f)")
    ax.legend(fontsize=6)
    img = save(fig, docs, "contact_forces.png")
    in_range = lambda a: 1.1 <= a <= 1.9

    def row(name, label):
        t = fits[name]
        better = "Gaussian" if t["e_gauss"] < t["e_exp"] else "exponential"
        return (f"| {label} | {t['n']} | {t['peak']:.1f} | {t['beta']:.2f} | {t['alpha']:.2f} | "
                f"{'yes' if in_range(t['alpha']) else 'no'} | {t['e_exp']:.2f} / {t['e_gauss']:.2f} ({better}) | {t['above3']} |")

    grain_cells = lambda g: f"{g['n']} | {g['beta']:.2f} | {g['alpha']:.2f}" if g else "- | - | -"
    lodged_cell = lambda p: f"{p.lodged_contacts} ({p.lodged_grains if p.lodged_grains is not None else '-'})"
    fill_rows = "\n".join(
        f"| {p.label} | {p.grains:,} | {p.height * 1e3:.0f} | {p.base['n']} | {p.base['beta']:.2f} | {p.base['alpha']:.2f} | "
        f"{lodged_cell(p)} | {p.on_plate['beta']:.2f} | {p.on_plate['alpha']:.2f} | "
        f"{grain_cells(p.grain)} | {p.bulk['n']} | {p.bulk['alpha']:.2f} |" for p in per_fill)
    lodged = sum(p.lodged_contacts for p in per_fill)
    lodged_grains = sum(p.lodged_grains or 0 for p in per_fill)
    on_plate_alphas = np.array([p.on_plate["alpha"] for p in per_fill])
    on_plate_text = (
        f"\n- Not a criterion, found after the runs above: {lodged} base contacts of {lodged_grains} grains touch the "
        f"plate below the plane of its sphere centres ({', '.join(f'{p.lodged_contacts}' for p in per_fill)} per fill): "
        f"a sphere of those grains sits in a gap of the plate's square lattice, pressed from the sides by the "
        f"plate's spheres (touching them below their centres, so mostly horizontally, with the overlap the gap "
        f"imposes), which the flat base under Mueth et al.'s carbon paper cannot hold. Without them the base tail is exp(-{fits['on_plate']['beta']:.2f} f) "
        f"and exp(-c f^{fits['on_plate']['alpha']:.2f}) (**{'within' if in_range(fits['on_plate']['alpha']) else 'outside'}** "
        f"1.1-1.9; per fill alpha {on_plate_alphas.min():.2f}-{on_plate_alphas.max():.2f}, "
        f"{int(sum(in_range(a) for a in on_plate_alphas))} of {len(fills)} in range). Likely cause, not tested "
        f"separately: each fill falls as one lattice, so its upper grains land on the growing pile at up to "
        f"sqrt(2 g h) (about 9 m/s for the silo's 4 m), and those impacts drive bottom grains into a plate only "
        f"one sphere thick; a plate backed by a solid, or a gentler fill, would keep them out."
        if lodged else "")
    grain_row = f"\n{row('grain', 'base load per grain')}" if "grain" in fits else ""
    grain_text = (f"\n- Not a criterion, added after the runs above found the base tail heavy: Mueth et al.'s carbon "
                  f"paper records the load of each bead on the base, one contact per bead, whereas a tetrahedral "
                  f"grain on the floor's spheres spreads its load over several contacts of uneven share. Summed "
                  f"per grain (the vertical force each grain puts on the floor, in the fills that record it: "
                  f"{fits['grain']['n']} grains), the base tail is exp(-{fits['grain']['beta']:.2f} f) "
                  f"(beta ~ 1.5 expected) with best alpha {fits['grain']['alpha']:.2f}."
                  if "grain" in fits else "")
    base_alphas = np.array([p.base["alpha"] for p in per_fill])
    base_betas = np.array([p.base["beta"] for p in per_fill])
    bulk_alphas = np.array([p.bulk["alpha"] for p in per_fill])
    heaviest = per_fill[int(np.argmin(base_alphas))]
    several = len(fills) > 1
    others = (f"the silo's own fill and {len(fills) - 1} more piles in the same cylinder with other seeds (other "
              f"lattice jitters and orientations), settled the same way (`tetrasand_validation_runs OUT forces`)"
              if several else "the silo's own fill")
    spread = (f" Over the {len(fills)} fills the base alpha ranges {base_alphas.min():.2f}-{base_alphas.max():.2f} and "
              f"beta {base_betas.min():.2f}-{base_betas.max():.2f}, the bulk alpha {bulk_alphas.min():.2f}-{bulk_alphas.max():.2f}; "
              f"{int(sum(in_range(a) for a in base_alphas))} of {len(fills)} base tails and "
              f"{int(sum(in_range(a) for a in bulk_alphas))} of {len(fills)} bulk tails are in 1.1-1.9 on their own; "
              f"the heaviest base tail is the {heaviest.label}'s ({heaviest.height * 1e3:.0f} mm deep). Alphas of 0.50 or 3.00 lie on the "
              f"edge of the range searched (0.5-3), so they are bounds, not fits."
              if several else "")
    return f"""## Normal contact forces in a sand pile at rest in a cylinder (thesis 7.2)

Settled fills of the silo above (before any orifice opens) are sand piles at rest in a cylinder, the
case of the thesis's table 7.1 and of Mueth, Jaeger & Nagel 1998: {others}. Normal forces of every
contact between particles of different bodies: at the base (grain on a floor particle), each over its
fill's mean base force; in the bulk (grain on grain), each over the mean of its fill's 5 cm layer,
since the load grows with depth. The fills are pooled; tail fits over histogram bins (width 0.2)
holding at least 5 forces.

{img}

| contacts (all fills) | count | peak of P(f) at f | beta, exp(-beta f) | alpha, exp(-c f^alpha) | alpha in 1.1-1.9 | residuals exp / Gauss | above f = 3 |
|---|---|---|---|---|---|---|---|
{row("bulk", "bulk")}
{row("base", "base")}
{row("on_plate", "base, without contacts lodged in the plate")}{grain_row}

| fill | grains | height (mm) | base contacts | base beta | base alpha | lodged in the plate: contacts (grains) | beta without them | alpha without them | grains on the base | per-grain beta | per-grain alpha | bulk contacts | bulk alpha |
|---|---|---|---|---|---|---|---|---|---|---|---|---|---|
{fill_rows}

- Expected: a plateau or peak near or below f = 1 and a tail that falls at least exponentially:
  P ~ exp(-beta f) with beta ~ 1.5 at the base (Mueth et al. 1998), and for large systems faster,
  exp(-c f^alpha) with alpha = 1.5 +- 0.4 (Mueth et al. 1998) or 1.7 +- 0.1 (van Eerd et al. 2007,
  DEM), the thesis's equation 7.2.
- Measured (all fills): peak below f = 1.5 in the bulk: **{'yes' if fits['bulk']['peak'] < 1.5 else 'no'}**, at the base:
  **{'yes' if fits['base']['peak'] < 1.5 else 'no'}**; bulk tail exponent alpha = {fits['bulk']['alpha']:.2f}
  (**{'meets' if in_range(fits['bulk']['alpha']) else 'does not meet'}** the literature's 1.1-1.9); base tail
  alpha = {fits['base']['alpha']:.2f} (**{'meets' if in_range(fits['base']['alpha']) else 'does not meet'}** it) on
  {fits['base']['n']} base contacts.{spread} The small version is the test
  `ContactForces.SettledBedCarriesItsWeightOnBroadlySpreadNormalForces`.{on_plate_text}{grain_text}
"""


def column(run, docs):
    d = np.genfromtxt(os.path.join(run, "column.csv"), delimiter=",", names=True, dtype=None, encoding=None)
    # A `source` column (the run's date) when the columns come from more than one run
    # (bench/validation/column_criteria.md: columns added to kept ones); absent in a plain run.
    sources = d["source"].astype(str) if "source" in d.dtype.names else np.array([""] * len(d))
    a, n = d["aspect"].astype(float), d["normalised_runout"].astype(float)
    order = np.argsort(a)
    a, n, grains, sources = a[order], n[order], int(d["grains"][0]), sources[order]
    rising = bool(np.all(np.diff(n) > 0))
    slope = float(np.polyfit(np.log(a), np.log(n), 1)[0])
    low, high = a < 1.7, a >= 1.7
    fit = lambda m: float(np.polyfit(np.log(a[m]), np.log(n[m]), 1)[0]) if m.sum() >= 2 else float("nan")
    slope_low, slope_high = fit(low), fit(high)
    lube_at = np.where(a < 1.7, 1.24 * a, 1.6 * np.sqrt(a))
    gap = float(np.max(np.abs(n / lube_at - 1)))
    x = np.linspace(min(a.min(), 0.3), max(a.max(), 6), 100)
    lube = np.where(x < 1.7, 1.24 * x, 1.6 * np.sqrt(x))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(a, n, "-", color="C0", lw=1)
    for k, src in enumerate(sorted(set(sources))):
        m = sources == src
        ax.loglog(a[m], n[m], "os^"[k % 3], color="C0", mfc="none" if k else "C0",
                  label=f"tetrasand (CPU reference, {grains} grains, r = 5 mm){', run of ' + src if src else ''}")
    ax.loglog(x, lube, "--", color="grey", label="Lube et al. 2004: 1.24 a, 1.6 a^(1/2) above a = 1.7")
    ax.set_xlabel("aspect ratio a = H0 / R0")
    ax.set_ylabel("normalised runout (R_inf - R0) / R0")
    ax.legend(fontsize=7)
    img = save(fig, docs, "column.png")
    several = len(set(sources)) > 1
    table = "\n".join(f"| {r0 * 1e3:.0f} | {h0 * 1e3:.0f} | {ai:.2f} | {ro * 1e3:.0f} | {ni:.2f} | "
                      f"{(1.24 * ai if ai < 1.7 else 1.6 * np.sqrt(ai)):.2f} | {ts:.2f} / {tp:.2f} |"
                      + (f" {src} |" if several else "")
                      for r0, h0, ai, ro, ni, ts, tp, src in zip(d["r0_m"][order], d["h0_m"][order], a,
                                                                d["runout_m"][order], n, d["settle_s"][order],
                                                                d["spread_s"][order], sources))
    head = "| R0 (mm) | H0 (mm) | a | R_inf (mm) | (R_inf - R0) / R0 | Lube et al. 2004 | settle / spread (s) |"
    rule = "|---|---|---|---|---|---|---|"
    if several:
        head, rule = head + " run |", rule + "---|"
    runs_note = ""
    if several:
        per = "; ".join(f"{src}: a = {', '.join(f'{x:.2f}' for x in a[sources == src])}" for src in sorted(set(sources)))
        runs_note = (f" The columns come from more than one run ({per}); bench/validation/column_criteria.md says "
                     f"which were added when and that the criteria apply to all of them together.")
    note_path = os.path.join(run, "column_note.md")  # how this run differs from the plan, when it does
    note = "\n" + open(note_path).read().strip() + "\n" if os.path.exists(note_path) else ""
    ok_low = abs(slope_low - 1.0) <= 0.25
    ok_high = abs(slope_high - 0.5) <= 0.15
    across = 2 * d["r0_m"].min() / COARSE_D_EQ
    return f"""## Column collapse: runout against aspect ratio

An axisymmetric column (`assets/scenes/reference/column.toml` scaled up: {grains} coarse grains per
column, r = 5 mm, E = 1 MPa, mu = 0.5, symplectic Euler) settles inside a smooth cylinder of radius R0
on a rough floor; the cylinder is then removed and the column spreads, undamped. The column is filled
by a lattice of grains falling onto the floor; from the moment its top grain would land, the filling
is damped (every grain's velocities decay with a 0.05 s time constant), which cuts the seconds a soft
fill takes to stop rebounding; it can also change the packing the fill reaches. Each phase runs until 99 % of
the grains move slower than 2 cm/s, or slower than 20 cm/s with the height (settling) or radius
(spreading) measured below staying within 0.3 % for 0.1 s (settling: at least 0.2 s after the damping
starts; spreading: at least 0.5 s; at most 2.5 s). H0 and
R_inf are the 95th percentiles of the
grains' outer extent (height; horizontal distance from the axis) before and after; the cylinder's
radius sets the aspect ratio a = H0 / R0. The narrowest column is {across:.0f} grain diameters across.

{img}

{head}
{rule}
{table}

- Expected: (R_inf - R0) / R0 = 1.24 a below a = 1.7 and 1.6 a^(1/2) above (Lube et al. 2004,
  axisymmetric); Lajeunesse et al. 2004 find the same two regimes, linear then sub-linear, with the
  break at a of order 1-3.
- Measured: runout rising with a: **{'yes' if rising else 'no'}**; power law over all runs a^{slope:.2f};
  below a = 1.7: a^{slope_low:.2f} (1 expected: **{'meets' if ok_low else 'does not meet'}** it within 0.25);
  above a = 1.7: a^{slope_high:.2f} (1/2 expected: **{'meets' if ok_high else 'does not meet'}** it within 0.15);
  largest gap to Lube's values {gap * 100:.0f} %. Each exponent rests on {int(low.sum())} and {int(high.sum())}
  columns (one run each), so it carries the run-to-run scatter of a single deposit; the tolerances were
  set before the run (bench/validation/column_criteria.md).{runs_note} The small version (400 grains) is the test
  `ColumnCollapse.RunoutGrowsWithAspectRatio`.
{note}"""


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
    if "seed" not in s.dtype.names:  # runs before the silo had four fills: one, the scene's own seed 5
        s = np.rec.fromarrays([s["backend"], np.full(len(s), 5), s["time_s"], s["discharged"]],
                              names="backend,seed,time_s,discharged")
    silo_seeds = sorted(set(int(x) for x in s["seed"]))
    rates = {b: np.array([discharge_rate(s["time_s"][(s["backend"] == b) & (s["seed"] == k)],
                                         s["discharged"][(s["backend"] == b) & (s["seed"] == k)]) for k in silo_seeds])
             for b in ("cpu", "gpu")}
    rate = {b: float(np.mean(v)) for b, v in rates.items()}
    rate_spread = {b: float((v.max() - v.min()) / v.mean()) for b, v in rates.items()}
    bed = np.genfromtxt(os.path.join(run, "agreement_bed.csv"), delimiter=",", names=True, dtype=None,
                        encoding="utf-8")
    mean = {b: bed["mean_height_m"][bed["backend"] == b] for b in ("cpu", "gpu")}
    seed_spread = float((mean["cpu"].max() - mean["cpu"].min()) / mean["cpu"].mean())
    bed_diff = float(mean["gpu"].mean() / mean["cpu"].mean() - 1)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for b, style, colour in (("cpu", "-", "C0"), ("gpu", "--", "C1")):
        for i, k in enumerate(silo_seeds):
            sel = (s["backend"] == b) & (s["seed"] == k)
            ax1.plot(s["time_s"][sel], s["discharged"][sel], style, color=colour, lw=1,
                     label=(f"{'CPU reference' if b == 'cpu' else 'GPU pipeline'}: mean {rate[b] * GRAIN_MASS * 1e3:.2f} g/s"
                            if i == 0 else None))
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
    silo_label = (f"mean of fill seeds {silo_seeds[0]}-{silo_seeds[-1]}" if len(silo_seeds) > 1 else f"seed {silo_seeds[0]}")
    ok_bed = abs(bed_diff) <= 0.02
    return f"""## GPU pipeline against the CPU reference (long runs, statistics)

Produced by `scripts/bench.sh agreement` ({time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPU cores, one process). The CPU
reference is deterministic (sums in particle order: the same scene gives the same numbers run after
run). On llvmpipe the GPU pipeline was too: two one-process runs of this command (2026-12-02 01:13 and
03:53) gave identical heap grains and bed heights; figures that differed before came from a run made
in parts, with code changes in between. So a difference here is no run-to-run noise of one backend:
it is float against double on one chaotic trajectory, and the fill-to-fill spread below is the scatter
to weigh it against.

The same scenes on the CPU reference (double) and the GPU pipeline (float; renderer {renderer}):
the trajectories part within a few hundred steps (float against double, chaotic contacts), so what must
agree is the statistics. Tolerances were set before the run: heap angle 3 deg (as against LAMMPS),
discharge rate 10 % (since 2026-12-02 on the mean of four fill seeds, before on one fill), bed height
2 % (mean of four fill seeds). The test
`GpuCpuAgreement.SettledBedHeightAgreesWithinThePackingSpread` is the small version.

{img}

| quantity | CPU reference | GPU pipeline | difference | tolerance | within |
|---|---|---|---|---|---|
| angle of repose, 400-grain heap (reference/heap.toml, mu = 0.5) | {heap['cpu']:.1f} deg | {heap['gpu']:.1f} deg | {heap['gpu'] - heap['cpu']:+.1f} deg | 3 deg | {'yes' if ok_heap else 'NO'} |
| silo discharge rate, 600 grains, D = 16 mm (reference/silo.toml, {silo_label}) | {rate['cpu'] * GRAIN_MASS * 1e3:.2f} g/s | {rate['gpu'] * GRAIN_MASS * 1e3:.2f} g/s | {(rate['gpu'] / rate['cpu'] - 1) * 100:+.1f} % | 10 % | {'yes' if ok_silo else 'NO'} |
| settled coarse bed (reference/coarse_bed.toml, 120 grains, seeds 1-4): mean centre height | {mean['cpu'].mean() * 1e3:.2f} mm | {mean['gpu'].mean() * 1e3:.2f} mm | {bed_diff * 100:+.2f} % | 2 % | {'yes' if ok_bed else 'NO'} |

- Expected: differences within the run-to-run scatter of each quantity. Seed-to-seed spread of the bed
  on the CPU reference here: {seed_spread * 100:.1f} % (max - min over the four seeds); of the silo
  rate: {rate_spread['cpu'] * 100:.1f} % on the CPU reference and {rate_spread['gpu'] * 100:.1f} % on the GPU pipeline
  (max - min over {len(silo_seeds)} fill{'s' if len(silo_seeds) > 1 else ''}; per fill, CPU / GPU in g/s:
  {', '.join(f"{c * GRAIN_MASS * 1e3:.2f} / {g * GRAIN_MASS * 1e3:.2f}" for c, g in zip(rates['cpu'], rates['gpu']))}).
- Small systems: a 400-grain heap's angle scatters by a few degrees from pour to pour, and the silo
  rate is fitted over a few tens of milliseconds, so these tolerances are loose; tighter tests need the
  large runs of a real GPU.
"""


AGREEMENT_START, AGREEMENT_END = "<!-- section: agreement -->\n", "<!-- end: agreement -->\n"
OEDOMETER_START, OEDOMETER_END = "<!-- section: oedometer -->\n", "<!-- end: oedometer -->\n"  # bench/validation/oedometer.py
# Controlled runs written up by hand beside the sections they test (their commands are in the text):
FORCES_BACKED_START, FORCES_BACKED_END = "<!-- section: forces-backed -->\n", "<!-- end: forces-backed -->\n"
FORCES_GENTLE_START, FORCES_GENTLE_END = "<!-- section: forces-gentle -->\n", "<!-- end: forces-gentle -->\n"
SILO_SPHERES_START, SILO_SPHERES_END = "<!-- section: silo-spheres -->\n", "<!-- end: silo-spheres -->\n"
SILO_LAMMPS_START, SILO_LAMMPS_END = "<!-- section: silo-lammps -->\n", "<!-- end: silo-lammps -->\n"  # silo_lammps.py
OEDOMETER_STIFF_START, OEDOMETER_STIFF_END = "<!-- section: oedometer-stiff -->\n", "<!-- end: oedometer-stiff -->\n"
# The bidisperse bed against LAMMPS: written by hand from its test (tests/export/lammps_deck_test.cpp).
BIDISPERSE_START, BIDISPERSE_END = "<!-- section: bidisperse -->\n", "<!-- end: bidisperse -->\n"
# Repose magnitude (issue 18): written by hand from `scripts/bench.sh repose` (bench/validation/repose_sweep.py).
REPOSE_SWEEP_START, REPOSE_SWEEP_END = "<!-- section: repose-sweep -->\n", "<!-- end: repose-sweep -->\n"


COLUMN_TITLE, COLUMN_NEXT = "## Column collapse: runout against aspect ratio\n", "## Silo discharge"


def column_only(run, docs, path):
    """`--only column`: rewrites the column-collapse section (and the header's count of columns) from
    RUN_DIR/column.csv, every other section as it last ran."""
    doc = open(path).read()
    if COLUMN_TITLE not in doc or COLUMN_NEXT not in doc:
        sys.exit(f"report: {path} has no column-collapse section followed by the silo's to replace")
    start = doc.index(COLUMN_TITLE)
    end = doc.index(COLUMN_NEXT, start)
    count = len(np.genfromtxt(os.path.join(run, "column.csv"), delimiter=",", names=True, dtype=None, encoding=None))
    doc = doc[:start] + column(run, docs) + "\n" + doc[end:]
    doc = re.sub(r"the column collapse \(\d+ columns of", f"the column collapse ({count} columns of", doc, count=1)
    open(path + ".tmp", "w").write(doc)
    os.replace(path + ".tmp", path)


def main():
    only = None
    if len(sys.argv) == 5 and sys.argv[3] == "--only" and sys.argv[4] == "column":
        only = "column"
    elif len(sys.argv) != 3:
        sys.exit(__doc__)
    run, docs = sys.argv[1], sys.argv[2]
    path = os.path.join(docs, "validation.md")
    if only == "column":
        column_only(run, docs, path)
        return
    if os.path.exists(os.path.join(run, "agreement_bed.csv")):
        # `scripts/bench.sh agreement`: only its section changes.
        replace_between(path, AGREEMENT_START, AGREEMENT_END, agreement(run, docs))
        print(open(path).read())
        return
    old = open(path).read() if os.path.exists(path) else ""

    def kept(start, end, command):
        # The sections of other commands stay as they last ran.
        return (start + (old[old.index(start) + len(start):old.index(end)] if start in old and end in old
                         else f"(not run yet: `{command}`)\n") + end)
    def section(make, needs, title):
        # A part that did not finish (a stopped run) leaves its section saying so, not a stale one.
        if all(os.path.exists(os.path.join(run, f)) for f in needs):
            return make(run, docs)
        return f"## {title}\n\nNot in this run: it stopped before this part finished.\n"

    parts = [section(restitution, ["restitution.csv"], "Restitution against impact speed"),
             section(repose, ["repose.csv"], "Angle of repose against friction"),
             kept(REPOSE_SWEEP_START, REPOSE_SWEEP_END, "scripts/bench.sh repose"),
             section(column, ["column.csv"], "Column collapse: runout against aspect ratio"),
             section(silo, ["silo.csv", "silo_fill.csv"], "Silo discharge against orifice diameter (Beverloo)"),
             kept(SILO_SPHERES_START, SILO_SPHERES_END, "tetrasand_validation_runs OUT silo-spheres"),
             kept(SILO_LAMMPS_START, SILO_LAMMPS_END, "bench/validation/silo_lammps.py BIN OUT spheres"),
             section(forces, ["contact_forces.csv", "silo_fill.csv"],
                     "Normal contact forces in a sand pile at rest in a cylinder"),
             kept(FORCES_BACKED_START, FORCES_BACKED_END, "tetrasand_validation_runs OUT forces-backed"),
             kept(FORCES_GENTLE_START, FORCES_GENTLE_END, "tetrasand_validation_runs OUT forces-gentle")]
    fill = os.path.join(run, "silo_fill.csv")
    silo_grains = int(np.genfromtxt(fill, delimiter=",", names=True)["grains"]) if os.path.exists(fill) else 0
    columns = os.path.join(run, "column.csv")
    column_rows = np.genfromtxt(columns, delimiter=",", names=True, dtype=None, encoding=None) if os.path.exists(columns) else []
    column_grains = int(column_rows["grains"][0]) if len(column_rows) else 0
    column_count = len(column_rows)
    extra_piles = max(0, len(force_fills(run)) - 1) if os.path.exists(fill) else 0
    piles = f" and {extra_piles} more pil{'es' if extra_piles > 1 else 'e'}" if extra_piles else ""
    note = os.path.join(run, "NOTE.md")  # how this run was made, when it was not one plain command
    made = (": see the note below for which parts ran when" if os.path.exists(note)
            else " in one run:\nevery section below except the hand-written controlled runs, the oedometer and the agreement comes from it")
    header = f"""# Physical validation

Produced by `scripts/bench.sh validation` ({time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPU cores){made}. All of them ran on the CPU reference (double
precision; the one NVIDIA GPU lent to this project so far had 15 minutes, spent on docs/benchmarks/device.md's
device run, and on Mesa's llvmpipe the GPU pipeline is slower than the CPU reference). Tetrahedral grains of four touching spheres, quartz density,
E = 1 MPa in the scene runs. The restitution run is one r = 1 mm sphere; the angle of repose (4 heaps of
3,000 grains), the column collapse ({column_count} columns of {column_grains:,} grains), the silo ({silo_grains:,} grains, sized to the
conditions of Mankoc et al. 2007) and the contact forces (that silo's settled fill{piles}) use coarse r = 5 mm
grains, whose longer time step covers the same number of grain diameters in fewer steps.

The same contact law run by LAMMPS (through `tetrasand export lammps`) settles beds, rebounds grains and
builds heaps like tetrasand does: see the section "Simulation against LAMMPS" of docs/benchmarks/sim.md,
produced by `scripts/bench.sh peers-sim`.
"""
    if os.path.exists(note):
        header += "\n" + open(note).read()
    text = (header + "\n" + "\n".join(parts) + "\n" + kept(OEDOMETER_START, OEDOMETER_END, "scripts/bench.sh oedometer")
            + kept(OEDOMETER_STIFF_START, OEDOMETER_STIFF_END,
                   "tetrasand_validation_runs OUT oedometer-SHAPE assets/scenes/validation/oedometer_stiff.toml")
            + kept(AGREEMENT_START, AGREEMENT_END, "scripts/bench.sh agreement")
            + kept(BIDISPERSE_START, BIDISPERSE_END,
                   "ctest -R LammpsSettlesExportedBidisperseBedToTetrasandsHeightAndPacking"))
    open(path + ".tmp", "w").write(text)
    os.replace(path + ".tmp", path)
    print(text)


if __name__ == "__main__":
    main()
