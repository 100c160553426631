#include "app/sample_batch.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "sampler/body_verdict.h"

namespace ts::app {

namespace {

// Lines of a list file: one mesh path each, relative to the list's folder unless absolute; blank lines and
// lines starting with # are skipped.
void append_list(const std::filesystem::path& list, std::vector<std::string>& out) {
  std::istringstream in(read_file(list));
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    const std::filesystem::path path = line.substr(first, last - first + 1);
    out.push_back((path.is_absolute() ? path : list.parent_path() / path).lexically_normal().string());
  }
}

struct Shard {
  std::size_t index = 0, count = 1;
};

Shard parse_shard(const std::string& text) {
  Shard s;
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    std::size_t used = 0;
    s.index = std::stoul(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("index");
    s.count = std::stoul(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) throw std::invalid_argument("count");
  } catch (const std::exception&) {
    throw Error(ExitCode::Usage, "--shard wants I/N with 0 <= I < N (got '" + text + "')");
  }
  if (s.count == 0 || s.index >= s.count)
    throw Error(ExitCode::Usage, "--shard wants I/N with 0 <= I < N (got '" + text + "')");
  return s;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

void write_summary(const std::filesystem::path& path, const std::vector<BatchRow>& rows) {
  std::string csv =
      "mesh,status,exit_code,particles,particle_radius_m,relative_radius,cv,covering_over_r,coverage_"
      "certified,covering_bound_over_r,uncovered_subtriangles,max_abs_phi_over_r,iterations,injection_rounds,"
      "converged,seconds,verdict,verdict_reasons,body_json,error\n";
  for (const BatchRow& r : rows) {
    const auto& q = r.quality;
    // A failed mesh has no certificate: its certificate columns are empty.
    const auto& c = q.certificate;
    csv += fmt::format(
        "{},{},{},{},{:.9g},{:.6f},{:.6f},{:.6f},{},{},{},{:.3e},{},{},{},{:.3f},{},{},{},{}\n",
        csv_field(r.mesh), r.status, r.exit_code, r.particles, r.radius, q.relative_radius, q.cv,
        q.covering_over_r, c ? (c->certified ? "1" : "0") : "",
        c ? fmt::format("{:.6f}", c->bound_over_r) : "", c ? std::to_string(c->uncovered_subtriangles) : "",
        q.max_abs_phi_over_r, q.iterations, q.injection_rounds, q.converged ? 1 : 0, q.seconds,
        csv_field(r.verdict), csv_field(fmt::format("{}", fmt::join(r.verdict_reasons, "; "))),
        csv_field(r.body_json), csv_field(r.error));
  }
  std::filesystem::create_directories(path.parent_path().empty() ? "." : path.parent_path());
  write_file_atomically(path, csv);
}

}  // namespace

std::vector<std::string> expand_inputs(const BatchInputs& in) {
  std::vector<std::string> all;
  for (const std::string& item : in.inputs) {
    if (item.size() > 1 && item[0] == '@') {
      append_list(item.substr(1), all);
    } else {
      all.push_back(item);
    }
  }
  if (!in.list.empty()) append_list(in.list, all);
  if (all.empty()) throw InputError("no meshes to convert (empty list)");
  const Shard shard = parse_shard(in.shard.empty() ? "0/1" : in.shard);
  std::vector<std::string> mine;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (k % shard.count == shard.index) mine.push_back(all[k]);
  return mine;
}

bool is_batch(const BatchInputs& in, std::size_t meshes) {
  return meshes > 1 || !in.list.empty() || !in.shard.empty() || !in.summary.empty() ||
         (!in.inputs.empty() && in.inputs[0].rfind('@', 0) == 0);
}

std::filesystem::path summary_path(const BatchInputs& in) {
  if (!in.summary.empty()) return in.summary;
  if (in.shard.empty()) return std::filesystem::path(in.output) / "summary.csv";
  const Shard s = parse_shard(in.shard);
  return std::filesystem::path(in.output) / fmt::format("summary-{}-of-{}.csv", s.index, s.count);
}

int run_batch(const std::vector<std::string>& meshes, const BatchInputs& in, bool json, bool strict,
              const ConvertMesh& convert) {
  std::vector<BatchRow> rows;
  std::set<std::string> names;
  int first_code = 0, short_of_ok = 0;
  for (const std::string& path : meshes) {
    BatchRow r;
    r.mesh = path;
    try {
      if (!names.insert(std::filesystem::path(path).stem().string()).second) {
        throw InputError(path, "another mesh of the batch has the same name; its outputs would overwrite");
      }
      r.exit_code = convert(path, rows.empty(), r);
    } catch (const GpuError&) {
      throw;  // the context is gone: no later mesh can run
    } catch (const Error& e) {
      r.status = "failed", r.error = e.what(), r.exit_code = static_cast<int>(e.code());
      log::error("{}", e.what());
    }
    if (r.exit_code != 0 && first_code == 0) first_code = r.exit_code;
    if (r.status == "ok" && r.verdict != sampler::verdict_name(sampler::Verdict::Ok)) ++short_of_ok;
    rows.push_back(r);
  }
  const std::filesystem::path csv = summary_path(in);
  write_summary(csv, rows);
  if (!json) {
    const auto converted =
        std::count_if(rows.begin(), rows.end(), [](const BatchRow& r) { return r.status == "ok"; });
    fmt::print("{} of {} meshes converted, {} of them short of 'body OK'{}; summary: {}\n", converted,
               rows.size(), short_of_ok, strict && short_of_ok > 0 ? " (exit 1: --strict)" : "",
               csv.string());
  }
  return first_code;
}

}  // namespace ts::app
