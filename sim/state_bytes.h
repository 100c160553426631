#pragma once
// Byte strings of simulation state for checkpoints (docs/checkpoint-format.md): plain values in the
// machine's byte order (little-endian; checked at compile time), strings and arrays as a 64-bit
// count followed by their bytes. The reader checks every count against the bytes left, so a damaged
// file is an error naming it, never a huge allocation.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace ts::sim {

static_assert(std::endian::native == std::endian::little, "checkpoints are little-endian");

class ByteWriter {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void put(const Eigen::Vector3d& v) { put_doubles(v.data(), 3); }
  void put(const Eigen::Vector2d& v) { put_doubles(v.data(), 2); }
  void put(const Eigen::Matrix3d& m) { put_doubles(m.data(), 9); }
  void put(const Eigen::Quaterniond& q) { put_doubles(q.coeffs().data(), 4); }
  void put_string(std::string_view text) {
    put<std::uint64_t>(text.size());
    bytes_.append(text);
  }
  // A count, then each element through put().
  template <typename T>
  void put_vector(const std::vector<T>& values) {
    put<std::uint64_t>(values.size());
    for (const T& v : values) put(v);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  void put_doubles(const double* values, std::size_t count) {
    bytes_.append(reinterpret_cast<const char*>(values), count * sizeof(double));
  }
  std::string bytes_;
};

class ByteReader {
 public:
  // `what` names the bytes in messages (the checkpoint file).
  ByteReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof value), sizeof value);
    return value;
  }
  void get(Eigen::Vector3d& v) { get_doubles(v.data(), 3); }
  void get(Eigen::Vector2d& v) { get_doubles(v.data(), 2); }
  void get(Eigen::Matrix3d& m) { get_doubles(m.data(), 9); }
  void get(Eigen::Quaterniond& q) { get_doubles(q.coeffs().data(), 4); }
  template <typename T>
  void get(T& value) {
    value = get<T>();
  }
  std::string get_string() {
    const std::uint64_t size = get_count(1);
    return std::string(take(size), size);
  }
  template <typename T>
  std::vector<T> get_vector(std::size_t element_bytes = sizeof(T)) {
    std::vector<T> values(get_count(element_bytes));
    for (T& v : values) get(v);
    return values;
  }
  // A count of elements of at least `element_bytes` each, checked against what is left.
  std::size_t get_count(std::size_t element_bytes) {
    const auto n = get<std::uint64_t>();
    if (n > (bytes_.size() - offset_) / element_bytes) fail("an array runs past the end of the file");
    return static_cast<std::size_t>(n);
  }
  bool done() const { return offset_ == bytes_.size(); }
  const std::string& what() const { return what_; }
  // Throws ts::InputError "what: problem (at byte N)".
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  const char* take(std::size_t size) {
    if (size > bytes_.size() - offset_) fail("truncated");
    const char* at = bytes_.data() + offset_;
    offset_ += size;
    return at;
  }
  void get_doubles(double* values, std::size_t count) {
    std::memcpy(values, take(count * sizeof(double)), count * sizeof(double));
  }

  std::string_view bytes_;
  std::string what_;
  std::size_t offset_ = 0;
};

// Arrays of structs: a count, then each element through `put_one`; read back likewise, the count
// checked against the bytes left (each element takes at least `min_bytes`).
template <typename T, typename Put>
void put_each(ByteWriter& w, const std::vector<T>& values, Put put_one) {
  w.put<std::uint64_t>(values.size());
  for (const T& v : values) put_one(v);
}
template <typename T, typename Get>
std::vector<T> get_each(ByteReader& r, std::size_t min_bytes, Get get_one) {
  std::vector<T> values(r.get_count(min_bytes));
  for (T& v : values) get_one(v);
  return values;
}

}  // namespace ts::sim
