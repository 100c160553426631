#include "body/json_fields.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "body/particle_body.h"
#include "core/error.h"

namespace ts::body::detail {

Fields::Fields(const std::filesystem::path& file, const Json& node, std::string prefix,
               std::vector<std::string> keys, std::optional<std::vector<std::string>> required)
    : file_(file),
      node_(node),
      prefix_(std::move(prefix)),
      required_(required ? std::move(*required) : keys) {
  if (!node.is_object()) {
    fail_at(prefix_.empty() ? "(top level)" : prefix_.substr(0, prefix_.size() - 1), "must be an object");
  }
  for (const auto& item : node.items()) {
    if (std::find(keys.begin(), keys.end(), item.key()) == keys.end()) {
      fail(item.key(),
           fmt::format("unknown key (format_version {} has: {})", kBodyFormatVersion, fmt::join(keys, ", ")));
    }
  }
}

void Fields::fail(const std::string& key, const std::string& problem) const {
  fail_at(prefix_ + key, problem);
}

void Fields::fail_at(const std::string& key_path, const std::string& problem) const {
  throw InputError(file_, fmt::format("{}: {}", key_path, problem));
}

bool Fields::has(const std::string& key) const {
  if (node_.contains(key)) return true;
  if (std::find(required_.begin(), required_.end(), key) != required_.end()) fail(key, "missing");
  return false;
}

const Json& Fields::at(const std::string& key) const {
  if (!node_.contains(key)) fail(key, "missing");
  return node_.at(key);
}

double Fields::number(const std::string& key, const Json& value) const {
  if (!value.is_number()) fail(key, "must be a number");
  const double v = value.get<double>();
  if (!std::isfinite(v)) fail(key, "must be finite");
  return v;
}

double Fields::number(const std::string& key) const { return number(key, at(key)); }

double Fields::positive(const std::string& key) const {
  const double v = number(key);
  if (!(v > 0.0)) fail(key, fmt::format("must be > 0, not {}", v));
  return v;
}

double Fields::non_negative(const std::string& key) const {
  const double v = number(key);
  if (v < 0.0) fail(key, fmt::format("must be >= 0, not {}", v));
  return v;
}

std::int64_t Fields::count(const std::string& key) const {
  const Json& v = at(key);
  if (!v.is_number_integer() || v.get<std::int64_t>() < 0) fail(key, "must be a non-negative integer");
  return v.get<std::int64_t>();
}

int Fields::small_count(const std::string& key) const {
  const std::int64_t v = count(key);
  if (v > std::numeric_limits<int>::max()) fail(key, "is too large");
  return static_cast<int>(v);
}

std::string Fields::string(const std::string& key) const {
  const Json& v = at(key);
  if (!v.is_string()) fail(key, "must be a string");
  return v.get<std::string>();
}

bool Fields::boolean(const std::string& key) const {
  const Json& v = at(key);
  if (!v.is_boolean()) fail(key, "must be true or false");
  return v.get<bool>();
}

Eigen::Vector3d Fields::vector(const std::string& key, const Json& value) const {
  if (!value.is_array() || value.size() != 3) fail(key, "must be an array of 3 numbers");
  return {number(key, value[0]), number(key, value[1]), number(key, value[2])};
}

Eigen::Vector3d Fields::vector(const std::string& key) const { return vector(key, at(key)); }

Eigen::Matrix3d Fields::rows(const std::string& key) const {
  const Json& v = at(key);
  if (!v.is_array() || v.size() != 3) fail(key, "must be 3 arrays of 3 numbers");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = vector(key, v[r]).transpose();
  return m;
}

}  // namespace ts::body::detail
