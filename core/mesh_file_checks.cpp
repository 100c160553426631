#include "core/mesh_file_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
}

}  // namespace ts::detail
