#!/usr/bin/python3
"""The oedometer section of docs/validation.md and docs/validation/oedometer.png, from the servo logs
oedometer_tetrahedra.csv and oedometer_spheres.csv of `tetrasand_validation_runs OUT oedometer`,
against bench/validation/oedometer_criteria.md (written before the run).

Usage: bench/validation/oedometer.py RUN_DIR DOCS_DIR
"""
import json
import os
import sys
import time
import tomllib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import plt, save  # noqa: E402  (one figure style for the whole report)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from docs_section import replace_between  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCENE = os.path.join(ROOT, "assets", "scenes", "validation", "oedometer.toml")
START, END = "<!-- section: oedometer -->\n", "<!-- end: oedometer -->\n"
WINDOW = 0.05  # s, for strain rates and smoothing (criteria: 0.05 s windows)
LEVELS = np.linspace(0.2, 0.9, 8)  # fractions of the peak stress where the branches are compared


def scene():
    """The schedule's phases, the piston's face offset, the grain's size and density."""
    with open(SCENE, "rb") as f:
        s = tomllib.load(f)
    prop = s["prop"][0]
    keys = prop["servo"]["schedule"]
    # The test's peak: the highest key after the approach (whose high target ends at the first drop).
    drop = next(k for k in range(1, len(keys)) if keys[k][1] < keys[k - 1][1])
    peak = max(range(drop, len(keys)), key=lambda k: keys[k][1])
    # The ramps may be graded (several keys each way): loading starts at the last key at the seating
    # stress before the peak, unloading ends at the first key back at it.
    seat_stress = keys[drop][1]
    seat = max(k for k in range(drop, peak) if keys[k][1] == seat_stress)
    end = next(k for k in range(peak + 1, len(keys)) if keys[k][1] == seat_stress)
    with open(os.path.join(os.path.dirname(SCENE), prop["body"])) as f:
        piston_radius = json.load(f)["particle_radius"]
    return dict(seat=keys[seat][0], peak=keys[peak][0], end=keys[end][0], seat_stress=seat_stress,
                graded=peak - seat > 1,
                peak_stress=keys[peak][1], face=piston_radius, radius=s["grain"]["radius"],
                density=s["material"][0]["density"], cylinder=s["boundary"][1]["radius"])


def smooth(t, v):
    """Running mean over WINDOW seconds (the samples are evenly spaced)."""
    n = max(1, int(round(WINDOW / np.median(np.diff(t)))))
    return np.convolve(v, np.ones(n) / n, mode="same")


def analyse(path, sc):
    d = np.genfromtxt(path, delimiter=",", names=True)
    t, sigma, pos = d["time_s"], d["measured_Pa"], d["position_m"]
    seat = np.argmin(np.abs(t - sc["seat"]))
    height = -pos[seat] - sc["face"]  # m: the piston's face above the floor (z = 0) at the start of loading
    eps = (pos - pos[seat]) / height
    s_sigma = smooth(t, sigma)  # the piston's position is smooth; its force is not
    load = (t >= sc["seat"]) & (t <= sc["peak"])
    unload = (t >= sc["peak"]) & (t <= sc["end"])
    i_end = np.argmin(np.abs(t - sc["end"]))
    eps_peak, eps_end = eps[load | unload].max(), eps[i_end]
    # The branches at the same stresses: each interpolated in its smoothed stress.
    levels = LEVELS * sc["peak_stress"]
    lo_s, lo_e = s_sigma[load], eps[load]
    un_s, un_e = s_sigma[unload], eps[unload]
    e_load = np.interp(levels, np.sort(lo_s), lo_e[np.argsort(lo_s)])
    e_unload = np.interp(levels, np.sort(un_s), un_e[np.argsort(un_s)])
    w_load = np.trapz(sigma[load], eps[load])      # J/m^3, work done on the sample loading
    w_unload = -np.trapz(sigma[unload], eps[unload])  # J/m^3, given back unloading
    # Inertial number over 0.05 s windows of the ramps.
    d_eq = 2 * sc["radius"] * 4 ** (1 / 3)
    inertial = []
    edges = np.arange(sc["seat"], sc["end"] - WINDOW / 2, WINDOW)
    for a in edges:
        w = (t >= a) & (t < a + WINDOW)
        if w.sum() < 2:
            continue
        rate = abs(eps[w][-1] - eps[w][0]) / (t[w][-1] - t[w][0])
        inertial.append(rate * d_eq / np.sqrt(max(sigma[w].mean(), 1e-9) / sc["density"]))
    before = (t > 0.05) & (t < sc["seat"])
    return dict(t=t, sigma=sigma, s_sigma=s_sigma, eps=eps, load=load, unload=unload, height=height, eps_peak=eps_peak,
                eps_end=eps_end, recovered=(eps_peak - eps_end) / eps_peak if eps_peak > 0 else float("nan"),
                e_load=e_load, e_unload=e_unload, hysteresis=bool(np.all(e_unload > e_load)),
                loop=w_load - w_unload, w_load=w_load, inertial_max=max(inertial),
                sigma_before=sigma[before].max() if before.any() else 0.0,
                sigma_seat=np.mean(sigma[(t >= sc["seat"] - WINDOW) & (t <= sc["seat"])]))


def runs_row(run, shape):
    path = os.path.join(run, f"oedometer_runs_{shape}.csv")
    return np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding=None)


def plot(results, docs, sc):
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for shape, r, colour in (("tetrahedra", results["tetrahedra"], "C0"), ("spheres", results["spheres"], "C1")):
        ax.plot(100 * r["eps"][r["load"]], r["s_sigma"][r["load"]] / 1e3, "-", color=colour, lw=1,
                label=f"{shape}: loading")
        ax.plot(100 * r["eps"][r["unload"]], r["s_sigma"][r["unload"]] / 1e3, "--", color=colour, lw=1,
                label=f"{shape}: unloading")
    ax.set_xlabel("axial strain (%)")
    ax.set_ylabel(f"stress on the piston (kPa, mean over {WINDOW:g} s)")
    ax.set_title(f"Oedometer: {sc['seat_stress']:.0f} Pa -> {sc['peak_stress'] / 1e3:.0f} kPa -> "
                 f"{sc['seat_stress']:.0f} Pa")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save(fig, docs, "oedometer.png")


def verdict(ok, tested=True):
    # The criteria file's rule: a run that is not quasi-static does not test the criteria.
    if not tested:
        return f"**not tested** (the run is not quasi-static; the measured value {'meets' if ok else 'misses'} it)"
    return "**met**" if ok else "**not met**"


def inertial_note(r, sc):
    """Where the inertial number exceeded 1e-3: the windows' start times and the stress there."""
    t, sigma, eps = r["t"], r["sigma"], r["eps"]
    d_eq = 2 * sc["radius"] * 4 ** (1 / 3)
    over = []
    for a in np.arange(sc["seat"], sc["end"] - WINDOW / 2, WINDOW):
        w = (t >= a) & (t < a + WINDOW)
        rate = abs(eps[w][-1] - eps[w][0]) / (t[w][-1] - t[w][0])
        if rate * d_eq / np.sqrt(max(sigma[w].mean(), 1e-9) / sc["density"]) >= 1e-3:
            over.append((a, sigma[w].mean()))
    if not over:
        return "nowhere"
    starts = ", ".join(f"{a - sc['seat']:.2f}" for a, _ in over)
    return (f"in {len(over)} windows (starting {starts} s after the start of loading; unloading ends at "
            f"{sc['end'] - sc['seat']:.1f} s), at {min(s for _, s in over):.0f}-{max(s for _, s in over):.0f} Pa")


def section(run, docs):
    sc = scene()
    results = {s: analyse(os.path.join(run, f"oedometer_{s}.csv"), sc) for s in ("tetrahedra", "spheres")}
    image = plot(results, docs, sc)
    rows = {s: runs_row(run, s) for s in results}
    tet, sph = results["tetrahedra"], results["spheres"]
    quasi = all(r["inertial_max"] < 1e-3 for r in results.values())
    lines = [f"## Oedometer: stress-strain loop (thesis ch. 7)\n",
             f"`scripts/bench.sh oedometer` ({time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPU cores, CPU reference), "
             f"criteria written before the run: bench/validation/oedometer_criteria.md. "
             f"`assets/scenes/validation/oedometer.toml`: {int(rows['tetrahedra']['grains'])} tetrahedral grains "
             f"(r = {sc['radius'] * 1e3:.0f} mm spheres, E = 1 MPa, mu = 0.5, tangential springs) in a smooth cylinder "
             f"of radius {sc['cylinder'] * 1e3:.0f} mm, pressed by a servo piston (`[prop.servo]`) seated at "
             f"{sc['seat_stress']:.0f} Pa, loaded {'along a graded ramp (stress rate about proportional to sigma^(1/2))' if sc['graded'] else 'linearly'} to {sc['peak_stress'] / 1e3:.0f} kPa over "
             f"{sc['peak'] - sc['seat']:.3g} s and unloaded {'along its mirror ' if sc['graded'] else ''}to {sc['seat_stress']:.0f} Pa over "
             f"{sc['end'] - sc['peak']:.3g} s. Strain from the piston's travel over the bed height at seating. "
             f"The contrast run replaces each grain by one sphere of its volume and mass (radius 4^(1/3) r; the "
             f"`[grain]` table cannot say one sphere, so the bench swaps them in the initial world).\n",
             image + "\n",
             "| grains | bed height at seating (mm) | peak strain (%) | strain after unloading (%) | recovered fraction "
             "| loop area (J/m^3) | loop / loading work | largest inertial number | run (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for s, r in results.items():
        lines.append(f"| {s} | {r['height'] * 1e3:.1f} | {100 * r['eps_peak']:.2f} | {100 * r['eps_end']:.2f} | "
                     f"{r['recovered']:.2f} | {r['loop']:.1f} | {r['loop'] / r['w_load']:.2f} | "
                     f"{r['inertial_max']:.1e} | {float(rows[s]['seconds']):.0f} |")
    lines.append("")
    lines.append("Measured (after the run), against the pre-set criteria:\n")
    lines.append(f"- Quasi-static (I < 1e-3 over both ramps, 0.05 s windows): largest I = "
                 f"{tet['inertial_max']:.1e} (tetrahedra), {sph['inertial_max']:.1e} (spheres): {verdict(quasi)}; "
                 f"I reached 1e-3 {inertial_note(tet, sc)} (tetrahedra), {inertial_note(sph, sc)} (spheres), "
                 f"below 1e-3 everywhere else. "
                 f"Before loading the stress stayed below {max(tet['sigma_before'], sph['sigma_before']):.0f} Pa "
                 f"(the seating target is {sc['seat_stress']:.0f} Pa: no pre-load beyond it when this is close to it).")
    lines.append(f"- 1. Hysteresis (unloading strain above loading strain at 20-90 % of the peak stress, 8 levels): "
                 f"tetrahedra {verdict(tet['hysteresis'], quasi)} (gap {100 * np.min(tet['e_unload'] - tet['e_load']):.2f} to "
                 f"{100 * np.max(tet['e_unload'] - tet['e_load']):.2f} % strain); loop area {tet['loop']:.1f} J/m^3, "
                 f"{100 * tet['loop'] / tet['w_load']:.0f} % of the loading work.")
    lines.append(f"- 2. Recovered fraction of the peak strain within 0.5-0.8: tetrahedra {tet['recovered']:.2f}, "
                 f"{verdict(0.5 <= tet['recovered'] <= 0.8, quasi)}.")
    lines.append(f"- 3. Spheres recover less than tetrahedra: spheres {sph['recovered']:.2f} against "
                 f"{tet['recovered']:.2f}, {verdict(sph['recovered'] < tet['recovered'], quasi)}; sphere loop area "
                 f"{sph['loop']:.1f} J/m^3 ({100 * sph['loop'] / sph['w_load']:.0f} % of its loading work), "
                 f"hysteresis {'present' if sph['hysteresis'] else 'not present at every level'}.")
    note = os.path.join(run, "oedometer_note.md")  # how this run differs from the plan, when it does
    if os.path.exists(note):
        lines += ["", open(note).read().strip()]
    return "\n".join(lines) + "\n"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    run, docs = sys.argv[1], sys.argv[2]
    text = section(run, docs)
    path = os.path.join(docs, "validation.md")
    doc = open(path).read()
    if START not in doc:  # first run: the section goes before the agreement section
        marker = "<!-- section: agreement -->\n"
        doc = doc.replace(marker, START + END + marker) if marker in doc else doc + START + END
        with open(path + ".tmp", "w") as f:
            f.write(doc)
        os.replace(path + ".tmp", path)
    replace_between(path, START, END, text)
    print(text)


if __name__ == "__main__":
    main()
