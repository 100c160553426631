// Scene file parsing: a small reader per TOML table that knows the file, its path of keys and
// which keys it has consumed, so every message reads "file:line: table.key: problem".
#include "scene/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#define TOML_EXCEPTIONS 1
#include <toml++/toml.h>

#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "body/body_file.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

// Levenshtein distance, for "did you mean" on unknown keys.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(a[i - 1]) == std::tolower(b[j - 1]);
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

class TableReader {
 public:
  TableReader(const toml::table& table, std::string path, const fs::path& file,
              std::map<std::string, int, std::less<>>* lines = nullptr)
      : table_(table), path_(std::move(path)), file_(file), lines_(lines) {}

  // "path.key" as errors and key lines name it; the root table's keys stand alone.
  std::string qualified(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  [[noreturn]] void fail(std::string_view key, const std::string& problem) const {
    const toml::node* node = key.empty() ? nullptr : table_.get(key);
    const int line = node ? line_of(*node) : line_of(table_);
    const std::string name = key.empty() ? path_ : qualified(key);
    throw InputError(fmt::format("{}:{}: {}: {}", file_.string(), line, name, problem));
  }

  // A required key that is absent. When the table holds a key nobody has read that is one or two edits
  // from it, that key is the likely typo: name it where it is, so the user fixes the right line. Keys of
  // under 4 letters are left out: "min" and "max", "nu" and "mu" are two edits apart and both valid.
  [[noreturn]] void missing(std::string_view key, const std::string& detail = "") const {
    for (const auto& [present, value] : table_) {
      if (key.size() < 4) break;  // no candidate can be close enough to name
      const std::string candidate(present.str());
      if (candidate.size() < 4 || used_.count(candidate) || edit_distance(candidate, key) > 2) continue;
      throw InputError(fmt::format("{}:{}: {}: unknown key (did you mean \"{}\"? {} is required{})",
                                   file_.string(), line_of(value), qualified(candidate), key, qualified(key),
                                   detail));
    }
    fail(key, "missing (required" + detail + ")");
  }

  bool has(std::string_view key) {
    used_.insert(std::string(key));
    return table_.contains(key);
  }

  const toml::node* node(std::string_view key) {
    used_.insert(std::string(key));
    const toml::node* found = table_.get(key);
    if (found && lines_) (*lines_)[qualified(key)] = line_of(*found);
    return found;
  }

  std::optional<double> optional_number(std::string_view key) {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_number()) fail(key, "must be a number");
    const double value = *n->value<double>();
    if (!std::isfinite(value)) fail(key, "must be finite");
    return value;
  }
  double number(std::string_view key, double fallback) { return optional_number(key).value_or(fallback); }
  double required_number(std::string_view key) {
    const auto value = optional_number(key);
    if (!value) missing(key);
    return *value;
  }
  double positive(std::string_view key, std::optional<double> fallback = std::nullopt) {
    const auto value = has(key) ? optional_number(key) : fallback;
    if (!value) missing(key);
    if (!(*value > 0)) fail(key, fmt::format("must be > 0 (got {})", *value));
    return *value;
  }
  double non_negative(std::string_view key, double fallback) {
    const double value = number(key, fallback);
    if (value < 0) fail(key, fmt::format("must be >= 0 (got {})", value));
    return value;
  }
  std::int64_t integer(std::string_view key, std::optional<std::int64_t> fallback, std::int64_t min_value) {
    const toml::node* n = node(key);
    if (!n && !fallback) missing(key);
    if (!n) return *fallback;
    if (!n->is_integer()) fail(key, "must be an integer");
    const std::int64_t value = *n->value<std::int64_t>();
    if (value < min_value) fail(key, fmt::format("must be >= {} (got {})", min_value, value));
    return value;
  }
  bool boolean(std::string_view key, bool fallback) {
    const toml::node* n = node(key);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(key, "must be true or false");
    return *n->value<bool>();
  }
  std::optional<std::string> optional_string(std::string_view key) {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_string()) fail(key, "must be a string");
    return *n->value<std::string>();
  }
  std::string required_string(std::string_view key) {
    auto s = optional_string(key);
    if (!s) missing(key);
    return *s;
  }
  // One of `choices`; returns its index.
  std::size_t choice(std::string_view key, const std::vector<std::string>& choices, std::optional<std::size_t> fallback) {
    const auto s = optional_string(key);
    if (!s && !fallback) missing(key, fmt::format("; one of: {}", fmt::join(choices, ", ")));
    if (!s) return *fallback;
    const auto it = std::find(choices.begin(), choices.end(), *s);
    if (it == choices.end()) fail(key, fmt::format("\"{}\" is not one of: {}", *s, fmt::join(choices, ", ")));
    return static_cast<std::size_t>(it - choices.begin());
  }
  template <int N>
  std::optional<Eigen::Matrix<double, N, 1>> optional_vector(std::string_view key) {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != N) fail(key, fmt::format("must be an array of {} numbers", N));
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) {
      const toml::node& element = *a->get(static_cast<std::size_t>(i));
      if (!element.is_number()) fail(key, fmt::format("must be an array of {} numbers", N));
      v[i] = *element.value<double>();
      if (!std::isfinite(v[i])) fail(key, "must be finite");
    }
    return v;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vector(std::string_view key, std::optional<Eigen::Matrix<double, N, 1>> fallback) {
    auto v = optional_vector<N>(key);
    if (!v && !fallback) missing(key);
    return v ? *v : *fallback;
  }
  // Where a key's value lies, for the value checker (core/checked_values.h).
  Where where(std::string_view key) const {
    const toml::node* n = key.empty() ? nullptr : table_.get(key);
    return Where{file_.string(), n ? line_of(*n) : line_of(table_), key.empty() ? path_ : qualified(key)};
  }
  Eigen::Vector3d unit_vector(std::string_view key, const Eigen::Vector3d& fallback) {
    const Eigen::Vector3d v = vector<3>(key, fallback);
    if (v.norm() < 1e-12) fail(key, "must not be the zero vector");
    return checked_unit_vector(v, where(key));
  }
  // A velocity (m/s), zero when absent.
  Eigen::Vector3d velocity(std::string_view key) {
    return checked_velocity(vector<3>(key, Eigen::Vector3d::Zero()), where(key));
  }
  // An orientation [w, x, y, z], identity when absent.
  Eigen::Quaterniond quaternion(std::string_view key) {
    const Eigen::Vector4d q = vector<4>(key, Eigen::Vector4d(1, 0, 0, 0));
    if (q.norm() < 1e-12) fail(key, "quaternion [w, x, y, z] must not be zero");
    return checked_quaternion(q, where(key));
  }

  // Rejects keys nobody asked for: a typo must not be silently ignored.
  void reject_unknown_keys() const {
    for (const auto& [key, value] : table_) {
      const std::string name(key.str());
      if (used_.count(name)) continue;
      std::string hint;
      std::size_t best = 3;
      for (const std::string& known : used_) {
        const std::size_t d = edit_distance(name, known);
        if (d < best) {
          best = d;
          hint = fmt::format(" (did you mean \"{}\"?)", known);
        }
      }
      const int line = line_of(value);
      const std::string full = qualified(name);
      throw InputError(fmt::format("{}:{}: {}: unknown key{}; expected one of: {}", file_.string(), line, full, hint,
                                   fmt::join(used_, ", ")));
    }
  }

  const toml::table& table() const { return table_; }
  const std::string& path() const { return path_; }

 private:
  const toml::table& table_;
  std::string path_;
  const fs::path& file_;
  std::map<std::string, int, std::less<>>* lines_;  // where the keys read are, when kept
  std::set<std::string> used_;
};

// Calls `each` with a reader for every table of the array-of-tables `key` (absent: none).
template <typename Fn>
void for_each_table(TableReader& parent, std::string_view key, Fn&& each) {
  const toml::node* n = parent.node(key);
  if (!n) return;
  const toml::array* array = n->as_array();
  if (!array || !array->is_array_of_tables()) parent.fail(key, fmt::format("must be [[{}]] tables", key));
  for (std::size_t i = 0; i < array->size(); ++i) each(*array->get(i)->as_table());
}

std::uint16_t material_index(TableReader& r, const Scene& scene, std::string_view key) {
  const std::string name = r.required_string(key);
  for (std::size_t i = 0; i < scene.material_names.size(); ++i) {
    if (scene.material_names[i] == name) return static_cast<std::uint16_t>(i);
  }
  r.fail(key, fmt::format("no [[material]] named \"{}\" (have: {})", name, fmt::join(scene.material_names, ", ")));
}

void read_material(const toml::table& t, const fs::path& file, Scene& scene) {
  TableReader r(t, "material", file);
  Material m;
  const std::string name = r.required_string("name");
  if (std::find(scene.material_names.begin(), scene.material_names.end(), name) != scene.material_names.end()) {
    r.fail("name", fmt::format("\"{}\" is defined twice", name));
  }
  m.youngs_modulus = r.required_number("E");
  m.poisson_ratio = r.required_number("nu");
  m.restitution = r.required_number("restitution");
  m.friction = r.required_number("mu");
  m.tangential_damping = r.number("gamma_s", m.tangential_damping);
  m.density = r.required_number("density");
  r.reject_unknown_keys();
  if (const std::string problem = validate(m); !problem.empty()) {
    const std::string key = problem.substr(0, problem.find(':'));
    r.fail(key, problem.substr(problem.find(':') + 2));
  }
  if (scene.materials.size() >= 65535) r.fail("", "too many materials");
  scene.materials.push_back(m);
  scene.material_names.push_back(name);
}

GrainSpec read_grain_type(const toml::table& t, const fs::path& file, const Scene& scene, bool named) {
  TableReader r(t, "grain", file);
  GrainSpec g;
  g.line = line_of(t);
  g.name = named ? r.required_string("name") : r.optional_string("name").value_or("");
  for (const GrainSpec& other : scene.grains) {
    if (other.name == g.name)
      r.fail("name", fmt::format("\"{}\" is defined twice (also at line {})", g.name, other.line));
  }
  g.radius = r.positive("radius");
  g.edge = r.positive("edge", 2 * g.radius);
  if (g.edge > 2 * g.radius * (1 + 1e-9)) {
    r.fail("edge",
           fmt::format("{} m leaves the spheres apart: must be <= 2 radius = {} m", g.edge, 2 * g.radius));
  }
  g.material = material_index(r, scene, "material");
  r.reject_unknown_keys();
  return g;
}

// `[grain]` (one type) or `[[grain]]` tables (several, each with a name).
void read_grains(TableReader& root, const fs::path& file, Scene& scene) {
  const toml::node* n = root.node("grain");
  const char* form =
      "; a [grain] table (radius, edge, material) or [[grain]] tables (name, radius, edge, material)";
  if (!n) root.missing("grain", form);
  if (const toml::table* one = n->as_table()) {
    scene.grains.push_back(read_grain_type(*one, file, scene, false));
    return;
  }
  const toml::array* many = n->as_array();
  if (!many || !many->is_array_of_tables() || many->empty())
    root.fail("grain", std::string("must be") + (form + 1));
  if (many->size() > 65535) root.fail("grain", "too many grain types");
  for (const toml::node& t : *many)
    scene.grains.push_back(read_grain_type(*t.as_table(), file, scene, many->size() > 1));
}

// emitter.grain: a type's name, or a list of them with `fractions` (number fractions, normalised).
void read_emitter_grains(TableReader& r, const Scene& scene, Emitter& e) {
  std::vector<std::string> names;
  auto type_of = [&](const std::string& name) {
    for (std::size_t t = 0; t < scene.grains.size(); ++t)
      if (scene.grains[t].name == name) return static_cast<std::uint16_t>(t);
    std::vector<std::string> have;
    for (const GrainSpec& g : scene.grains) have.push_back(fmt::format("\"{}\"", g.name));
    r.fail("grain", fmt::format("no grain type named \"{}\" (have: {})", name, fmt::join(have, ", ")));
  };
  const toml::node* n = r.node("grain");
  if (!n && scene.grains.size() > 1)
    r.missing("grain",
              " when the scene has several grain types: a [[grain]] name, or a list of them with fractions");
  e.grains = {0};
  if (n && n->is_string()) e.grains = {type_of(*n->value<std::string>())};
  if (n && !n->is_string()) {
    const toml::array* a = n->as_array();
    if (!a || a->empty() || !a->is_homogeneous(toml::node_type::string))
      r.fail("grain", "must be a grain type's name or an array of names");
    e.grains.clear();
    for (const toml::node& name : *a) {
      const std::uint16_t t = type_of(*name.value<std::string>());
      if (std::find(e.grains.begin(), e.grains.end(), t) != e.grains.end())
        r.fail("grain", fmt::format("\"{}\" is listed twice", *name.value<std::string>()));
      e.grains.push_back(t);
    }
  }
  e.fractions.assign(e.grains.size(), 1.0);
  const toml::node* f = r.node("fractions");
  if (!f && e.grains.size() > 1) r.missing("fractions", " with several grain types: their number fractions");
  if (!f) return;
  const toml::array* a = f->as_array();
  if (!a || a->size() != e.grains.size() ||
      !std::all_of(a->begin(), a->end(), [](const toml::node& x) { return x.is_number(); })) {
    r.fail("fractions", fmt::format("must be an array of {} numbers, one per grain type", e.grains.size()));
  }
  double total = 0;
  for (std::size_t k = 0; k < a->size(); ++k) {
    e.fractions[k] = *a->get(k)->value<double>();
    if (!(e.fractions[k] >= 0) || !std::isfinite(e.fractions[k]))
      r.fail("fractions", "must be finite and >= 0");
    total += e.fractions[k];
  }
  if (!(total > 0)) r.fail("fractions", "must not all be 0");
  for (double& x : e.fractions) x /= total;
}

// sieve = [[scale, mass_fraction], ...]: scales > 0 and distinct, fractions >= 0 (normalised).
void read_sieve(TableReader& r, SizeSpec& s) {
  const toml::array* rows = r.node("sieve")->as_array();
  const char* form = "must be an array of [scale, mass fraction] pairs";
  if (!rows || rows->empty()) r.fail("sieve", form);
  double total = 0;
  for (const toml::node& row : *rows) {
    const toml::array* pair = row.as_array();
    if (!pair || pair->size() != 2 || !pair->get(0)->is_number() || !pair->get(1)->is_number())
      r.fail("sieve", form);
    const double scale = *pair->get(0)->value<double>(), fraction = *pair->get(1)->value<double>();
    if (!(scale > 0) || !std::isfinite(scale)) r.fail("sieve", fmt::format("scale {}: must be > 0", scale));
    if (!(fraction >= 0) || !std::isfinite(fraction))
      r.fail("sieve", fmt::format("mass fraction {} at scale {}: must be >= 0", fraction, scale));
    for (const auto& [other, ignored] : s.sieve)
      if (other == scale) r.fail("sieve", fmt::format("scale {} is listed twice", scale));
    s.sieve.emplace_back(scale, fraction);
    total += fraction;
  }
  if (!(total > 0)) r.fail("sieve", "the mass fractions must not all be 0");
  for (auto& [scale, fraction] : s.sieve) fraction /= total;
}

// emitter.size = { distribution = "uniform", min, max } | { distribution = "lognormal", median, sigma
// [, min, max] } | { sieve = [[scale, mass_fraction], ...] }.
void read_size(TableReader& emitter, const fs::path& file, Emitter& e) {
  const toml::node* n = emitter.node("size");
  if (!n) return;
  if (!n->is_table())
    emitter.fail("size",
                 "must be a table: { distribution = \"uniform\", min, max }, "
                 "{ distribution = \"lognormal\", median, sigma } or { sieve = [...] }");
  TableReader r(*n->as_table(), "emitter.size", file);
  SizeSpec& s = e.size;
  const bool sieve = r.has("sieve");
  const std::size_t kind = r.choice("distribution", {"uniform", "lognormal", "sieve"},
                                    sieve ? std::optional<std::size_t>(2) : std::nullopt);
  if (kind == 2 && !sieve) r.missing("sieve", ": [[scale, mass fraction], ...]");
  if (kind != 2 && sieve)
    r.fail("sieve", "sieve classes go with distribution = \"sieve\" (or no distribution)");
  if (kind == 0) {
    s.distribution = SizeDistribution::Uniform;
    s.min = r.positive("min");
    s.max = r.positive("max");
    if (s.max < s.min) r.fail("max", fmt::format("{} is below min = {}", s.max, s.min));
  } else if (kind == 1) {
    s.distribution = SizeDistribution::Lognormal;
    s.median = r.positive("median");
    s.sigma = r.positive("sigma");
    s.min = r.positive("min", s.median * std::exp(-3 * s.sigma));
    s.max = r.positive("max", s.median * std::exp(3 * s.sigma));
    if (!(s.min < s.max))
      r.fail("max", fmt::format("{} must exceed min = {} (one scale: no size key)", s.max, s.min));
    if (!(s.min <= s.median && s.median <= s.max))
      r.fail(s.min > s.median ? "min" : "max",
             fmt::format("the truncation [{}, {}] must hold the median {}", s.min, s.max, s.median));
  } else {
    s.distribution = SizeDistribution::Sieve;
    read_sieve(r, s);
  }
  r.reject_unknown_keys();
}

void read_emitter(const toml::table& t, const fs::path& file, Scene& scene) {
  TableReader r(t, "emitter", file);
  Emitter e;
  e.line = line_of(t);
  e.type = static_cast<EmitterType>(r.choice("type", {"fill", "pour", "column"}, std::nullopt));
  e.count = static_cast<std::size_t>(r.integer("count", std::nullopt, 1));
  e.velocity = r.velocity("velocity");
  e.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0));
  read_emitter_grains(r, scene, e);
  read_size(r, file, e);
  if (e.type == EmitterType::Column) {
    e.centre = r.vector<3>("centre", std::nullopt);
    e.radius = r.positive("radius");
  } else {
    e.min = r.vector<3>("min", std::nullopt);
    e.max = r.vector<3>("max", std::nullopt);
    if (!(e.max.array() > e.min.array()).all()) r.fail("max", "must exceed min in x, y and z");
  }
  if (e.type == EmitterType::Pour) {
    e.rate = r.positive("rate");
    e.start = r.non_negative("start", 0.0);
  }
  r.reject_unknown_keys();
  scene.emitters.push_back(e);
}

// [[prop.keyframes]]: time (s), position (m) and orientation ([w, x, y, z]) of the mesh frame.
void read_keyframes(TableReader& prop, const fs::path& file, Prop& p) {
  const toml::node* n = prop.node("keyframes");
  if (!n) return;
  const toml::array* array = n->as_array();
  if (!array || !array->is_array_of_tables()) prop.fail("keyframes", "must be [[prop.keyframes]] tables");
  if (p.motion != MotionType::Kinematic) prop.fail("keyframes", "only a kinematic prop follows keyframes (motion = \"kinematic\")");
  if (prop.table().contains("velocity") || prop.table().contains("angular_velocity")) {
    prop.fail("keyframes", "a prop follows either keyframes or velocity/angular_velocity, not both");
  }
  if (prop.table().contains("position") || prop.table().contains("orientation")) {
    prop.fail("keyframes", "a prop with keyframes takes its pose from them: remove position/orientation");
  }
  if (array->size() < 2) prop.fail("keyframes", "needs at least two keys (one pose is a static prop)");
  for (std::size_t i = 0; i < array->size(); ++i) {
    TableReader r(*array->get(i)->as_table(), fmt::format("prop.keyframes[{}]", i), file);
    Keyframe k;
    k.time = r.required_number("time");
    if (i > 0 && !(k.time > p.keyframes.back().time)) {
      r.fail("time", fmt::format("{} s is not after the previous key's {} s: keys must be sorted by time, each "
                                 "time once", k.time, p.keyframes.back().time));
    }
    k.position = r.vector<3>("position", std::nullopt);
    k.orientation = r.quaternion("orientation");
    r.reject_unknown_keys();
    p.keyframes.push_back(k);
  }
  p.position = p.keyframes.front().position;
  p.orientation = p.keyframes.front().orientation;
}

// servo.schedule = [[t, stress], ...]: times strictly increasing, stresses >= 0.
std::vector<ServoKey> read_servo_schedule(TableReader& r) {
  const toml::array* rows = r.node("schedule")->as_array();
  const char* form = "must be an array of [time (s), stress (Pa)] pairs";
  if (!rows || rows->empty()) r.fail("schedule", form);
  std::vector<ServoKey> keys;
  for (const toml::node& row : *rows) {
    const toml::array* pair = row.as_array();
    if (!pair || pair->size() != 2 || !pair->get(0)->is_number() || !pair->get(1)->is_number())
      r.fail("schedule", form);
    const ServoKey k{*pair->get(0)->value<double>(), *pair->get(1)->value<double>()};
    if (!std::isfinite(k.time) || !std::isfinite(k.stress)) r.fail("schedule", "must be finite");
    if (k.stress < 0)
      r.fail("schedule",
             fmt::format("stress {} Pa at t = {} s: must be >= 0 (compressive)", k.stress, k.time));
    if (!keys.empty() && !(k.time > keys.back().time)) {
      r.fail("schedule", fmt::format("time {} s is not after the previous {} s: keys must be sorted by time",
                                     k.time, keys.back().time));
    }
    keys.push_back(k);
  }
  return keys;
}

// [prop.servo]: a stress-controlled piston (scene/servo.h) on a kinematic prop without keyframes.
void read_servo(TableReader& prop, const fs::path& file, Prop& p) {
  const toml::node* n = prop.node("servo");
  if (!n) return;
  if (!n->is_table()) prop.fail("servo", "must be a [prop.servo] table");
  if (p.motion != MotionType::Kinematic)
    prop.fail("servo", "only a kinematic prop has a servo (motion = \"kinematic\")");
  if (!p.keyframes.empty()) prop.fail("servo", "a prop follows either keyframes or its servo, not both");
  if (prop.table().contains("velocity"))
    prop.fail("servo", "the servo sets the prop's velocity: remove velocity");
  TableReader r(*n->as_table(), "prop.servo", file);
  Servo s;
  const bool constant = r.has("stress"), scheduled = r.has("schedule");
  if (constant == scheduled) r.fail("", "needs exactly one of stress (Pa) or schedule = [[t, stress], ...]");
  if (constant) s.schedule = {{0.0, r.non_negative("stress", 0.0)}};
  if (scheduled) s.schedule = read_servo_schedule(r);
  s.area = r.positive("area");
  s.gain = r.positive("gain");
  s.max_speed = r.positive("max_speed");
  s.direction = r.unit_vector("direction", s.direction);
  s.every = r.integer("every", s.every, 1);
  r.reject_unknown_keys();
  p.servo = s;
}

// [[bond_material]]: the bond law's parameters (sim/bond_model.h), E as [[material]] names Young's modulus.
void read_bond_material(const toml::table& t, const fs::path& file, Scene& scene) {
  TableReader r(t, "bond_material", file);
  BondMaterialSpec spec;
  spec.line = line_of(t);
  spec.name = r.required_string("name");
  for (const BondMaterialSpec& other : scene.bond_materials) {
    if (other.name == spec.name)
      r.fail("name", fmt::format("\"{}\" is defined twice (also at line {})", spec.name, other.line));
  }
  BondMaterial& m = spec.material;
  m.youngs_modulus = r.required_number("E");
  m.stiffness_ratio = r.number("stiffness_ratio", m.stiffness_ratio);
  m.radius_factor = r.number("radius_factor", m.radius_factor);
  m.tensile_strength = r.required_number("tensile_strength");
  m.shear_strength = r.required_number("shear_strength");
  m.strength_spread = r.number("strength_spread", 0.0);
  m.bond_distance = r.number("bond_distance", m.bond_distance);
  spec.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0));
  r.reject_unknown_keys();
  if (const std::string problem = validate(m); !problem.empty()) {
    const std::string key = problem.substr(0, problem.find(':'));
    r.fail(key == "youngs_modulus" ? "E" : key, problem.substr(problem.find(':') + 2));
  }
  if (scene.bond_materials.size() >= 65535) r.fail("", "too many bond materials");
  scene.bond_materials.push_back(spec);
}

int bond_material_index(TableReader& r, const Scene& scene, std::string_view key) {
  const std::string name = r.required_string(key);
  std::vector<std::string> have;
  for (std::size_t i = 0; i < scene.bond_materials.size(); ++i) {
    if (scene.bond_materials[i].name == name) return static_cast<int>(i);
    have.push_back(fmt::format("\"{}\"", scene.bond_materials[i].name));
  }
  r.fail(key, fmt::format("no [[bond_material]] named \"{}\" ({})", name,
                          have.empty() ? "the scene has none: add a [[bond_material]] table"
                                       : fmt::format("have: {}", fmt::join(have, ", "))));
}

// A prop's name when the table gives none: its body file without ".body.json" ("cube").
std::string body_stem(const fs::path& body_file) {
  std::string name = body_file.filename().string();
  for (const std::string_view suffix : {".body.json", ".json"}) {
    if (name.size() > suffix.size() && name.ends_with(suffix))
      return name.substr(0, name.size() - suffix.size());
  }
  return name;
}

// breakable = true: a dynamic prop whose body has interior particles (`sample --fill`), with a bond
// material; its particle count is read here, as each particle becomes a body of the world.
void read_breakable(TableReader& r, Prop& p, const Scene& scene) {
  p.breakable = r.boolean("breakable", false);
  if (!p.breakable) {
    for (const char* key : {"bond_material", "bind_to", "bind_material"}) {
      if (r.has(key)) r.fail(key, "only a breakable prop has bonds (breakable = true)");
    }
    return;
  }
  if (p.motion != MotionType::Dynamic)
    r.fail("breakable", "a breakable prop moves as its spheres do: it must be motion = \"dynamic\"");
  p.bond_material = bond_material_index(r, scene, "bond_material");
  const body::ParticleBody body = body::read_body(p.body_file, body::BodyKeys::Physical);
  if (body.interior_count == 0) {
    r.fail("breakable",
           fmt::format("{} has no interior particles: a breakable prop is filled with bonded spheres; resample "
                       "its mesh with `tetrasand sample MESH --fill ...`",
                       p.body_file.string()));
  }
  p.spheres = body.positions.size();
  if (r.has("bind_to")) {
    p.bind_material = bond_material_index(r, scene, "bind_material");
  } else if (r.has("bind_material")) {
    r.fail("bind_material", "binds the prop to the prop named by bind_to: add bind_to = \"NAME\"");
  }
}

void read_prop(const toml::table& t, const fs::path& file, Scene& scene) {
  TableReader r(t, "prop", file);
  Prop p;
  p.line = line_of(t);
  const std::string body = r.required_string("body");
  p.body_file = file.parent_path() / body;
  if (!fs::exists(p.body_file)) r.fail("body", fmt::format("{} does not exist", p.body_file.string()));
  p.name = r.optional_string("name").value_or(body_stem(p.body_file));
  if (r.has("name")) {
    if (p.name.empty()) r.fail("name", "must not be empty");
    for (const Prop& other : scene.props) {
      if (other.name == p.name)
        r.fail("name", fmt::format("\"{}\" is also the [[prop]] at line {}: names must differ", p.name, other.line));
    }
  }
  p.position = r.vector<3>("position", Eigen::Vector3d::Zero());
  p.orientation = r.quaternion("orientation");
  p.motion = static_cast<MotionType>(r.choice("motion", {"dynamic", "kinematic", "static"}, 2));
  p.velocity = r.velocity("velocity");
  p.angular_velocity = r.vector<3>("angular_velocity", Eigen::Vector3d::Zero());
  if (p.motion == MotionType::Static && (p.velocity.norm() > 0 || p.angular_velocity.norm() > 0)) {
    r.fail("velocity", "a static prop cannot move (use motion = \"kinematic\")");
  }
  p.material = material_index(r, scene, "material");
  read_keyframes(r, file, p);
  read_servo(r, file, p);
  read_breakable(r, p, scene);
  r.reject_unknown_keys();
  scene.props.push_back(p);
}

// bind_to = "NAME", once every prop is read (the surface may come after the layer): another prop.
void resolve_bind_to(const toml::array& tables, const fs::path& file, Scene& scene) {
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    Prop& p = scene.props[i];
    TableReader r(*tables.get(i)->as_table(), "prop", file);
    if (!p.breakable || !r.has("bind_to")) continue;
    const std::string wanted = r.required_string("bind_to");
    std::vector<std::string> names;
    for (std::size_t k = 0; k < scene.props.size(); ++k) {
      if (k == i) continue;
      names.push_back(fmt::format("\"{}\"", scene.props[k].name));
      if (scene.props[k].name != wanted) continue;
      if (p.bind_to >= 0)
        r.fail("bind_to", fmt::format("\"{}\" names several props: give them distinct name keys", wanted));
      p.bind_to = static_cast<int>(k);
    }
    if (p.bind_to < 0) {
      r.fail("bind_to", fmt::format("no other [[prop]] named \"{}\" ({})", wanted,
                                    names.empty() ? "the scene has no other prop"
                                                  : fmt::format("have: {}", fmt::join(names, ", "))));
    }
  }
}

void read_roughness(TableReader& r, Boundary& b) {
  b.rough = r.boolean("rough", false);
  if (!b.rough) return;
  b.particle_radius = r.positive("particle_radius");
  b.spacing = r.positive("spacing", 2 * b.particle_radius);
}

void read_boundary(const toml::table& t, const fs::path& file, Scene& scene) {
  TableReader r(t, "boundary", file);
  Boundary b;
  b.line = line_of(t);
  b.type = static_cast<BoundaryType>(r.choice("type", {"plane", "box", "cylinder"}, std::nullopt));
  b.material = material_index(r, scene, "material");
  read_roughness(r, b);
  switch (b.type) {
    case BoundaryType::Plane:
      b.point = r.vector<3>("point", Eigen::Vector3d::Zero());
      b.normal = r.unit_vector("normal", Eigen::Vector3d::UnitZ());
      if (b.rough) {
        b.size = r.vector<2>("size", std::nullopt);
        if (!(b.size.array() > 0).all()) r.fail("size", "must be > 0 in both directions");
        b.hole_radius = r.non_negative("hole_radius", 0.0);
        b.round_rim = r.choice("hole_rim", {"lattice", "round"}, 0) == 1;
        if (b.round_rim && b.hole_radius == 0) r.fail("hole_rim", "needs a hole_radius > 0");
      }
      break;
    case BoundaryType::Box:
      b.min = r.vector<3>("min", std::nullopt);
      b.max = r.vector<3>("max", std::nullopt);
      if (!(b.max.array() > b.min.array()).all()) r.fail("max", "must exceed min in x, y and z");
      break;
    case BoundaryType::Cylinder:
      b.axis = r.vector<2>("centre", Eigen::Vector2d::Zero());
      b.radius = r.positive("radius");
      b.z_min = r.required_number("z_min");
      b.z_max = r.required_number("z_max");
      if (!(b.z_max > b.z_min)) r.fail("z_max", "must exceed z_min");
      break;
  }
  r.reject_unknown_keys();
  scene.boundaries.push_back(b);
}

void read_simulation(TableReader& root, const fs::path& file, Scene& scene) {
  const toml::node* n = root.node("simulation");
  if (!n) return;
  if (!n->is_table()) root.fail("simulation", "must be a table");
  TableReader r(*n->as_table(), "simulation", file, &scene.key_lines);
  SimulationSettings& s = scene.simulation;
  s.duration = r.positive("duration", s.duration);
  if (const toml::node* dt = r.node("dt")) {
    if (dt->is_string() && *dt->value<std::string>() == "auto") {
      s.dt = 0;
    } else if (dt->is_number() && *dt->value<double>() > 0) {
      s.dt = *dt->value<double>();
    } else {
      r.fail("dt", "must be a time step > 0 (s) or \"auto\"");
    }
    // dt = inf, or a dt longer than the run, would take no step at all and report success.
    if (s.dt > 0) checked_step_count(s.duration, s.dt, r.where("dt"));
  }
  s.max_impact_speed = r.non_negative("max_impact_speed", 0.0);
  s.step.normal_damping = static_cast<NormalDamping>(r.choice("normal_damping", {"tsuji", "thesis"}, 0));
  s.step.thesis_reference_speed = r.positive("thesis_reference_speed", s.step.thesis_reference_speed);
  s.step.integrator = static_cast<Integrator>(
      r.choice("integrator", {"euler", "symplectic"}, static_cast<std::size_t>(s.step.integrator)));
  s.step.tangential = static_cast<TangentialModel>(r.choice("tangential", {"viscous", "spring"}, 0));
  s.step.resort_every = r.integer("resort_every", s.step.resort_every, 0);
  s.step.skin = r.non_negative("skin", 0.0);
  s.step.cfl = r.non_negative("cfl", s.step.cfl);
  s.step.max_overlap_ratio = r.non_negative("max_overlap_ratio", s.step.max_overlap_ratio);
  s.step.angular_damping_rate = r.non_negative("angular_damping_rate", 0.0);
  s.step.angular_damping_speed = r.non_negative("angular_damping_speed", 0.0);
  s.step.check_energy = r.boolean("check_energy", true);
  s.step.check_penetration = r.boolean("check_penetration", true);
  s.check_clamps = r.boolean("check_clamps", true);
  s.check_time_step = r.boolean("check_time_step", true);
  r.reject_unknown_keys();
}

// A prop's name in follow = "prop NAME": its name key, or its body file without ".body.json" ("cube").
const std::string& prop_name(const Prop& p) { return p.name; }

// follow = "scene" | "prop NAME" | "prop INDEX" (the [[prop]] tables in order, from 0): -1 for the
// scene, else the prop's index.
int read_follow(TableReader& r, const Scene& scene) {
  const auto text = r.optional_string("follow");
  if (!text || *text == "scene") return -1;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < scene.props.size(); ++i)
    names.push_back(fmt::format("\"prop {}\" or \"prop {}\"", prop_name(scene.props[i]), i));
  const std::string available =
      names.empty() ? "the scene has no [[prop]]" : fmt::format("have: {}", fmt::join(names, ", "));
  if (!text->starts_with("prop "))
    r.fail("follow", fmt::format("\"{}\" is not \"scene\" or \"prop NAME\" ({})", *text, available));
  const std::string wanted = text->substr(5);
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    if (prop_name(scene.props[i]) != wanted && std::to_string(i) != wanted) continue;
    if (scene.props[i].breakable)
      r.fail("follow", fmt::format("\"prop {}\" is breakable: its spheres part, so there is no one centre to "
                                   "follow (follow another prop, or a fixed eye and target)",
                                   wanted));
    return static_cast<int>(i);
  }
  r.fail("follow", fmt::format("no [[prop]] \"{}\" ({})", wanted, available));
}

// [output.camera]: eye, target, up (m, world), fov (degrees), size ([width, height] pixels), follow.
void read_camera(TableReader& output, const fs::path& file, Scene& scene) {
  const toml::node* n = output.node("camera");
  if (!n) return;
  if (!n->is_table()) output.fail("camera", "must be an [output.camera] table");
  TableReader r(*n->as_table(), "output.camera", file, &scene.key_lines);
  FrameCamera& c = scene.output.camera;
  c.follow_prop = read_follow(r, scene);
  c.eye = r.optional_vector<3>("eye");
  c.target = r.optional_vector<3>("target");
  c.up = r.unit_vector("up", c.up);
  c.fov = r.positive("fov", c.fov);
  if (!(c.fov < 180.0)) r.fail("fov", fmt::format("must be < 180 degrees (got {})", c.fov));
  if (const toml::node* size = r.node("size")) {
    const toml::array* a = size->as_array();
    const char* form = "must be [width, height] in pixels, two integers";
    if (!a || a->size() != 2 || !a->get(0)->is_integer() || !a->get(1)->is_integer()) r.fail("size", form);
    const std::int64_t w = *a->get(0)->value<std::int64_t>(), h = *a->get(1)->value<std::int64_t>();
    constexpr std::int64_t kMin = 16, kMax = 8192;
    if (w < kMin || h < kMin || w > kMax || h > kMax)
      r.fail("size", fmt::format("{} x {} pixels: each side must be {} to {} pixels", w, h, kMin, kMax));
    c.width = static_cast<int>(w);
    c.height = static_cast<int>(h);
  }
  if (c.follow_prop >= 0 && c.target)
    r.fail("target",
           "a camera following a prop looks at the prop's centre: remove target (eye alone sets where "
           "the eye starts)");
  if (c.follow_prop < 0 && c.eye.has_value() != c.target.has_value())
    r.fail(c.eye ? "eye" : "target",
           "a fixed camera needs both eye and target (m); without either, the default "
           "camera frames the scene");
  if (c.eye && c.target) {
    const Eigen::Vector3d view = *c.target - *c.eye;
    if (view.norm() < 1e-9) r.fail("target", "must differ from eye");
    if (view.normalized().cross(c.up).norm() < 1e-6) r.fail("up", "must not be parallel to target - eye");
  }
  r.reject_unknown_keys();
}

void read_output(TableReader& root, const fs::path& file, Scene& scene) {
  const toml::node* n = root.node("output");
  if (!n) return;
  if (!n->is_table()) root.fail("output", "must be a table");
  TableReader r(*n->as_table(), "output", file, &scene.key_lines);
  OutputSettings& o = scene.output;
  o.every = r.integer("every", o.every, 1);
  o.frames = r.boolean("frames", o.frames);
  o.color_by = static_cast<FrameColoring>(
      r.choice("color_by", {"sand", "height", "speed", "body"}, static_cast<std::size_t>(o.color_by)));
  o.walls = r.boolean("walls", o.walls);
  read_camera(r, file, scene);
  o.ply = r.boolean("ply", o.ply);
  o.vtp = r.boolean("vtp", o.vtp);
  o.csv = r.boolean("csv", o.csv);
  o.contacts = r.boolean("contacts", o.contacts);
  o.checkpoint_every = r.integer("checkpoint_every", 0, 0);
  o.checkpoint_seconds = r.non_negative("checkpoint_seconds", 0.0);
  r.reject_unknown_keys();
}

// The servo's samples (servo.csv) are not part of a checkpoint, so a resumed run would lose them.
void reject_servo_checkpoints(const Scene& scene) {
  const OutputSettings& o = scene.output;
  if (o.checkpoint_every == 0 && o.checkpoint_seconds == 0) return;
  for (const Prop& p : scene.props) {
    if (!p.servo) continue;
    const char* key = o.checkpoint_every > 0 ? "output.checkpoint_every" : "output.checkpoint_seconds";
    throw InputError(
        fmt::format("{}: checkpoints cannot be written yet in a run with a servo ([prop.servo] of "
                    "the [[prop]] at line {}: servo.csv is not kept in them)",
                    scene_location(scene, key), p.line));
  }
}

// Forward Euler adds energy to every undamped oscillation, and a bond is one: bonded spheres would
// shake themselves apart. Symplectic Euler keeps the bonds' energy bounded at the bond time step.
void reject_euler_bonds(const Scene& scene) {
  if (!scene.has_bonds() || scene.simulation.step.integrator != Integrator::ForwardEuler) return;
  throw InputError(fmt::format("{}: \"euler\" cannot run a breakable prop (forward Euler gains energy in every "
                               "bond's oscillation until the bonds break by themselves); use integrator = "
                               "\"symplectic\" (the default)",
                               scene_location(scene, "simulation.integrator")));
}

Scene read_scene(const toml::table& root_table, const fs::path& file) {
  Scene scene;
  scene.file = file;
  TableReader root(root_table, "", file, &scene.key_lines);
  scene.gravity = root.vector<3>("gravity", scene.gravity);
  for_each_table(root, "material", [&](const toml::table& t) { read_material(t, file, scene); });
  if (scene.materials.empty()) root.fail("material", "no [[material]] table: a scene needs at least one");
  read_grains(root, file, scene);
  for_each_table(root, "emitter", [&](const toml::table& t) { read_emitter(t, file, scene); });
  for_each_table(root, "bond_material", [&](const toml::table& t) { read_bond_material(t, file, scene); });
  for_each_table(root, "prop", [&](const toml::table& t) { read_prop(t, file, scene); });
  if (const toml::node* props = root_table.get("prop"); props && props->is_array())
    resolve_bind_to(*props->as_array(), file, scene);
  for_each_table(root, "boundary", [&](const toml::table& t) { read_boundary(t, file, scene); });
  read_simulation(root, file, scene);
  read_output(root, file, scene);
  root.reject_unknown_keys();
  reject_servo_checkpoints(scene);
  reject_euler_bonds(scene);
  return scene;
}

}  // namespace

Scene parse_scene(std::string_view text, const std::filesystem::path& file) {
  toml::table table;
  try {
    table = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}: {}", file.string(), e.source().begin.line, e.description()));
  }
  return read_scene(table, file);
}

Scene load_scene(const std::filesystem::path& file) {
  // A scene is a text of keys (the largest bundled one is a few kB); the bound refuses a huge file
  // at once instead of reading it (a device or a FIFO is refused by read_file).
  constexpr std::uint64_t kMostSceneBytes = std::uint64_t{64} << 20;
  return parse_scene(read_file(file, kMostSceneBytes, "a scene file is a text of keys"), file);
}

bool Scene::has_bonds() const {
  return std::any_of(props.begin(), props.end(), [](const Prop& p) { return p.breakable; });
}

std::string scene_location(const Scene& scene, std::string_view key, int line) {
  if (line == 0) {
    const auto it = scene.key_lines.find(key);
    if (it != scene.key_lines.end()) line = it->second;
  }
  if (line == 0) return fmt::format("{}: {}", scene.file.string(), key);
  return fmt::format("{}:{}: {}", scene.file.string(), line, key);
}

}  // namespace ts::scene
