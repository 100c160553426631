#include "core/mesh_file_checks.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/ply.h"
#include "core/text_tokens.h"

namespace ts::detail {
namespace {

bool parses_as_number(std::string_view token) { return parse_number(token).has_value(); }

// The lines of an OFF file without comments and blank lines, each with its 1-based number.
struct Line {
  std::size_t number;
  std::vector<std::string_view> tokens;
};

class OffLines {
 public:
  explicit OffLines(std::string_view text) : text_(text) {}
  std::optional<Line> next() {
    while (pos_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
      std::string_view content = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++number_;
      content = content.substr(0, content.find('#'));
      Line line{number_, {}};
      Tokens tokens(content);
      while (auto t = tokens.next()) line.tokens.push_back(*t);
      if (!line.tokens.empty()) return line;
    }
    return std::nullopt;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

[[noreturn]] void fail(const std::filesystem::path& path, std::size_t line, const std::string& problem) {
  throw InputError(path, fmt::format("line {}: {}", line, problem));
}

}  // namespace

void check_off_file(const std::filesystem::path& path, std::string_view text) {
  OffLines lines(text);
  auto header = lines.next();
  if (!header) throw InputError(path, "holds no OFF header");
  const std::string_view keyword = header->tokens[0];
  static constexpr std::string_view known[] = {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
  if (std::find(std::begin(known), std::end(known), keyword) == std::end(known)) {
    fail(path, header->number,
         fmt::format("'{}' is not an OFF header this reader supports (OFF, COFF, NOFF, CNOFF; not 4OFF, nOFF or binary)",
                     keyword));
  }
  // The counts may follow the keyword on the same line.
  Line counts = *header;
  counts.tokens.erase(counts.tokens.begin());
  if (counts.tokens.empty()) {
    auto next = lines.next();
    if (!next) throw InputError(path, "ends after the OFF header, before the vertex and face counts");
    counts = *next;
  }
  if (counts.tokens.size() < 2) fail(path, counts.number, "expected 'vertices faces [edges]' counts");
  const auto vertex_count = parse_integer(counts.tokens[0]), face_count = parse_integer(counts.tokens[1]);
  if (!vertex_count || !face_count || *vertex_count < 0 || *face_count < 0) {
    fail(path, counts.number, fmt::format("vertex and face counts must be non-negative integers (got '{}' '{}')",
                                          counts.tokens[0], counts.tokens[1]));
  }
  for (std::int64_t v = 0; v < *vertex_count; ++v) {
    auto line = lines.next();
    if (!line) throw InputError(path, fmt::format("the header declares {} vertices but the file ends after {}", *vertex_count, v));
    if (line->tokens.size() < 3 || !std::all_of(line->tokens.begin(), line->tokens.begin() + 3, parses_as_number)) {
      fail(path, line->number, fmt::format("vertex {} needs three numeric coordinates", v));
    }
  }
  for (std::int64_t f = 0; f < *face_count; ++f) {
    auto line = lines.next();
    if (!line) throw InputError(path, fmt::format("the header declares {} faces but the file ends after {}", *face_count, f));
    const auto corners = parse_integer(line->tokens[0]);
    if (!corners || *corners < 3) {
      fail(path, line->number, fmt::format("face {} must start with its number of corners, at least 3 (got '{}')", f,
                                           line->tokens[0]));
    }
    if (static_cast<std::int64_t>(line->tokens.size()) - 1 < *corners) {
      fail(path, line->number, fmt::format("face {} declares {} corners but lists {}", f, *corners, line->tokens.size() - 1));
    }
    for (std::int64_t c = 1; c <= *corners; ++c) {
      const auto index = parse_integer(line->tokens[static_cast<std::size_t>(c)]);
      if (!index || *index < 0 || *index >= *vertex_count) {
        fail(path, line->number, fmt::format("face {} refers to vertex '{}', outside 0..{}", f,
                                             line->tokens[static_cast<std::size_t>(c)], *vertex_count - 1));
      }
    }
  }
}

namespace {

// The elements assimp gives a meaning to, by name: positions, polygons and triangle strips, whose
// corner lists are named vertex_indices or vertex_index.
bool is_vertex_index_name(const std::string& name) {
  return name == "vertex_indices" || name == "vertex_index";
}
bool has_corner_lists(const ply::Element& element) {
  return element.name == "face" || element.name == "tristrips";
}

// What assimp makes of the header is what was checked: one vertex element with scalar x, y and z
// (assimp reads a missing one as 0), one face element, corner lists that are lists.
void check_ply_layout(const std::filesystem::path& path, const ply::Header& header) {
  std::vector<std::string> seen;
  for (const ply::Element& element : header.elements) {
    if ((element.name == "vertex" || has_corner_lists(element)) &&
        std::find(seen.begin(), seen.end(), element.name) != seen.end()) {
      throw InputError(path, fmt::format("the PLY header declares element '{}' twice", element.name));
    }
    seen.push_back(element.name);
    if (element.name == "vertex") {
      for (const char* axis : {"x", "y", "z"}) {
        if (!element.scalar_property(axis)) {
          throw InputError(
              path,
              fmt::format("the vertex element has no scalar property {} (a mesh needs x, y and z)", axis));
        }
      }
    }
    if (!has_corner_lists(element)) continue;
    const auto corners = std::find_if(element.properties.begin(), element.properties.end(),
                                      [](const ply::Property& p) { return is_vertex_index_name(p.name); });
    if (element.count > 0 && (corners == element.properties.end() || !corners->is_list())) {
      throw InputError(path, fmt::format("element '{}' has no list property vertex_indices", element.name));
    }
  }
  if (std::find(seen.begin(), seen.end(), "vertex") == seen.end())
    throw InputError(path, "the PLY header declares no vertex element (a mesh needs one, with x, y and z)");
}

// One corner of row `row` of a face or tristrips element: a vertex index (a strip may also hold -1,
// its restart marker).
void check_corner(const std::filesystem::path& path, const ply::DataReader& reader,
                  const ply::Element& element, std::uint64_t row, double index, std::int64_t vertex_count) {
  const bool restart = element.name == "tristrips" && index == -1.0;
  if (restart || (index >= 0 && index < static_cast<double>(vertex_count) && index == std::floor(index)))
    return;
  throw InputError(path, fmt::format("{}{} {} refers to vertex {}, outside 0..{}",
                                     reader.line() ? fmt::format("line {}: ", reader.line()) : "",
                                     element.name, row, index, vertex_count - 1));
}

// A face has three corners or more (assimp's triangulation aborts the process on a face without
// any); an ascii row is one line, as assimp reads it (a row spread over lines, or two on one line,
// would be misread).
void check_row_shape(const std::filesystem::path& path, const ply::DataReader& reader,
                     const ply::Element& element, std::uint64_t row, double corners, std::size_t& last_line) {
  if (element.name == "face" && corners < 3) {
    throw InputError(path,
                     fmt::format("{}face {} has {} corners; a face needs at least 3",
                                 reader.line() ? fmt::format("line {}: ", reader.line()) : "", row, corners));
  }
  if (reader.row_line() == 0) return;  // binary data
  if (reader.row_line() <= last_line || reader.line() != reader.row_line()) {
    throw InputError(path,
                     fmt::format("line {}: '{}' {} does not stand on a line of its own (one row per line, as "
                                 "the PLY format and assimp want it)",
                                 reader.row_line(), element.name, row));
  }
  last_line = reader.line();
}

// Reads every row of every element, as assimp will: truncation, list lengths and (in ascii data)
// numbers are checked by the reader, the rows' shapes and the corners here.
void check_ply_data(const std::filesystem::path& path, std::string_view bytes, const ply::Header& header) {
  std::int64_t vertex_count = 0;
  for (const auto& e : header.elements)
    if (e.name == "vertex") vertex_count = static_cast<std::int64_t>(e.count);
  ply::DataReader reader(path, bytes, header);
  std::size_t last_line = 0;
  for (const ply::Element& element : header.elements) {
    if (element.properties.empty()) continue;  // its rows hold no data
    std::optional<std::size_t> corners;
    for (std::size_t p = 0; p < element.properties.size(); ++p)
      if (has_corner_lists(element) && is_vertex_index_name(element.properties[p].name)) corners = p;
    std::vector<double> values(element.properties.size());
    for (std::uint64_t i = 0; i < element.count; ++i) {
      reader.read_row(element, i, values, [&](std::size_t p, double index) {
        if (p == corners) check_corner(path, reader, element, i, index, vertex_count);
      });
      check_row_shape(path, reader, element, i, corners ? values[*corners] : 3.0, last_line);
    }
  }
}

}  // namespace

void check_ply_file(const std::filesystem::path& path, std::string_view bytes) {
  // Unknown header lines are skipped, as assimp does (exporters wrap long comments onto lines of
  // their own), but not between an element's properties, where assimp would misread the data; and
  // big-endian files are read like the others: ply::HeaderRules' defaults.
  const ply::Header header = ply::parse_header(path, bytes);
  check_ply_layout(path, header);
  check_ply_data(path, bytes, header);
}

namespace {

std::uint32_t read_u32_le(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(b)]);
  return v;
}

}  // namespace

void check_glb_file(const std::filesystem::path& path, std::string_view bytes) {
  constexpr std::size_t kHeader = 12, kChunkHeader = 8;
  if (bytes.size() < kHeader) throw InputError(path, fmt::format("a GLB file needs a 12-byte header; it has {} bytes", bytes.size()));
  const std::uint32_t version = read_u32_le(bytes, 4), length = read_u32_le(bytes, 8);
  // Version 1 (KHR_binary_glTF) is left to assimp, which has no reader for it and says so.
  if (version != 2) return;
  if (length != bytes.size()) {
    throw InputError(path, fmt::format("the GLB header says the file is {} bytes long; it is {}", length, bytes.size()));
  }
  std::size_t at = kHeader;
  for (int chunk = 0; at < bytes.size(); ++chunk) {
    if (at + kChunkHeader > bytes.size()) {
      throw InputError(path, fmt::format("GLB chunk {} at byte {} has no room for its 8-byte header", chunk, at));
    }
    const std::uint64_t chunk_length = read_u32_le(bytes, at);
    const std::uint32_t type = read_u32_le(bytes, at + 4);
    if (chunk == 0 && type != 0x4E4F534Au) throw InputError(path, "the first GLB chunk is not JSON");
    if (at + kChunkHeader + chunk_length > bytes.size()) {
      throw InputError(path, fmt::format("GLB chunk {} of {} bytes at byte {} runs past the end of the file ({} bytes)",
                                         chunk, chunk_length, at, bytes.size()));
    }
    at += kChunkHeader + static_cast<std::size_t>(chunk_length);
  }
  const std::uint64_t json_length = read_u32_le(bytes, kHeader);
  const std::size_t bin_at = kHeader + kChunkHeader + static_cast<std::size_t>(json_length);
  std::optional<std::uint64_t> bin_length;
  if (bin_at + kChunkHeader <= bytes.size() && read_u32_le(bytes, bin_at + 4) == 0x004E4942u)
    bin_length = read_u32_le(bytes, bin_at);
  check_gltf_json(path, bytes.substr(kHeader + kChunkHeader, static_cast<std::size_t>(json_length)),
                  bin_length.value_or(0));
}

namespace {

using Json = nlohmann::json;

// glTF's sizes and offsets are JSON numbers; anything that is not a whole number from 0 to 2^53 is
// refused. Lengths are compared in long double: exact below 2^64, and far past any buffer above.
class GltfChecker {
 public:
  GltfChecker(const std::filesystem::path& path, const Json& doc) : path_(path), doc_(doc) {}

  [[noreturn]] void fail(const std::string& problem) const { throw InputError(path_, "glTF: " + problem); }

  const Json& array(const char* key) const {
    static const Json kEmpty = Json::array();
    if (!doc_.contains(key)) return kEmpty;
    if (!doc_[key].is_array()) fail(fmt::format("'{}' is not an array", key));
    return doc_[key];
  }

  // `value`, found under `key` of `what`, as a whole number.
  std::uint64_t whole_number(const Json& value, std::string_view key, const std::string& what) const {
    constexpr double kLargest = 9007199254740992.0;  // 2^53
    if (!value.is_number() || value.get<double>() < 0 || value.get<double>() > kLargest ||
        std::floor(value.get<double>()) != value.get<double>())
      fail(fmt::format("{}: '{}' is {}, not a whole number from 0 to 2^53", what, key, value.dump().substr(0, 40)));
    return static_cast<std::uint64_t>(value.get<double>());
  }

  std::uint64_t number(const Json& object, const char* key, const std::string& what,
                       std::optional<std::uint64_t> fallback = std::nullopt) const {
    if (!object.is_object()) fail(what + " is not an object");
    if (!object.contains(key)) {
      if (fallback) return *fallback;
      fail(fmt::format("{} has no '{}'", what, key));
    }
    return whole_number(object[key], key, what);
  }

  // `value` (under `key` of `what`) as an index into doc_[into], checked.
  std::uint64_t index_of(const Json& value, std::string_view key, const char* into, const std::string& what) const {
    const std::uint64_t i = whole_number(value, key, what);
    if (i >= array(into).size())
      fail(fmt::format("{} refers to {}[{}]; there are {}", what, into, i, array(into).size()));
    return i;
  }

  std::uint64_t index(const Json& object, const char* key, const char* into, const std::string& what) const {
    if (!object.is_object()) fail(what + " is not an object");
    if (!object.contains(key)) fail(fmt::format("{} has no '{}'", what, key));
    return index_of(object[key], key, into, what);
  }

 private:
  const std::filesystem::path& path_;
  const Json& doc_;
};

std::uint64_t accessor_component_bytes(const GltfChecker& gltf, std::uint64_t type, const std::string& what) {
  switch (type) {
    case 5120: case 5121: return 1;  // (unsigned) byte
    case 5122: case 5123: return 2;  // (unsigned) short
    case 5125: case 5126: return 4;  // unsigned int, float
    default: gltf.fail(fmt::format("{} has componentType {}, which glTF 2.0 does not define", what, type));
  }
}

std::uint64_t accessor_components(const GltfChecker& gltf, const Json& accessor, const std::string& what) {
  static const std::map<std::string, std::uint64_t> kComponents = {
      {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};
  if (!accessor.contains("type") || !accessor["type"].is_string()) gltf.fail(what + " has no type");
  const auto it = kComponents.find(accessor["type"].get<std::string>());
  if (it == kComponents.end()) gltf.fail(fmt::format("{} has type {}", what, accessor["type"].dump().substr(0, 40)));
  return it->second;
}

// The bytes behind a buffer: the GLB's BIN chunk, a data: URI's decoded payload, or a file beside the
// glTF (its name percent-decoded). nullopt when the file cannot be found (assimp reports that).
std::optional<std::uint64_t> buffer_bytes(const std::filesystem::path& path, const Json& buffer, std::size_t i,
                                          std::optional<std::uint64_t> glb_binary) {
  if (!buffer.contains("uri")) return i == 0 && glb_binary ? glb_binary : std::optional<std::uint64_t>(0);
  if (!buffer["uri"].is_string()) return 0;
  const std::string uri = buffer["uri"].get<std::string>();
  if (uri.starts_with("data:")) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos) return 0;
    const std::string_view payload = std::string_view(uri).substr(comma + 1);
    if (std::string_view(uri).substr(0, comma).ends_with(";base64")) {
      // 3 bytes for every 4 characters, padded or not; '=' padding carries none.
      std::size_t padding = 0;
      for (std::size_t k = payload.size(); k > 0 && payload[k - 1] == '=' && padding < 2; --k) ++padding;
      const std::uint64_t decoded = static_cast<std::uint64_t>(payload.size()) * 3 / 4;
      return decoded - std::min<std::uint64_t>(padding, decoded);
    }
    return payload.size();
  }
  std::string name;
  for (std::size_t k = 0; k < uri.size(); ++k) {
    if (uri[k] == '%' && k + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[k + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[k + 2]))) {
      name += static_cast<char>(std::stoi(uri.substr(k + 1, 2), nullptr, 16));
      k += 2;
    } else {
      name += uri[k];
    }
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path.parent_path() / name, ec);
  if (ec) return std::nullopt;
  return size;
}

}  // namespace

namespace {

// The declared length of every buffer, each checked against the bytes behind it.
std::vector<std::uint64_t> check_buffers(const GltfChecker& gltf, const std::filesystem::path& path,
                                         std::optional<std::uint64_t> glb_binary) {
  std::vector<std::uint64_t> buffer_lengths;
  for (std::size_t i = 0; i < gltf.array("buffers").size(); ++i) {
    const Json& buffer = gltf.array("buffers")[i];
    const std::string what = fmt::format("buffer {}", i);
    const std::uint64_t declared = gltf.number(buffer, "byteLength", what);
    const auto available = buffer_bytes(path, buffer, i, glb_binary);
    if (available && declared > *available)
      gltf.fail(fmt::format("{} declares {} bytes; its data has {}", what, declared, *available));
    buffer_lengths.push_back(declared);
  }
  return buffer_lengths;
}

struct View {
  std::uint64_t length;
  std::optional<std::uint64_t> stride;
};

// Every bufferView, checked to lie inside its buffer.
std::vector<View> check_buffer_views(const GltfChecker& gltf,
                                     const std::vector<std::uint64_t>& buffer_lengths) {
  std::vector<View> views;
  for (std::size_t i = 0; i < gltf.array("bufferViews").size(); ++i) {
    const Json& view = gltf.array("bufferViews")[i];
    const std::string what = fmt::format("bufferView {}", i);
    const std::uint64_t buffer = gltf.index(view, "buffer", "buffers", what);
    const std::uint64_t offset = gltf.number(view, "byteOffset", what, 0);
    const std::uint64_t length = gltf.number(view, "byteLength", what);
    if (static_cast<long double>(offset) + length > buffer_lengths[buffer])
      gltf.fail(fmt::format("{} spans bytes {} to {} of buffer {}, which has {}", what, offset,
                            static_cast<long double>(offset) + length, buffer, buffer_lengths[buffer]));
    // No stride, or 0, is tightly packed: assimp then steps by the element's size.
    const std::uint64_t stride = gltf.number(view, "byteStride", what, 0);
    views.push_back({length, stride == 0 ? std::nullopt : std::optional<std::uint64_t>(stride)});
  }
  return views;
}

// Where assimp copies an accessor's elements from: `count` elements of `element` bytes, `stride`
// apart, from `offset` into bufferView `view`; all of it inside the view.
void check_span(const GltfChecker& gltf, const std::vector<View>& views, const std::string& what,
                std::uint64_t view, std::uint64_t offset, std::uint64_t count, std::uint64_t element,
                std::uint64_t stride) {
  if (count == 0) return;
  const long double end =
      static_cast<long double>(offset) + static_cast<long double>(count - 1) * stride + element;
  if (end > views[view].length)
    gltf.fail(
        fmt::format("{} reads {} elements of {} bytes, {} apart, from byte {} of bufferView {}: up to byte "
                    "{}, past its {} bytes",
                    what, count, element, stride, offset, view, end, views[view].length));
}

// A sparse accessor's indices and values (elements of `element` bytes) inside their views.
void check_sparse(const GltfChecker& gltf, const std::vector<View>& views, const Json& sparse,
                  const std::string& what, std::uint64_t element) {
  const std::string sparse_what = what + "'s sparse";
  const std::uint64_t sparse_count = gltf.number(sparse, "count", sparse_what);
  if (!sparse.contains("indices") || !sparse.contains("values"))
    gltf.fail(sparse_what + " lacks indices or values");
  const Json& indices = sparse["indices"];
  const Json& values = sparse["values"];
  const std::string indices_what = sparse_what + " indices";
  const std::string values_what = sparse_what + " values";
  const std::uint64_t index_bytes =
      accessor_component_bytes(gltf, gltf.number(indices, "componentType", indices_what), indices_what);
  const std::uint64_t index_view = gltf.index(indices, "bufferView", "bufferViews", indices_what);
  check_span(gltf, views, indices_what, index_view, gltf.number(indices, "byteOffset", indices_what, 0),
             sparse_count, index_bytes, index_bytes);
  const std::uint64_t value_view = gltf.index(values, "bufferView", "bufferViews", values_what);
  check_span(gltf, views, values_what, value_view, gltf.number(values, "byteOffset", values_what, 0),
             sparse_count, element, element);
}

void check_accessors(const GltfChecker& gltf, const std::vector<View>& views) {
  for (std::size_t i = 0; i < gltf.array("accessors").size(); ++i) {
    const Json& accessor = gltf.array("accessors")[i];
    const std::string what = fmt::format("accessor {}", i);
    const std::uint64_t component = accessor_component_bytes(gltf, gltf.number(accessor, "componentType", what), what);
    const std::uint64_t element = component * accessor_components(gltf, accessor, what);
    const std::uint64_t count = gltf.number(accessor, "count", what);
    if (accessor.contains("bufferView")) {
      const std::uint64_t view = gltf.index(accessor, "bufferView", "bufferViews", what);
      check_span(gltf, views, what, view, gltf.number(accessor, "byteOffset", what, 0), count, element,
                 views[view].stride.value_or(element));
    }
    if (accessor.contains("sparse")) check_sparse(gltf, views, accessor["sparse"], what, element);
  }
}

// One primitive of a mesh: the accessors it names exist, and it has positions.
void check_primitive(const GltfChecker& gltf, const Json& primitive, const std::string& what) {
  if (!primitive.is_object()) gltf.fail(what + " is not an object");
  if (primitive.contains("indices")) gltf.index(primitive, "indices", "accessors", what);
  // assimp's reader builds a primitive's faces on its positions: a line loop without them
  // dereferenced a null vertex array (SIGSEGV, fuzz_mesh, 2026-12-06).
  if (!primitive.contains("attributes") || !primitive["attributes"].is_object() ||
      !primitive["attributes"].contains("POSITION"))
    gltf.fail(what + " has no POSITION attribute: its faces would have no vertices");
  std::vector<const Json*> attribute_sets{&primitive["attributes"]};
  if (primitive.contains("targets") && primitive["targets"].is_array())
    for (const Json& target : primitive["targets"]) attribute_sets.push_back(&target);
  for (const Json* attributes : attribute_sets) {
    if (!attributes->is_object()) gltf.fail(what + ": attributes are not an object");
    for (const auto& [name, value] : attributes->items())
      gltf.index_of(value, name, "accessors", what + " attribute " + name);
  }
}

void check_meshes(const GltfChecker& gltf) {
  for (std::size_t m = 0; m < gltf.array("meshes").size(); ++m) {
    const Json& mesh = gltf.array("meshes")[m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (std::size_t p = 0; p < mesh["primitives"].size(); ++p)
      check_primitive(gltf, mesh["primitives"][p], fmt::format("mesh {} primitive {}", m, p));
  }
}

// The node graph is a forest (one parent at most, no cycle) of at most kMostNodes nodes and
// kMostNodeDepth levels: assimp's glTF reader builds it recursively, and a chain of tens of thousands
// of nodes overflowed its stack (SIGSEGV; issue 46). Iterative, linear in the nodes.
void check_node_tree(const GltfChecker& gltf) {
  const Json& nodes = gltf.array("nodes");
  if (nodes.size() > kMostNodes)
    gltf.fail(fmt::format("{} nodes; at most {} are read", nodes.size(), kMostNodes));
  std::vector<std::int64_t> parent(nodes.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string what = fmt::format("node {}", i);
    if (!nodes[i].is_object()) gltf.fail(what + " is not an object");
    if (!nodes[i].contains("children")) continue;
    if (!nodes[i]["children"].is_array()) gltf.fail(what + ": 'children' is not an array");
    for (const Json& child : nodes[i]["children"]) {
      const std::uint64_t c = gltf.index_of(child, "children", "nodes", what);
      if (parent[c] >= 0 || c == i)
        gltf.fail(fmt::format("node {} is a child of node {} and of node {}: the nodes do not form a tree", c,
                              parent[c] >= 0 ? parent[c] : static_cast<std::int64_t>(i), i));
      parent[c] = static_cast<std::int64_t>(i);
    }
  }
  // Each node's depth: walk up to a node of known depth, then back down the path.
  std::vector<std::size_t> depth(nodes.size(), 0);  // 0: not known yet
  std::vector<std::size_t> path;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    path.clear();
    std::int64_t at = static_cast<std::int64_t>(i);
    while (at >= 0 && depth[static_cast<std::size_t>(at)] == 0) {
      if (path.size() > nodes.size()) gltf.fail(fmt::format("node {} is its own ancestor", i));
      path.push_back(static_cast<std::size_t>(at));
      at = parent[static_cast<std::size_t>(at)];
    }
    std::size_t level = at >= 0 ? depth[static_cast<std::size_t>(at)] : 0;
    for (auto it = path.rbegin(); it != path.rend(); ++it) depth[*it] = ++level;
    if (level > kMostNodeDepth)
      gltf.fail(fmt::format("the node tree is {} levels deep (node {}); at most {} are read", level, i,
                            kMostNodeDepth));
  }
}

}  // namespace

void check_gltf_json(const std::filesystem::path& path, std::string_view json,
                     std::optional<std::uint64_t> glb_binary) {
  check_json_nesting(path, json);
  const Json doc = Json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) throw InputError(path, "glTF: its JSON does not parse");
  if (!doc.is_object()) throw InputError(path, "glTF: its JSON is not an object");
  // glTF 1.0 (asset.version "1.x") has another layout; assimp's reader of it is left as it is.
  if (doc.contains("asset") && doc["asset"].is_object() && doc["asset"].contains("version") &&
      doc["asset"]["version"].is_string() && !doc["asset"]["version"].get<std::string>().starts_with("2"))
    return;
  const GltfChecker gltf(path, doc);
  const std::vector<View> views = check_buffer_views(gltf, check_buffers(gltf, path, glb_binary));
  check_accessors(gltf, views);
  check_meshes(gltf);
  check_node_tree(gltf);
}

void check_json_nesting(const std::filesystem::path& path, std::string_view json) {
  std::size_t depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character, a quote included
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMostNesting)
        throw InputError(path,
                         fmt::format("its JSON nests arrays and objects more than {} deep", kMostNesting));
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}

namespace {

// Past the markup construct that starts at `at` ("<!--", "<?", "<![CDATA[", "<!DOCTYPE ...[...]>"):
// the index of its last character, or the text's end when it is not closed.
std::size_t skip_markup(std::string_view xml, std::size_t at) {
  const auto past = [&](std::string_view end) {
    const std::size_t found = xml.find(end, at);
    return found == std::string_view::npos ? xml.size() : found + end.size() - 1;
  };
  if (xml.substr(at).starts_with("<!--")) return past("-->");
  if (xml.substr(at).starts_with("<![CDATA[")) return past("]]>");
  if (xml.substr(at).starts_with("<?")) return past("?>");
  // A declaration; its internal subset (between [ and ]) may hold '>'.
  int brackets = 0;
  for (std::size_t i = at + 2; i < xml.size(); ++i) {
    if (xml[i] == '[') {
      ++brackets;
    } else if (xml[i] == ']') {
      --brackets;
    } else if (xml[i] == '>' && brackets <= 0) {
      return i;
    }
  }
  return xml.size();
}

// The end ('>') of the tag that starts at `at`, past quoted attribute values.
std::size_t tag_end(std::string_view xml, std::size_t at) {
  char quote = 0;
  for (std::size_t i = at + 1; i < xml.size(); ++i) {
    if (quote) {
      if (xml[i] == quote) quote = 0;
    } else if (xml[i] == '"' || xml[i] == '\'') {
      quote = xml[i];
    } else if (xml[i] == '>') {
      return i;
    }
  }
  return xml.size();
}

// A tag's element name without its namespace prefix ("node" of "<dae:node id='a'>").
std::string_view local_name(std::string_view xml, std::size_t at, std::size_t end) {
  std::size_t stop = at + 1;
  while (stop < end && xml[stop] != '/' && !std::isspace(static_cast<unsigned char>(xml[stop]))) ++stop;
  std::string_view name = xml.substr(at + 1, stop - at - 1);
  const std::size_t colon = name.rfind(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

}  // namespace

void check_xml_nesting(const std::filesystem::path& path, std::string_view xml) {
  std::vector<bool> open_is_node;  // one entry per open element, at most kMostNesting
  std::size_t node_depth = 0, nodes = 0;
  for (std::size_t i = xml.find('<'); i < xml.size(); i = xml.find('<', i + 1)) {
    if (i + 1 >= xml.size()) break;
    if (xml[i + 1] == '!' || xml[i + 1] == '?') {
      i = skip_markup(xml, i);
      continue;
    }
    const std::size_t end = tag_end(xml, i);
    if (end >= xml.size()) break;  // unclosed: the parser reports it
    if (xml[i + 1] == '/') {
      if (!open_is_node.empty()) {
        node_depth -= open_is_node.back() ? 1 : 0;
        open_is_node.pop_back();
      }
    } else {
      const bool is_node = local_name(xml, i, end) == "node";
      if (is_node && ++nodes > kMostNodes)
        throw InputError(
            path, fmt::format("more than {} <node> elements; at most {} are read", kMostNodes, kMostNodes));
      if (xml[end - 1] != '/') {
        open_is_node.push_back(is_node);
        node_depth += is_node ? 1 : 0;
        if (node_depth > kMostNodeDepth)
          throw InputError(path, fmt::format("<node> elements nest more than {} deep; at most {} are read",
                                             kMostNodeDepth, kMostNodeDepth));
        if (open_is_node.size() > kMostNesting)
          throw InputError(path, fmt::format("its XML elements nest more than {} deep", kMostNesting));
      }
    }
    i = end;
  }
}

}  // namespace ts::detail
