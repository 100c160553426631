#pragma once
// Points as VTK XML PolyData (.vtp) in the "appended raw" encoding vtkXMLPolyDataWriter writes by
// default: each array's bytes after a UInt64 byte count, in one block at the end of the file. Every
// point is a vertex cell, so ParaView and VTK show the points without a Glyph filter. Used for a run's
// particles (scene/vtk_files.h) and a body's (body/body_file.h).
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace ts {

class VtpPoints {
 public:
  // `points`: x, y, z of each point.
  explicit VtpPoints(std::vector<double> points) : points_(std::move(points)) {}

  // A point array of `components` values a point (Float64, Float32, UInt32 or UInt8 by T).
  template <typename T>
  void add(const char* name, int components, const std::vector<T>& values) {
    add_raw(vtk_type<T>(), name, components, values.data(), values.size(), sizeof(T));
  }
  // Field data: the time of the file (s), read by ParaView as TimeValue.
  void set_time(double time) { time_ = time; has_time_ = true; }

  // The whole file.
  std::string bytes() const;

 private:
  template <typename T>
  static const char* vtk_type() {
    if constexpr (std::is_same_v<T, double>) return "Float64";
    if constexpr (std::is_same_v<T, float>) return "Float32";
    if constexpr (std::is_same_v<T, std::uint32_t>) return "UInt32";
    if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, float> || std::is_same_v<T, std::uint32_t> ||
                  std::is_same_v<T, std::uint8_t>);
  }
  void add_raw(const char* type, const char* name, int components, const void* data, std::size_t count,
               std::size_t size);
  struct Array {
    std::string type, name;
    int components;
    std::string data;
  };
  std::vector<double> points_;
  std::vector<Array> arrays_;
  double time_ = 0;
  bool has_time_ = false;
};

}  // namespace ts
