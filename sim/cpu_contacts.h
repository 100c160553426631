#pragma once
// The contact stage of the CPU reference, in double precision: particle positions from the body
// poses, contact candidate lists with a skin rebuilt only when stale (sim/cpu_lists.h), and for each
// dynamic particle, visited in cell order, the forces of its touching partners (other bodies'
// particles by increasing id, then walls in declaration order), TBB-parallel and deterministic. It is
// apart from the stepper (sim/cpu_stepper.h) because both engines need it: sim::CpuStepper gathers
// its forces here, and the GPU pipeline takes from it what only the reference computes (contact
// dumps, the spring energy of a state it is given).
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/contact_model.h"
#include "sim/cpu_lists.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim {

// What one gather of a state produces, per particle in world order.
struct GatheredForces {
  std::vector<Eigen::Vector3d> force;   // N, contact force on the particle
  std::vector<Eigen::Vector3d> torque;  // N m, about the particle centre (tangential forces' arms)
  ContactSprings springs;               // the springs advanced by the step (TangentialModel::Spring only)
};

class CpuContacts {
 public:
  explicit CpuContacts(const StepSettings& settings) : settings_(settings) {}

  // Builds the material-pair table; call again when materials were added (it rebuilds only then,
  // unless `force` is set).
  void set_materials(const World& world, bool force = false);

  // One step's contact forces on `world` as it stands: forces, torques and springs into `out`,
  // contact counts, overlap statistics, clamps and elastic energy into `stats`.
  void gather(const World& world, GatheredForces& out, StepStats& stats);

  // Every contact of `world` as it stands (each particle pair once); springs are read, not advanced.
  std::vector<ContactRecord> contacts(const World& world);

  // J: the Hertz energy stored in every contact of `world` (each once), as gather() counts it.
  double elastic_energy(const World& world);

  // The next step rebuilds the lists (a new world loaded, a state restored).
  void invalidate_lists() { lists_.invalidate(); }

  // Of the state last gathered or listed: particle world positions (m) and the lists.
  const std::vector<Eigen::Vector3d>& positions() const { return position_; }
  const CpuContactLists& lists() const { return lists_; }

  // For --timings: the skin, the list builds and what they cost, candidates and contacts per particle.
  std::string report() const;

 private:
  // What a step reads of a particle, in cell order: one and a half cache lines per candidate.
  struct ParticleState {
    Eigen::Vector3d position;          // m
    Eigen::Vector3d velocity;          // m/s
    Eigen::Vector3d angular_velocity;  // rad/s, of its body
    double radius = 0;                 // m
    double inverse_mass = 0;           // 1/kg, of its body
    std::uint32_t material = 0;
  };
  // Everything one particle's gather produces.
  struct ParticleContacts {
    Eigen::Vector3d force = Eigen::Vector3d::Zero();   // N
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // N m, about the particle centre
    std::uint32_t pairs = 0, walls = 0, overlap_clamps = 0;
    std::uint32_t touching = 0;  // particle partners touching, counted here or not
    double max_overlap_ratio = 0;
    double elastic_energy = 0;  // J
    // The first smooth wall (in visiting order) the particle has passed through; -1: none.
    std::int64_t passed_wall = -1;

    void add(const ContactForce<double>& c, double smaller_radius, bool count);
  };
  // One candidate pair's contact (CandidatePairs), computed once for both sides: viscous friction
  // only, as a spring belongs to one side of a pair.
  struct PairContact {
    Eigen::Vector3d force = Eigen::Vector3d::Zero();  // N, on the first particle; the second takes -force
    Eigen::Vector3d arm_first = Eigen::Vector3d::Zero(), arm_second = Eigen::Vector3d::Zero();  // m
    double overlap_ratio = 0;   // overlap (after the clamp) / the smaller radius
    double elastic_energy = 0;  // J
    bool overlap_clamped = false;
  };
  // Particle i's spring slots: the old ones it reads and, when stepping, the new ones it writes.
  struct SpringSlots {
    const std::int64_t* old_partner = nullptr;
    const Eigen::Vector3d* old_displacement = nullptr;
    std::int64_t* new_partner = nullptr;
    Eigen::Vector3d* new_displacement = nullptr;
    std::size_t used = 0, overflows = 0;
  };

  // Particle positions and velocities from the poses, the lists rebuilt if stale, the step's state
  // in cell order.
  void prepare_particles(const World& world);
  // Calls fn(force, partner, smaller radius) for each touching partner of the particle at `slot` of
  // the cell order: other particles by increasing id, then walls.
  // With springs (TangentialModel::Spring) each touching contact takes its spring from `springs`'
  // old slots and, when its new slots are given, writes it back there, advanced.
  template <typename Fn>
  void visit_contacts(const World& world, std::uint32_t slot, Fn&& fn, SpringSlots* springs = nullptr) const;
  class SpringLookup;
  // Every touching candidate pair's contact into pair_contacts_ (no springs).
  void compute_pair_contacts();
  // Whether the two touch; if so, their contact into `out`.
  bool pair_contact(const ParticleState& first, const ParticleState& second, double cap, double rest_overlap,
                    PairContact& out) const;
  bool spheres_touch(std::uint32_t first_slot, std::uint32_t second_slot) const;
  // As ParticleContacts::add for each touching partner of the particle at `slot`, by increasing
  // partner id, the contacts read from pair_contacts_.
  void add_pair_contacts(std::uint32_t slot, ParticleContacts& out) const;
  template <typename Fn>
  void visit_neighbours(std::uint32_t slot, Fn& fn, SpringLookup& lookup) const;
  template <typename Fn>
  void visit_walls(const World& world, std::uint32_t slot, Fn& fn, SpringLookup& lookup) const;
  // Sums the per-particle results into `out_forces` and `stats`, in world order.
  void reduce(GatheredForces& out_forces, StepStats& stats);
  double overlap_ratio_cap() const;  // settings' max_overlap_ratio, or no cap
  // Slots of particle i for reading the springs of `world` (none without the spring model).
  SpringSlots read_only_slots(const World& world, std::uint32_t i) const;

  StepSettings settings_;
  std::size_t material_count_ = 0;
  std::vector<ContactCoefficients<double>> pairs_;  // material_count^2, row-major
  CpuContactLists lists_;
  // Reused from step to step, so a step allocates nothing once the sizes are reached.
  std::vector<Eigen::Vector3d> position_, velocity_;  // world order
  std::vector<ParticleState> state_;                  // cell order
  std::vector<ParticleContacts> particle_contacts_;   // world order
  // As lists_.pairs(): the pair's place in pair_contacts_, or kNotTouching. Only touching pairs keep
  // a contact (about one in five candidates on a settled bed), in pair order.
  static constexpr std::uint32_t kNotTouching = 0xffffffffu;
  std::vector<std::uint32_t> contact_of_pair_;
  std::vector<std::uint32_t> touching_pairs_;
  std::vector<PairContact> pair_contacts_;
  // Cell order, what the touching test reads: half a cache line a particle.
  struct Sphere {
    Eigen::Vector3d centre;  // m
    double radius = 0;       // m
  };
  std::vector<Sphere> sphere_;
  std::vector<std::size_t> overflows_;                // world order
  // Cell order: 0 where the particle cannot reach any smooth wall before the lists go stale (every
  // wall's gap at least its radius + the skin, when it has moved at most half the skin since the
  // build), so the walls' tests are skipped. Marked at each build, and again when the walls change.
  std::vector<std::uint8_t> near_wall_;
  Walls walls_marked_;  // the walls near_wall_ was marked for
  void mark_near_walls(const World& world);
  // For report(): steps gathered, touching particle partners summed over them (both sides of a
  // pair), and seconds spent building lists and gathering in all.
  std::size_t gathers_ = 0, touching_ = 0;
  double build_seconds_ = 0, gather_seconds_ = 0;
};

}  // namespace ts::sim
