// Binding slots of the simulator's kernels, named once for GLSL and C++ (sim/gpu_stepper.cpp).
// The state buffers (TS_SIM_PARTICLE_* .. TS_SIM_STAT_PARTIALS, 0-25) are one structure of arrays, one
// vec4 (or uvec4) buffer per quantity, bound together by GpuStepper::bind_state before each step's
// kernels. The re-sort's scratch buffers (TS_SIM_RESORT_*, TS_SIM_GATHER_*) reuse low slots only in
// their own passes, which bind them first. The preview renderer, which shares the context in
// `tetrasand sim`, keeps clear of every slot here (shaders/preview/bindings.h); tests/gpu/
// bindings_test.cpp checks that, that no kernel uses a bare number and that no two names of one
// pass share a slot. The hashed grid's slots are in shaders/common/bindings.h.
//
//   pass (kernel)                 slots
//   sim/update_particles.comp     PARTICLE_POSITION, _VELOCITY, _INFO, _LOCAL, _POSITION_EXACT (fp64),
//                                 BODY_POSITION, _ORIENTATION, _VELOCITY, _OMEGA, BUILD_POSITION, LIST_STATE
//   sim/list_decide.comp          LIST_STATE, LIST_PLAN, LIST_ARGS, COUNTERS
//   common/grid_* (the grid)      TS_GRID_POSITIONS = PARTICLE_POSITION, TS_SORT_* (1-5), TS_FILL_*, TS_COPY_*
//   sim/list_build.comp           PARTICLE_POSITION, _INFO, BODY_POSITION, LIST, BUILD_POSITION, COUNTERS,
//                                 TS_GRID_CELL_START, TS_GRID_SORTED
//   sim/contact_forces.comp       PARTICLE_POSITION, _VELOCITY, _INFO, _WRENCH, _STATS, _POSITION_EXACT
//                                 (fp64), BODY_POSITION, _OMEGA, PAIRS, PLANES, CYLINDERS, COUNTERS,
//                                 SPRINGS, LIST, TS_GRID_CELL_START, TS_GRID_SORTED
//   sim/integrate_bodies.comp     BODY_POSITION, _ORIENTATION, _VELOCITY, _OMEGA, _INV_INERTIA, _RANGE,
//                                 _MOMENTUM, PARTICLE_WRENCH, COUNTERS, KEYFRAMES
//   sim/reduce_metrics.comp       BODY_POSITION, _VELOCITY, _OMEGA, _MOMENTUM, METRIC_PARTIALS
//   sim/reduce_particle_stats.comp PARTICLE_STATS, STAT_PARTIALS
//   sim/resort_keys.comp          BODY_POSITION, TS_SORT_KEY, TS_SORT_BUCKET_COUNT, TS_SORT_SLOT
//   sim/resort_ranges.comp        RESORT_ORDER, BODY_RANGE, RESORT_NEW_FIRST
//   sim/resort_particles.comp     RESORT_ORDER, RESORT_NEW_FIRST, BODY_RANGE, RESORT_NEW_RANGE,
//                                 RESORT_SOURCE, RESORT_DESTINATION, RESORT_OWNER
//   sim/gather_rows.comp          GATHER_SOURCE, GATHER_DESTINATION, GATHER_INDEX
//   sim/resort_fixup.comp         PARTICLE_INFO, RESORT_DESTINATION, RESORT_OWNER, SPRINGS
//   sim/resort_bonds.comp         BOND_PAIR, RESORT_DESTINATION
//   sim/bond_forces.comp          PARTICLE_POSITION, _VELOCITY, _INFO, _POSITION_EXACT (fp64), BODY_OMEGA,
//                                 BOND_PAIR, _STATE, _PARAMS, _LOAD, COUNTERS, LIST_STATE
//   sim/bond_sums.comp            PARTICLE_POSITION, _INFO, _WRENCH, _POSITION_EXACT (fp64), BODY_POSITION,
//                                 BOND_PAIR, _CSR, _LOAD
//   sim/bond_energy.comp          BOND_PAIR, _STATE, _ENERGY_FACTORS, _ENERGY_PARTIALS (statistics only)
// list_build.comp also binds BOND_PAIR and BOND_CSR (intact bonded pairs are no contact candidates),
// contact_forces.comp (TS_CONTACT_BONDS) BOND_CSR (a broken bond's pair meets past its rest overlap).
#ifndef TETRASAND_SIM_BINDINGS_H
#define TETRASAND_SIM_BINDINGS_H

// Uniform-block slot (a namespace of its own in GL) of each kernel's parameter struct
// (shaders/common/params.h), bound by gpu::ParamBlock::bind right before the kernel runs.
#define TS_SIM_PARAMS 0

// Aliases of shaders/common/bindings.h names (TS_SORT_*) expand where they are used: a user includes
// both headers.

// ---- State: one buffer per quantity (structure of arrays). real4 = vec4, or dvec4 with TS_FP64.
#define TS_SIM_PARTICLE_POSITION 0   // vec4: xyz world position [m]; w: radius [m] (= TS_GRID_POSITIONS)
#define TS_SIM_PARTICLE_VELOCITY 6   // real4: xyz velocity of the sphere centre [m/s]
#define TS_SIM_PARTICLE_INFO 7       // uvec4: x body index, y material index, z world particle id
#define TS_SIM_PARTICLE_LOCAL 8      // real4: xyz offset from the body's centre of mass in its frame [m]; w: radius [m]
#define TS_SIM_BODY_POSITION 9       // real4: xyz centre of mass [m]; w: inverse mass [1/kg] (0 unless dynamic)
#define TS_SIM_BODY_ORIENTATION 10   // real4: unit quaternion (x, y, z, w); body axes = principal axes
#define TS_SIM_BODY_VELOCITY 11      // real4: xyz [m/s]; w: motion type (TS_MOTION_*)
#define TS_SIM_BODY_OMEGA 12         // real4: xyz angular velocity [rad/s] (derived from the momentum)
#define TS_SIM_BODY_INV_INERTIA 13   // 3 real4 per body: rows of I0^-1 (body frame) [1/(kg m^2)]; row 0 w: bounding radius [m]
#define TS_SIM_BODY_RANGE 14         // uvec4: x first particle, y particle count, z first keyframe, w keyframe count (0: none)
// 2 real4 per particle (one buffer, so the contact kernel stays within 16 storage blocks): [2i] xyz
// contact force on the particle [N]; [2i + 1] xyz its torque about the body's centre of mass [N m].
#define TS_SIM_PARTICLE_WRENCH 15
#define TS_SIM_SPRINGS 16            // SimSpringSlots (SimSpringSlots64 with TS_FP64) per particle
#define TS_SIM_PAIRS 17              // SimPair[material_count^2]
#define TS_SIM_PLANES 18             // SimPlane[]
#define TS_SIM_CYLINDERS 19          // SimCylinder[]
#define TS_SIM_PARTICLE_STATS 20     // vec4: x pair contacts (counted by the lower id), y wall contacts, z largest overlap / smaller radius, w overlap clamps
// uint[]: 0 velocity clamps, 1 angular velocity clamps, 2 spring slot overflows, then the wall
// penetrations (TS_SIM_COUNTER_*): a count, and per smooth wall (planes, then cylinders) ~id of the
// lowest world particle id found wholly behind it, under atomicMax (0: none).
#define TS_SIM_COUNTERS 21
#define TS_SIM_BODY_MOMENTUM 22      // real4: xyz angular momentum [kg m^2/s] (world frame)
#define TS_SIM_PARTICLE_POSITION_EXACT 23  // dvec4 (TS_FP64 only): the particle position before rounding to float [m]
#define TS_SIM_METRIC_PARTIALS 24    // dvec4 per 256 bodies: kinetic translational, rotational, potential [J], non-finite bodies
#define TS_SIM_STAT_PARTIALS 25      // vec4 per 256 particles: TS_SIM_PARTICLE_STATS summed (z: max)
#define TS_SIM_KEYFRAMES 26          // 2 real4 per key of a kinematic track (sim::Keyframe): xyz centre of mass [m], w time [s]; quaternion (x, y, z, w)

// Entries of TS_SIM_COUNTERS after the three clamp and overflow counts.
#define TS_SIM_COUNTER_PENETRATIONS 3     // particle-steps of a dynamic particle wholly behind a smooth wall
#define TS_SIM_COUNTER_LIST_BUILDS 4      // contact list builds (list_decide.comp)
#define TS_SIM_COUNTER_LIST_OVERFLOWS 5   // particles found with more than K candidates, summed over builds
#define TS_SIM_COUNTER_BONDS_BROKEN 6     // bonds broken (bond_forces.comp)
// Particles whose candidates overflowed the list and whose intact bonded partners did not fit in the
// list's rows either (list_build.comp): their contact walk would meet a bonded pair; a run stops.
#define TS_SIM_COUNTER_BOND_EXCLUSIONS_LOST 7
#define TS_SIM_COUNTER_WALL_SLOTS 8       // the first per-wall slot

// ---- Contact candidate lists (sim/contact_lists.h; GpuStepper::rebuild_lists). LIST and
// BUILD_POSITION share slots with the statistics' partials, which only their own passes bind; the
// decision's buffers reuse low slots that the grid passes after it bind for themselves.
#define TS_SIM_LIST 24               // uint[(K + 1) N], column-major: [i] count, [(k + 1) N + i] candidate k (list_build.comp)
// Set in a listed candidate whose bond with the particle broke (the rest of the word is its GPU index):
// only for such pairs does the contact kernel look up the bond's rest overlap (list_build.comp).
#define TS_SIM_LIST_BROKEN_BOND 0x80000000u
#define TS_SIM_BUILD_POSITION 25     // vec4 per particle: TS_SIM_PARTICLE_POSITION at the last list build
#define TS_SIM_LIST_STATE 1          // uint[2]: TS_SIM_LIST_MAX_DISPLACEMENT, TS_SIM_LIST_FORCED
#define TS_SIM_LIST_PLAN 2           // uvec4 per rebuild dispatch: its work groups x, y, z (gpu::Queue::end_indirect)
#define TS_SIM_LIST_ARGS 3           // uvec4 per rebuild dispatch: the plan's row or zeros (read by glDispatchComputeIndirect)
#define TS_SIM_LIST_MAX_DISPLACEMENT 0  // float bits: the largest distance a particle moved since the last build [m]
#define TS_SIM_LIST_FORCED 1            // 1: rebuild at the next step whatever the displacement

// ---- Bonds of breakable props (sim/bonds.h, sim/bond_model.h; GpuStepper's bond passes in
// sim/gpu_bonds.cpp). GPU bond k is the world's bond k (BondSet order, ascending (a, b) world ids),
// whatever the re-sort does to the particles. The bond passes (resort_bonds, bond_forces, bond_sums)
// and list_build bind these on slots that no other buffer of those passes uses; every pass after them
// rebinds the state (GpuStepper::bind_state).
#define TS_SIM_BOND_PAIR 2    // uvec4 per bond: x GPU index of sphere a, y of sphere b (renamed at each re-sort), z 1 while intact, w unused
// uint[]: [w], w <= N (world particles): where world particle w's entries start; entry e is 3 uints
// from N + 1 + 3e: the bond's index, the partner's world particle id, and the bond's rest overlap
// (float bits, m; sim::BondSet::rest_overlap). Each particle's bonds in ascending index (the sums'
// fixed order). Static: a re-sort leaves it valid.
#define TS_SIM_BOND_CSR 3
#define TS_SIM_BOND_CSR_STRIDE 3
// 2 real4 per bond (sim::BondState): [2k] xyz shear force [N], w normal force [N] (> 0 compression);
// [2k + 1] xyz bending moment [N m], w twisting moment [N m]. Zero once broken.
#define TS_SIM_BOND_STATE 4
// 2 real4 per bond (sim::BondGeometry and the bond's strengths): [2k] area [m^2], bending inertia I
// [m^4], polar inertia J [m^4], bond radius [m]; [2k + 1] k_n, k_s [Pa/m], tensile, shear strength [Pa].
#define TS_SIM_BOND_PARAMS 5
// 4 real4 per bond, this step's load (sim::BondLoad): [4k] force on a [N], [4k + 1] moment on a [N m],
// [4k + 2] arm from a's centre to the bond's centre [m], [4k + 3] the same from b's. Zero when broken.
#define TS_SIM_BOND_LOAD 8
// The bonds' energy reduction (sim/bond_energy.comp, run by statistics()), on the slots of BOND_PARAMS
// and BOND_LOAD, which that pass does not bind. dvec4 per bond, the factors 1 / (2 stiffness) of
// sim::bond_energy's four springs: x 1 / (2 k_n A), y 1 / (2 k_s A), z 1 / (2 k_s J), w 1 / (2 k_n I)
// [J/N^2, J/N^2, J/(N m)^2, J/(N m)^2].
#define TS_SIM_BOND_ENERGY_FACTORS 5
// double per 256 bonds, each work group's energy [J], then the total [J] after them (read back).
#define TS_SIM_BOND_ENERGY_PARTIALS 8

// ---- Re-sort by Morton key (GpuStepper::resort): the keys go through gpu::BucketSort (TS_SORT_*).
#define TS_SIM_RESORT_ORDER TS_SORT_SORTED  // uint per new body: its old index (the sort's output)
#define TS_SIM_RESORT_NEW_FIRST 6           // uint per new body: its first particle in the new order
#define TS_SIM_RESORT_NEW_RANGE 1           // uvec4 per new body: its new TS_SIM_BODY_RANGE row
#define TS_SIM_RESORT_SOURCE 2              // uint per new particle: its old index
#define TS_SIM_RESORT_DESTINATION 3         // uint per old particle: its new index
#define TS_SIM_RESORT_OWNER 4               // uint per new particle: its new body
// Row gather (gather_rows.comp): destination row r = source row index[r], rows of `width` uvec4.
#define TS_SIM_GATHER_SOURCE 1
#define TS_SIM_GATHER_DESTINATION 2
#define TS_SIM_GATHER_INDEX 3

#endif
