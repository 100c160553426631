#pragma once
// Private to body/: typed, validated access to the keys of one JSON object of a body file.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace ts::body::detail {

using Json = nlohmann::ordered_json;  // keeps the documented key order in written files

// Every error is ts::InputError "FILE: KEY_PATH: problem", the key path with the object's prefix
// (e.g. quality.cv).
class Fields {
 public:
  // `node` is the object at `prefix` ("" for the top level, else "quality." and the like). Its keys
  // must be among `keys`; `required` of them must be present (all of `keys` when not given).
  Fields(const std::filesystem::path& file, const Json& node, std::string prefix,
         std::vector<std::string> keys, std::optional<std::vector<std::string>> required = std::nullopt);

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

  // Whether `key` is present; a required key that is absent fails ("missing").
  bool has(const std::string& key) const;
  // The value of `key`; fails when it is absent.
  const Json& at(const std::string& key) const;

  double number(const std::string& key, const Json& value) const;  // finite
  double number(const std::string& key) const;
  double positive(const std::string& key) const;      // finite, > 0
  double non_negative(const std::string& key) const;  // finite, >= 0
  std::int64_t count(const std::string& key) const;   // integer >= 0
  int small_count(const std::string& key) const;      // integer >= 0 that fits an int
  std::string string(const std::string& key) const;
  bool boolean(const std::string& key) const;
  Eigen::Vector3d vector(const std::string& key, const Json& value) const;  // [x, y, z]
  Eigen::Vector3d vector(const std::string& key) const;
  // Three arrays of three numbers, returned as the rows of a matrix.
  Eigen::Matrix3d rows(const std::string& key) const;

 private:
  [[noreturn]] void fail_at(const std::string& key_path, const std::string& problem) const;

  const std::filesystem::path& file_;
  const Json& node_;
  std::string prefix_;
  std::vector<std::string> required_;
};

}  // namespace ts::body::detail
