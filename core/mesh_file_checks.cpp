#include "core/mesh_file_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"

namespace ts::detail {
namespace {

// Whitespace-separated tokens of a text, with the line each came from.
class Tokens {
 public:
  explicit Tokens(std::string_view text, std::size_t start = 0, std::size_t line = 1)
      : text_(text), pos_(start), line_(line) {}

  // The next token, or nullopt at the end of the text.
  std::optional<std::string_view> next() {
    skip_space();
    if (pos_ >= text_.size()) return std::nullopt;
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return text_.substr(begin, pos_ - begin);
  }
  std::size_t line() const { return line_; }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) line_ += text_[pos_++] == '\n' ? 1 : 0;
  }
  std::string_view text_;
  std::size_t pos_;
  std::size_t line_;
};

std::optional<std::int64_t> parse_integer(std::string_view token) {
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

bool parses_as_number(std::string_view token) {
  // from_chars also accepts "nan" and "inf": those are reported later, by value, with a clearer message.
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return end == token.data() + token.size() && (ec == std::errc() || ec == std::errc::result_out_of_range);
}

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

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
  std::string name;
  int size = 0;              // bytes of the scalar, or of each list item
  bool is_float = false;
  bool is_signed = false;
  bool is_list = false;
  int count_size = 0;        // bytes of a list's count
  bool count_is_float = false;
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
};

// Size in bytes, floating point, signed; nullopt for an unknown type name.
struct PlyType {
  int size;
  bool is_float;
  bool is_signed;
};
std::optional<PlyType> ply_type(std::string_view name) {
  static const std::pair<std::string_view, PlyType> types[] = {
      {"char", {1, false, true}},    {"int8", {1, false, true}},     {"uchar", {1, false, false}},
      {"uint8", {1, false, false}},  {"short", {2, false, true}},    {"int16", {2, false, true}},
      {"ushort", {2, false, false}}, {"uint16", {2, false, false}},  {"int", {4, false, true}},
      {"int32", {4, false, true}},   {"uint", {4, false, false}},    {"uint32", {4, false, false}},
      {"float", {4, true, true}},    {"float32", {4, true, true}},   {"double", {8, true, true}},
      {"float64", {8, true, true}}};
  for (const auto& [n, t] : types)
    if (n == name) return t;
  return std::nullopt;
}

bool is_vertex_index_list(const PlyElement& element, const PlyProperty& property) {
  return element.name == "face" && property.is_list && (property.name == "vertex_indices" || property.name == "vertex_index");
}

// Reads one binary value (integer or floating point) as a double; false at the end of the data.
class BinaryReader {
 public:
  BinaryReader(std::string_view bytes, std::size_t pos, bool big_endian) : bytes_(bytes), pos_(pos), big_(big_endian) {}
  bool read(int size, bool is_float, bool is_signed, double& value) {
    if (bytes_.size() - pos_ < static_cast<std::size_t>(size)) return false;
    // Assemble the value from the file's byte order, whatever the host's.
    std::uint64_t u = 0;
    for (int k = 0; k < size; ++k) {
      const auto byte = static_cast<unsigned char>(bytes_[pos_ + static_cast<std::size_t>(big_ ? size - 1 - k : k)]);
      u |= static_cast<std::uint64_t>(byte) << (8 * k);
    }
    pos_ += static_cast<std::size_t>(size);
    if (is_float) {
      value = size == 4 ? static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(u))) : std::bit_cast<double>(u);
    } else if (is_signed && size < 8 && ((u >> (8 * size - 1)) & 1u)) {
      value = static_cast<double>(static_cast<std::int64_t>(u | (~std::uint64_t{0} << (8 * size))));
    } else {
      value = is_signed ? static_cast<double>(static_cast<std::int64_t>(u)) : static_cast<double>(u);
    }
    return true;
  }

 private:
  std::string_view bytes_;
  std::size_t pos_;
  bool big_;
};

}  // namespace

void check_ply_file(const std::filesystem::path& path, std::string_view bytes) {
  // Header: text lines up to "end_header".
  std::size_t pos = 0, line_number = 0;
  std::optional<PlyFormat> format;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (pos < bytes.size() && !ended) {
    const std::size_t end = std::min(bytes.find('\n', pos), bytes.size());
    const std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    std::vector<std::string_view> t;
    Tokens tokens(line);
    while (auto token = tokens.next()) t.push_back(*token);
    if (line_number == 1) {
      if (t.size() != 1 || t[0] != "ply") fail(path, 1, "a PLY file must start with the line 'ply'");
      continue;
    }
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      ended = true;
    } else if (t[0] == "format" && t.size() >= 2) {
      if (t[1] == "ascii") format = PlyFormat::Ascii;
      else if (t[1] == "binary_little_endian") format = PlyFormat::BinaryLittle;
      else if (t[1] == "binary_big_endian") format = PlyFormat::BinaryBig;
      else fail(path, line_number, fmt::format("unknown PLY format '{}'", t[1]));
    } else if (t[0] == "element" && t.size() == 3) {
      const auto count = parse_integer(t[2]);
      if (!count || *count < 0) fail(path, line_number, fmt::format("element '{}' has an invalid count '{}'", t[1], t[2]));
      elements.push_back({std::string(t[1]), *count, {}});
    } else if (t[0] == "property" && !elements.empty() && t.size() == 3 && ply_type(t[1])) {
      const PlyType type = *ply_type(t[1]);
      elements.back().properties.push_back({std::string(t[2]), type.size, type.is_float, type.is_signed, false, 0, false});
    } else if (t[0] == "property" && !elements.empty() && t.size() == 5 && t[1] == "list" && ply_type(t[2]) &&
               ply_type(t[3])) {
      const PlyType count_type = *ply_type(t[2]), item = *ply_type(t[3]);
      elements.back().properties.push_back(
          {std::string(t[4]), item.size, item.is_float, item.is_signed, true, count_type.size, count_type.is_float});
    } else if (t[0] == "element" || t[0] == "property") {
      fail(path, line_number, fmt::format("malformed PLY header line '{}'", line));
    }
    // Other lines are ignored, as assimp does (exporters wrap long comments onto lines of their own).
  }
  if (!ended) throw InputError(path, "the PLY header has no 'end_header' line");
  if (!format) throw InputError(path, "the PLY header has no 'format' line");

  std::int64_t vertex_count = 0;
  for (const auto& e : elements)
    if (e.name == "vertex") vertex_count = e.count;

  Tokens ascii(bytes, pos, line_number + 1);
  BinaryReader binary(bytes, pos, *format == PlyFormat::BinaryBig);
  // Reads the next value, whatever the encoding; false at the end of the file. `line` is for messages.
  auto read_value = [&](int size, bool is_float, bool is_signed, double& value, std::size_t& line) {
    if (*format != PlyFormat::Ascii) {
      line = 0;
      return binary.read(size, is_float, is_signed, value);
    }
    const auto token = ascii.next();
    line = ascii.line();
    if (!token) return false;
    if (!parses_as_number(*token)) fail(path, line, fmt::format("'{}' is not a number", *token));
    std::from_chars(token->data(), token->data() + token->size(), value);
    return true;
  };
  auto truncated = [&](const PlyElement& e, std::int64_t i) {
    throw InputError(path, fmt::format("the header declares {} '{}' elements but the file ends in number {}", e.count,
                                       e.name, i));
  };
  for (const auto& element : elements) {
    for (std::int64_t i = 0; i < element.count; ++i) {
      for (const auto& property : element.properties) {
        double value = 0;
        std::size_t line = 0;
        if (!property.is_list) {
          if (!read_value(property.size, property.is_float, property.is_signed, value, line)) truncated(element, i);
          continue;
        }
        if (!read_value(property.count_size, property.count_is_float, false, value, line)) truncated(element, i);
        if (!(value >= 0) || value != static_cast<double>(static_cast<std::int64_t>(value))) {
          throw InputError(path, fmt::format("{}'{}' {} has an invalid list length {}", line ? fmt::format("line {}: ", line) : "",
                                             element.name, i, value));
        }
        const auto length = static_cast<std::int64_t>(value);
        for (std::int64_t k = 0; k < length; ++k) {
          if (!read_value(property.size, property.is_float, property.is_signed, value, line)) truncated(element, i);
          if (is_vertex_index_list(element, property) && !(value >= 0 && value < static_cast<double>(vertex_count))) {
            throw InputError(path, fmt::format("{}face {} refers to vertex {}, outside 0..{}",
                                               line ? fmt::format("line {}: ", line) : "", i, value, vertex_count - 1));
          }
        }
      }
    }
  }
}

}  // namespace ts::detail
