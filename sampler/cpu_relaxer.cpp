#include "sampler/cpu_relaxer.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "core/error.h"
#include "core/morton.h"
#include "core/stopwatch.h"

namespace ts::sampler {

// The particles in work order (see spatial_order), with what relax.comp keeps per particle.
struct CpuRelaxer::State {
  std::vector<Eigen::Vector3d> positions, next;  // m, relative to voxel (0,0,0); next: the Jacobi target
  std::vector<Eigen::Vector3d> velocities;       // m, the momentum step (relax.comp's velocity)
  std::vector<std::uint8_t> mobile;
  std::vector<std::uint32_t>
      ids;  // index in the caller's list: the i < j of coincident parting, the output order
  std::vector<Eigen::Vector4d> info;  // relax.comp's step_info: |gain F_t| [m], |phi| [m], outside, mobile

  std::size_t size() const { return positions.size(); }
};

// relax.comp's uniforms.
struct CpuRelaxer::Parameters {
  double cell_size = 0.0;       // = repulsion cut-off [m]
  double inv_two_sigma2 = 0.0;  // 1 / (2 sigma^2) [1/m^2]
  double repulsion_gain = 0.0;
  double momentum = 0.0;
  double max_move = 0.0;    // m
  double band_limit = 0.0;  // m
};

// A hashed uniform grid of the particles (cells of the cut-off), rebuilt every step like the GPU's
// (common/hash_grid.glsl): buckets of Teschner's hash, a table of about twice the particle count,
// entries counting-sorted by bucket (stable, so the neighbour order is deterministic) with their
// positions copied beside them, so a bucket's particles are read contiguously.
class CpuRelaxer::NeighbourGrid {
 public:
  void build(const std::vector<Eigen::Vector3d>& positions, double cell) {
    const std::size_t n = positions.size();
    cell_ = cell;
    std::size_t table = 1;
    while (table < 2 * n) table <<= 1;
    mask_ = table - 1;
    bucket_of_.resize(n);
    tbb::parallel_for(std::size_t{0}, n,
                      [&](std::size_t i) { bucket_of_[i] = bucket(cell_of(positions[i])); });
    start_.assign(table + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++start_[bucket_of_[i] + 1];
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    cursor_.assign(start_.begin(), start_.end() - 1);
    ids_.resize(n);
    points_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t slot = cursor_[bucket_of_[i]]++;
      ids_[slot] = static_cast<std::uint32_t>(i);
      points_[slot] = positions[i];
    }
  }

  // Calls visit(j, position of j) for every particle in the 27 cells around `p`'s (and any other that
  // shares their buckets), each bucket once.
  template <class Visit>
  void for_each_near(const Eigen::Vector3d& p, Visit&& visit) const {
    const Eigen::Vector3i c = cell_of(p);
    std::array<std::uint32_t, 27> visited{};
    int visited_count = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint32_t h = bucket(c + Eigen::Vector3i(dx, dy, dz));
          // Two neighbour cells may share a hash bucket: visit each bucket once.
          if (std::find(visited.begin(), visited.begin() + visited_count, h) !=
              visited.begin() + visited_count)
            continue;
          visited[visited_count++] = h;
          for (std::uint32_t k = start_[h]; k < start_[h + 1]; ++k) visit(ids_[k], points_[k]);
        }
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>().matrix();
  }
  // common/hash_grid.glsl's hash_cell.
  std::uint32_t bucket(const Eigen::Vector3i& c) const {
    const std::uint32_t h = (static_cast<std::uint32_t>(c.x()) * 73856093u) ^
                            (static_cast<std::uint32_t>(c.y()) * 19349663u) ^
                            (static_cast<std::uint32_t>(c.z()) * 83492791u);
    return h & static_cast<std::uint32_t>(mask_);
  }

  double cell_ = 1.0;
  std::size_t mask_ = 0;
  std::vector<std::uint32_t> bucket_of_, start_, cursor_, ids_;
  std::vector<Eigen::Vector3d> points_;
};

namespace {

// The particles sorted along a Morton curve of cells of `cell` [m]: neighbours in space are then
// neighbours in memory, so the threads' blocks of particles read the same few buckets (at 10^6
// particles the positions no longer fit the cache). Particles move about a spacing in a relaxation,
// so the order found at the start stays good. The order changes no result (Jacobi steps).
std::vector<std::uint32_t> spatial_order(const std::vector<Eigen::Vector3f>& positions, double cell) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
  for (const auto& p : positions) lo = lo.cwiseMin(p.cast<double>());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(positions.size());
  tbb::parallel_for(std::size_t{0}, positions.size(), [&](std::size_t i) {
    const Eigen::Vector3d c = ((positions[i].cast<double>() - lo) / cell).array().floor();
    keyed[i] = {morton_code(static_cast<std::uint64_t>(c.x()), static_cast<std::uint64_t>(c.y()),
                       static_cast<std::uint64_t>(c.z())),
                static_cast<std::uint32_t>(i)};
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(positions.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) order[k] = keyed[k].second;
  return order;
}

}  // namespace

CpuRelaxer::CpuRelaxer(sdf::HostField field) : field_(std::move(field)) {}

// relax.comp's repulsion_at: the Gaussian repulsion on particle i from every other one within the
// cut-off [m] (unnormalised: the kernel times the separation).
Eigen::Vector3d CpuRelaxer::repulsion(const State& s, const NeighbourGrid& grid, std::size_t i,
                                      const Parameters& q) const {
  const Eigen::Vector3d& p = s.positions[i];
  const double cutoff2 = q.cell_size * q.cell_size;
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  grid.for_each_near(p, [&](std::uint32_t j, const Eigen::Vector3d& pj) {
    if (j == i) return;
    Eigen::Vector3d x = p - pj;
    const double d2 = x.squaredNorm();
    // Coincident particles feel no Gaussian force (x = 0): part them along a fixed axis, the lower id
    // one way and the higher the other; the tangential projection keeps it on the surface.
    if (d2 == 0.0) x = (s.ids[i] < s.ids[j] ? 1e-3 : -1e-3) * q.cell_size * Eigen::Vector3d(0.6, 0.48, 0.64);
    if (d2 < cutoff2) f += std::exp(-d2 * q.inv_two_sigma2) * x;
  });
  return f;
}

// relax.comp's main: particle i's step into s.next, its momentum step and its step_info.
void CpuRelaxer::move_particle(State& s, const NeighbourGrid& grid, std::size_t i, const Parameters& q,
                               sdf::FieldAccessor& accessor) const {
  const Eigen::Vector3d p = s.positions[i];
  const sdf::FieldSample sample = field_.sample(accessor, p);
  const Eigen::Vector3d& n = sample.normal;
  const double phi = sample.value;
  const double outside = std::abs(phi) >= q.band_limit ? 1.0 : 0.0;
  if (!s.mobile[i]) {
    s.next[i] = p;
    s.info[i] = Eigen::Vector4d(0.0, std::abs(phi), outside, 0.0);
    return;
  }
  Eigen::Vector3d f = repulsion(s, grid, i, q);
  f = q.repulsion_gain * (f - f.dot(n) * n);
  // Heavy-ball momentum with per-particle adaptive restart (momentum against the force is dropped),
  // kept tangential; the attraction -phi n is not accumulated.
  const Eigen::Vector3d& v_old = s.velocities[i];
  Eigen::Vector3d v = f;
  if (v_old.dot(f) > 0.0) v = q.momentum * v_old + f;
  v -= v.dot(n) * n;
  Eigen::Vector3d move = v - phi * n;
  const double length_move = move.norm();
  if (length_move > q.max_move) {  // the CFL guard
    move *= q.max_move / length_move;
    v *= q.max_move / length_move;
  }
  s.velocities[i] = v;
  s.next[i] = p + move;
  s.info[i] = Eigen::Vector4d(f.norm(), std::abs(phi), outside, 1.0);
}

// One Jacobi step: the grid rebuilt, every particle moved from the positions before the step.
void CpuRelaxer::step(State& s, const Parameters& q, NeighbourGrid& grid) {
  timed(grid_seconds_, [&] { grid.build(s.positions, q.cell_size); });
  timed(step_seconds_, [&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, s.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
          sdf::FieldAccessor accessor = field_.accessor();  // one per task: it caches the last nodes read
          for (std::size_t i = r.begin(); i != r.end(); ++i) move_particle(s, grid, i, q, accessor);
        });
  });
  std::swap(s.positions, s.next);
}

// reduce_steps.comp's sums, in double and in order.
CpuRelaxer::StepSums CpuRelaxer::check(const State& s) const {
  StepSums sums;
  for (const Eigen::Vector4d& info : s.info)
    sums.moved += info.x(), sums.outside += info.z(), sums.moving += info.w();
  return sums;
}

// project.comp: p <- p - phi grad(phi), mobile particles only.
void CpuRelaxer::project(State& s, int steps) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      sdf::FieldAccessor accessor = field_.accessor();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        if (!s.mobile[i]) continue;  // frozen: already on the exact surface
                        for (int k = 0; k < steps; ++k) {
                          const sdf::FieldSample sample = field_.sample(accessor, s.positions[i]);
                          s.positions[i] -= sample.value * sample.normal;
                        }
                      }
                    });
}

namespace {

// Drops the particles that left the band (info.z set) and clears every momentum step, as the GPU
// relaxer's re-upload does.
template <class State>
std::size_t remove_outside(State& s) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.info[i].z() != 0.0) continue;
    s.positions[kept] = s.positions[i];
    s.mobile[kept] = s.mobile[i];
    s.ids[kept] = s.ids[i];
    ++kept;
  }
  const std::size_t removed = s.size() - kept;
  s.positions.resize(kept);
  s.mobile.resize(kept);
  s.ids.resize(kept);
  s.next.resize(kept);
  s.info.resize(kept);
  s.velocities.assign(kept, Eigen::Vector3d::Zero());
  return removed;
}

}  // namespace

// The caller's particles in work order (spatial_order), at rest.
CpuRelaxer::State CpuRelaxer::load(const std::vector<Eigen::Vector3f>& positions,
                                   const std::vector<std::uint8_t>* mobile, double cell) {
  State s;
  s.ids = spatial_order(positions, cell);
  const std::size_t n = positions.size();
  s.positions.resize(n);
  s.mobile.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    s.positions[k] = positions[s.ids[k]].cast<double>();
    s.mobile[k] = mobile == nullptr || (*mobile)[s.ids[k]] ? 1 : 0;
  }
  s.next.resize(n);
  s.velocities.assign(n, Eigen::Vector3d::Zero());
  s.info.resize(n);
  return s;
}

// The survivors back in the caller's order (their ids increase as their indices did), as floats.
void CpuRelaxer::store(const State& s, std::vector<Eigen::Vector3f>& positions,
                       std::vector<std::uint8_t>* mobile) {
  std::vector<std::size_t> back(s.size());
  std::iota(back.begin(), back.end(), std::size_t{0});
  std::sort(back.begin(), back.end(), [&](std::size_t a, std::size_t b) { return s.ids[a] < s.ids[b]; });
  positions.resize(s.size());
  if (mobile) mobile->resize(s.size());
  for (std::size_t m = 0; m < back.size(); ++m) {
    positions[m] = s.positions[back[m]].cast<float>();
    if (mobile) (*mobile)[m] = s.mobile[back[m]];
  }
}

RelaxStats CpuRelaxer::run(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                           const RelaxProgress& progress, std::vector<std::uint8_t>* mobile) {
  if (!(settings.spacing > 0.0)) throw InputError("sampler spacing must be positive");
  if (mobile && mobile->size() != positions.size())
    throw Error(ExitCode::Internal, "relax: mobile mask size");
  const double sigma = settings.sigma_over_spacing * settings.spacing;
  const double cutoff = sigma * std::sqrt(2.0 * std::log(1.0 / settings.kernel_epsilon));
  const Parameters q{cutoff,
                     1.0 / (2.0 * sigma * sigma),
                     settings.repulsion_gain,
                     settings.momentum,
                     settings.max_move_over_cell * cutoff,
                     settings.band_limit};

  State s = load(positions, mobile, cutoff);
  RelaxStats stats;
  NeighbourGrid grid;
  while (stats.iterations < settings.max_iterations && s.size() > 0) {
    step(s, q, grid);
    ++stats.iterations, ++iterations_run_;
    if (stats.iterations % settings.check_every != 0 && stats.iterations < settings.max_iterations) continue;

    const auto start = std::chrono::steady_clock::now();
    ++stats.checks, ++checks_run_;
    const StepSums sums = check(s);
    stats.mean_move_over_spacing = sums.moving > 0.0 ? sums.moved / sums.moving / settings.spacing : 0.0;
    if (progress) progress(stats.iterations, s.size(), stats.mean_move_over_spacing);
    if (sums.outside > 0.0) stats.removed += remove_outside(s);
    check_seconds_ += seconds_since(start);
    if (stats.mean_move_over_spacing < settings.tolerance) {
      stats.converged = true;
      break;
    }
  }
  timed(project_seconds_, [&] { project(s, settings.projection_steps); });

  store(s, positions, mobile);
  return stats;
}

std::vector<gpu::HostSyncPhase> CpuRelaxer::round_trips() const {
  return {{"relaxation iterations between checks", {}, iterations_run_, "iteration"},
          {"convergence checks", {}, checks_run_, "check"},
          {"relaxation in all (on the CPU: no GPU work)", {}, 0, ""}};
}

std::string CpuRelaxer::timing_report() {
  return fmt::format(
      "CPU relaxation ({} threads): {} iterations, {} checks; neighbour grid {:.3f} s, steps {:.3f} s, "
      "checks and band removals {:.3f} s, projection {:.3f} s\n",
      tbb::info::default_concurrency(), iterations_run_, checks_run_, grid_seconds_, step_seconds_,
      check_seconds_, project_seconds_);
}

}  // namespace ts::sampler
