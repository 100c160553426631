# docs/validation.md "Bonded particles", criterion 6: criterion 4's uniaxial tension (tests/sim/
# bond_criteria_test.cpp, pull_apart) rerun in Yade's cohesive-frictional model (CohFrictMat,
# Law2_ScGeom6D_CohFrictPhys_CohesionMoment) on the same FCC cylinder, with the bonds' stiffness and
# strength carried over as forces per bond (see the criterion's result paragraph for the mapping).
# Usage: yade -n -x bench/yade_tension.py ACROSS PLANES   (Debian's yade); prints the peak stress over
# the tensile strength as tetrasand's test measures it.
import math
import sys

from yade import *  # noqa: F401,F403  (O, Sphere, ... come from Yade's own namespace)
from yade import utils

across, planes = int(sys.argv[1]), int(sys.argv[2])
r = 1e-3                      # m, as kRadius
E_bond = 1e8                  # Pa, tetrasand's bond modulus (kBondModulus)
stiffness_ratio = 2.5         # tetrasand's k_n / k_s
sigma_t = 1e5                 # Pa, tensile (= shear) strength of every bond (spread 0)
rho = 2600.0                  # kg/m^3, tetrasand's Material density
cell = 4.0 * math.sqrt(2.0) * r ** 3     # FCC volume per sphere: tetrasand's sphere mass is rho * cell
spacing = math.sqrt(2.0) * r

# The same sites as bonded_cylinder(): FCC along x, spheres within (across - 1) r of the axis.
reach = (across - 1) * r
lateral = across + 2
sites = []
for i in range(planes):
    for j in range(-lateral, lateral + 1):
        for k in range(-lateral, lateral + 1):
            if (i + j + k) % 2:
                continue
            y, z = j * spacing, k * spacing
            if math.hypot(y, z) > reach + 1e-12:
                continue
            sites.append((i * spacing, y, z))

# Stiffness and strength per bond, matched to tetrasand's parallel bond of radius r (area pi r^2):
#   normal: Yade k_n = E r for equal spheres; tetrasand k_n A = (E / 2r) pi r^2 = pi E r / 2
#   shear: Yade k_s = poisson k_n; tetrasand k_s = k_n / stiffness_ratio
#   strength: Yade breaks at F_n > normalCohesion r^2; tetrasand at F_n > sigma_t pi r^2
#   mass: Yade's sphere volume against tetrasand's lattice cell
mat = CohFrictMat(young=math.pi / 2 * E_bond, poisson=1.0 / stiffness_ratio, frictionAngle=math.atan(0.5),
                  density=rho * cell / (4.0 / 3.0 * math.pi * r ** 3), isCohesive=True,
                  normalCohesion=math.pi * sigma_t, shearCohesion=math.pi * sigma_t, momentRotationLaw=False)
O.materials.append(mat)
ids = [O.bodies.append(utils.sphere(s, r, material=mat)) for s in sites]

length = (planes - 1) * spacing
specimen_length = planes * spacing
area = len(sites) * cell / specimen_length
wave = math.sqrt(E_bond / rho)
strain_rate = (sigma_t / E_bond) / (20.0 * length / wave)   # kLoadingTransits = 20, as the test
grip_speed = 0.5 * strain_rate * length
far = set()
for b in O.bodies:
    x = b.state.pos[0]
    b.state.vel = Vector3(strain_rate * (x - 0.5 * length), 0, 0)
    near_grip, far_grip = x < 1.5 * spacing, x > length - 1.5 * spacing
    if near_grip or far_grip:
        b.state.blockedDOFs = 'xyzXYZ'
        b.state.vel = Vector3(grip_speed if far_grip else -grip_speed, 0, 0)
        if far_grip:
            far.add(b.id)

factor = 1.2  # tetrasand's bond_distance: spheres closer than 1.2 (r_a + r_b) are bonded
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=factor, label='aabb')]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=factor, label='geom')],
                    [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True, label='phys')],
                    [Law2_ScGeom6D_CohFrictPhys_CohesionMoment()]),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, 0)),
]
O.dt = 0.2 * utils.PWaveTimeStep()
O.step()
aabb.aabbEnlargeFactor = -1
geom.interactionDetectionFactor = -1
phys.setCohesionNow = False
bonds = sum(1 for i in O.interactions if i.isReal)

peak = 0.0
steps = int(3.0 * 20.0 * length / wave / O.dt)
for step in range(steps):
    O.step()
    pull = -sum(O.forces.f(i)[0] for i in far)   # N: what holds the far grip back
    peak = max(peak, pull)
    if step % 200 == 0 and peak > 0 and pull < 0.5 * peak:
        break
intact = sum(1 for i in O.interactions if i.isReal and i.phys.cohesionBroken is False)
print(f"yade tension, {across} across, {planes} planes: {len(sites)} spheres, {bonds} bonds at the start, "
      f"{intact} cohesive at the end, dt {O.dt:.3g} s, {O.iter} steps; "
      f"peak stress / tensile strength {peak / area / sigma_t:.4f}")
