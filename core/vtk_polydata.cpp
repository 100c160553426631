#include "core/vtk_polydata.h"

#include <fmt/format.h>

namespace ts {
namespace {

// The DataArray elements and the appended block they point into, filled array by array.
class AppendedBlock {
 public:
  std::string element(const std::string& type, const std::string& name, int components, const std::string& data) {
    const std::uint64_t bytes = data.size();
    const std::size_t size = type == "UInt8" ? 1 : (type == "Float32" || type == "UInt32") ? 4 : 8;
    std::string e = fmt::format("<DataArray type=\"{}\"{} NumberOfComponents=\"{}\" NumberOfTuples=\"{}\" "
                                "format=\"appended\" offset=\"{}\"/>\n",
                                type, name.empty() ? std::string() : fmt::format(" Name=\"{}\"", name), components,
                                bytes / size / static_cast<std::size_t>(components), block_.size());
    block_.append(reinterpret_cast<const char*>(&bytes), sizeof bytes);
    block_ += data;
    return e;
  }
  const std::string& block() const { return block_; }

 private:
  std::string block_;
};

template <typename T>
std::string raw(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace

void VtpPoints::add_raw(const char* type, const char* name, int components, const void* data, std::size_t count,
                        std::size_t size) {
  arrays_.push_back({type, name, components, std::string(static_cast<const char*>(data), count * size)});
}

std::string VtpPoints::bytes() const {
  const std::size_t n = points_.size() / 3;
  AppendedBlock block;
  std::string field_data;
  if (has_time_) field_data = block.element("Float64", "TimeValue", 1, raw(std::vector<double>{time_}));
  std::string point_data;
  for (const Array& a : arrays_) point_data += block.element(a.type, a.name, a.components, a.data);
  const std::string points = block.element("Float64", "", 3, raw(points_));
  std::vector<std::int64_t> connectivity(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  const std::string cells = block.element("Int64", "connectivity", 1, raw(connectivity)) +
                            block.element("Int64", "offsets", 1, raw(offsets));
  std::string bytes = fmt::format(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "<PolyData>\n{0}"
      "<Piece NumberOfPoints=\"{1}\" NumberOfVerts=\"{1}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"0\">\n<PointData>\n{2}</PointData>\n"
      "<Points>\n{3}</Points>\n<Verts>\n{4}</Verts>\n</Piece>\n</PolyData>\n"
      "<AppendedData encoding=\"raw\">\n_",
      field_data.empty() ? std::string() : "<FieldData>\n" + field_data + "</FieldData>\n", n, point_data, points,
      cells);
  bytes += block.block();
  bytes += "\n</AppendedData>\n</VTKFile>\n";
  return bytes;
}

}  // namespace ts
