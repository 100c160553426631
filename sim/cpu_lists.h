#pragma once
// The CPU reference's contact candidate lists (Verlet lists, the rule of sim/contact_lists.h) and the
// cell order it visits particles in. At a build: a hashed grid with cell = largest diameter + skin,
// particles sorted by the Morton code of their cell (neighbours in space become neighbours in memory),
// and for each particle that can receive a force (its body's inverse mass > 0) the other bodies'
// particles whose surfaces are within the skin of its own. Between builds a step only evaluates the
// lists; they are rebuilt once some particle has moved more than skin / 2 since the build.
//
// Each list is sorted by partner world id, so a particle's forces are summed in increasing partner id
// whatever the build they come from: when the lists were built changes no bit of a result, which keeps
// the CPU reference deterministic across thread counts and checkpoints resumable bit for bit without
// saving the lists. The World and its numbering are never touched: the cell order is a view beside it.
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim {

// The hashed uniform grid: a table of next_pow2(max(2 N, 4)) buckets filled by counting sort in
// particle order, so a bucket lists its particles by increasing id.
struct NeighbourGrid {
  double cell_size = 0;                     // m
  std::uint32_t table_size = 0;             // power of two
  std::vector<Eigen::Vector3i> cell;        // per particle
  std::vector<std::uint32_t> bucket_start;  // table_size + 1 entries
  std::vector<std::uint32_t> sorted;        // particle ids grouped by bucket
};
void build_neighbour_grid(const std::vector<Eigen::Vector3d>& positions, double cell_size,
                          NeighbourGrid& grid);
// x + P1 y + P2 z modulo the table (Teschner et al. 2003 with the x factor set to 1): cells next to
// each other along x get consecutive buckets, so a particle's 27 neighbour cells are 9 contiguous
// scans. (The GPU grid of shaders/common/hash_grid.glsl keeps Teschner's XOR hash; the two grids
// need not agree.)
std::uint32_t hash_cell(const Eigen::Vector3i& cell, std::uint32_t table_size);

// One candidate of a particle's list.
struct ListEntry {
  std::uint32_t slot = 0;      // the partner's place in cell order (where a step keeps its state)
  std::uint32_t particle = 0;  // the partner's world id (the order forces are summed in)
  std::uint32_t pair = 0;      // the pair's index in CpuContactLists::pairs()
  bool first = false;          // whether this list's particle is the pair's first
};

// Every candidate pair once (half lists, as LAMMPS's "newton on"), so that a step computes each
// contact once and applies it to both sides. The first particle of a pair is the side that counts the
// contact in the statistics: the lower world id of two particles that take a force, else the one that
// does. Pairs are grouped by their first particle, in cell order. Slots of the cell order.
struct CandidatePairs {
  std::vector<std::uint32_t> first, second;
  // m, per pair: the rest overlap of a broken bond between the two (RestOverlaps), found once at the
  // build instead of by a search a step; empty (every pair 0) when no broken bond has one.
  std::vector<double> rest_overlap;
  double rest_overlap_of(std::uint32_t pair) const { return rest_overlap.empty() ? 0.0 : rest_overlap[pair]; }
  std::size_t size() const { return first.size(); }
};

class CpuContactLists {
 public:
  // Whether the lists may miss a touching pair of `positions` (world order, m): never built (or
  // invalidated), built for another particle count, or some particle has moved more than skin / 2
  // since the build (lists_need_rebuild). A non-finite displacement counts as stale.
  bool stale(const std::vector<Eigen::Vector3d>& positions) const;

  // Builds the grid, the cell order and the lists of `world` whose particles are at `positions`
  // (world order, m), with the skin choose_skin() picks from `settings` and the largest diameter.
  void build(const World& world, const std::vector<Eigen::Vector3d>& positions, const StepSettings& settings);

  // The next stale() is true (load(), new materials, a state restored from a checkpoint).
  void invalidate() { built_ = false; }

  // World ids in cell order, and where each world id sits in it.
  const std::vector<std::uint32_t>& order() const { return order_; }
  std::uint32_t slot(std::uint32_t particle) const { return slot_[particle]; }
  // The candidates of the particle at `slot` of the cell order, by increasing world id (empty for a
  // particle that receives no force).
  std::span<const ListEntry> candidates(std::uint32_t slot) const {
    return {entries_.data() + offsets_[slot], entries_.data() + offsets_[slot + 1]};
  }
  // The same candidates, each pair once; every list entry names its pair.
  const CandidatePairs& pairs() const { return pairs_; }

  double skin() const { return skin_; }                          // m
  double largest_diameter() const { return largest_diameter_; }  // m, of the last build
  std::size_t builds() const { return builds_; }                 // since construction
  std::size_t candidate_count() const { return entries_.size(); }
  std::size_t listed_particles() const { return listed_; }  // particles that receive a force
  const NeighbourGrid& grid() const { return grid_; }

 private:
  // What the search reads of each particle, in the grid's bucket order: one cache line per
  // candidate instead of scattered loads.
  struct GridEntry {
    Eigen::Vector3d position;  // m
    double radius = 0;         // m
    Eigen::Vector3i cell;
    std::uint32_t body = 0, particle = 0;
    bool receives_force = false;
  };

  void fill_grid_entries(const World& world, const std::vector<Eigen::Vector3d>& positions);
  void sort_by_cell();
  void fill_lists();
  // The half lists from the full ones: a pair for each entry on its first side, then each second
  // side's entry pointed at it.
  void fill_pairs();
  bool first_of_pair(std::uint32_t particle, std::uint32_t partner) const;
  // Calls fn(world id) for each particle of another body within the skin of `self`'s surface (and
  // not both unable to receive a force, nor bonded to it by an intact bond), in grid order.
  template <typename Fn>
  void search(const GridEntry& self, Fn&& fn) const;

  NeighbourGrid grid_;
  std::vector<GridEntry> grid_entries_;      // bucket order
  std::vector<std::uint32_t> grid_slot_;     // world id -> place in bucket order
  std::vector<std::uint32_t> order_, slot_;  // cell order -> world id, world id -> cell order
  std::vector<std::uint32_t> offsets_;       // CSR by slot: size + 1 entries
  std::vector<ListEntry> entries_;
  CandidatePairs pairs_;
  std::vector<Eigen::Vector3d> built_position_;  // m, world order, at the build
  BondedPartners bonded_;                        // of the build: pairs the contact law leaves to their bond
  RestOverlaps rest_;                            // of the build: broken bonds' pairs meet past these
  double skin_ = 0, largest_diameter_ = 0;
  std::size_t builds_ = 0, listed_ = 0;
  bool built_ = false;
};

}  // namespace ts::sim
