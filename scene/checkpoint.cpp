// The checkpoint file (docs/checkpoint-format.md): magic, version, the payload's length, the payload
// (fixed order, sim/state_bytes.h encoding) and a SHA-256 of everything before it.
#include "scene/checkpoint.h"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <regex>
#include <type_traits>

#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "core/log.h"
#include "core/temporary_name.h"

namespace ts::scene {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kMagic("TSCKPT\r\n", 8);  // \r\n: a text-mode copy shows as damage
constexpr std::size_t kDigest = 32;                  // SHA-256

std::string sha256(std::string_view bytes) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr) != 1 ||
      length != kDigest) {
    throw Error(ExitCode::Internal, "SHA-256 failed");
  }
  return std::string(reinterpret_cast<const char*>(digest.data()), length);
}

std::string hex(std::string_view bytes) {
  std::string out;
  for (unsigned char c : bytes) out += fmt::format("{:02x}", c);
  return out;
}

void put_stats(ByteWriter& w, const StepStats& s) {
  for (double v : {s.energy.translational, s.energy.rotational, s.energy.potential, s.elastic_energy,
                   s.max_overlap_ratio})
    w.put(v);
  for (std::size_t v : {s.contacts, s.wall_contacts, s.velocity_clamps, s.angular_velocity_clamps,
                        s.overlap_clamps, s.spring_overflows, s.penetration.count})
    w.put<std::uint64_t>(v);
  w.put(s.penetration.particle);
  w.put(s.penetration.wall);
}

StepStats get_stats(ByteReader& r) {
  StepStats s;
  for (double* v : {&s.energy.translational, &s.energy.rotational, &s.energy.potential, &s.elastic_energy,
                    &s.max_overlap_ratio})
    r.get(*v);
  for (std::size_t* v : {&s.contacts, &s.wall_contacts, &s.velocity_clamps, &s.angular_velocity_clamps,
                         &s.overlap_clamps, &s.spring_overflows, &s.penetration.count})
    *v = static_cast<std::size_t>(r.get<std::uint64_t>());
  r.get(s.penetration.particle);
  r.get(s.penetration.wall);
  return s;
}

std::int64_t step_of(const fs::path& file) {
  static const std::regex name(R"(checkpoint_(\d{12})\.tsck)");
  std::smatch m;
  const std::string base = file.filename().string();
  return std::regex_match(base, m, name) ? std::stoll(m[1].str()) : -1;
}

// Checkpoints in `dir`, by step ascending.
std::vector<std::pair<std::int64_t, fs::path>> list_checkpoints(const fs::path& dir) {
  std::vector<std::pair<std::int64_t, fs::path>> out;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::int64_t step = step_of(e.path());
    if (step >= 0 && e.is_regular_file(ec)) out.emplace_back(step, e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

namespace {

std::string payload(const RunState& s) {
  ByteWriter w;
  w.put_string(s.scene_hash);
  w.put_string(s.engine);
  w.put(s.duration);
  w.put(s.dt);
  for (std::int64_t v : {s.step, s.stretch_end, s.stretch_output, s.frames, s.last_output_step}) w.put(v);
  for (std::uint64_t v : {s.velocity_clamps, s.angular_clamps, s.overlap_clamps, s.spring_overflows,
                          s.run_spring_overflows, std::uint64_t{s.clamp_watch.clamps}})
    w.put(v);
  w.put<std::uint8_t>(s.clamp_watch.saturated ? 1 : 0);
  put_stats(w, s.last);
  put_each(w, s.pours, [&](const PourProgress& p) {
    w.put(p.next_site);
    w.put(p.emitted);
    w.put_string(p.rng);
  });
  w.put_string(s.metrics_csv);
  w.put_string(world_bytes(s.world));
  w.put_string(s.engine_state);
  return w.bytes();
}

RunState read_payload(ByteReader& r) {
  RunState s;
  s.scene_hash = r.get_string();
  s.engine = r.get_string();
  r.get(s.duration);
  r.get(s.dt);
  for (std::int64_t* v : {&s.step, &s.stretch_end, &s.stretch_output, &s.frames, &s.last_output_step})
    r.get(*v);
  std::uint64_t watch_clamps = 0;
  for (std::uint64_t* v : {&s.velocity_clamps, &s.angular_clamps, &s.overlap_clamps, &s.spring_overflows,
                           &s.run_spring_overflows, &watch_clamps})
    r.get(*v);
  s.clamp_watch = {static_cast<std::size_t>(watch_clamps), r.get<std::uint8_t>() != 0};
  s.last = get_stats(r);
  s.pours = get_each<PourProgress>(r, 24, [&](PourProgress& p) {
    r.get(p.next_site);
    r.get(p.emitted);
    p.rng = r.get_string();
  });
  s.metrics_csv = r.get_string();
  const std::string world = r.get_string();
  ByteReader world_reader(world, r.what() + " (world)");
  s.world = world_from_bytes(world_reader);
  s.engine_state = r.get_string();
  if (!r.done()) r.fail("bytes left after the state");
  if (s.step < 0 || s.stretch_end < s.step || s.frames < 1) r.fail("inconsistent step counters");
  // The same checks as a fresh scene's dt and duration: finite, > 0, and at least one step.
  try {
    checked_step_count(s.duration, s.dt, Where{});
  } catch (const InputError& e) {
    r.fail(fmt::format("dt and duration: {}", e.what()));
  }
  return s;
}

RunState read_checkpoint(const fs::path& file) {
  const std::string bytes = read_file(file);
  const std::string what = file.string();
  if (bytes.size() < kMagic.size() + 16 + kDigest || bytes.compare(0, kMagic.size(), kMagic) != 0) {
    throw InputError(file, "not a tetrasand checkpoint (no TSCKPT header), or truncated");
  }
  const std::string_view body(bytes.data(), bytes.size() - kDigest);
  // The version first: another version may lay out even its checksum otherwise.
  ByteReader header(body.substr(kMagic.size()), what);
  const auto version = header.get<std::uint32_t>();
  if (version != kCheckpointVersion) {
    throw InputError(file, fmt::format("checkpoint format version {}, this tetrasand reads version {}",
                                       version, kCheckpointVersion));
  }
  if (sha256(body) != bytes.substr(bytes.size() - kDigest)) {
    throw InputError(file,
                     "corrupt: its SHA-256 does not match its contents (damaged or changed after writing)");
  }
  header.get<std::uint32_t>();  // flags, 0
  const auto length = header.get<std::uint64_t>();
  if (length != body.size() - kMagic.size() - 16)
    throw InputError(file, "the payload length does not match the file");
  ByteReader reader(body.substr(kMagic.size() + 16), what);
  return read_payload(reader);
}

}  // namespace

std::string scene_hash(const Scene& scene, const World& initial_world) {
  return hex(sha256(read_file(scene.file) + world_bytes(initial_world)));
}

fs::path checkpoint_path(const fs::path& dir, std::int64_t step) {
  return dir / fmt::format("checkpoint_{:012d}.tsck", step);
}

void write_checkpoint(const fs::path& dir, const RunState& state, std::size_t keep) {
  const std::string content = payload(state);
  ByteWriter header;
  header.put(kCheckpointVersion);
  header.put<std::uint32_t>(0);
  header.put<std::uint64_t>(content.size());
  std::string bytes = std::string(kMagic) + header.bytes() + content;
  bytes += sha256(bytes);
  write_file_atomically(checkpoint_path(dir, state.step), bytes);
  const auto all = list_checkpoints(dir);
  std::error_code ec;
  for (std::size_t i = 0; i + keep < all.size(); ++i) fs::remove(all[i].second, ec);
  remove_dead_temporaries(dir);
}

RunState read_latest_checkpoint(const fs::path& dir, fs::path* file) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir, "no such folder to resume from");
  remove_dead_temporaries(dir);
  const auto all = list_checkpoints(dir);
  if (all.empty()) {
    throw InputError(dir,
                     "no checkpoint to resume from (checkpoint_STEP.tsck; [output] checkpoint_every or "
                     "checkpoint_seconds writes them)");
  }
  if (file) *file = all.back().second;
  try {
    return read_checkpoint(all.back().second);
  } catch (const InputError& e) {
    if (all.size() < 2) throw;
    throw InputError(fmt::format("{}; to resume from the checkpoint before it ({}), remove it", e.what(),
                                 all[all.size() - 2].second.filename().string()));
  }
}

void remove_checkpoints(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  remove_dead_temporaries(dir);
  for (const auto& [step, file] : list_checkpoints(dir)) {
    log::info("{}: removed (this run replaces the folder's outputs)", file.string());
    fs::remove(file, ec);
  }
}

}  // namespace ts::scene
