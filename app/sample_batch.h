#pragma once
// `tetrasand sample`'s batch runs (a whole asset library, split across machines with no coordination): the
// input list (meshes, @LIST files, --list), --shard I/N, a failed mesh as a row of the summary CSV rather
// than the end of the batch, and the summary CSV itself.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "body/particle_body.h"

namespace ts::app {

struct BatchInputs {
  std::vector<std::string> inputs;  // meshes and @list files from the command line
  std::string list, shard, summary;
  std::string output = ".";
};

// One mesh's line of the summary CSV.
struct BatchRow {
  std::string mesh, status = "ok", error, body_json;
  std::string verdict;  // sampler::verdict_name(); empty for a failed mesh
  std::vector<std::string> verdict_reasons;
  int exit_code = 0;
  std::size_t particles = 0;
  body::ParticleBody::Quality quality;
  double radius = 0.0;
};

// The meshes of this shard, in the order of the expanded list: mesh k of the list belongs to shard k mod N,
// so `--shard I/N` for I = 0..N-1 converts every mesh exactly once. Throws on an empty list (InputError) or a
// malformed --shard (usage).
std::vector<std::string> expand_inputs(const BatchInputs& in);
// Whether the run is a batch (a summary CSV and JSON Lines): several meshes, a list, a shard or a summary
// path.
bool is_batch(const BatchInputs& in, std::size_t meshes);
// DIR/summary.csv, DIR/summary-I-of-N.csv with --shard, or --summary.
std::filesystem::path summary_path(const BatchInputs& in);

// Converts one mesh, filling its row; returns its exit code (a thrown ts::Error fails the row).
using ConvertMesh = std::function<int(const std::string& mesh, bool first, BatchRow& row)>;
// Every mesh of a batch, a failure a row of the summary (a GpuError ends the batch: the context is gone);
// writes the summary and, unless `json`, a closing line. Returns the first failure's exit code.
int run_batch(const std::vector<std::string>& meshes, const BatchInputs& in, bool json, bool strict,
              const ConvertMesh& convert);

}  // namespace ts::app
