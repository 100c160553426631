#!/usr/bin/python3
"""The rules of bench/defaults_criteria.md as bench/defaults.py applies them, without its runs: the
tables it reads are still in the benchmark pages (docs/benchmarks/*.md) and docs/validation.md in the shape it
parses, the
committed figures meet the rules they met, and figures that break a rule make it fail.
Usage: defaults_rules_test.py ROOT. Exit status 0 when every check holds."""
import os
import sys

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import defaults  # noqa: E402

failures = []


def check(ok, what):
    print(("ok:   " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def verdict(rows, name):
    return next(m for n, _, m in rows if n.startswith(name))


doc = defaults.benchmark_pages(os.path.join(ROOT, "docs"))
validation = open(os.path.join(ROOT, "docs", "validation.md")).read()
energy, restitution, trade = defaults.energy_rows(doc), defaults.restitution_rows(doc), defaults.sampler_trade_rows(doc)
tsuji = defaults.tsuji_spread(validation)
check(any(r[1] == 1 for r in energy) and len(energy) >= 3, "the energy table has rows at dt / bound = 1")
check(any(r[0] == 1 and r[2] is not None for r in restitution), "the restitution table has symplectic at dt / bound = 1")
check(any(r[0] == 12 for r in trade), "the sampler trade table has the default --rounds 12")

committed = defaults.verdicts(energy, restitution, trade, tsuji, [], [])
for name in ("sim `dt", "integrator", "GPU precision", "normal damping", "sampler `--rounds", "sampler `--max-iter"):
    check(verdict(committed, name) is True, f"committed figures: {name} meets its rule")

# A symplectic restitution 8 % off at the automatic step breaks the dt and the integrator rules.
off = [(f, fwd, 0.70 if f == 1 else sym) for f, fwd, sym in restitution]
broken = defaults.verdicts(energy, off, trade, tsuji, [], [])
check(verdict(broken, "sim `dt") is False, "restitution 0.70 at the bound fails the dt rule")
check(verdict(broken, "integrator") is False, "restitution 0.70 at the bound fails the integrator rule")

# Float drifting 2x double's fails the precision rule.
drifting = [(e, f, [err[0], 2.0 * err[2], err[2]], ovl) for e, f, err, ovl in energy]
check(verdict(defaults.verdicts(drifting, restitution, trade, tsuji, [], []), "GPU precision") is False,
      "float drift 2x double's fails the precision rule")

# The relaxation hitting its cap fails the iterations rule.
capped = [(rounds, cap, cap, s, c) for rounds, cap, _, s, c in trade]
check(verdict(defaults.verdicts(energy, restitution, capped, tsuji, [], []), "sampler `--max-iter") is False,
      "iterations at the cap fail the iterations rule")


def bands(t3, m3, err=1e-5):
    return [dict(resolution=128, band=b, seconds=t3 if b == 3 else 1.0, peak_mib=m3 if b == 3 else 1.0,
                 band_voxels=0, nanovdb_mib=0, max_error=err) for b in (1, 2, 3, 5)]


check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, [], bands(1.2, 1.1)), "`sdf --band") is True,
      "band 3 at 1.2x band 1's time meets the band rule")
check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, [], bands(2.0, 1.1)), "`sdf --band") is False,
      "band 3 at 2x band 1's time fails the band rule")
check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, [], bands(1.2, 1.1, 2e-3)), "`sdf --band") is False,
      "an error of 2e-3 voxel fails the band rule")


def voxels(rho_r, sec_r, certified_half=True):
    rows = []
    for f, rho, sec in ((1.0, rho_r, sec_r), (0.5, 0.80, 10.0), (0.25, 0.80, 14.0)):
        rows.append(dict(mesh="m", voxel_over_r=f, n=1, seconds=sec, c_over_r=0.95, rho=rho, converged=True,
                         certified=certified_half if f == 0.5 else True, bound_over_r=0.97))
    return rows


check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, voxels(0.75, 10.0), []), "sampler voxel") is True,
      "r / 2 certified, r no faster: the voxel rule is met")
check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, voxels(0.80, 5.0), []), "sampler voxel") is False,
      "a voxel of r as good and twice as fast fails the r / 2 rule")
check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, voxels(0.75, 10.0, False), []), "sampler voxel") is False,
      "r / 2 not certified fails the voxel rule")



def counts(verdicts_by_mesh):
    """Count-sweep rows: {mesh: [verdict at 1000, 2000, 4000, 8000, 16000]}."""
    return [dict(mesh=m, count=c, verdict=v) for m, vs in verdicts_by_mesh.items() for c, v in zip(defaults.COUNTS, vs)]


OK, CAV, BAD = "body OK", "usable with caveats", "not usable"
pick = defaults.count_rule(counts({"bunny": [CAV, OK, OK, OK, OK], "dino": [BAD, CAV, CAV, CAV, CAV]}))
check(pick[0] == 2000 and pick[2] is (defaults.DEFAULT_COUNT == 2000), "everything settled at 2000: the rule picks 2000")
pick = defaults.count_rule(counts({"bunny": [CAV, CAV, OK, OK, OK], "dino": [BAD, CAV, CAV, CAV, CAV]}))
check(pick[0] == 4000, "the bunny OK from 4000, the dino caveats throughout: the rule picks 4000")
pick = defaults.count_rule(counts({"bunny": [CAV, CAV, OK, OK, OK], "dino": [BAD, CAV, CAV, OK, OK]}), 4000)
check(pick[0] == 8000 and pick[2] is (defaults.DEFAULT_COUNT == 8000) and "changed from 4000" in pick[1],
      "the dino OK from 8000: doubling buys a verdict, so the rule picks 8000 (and names the run's default)")
pick = defaults.count_rule(counts({"bunny": [CAV, CAV, OK, OK, OK], "knot1": [CAV] * 5}))
check(pick[0] is None and pick[2] is False, "a mesh other than the dino never OK: no count meets the rule")
pick = defaults.count_rule(counts({"bunny": [CAV, OK, OK, CAV, OK]}))
check(pick[0] == 2000, "a worse verdict at a larger count does not block a smaller one")
settles_at_default = [CAV if c < defaults.DEFAULT_COUNT else OK for c in defaults.COUNTS]
check(verdict(defaults.verdicts(energy, restitution, trade, tsuji, [], [], counts({"bunny": settles_at_default})),
              "`sample` count") is True, "the count row of the verdicts follows the rule")


def radius_map(two, small=20000, default=4000):
    return dict(default=dict(n=default), small=dict(n=small), two_radius_most=two)


measures, end_to_end, _ = defaults.radius_map_rule(radius_map(4500), False, True)
check(measures and not end_to_end, "a cheap two-radius body measures well, but not end to end without body radii")
check(not defaults.radius_map_rule(radius_map(6000), True, True)[0], "30 % of the global radius's count: not well")
check(not defaults.radius_map_rule(radius_map(17000, small=100000), True, True)[0], "over 4x the default: not well")
v = defaults.verdicts(energy, restitution, trade, tsuji, [], [], None, radius_map(4500), (True, True))
check(verdict(v, "no radius map") is False, "measuring well end to end: not offering it fails the rule")
check(defaults.per_particle_radii(ROOT)[1] is True, "the sim's particles carry one radius each (sim/world.h)")

sys.exit(1 if failures else 0)
