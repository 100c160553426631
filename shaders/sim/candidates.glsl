// A particle's contact candidates in ascending GPU index, walked from the hashed grid of the last
// list build (gpu::HashGrid): the 27 cells around `cell`, each distinct non-empty bucket once (two of
// the 27 cells that hash to one bucket would otherwise give its particles twice), merged by index.
// The ascending order makes the list, and every sum taken over it, the same whatever the positions
// the lists were built at, so a rebuild at another step (a resumed checkpoint) changes no bit.
// Buckets also hold particles of far cells (hash collisions): callers test the distance.
// The includer declares cell_start[] and sorted_ids[] (TS_GRID_CELL_START, TS_GRID_SORTED) first.
#ifndef TETRASAND_SIM_CANDIDATES_GLSL
#define TETRASAND_SIM_CANDIDATES_GLSL
#include "common/hash_grid.glsl"

#define TS_SIM_WALK_DONE 0xFFFFFFFFu  // no candidate left (particle ids are below it)

// The walk's state: one lane per distinct bucket, its next position in sorted_ids, its end, and the
// id at that position (the merge compares these heads only).
uint walk_next[27], walk_end[27], walk_head[27];
uint walk_lanes = 0u;

void begin_walk(ivec3 cell, uint table_size, uint particles) {
  walk_lanes = 0u;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        uint h = hash_cell(cell + ivec3(dx, dy, dz), table_size);
        // A bucket ends where the next begins (the last one at the particle count).
        uint begin = cell_start[h], end = h + 1u < table_size ? cell_start[h + 1u] : particles;
        if (begin == end) continue;
        // Non-empty buckets start at distinct places, so the start names the bucket.
        bool seen = false;
        for (uint l = 0u; l < walk_lanes; ++l) seen = seen || walk_next[l] == begin;
        if (seen) continue;
        walk_next[walk_lanes] = begin;
        walk_end[walk_lanes] = end;
        walk_head[walk_lanes] = sorted_ids[begin];
        ++walk_lanes;
      }
}

// The next candidate in ascending index, or TS_SIM_WALK_DONE. Ids ascend within a bucket
// (common/grid_sort_cells.comp), so the smallest head is the smallest id left.
uint next_candidate() {
  uint best = TS_SIM_WALK_DONE, lane = 0u;
  for (uint l = 0u; l < walk_lanes; ++l) {
    if (walk_head[l] < best) {
      best = walk_head[l];
      lane = l;
    }
  }
  if (best == TS_SIM_WALK_DONE) return best;
  ++walk_next[lane];
  walk_head[lane] = walk_next[lane] < walk_end[lane] ? sorted_ids[walk_next[lane]] : TS_SIM_WALK_DONE;
  return best;
}
#endif
