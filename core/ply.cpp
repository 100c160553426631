#include "core/ply.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>

#include "core/error.h"

namespace ts::ply {
namespace {

namespace fs = std::filesystem;

struct ScalarInfo {
  std::array<std::string_view, 2> names;  // the classic name and the sized one
  std::size_t size;                       // bytes
  bool is_float;
  bool is_signed;
};

// Indexed by Scalar.
constexpr std::array<ScalarInfo, 8> kScalars = {{
    {{"char", "int8"}, 1, false, true},
    {{"uchar", "uint8"}, 1, false, false},
    {{"short", "int16"}, 2, false, true},
    {{"ushort", "uint16"}, 2, false, false},
    {{"int", "int32"}, 4, false, true},
    {{"uint", "uint32"}, 4, false, false},
    {{"float", "float32"}, 4, true, true},
    {{"double", "float64"}, 8, true, true},
}};

const ScalarInfo& info(Scalar type) { return kScalars[static_cast<std::size_t>(type)]; }

// `line` without the spaces and tabs around it.
std::string_view trimmed_blanks(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return line.substr(first, line.find_last_not_of(" \t") - first + 1);
}

// The header, line by line: each line is split into words and handled by its keyword.
class HeaderParser {
 public:
  HeaderParser(const fs::path& file, std::string_view bytes, const HeaderRules& rules)
      : file_(file), bytes_(bytes), rules_(rules) {}

  Header parse() {
    std::vector<std::string_view> words = next_line();
    if (words.size() != 1 || words[0] != "ply") fail("not a PLY file: it must start with the line 'ply'");
    bool ended = false;
    while (pos_ < bytes_.size() && !ended) {
      words = next_line();
      if (words.empty()) continue;
      ended = words[0] == "end_header";
      // assimp reads binary data from the byte after the end_header line; any byte on that line but
      // blanks (a vertical tab, binary data) sent its reader into a SIGSEGV (fuzz_mesh, 2026-12-06).
      if (ended && trimmed_blanks(line_) != "end_header")
        fail("the end_header line holds more than 'end_header' (the data must start on the next line)");
      if (!ended) keyword_line(words);
    }
    if (!ended) throw InputError(file_, "the PLY header has no end_header line");
    if (!has_format_) throw InputError(file_, "the PLY header has no format line");
    header_.data_offset = std::min(pos_, bytes_.size());
    header_.data_line = line_number_ + 1;
    return header_;
  }

 private:
  // The words of the next line (up to '\n' or the end of the file); line_ keeps its text for messages.
  std::vector<std::string_view> next_line() {
    const std::size_t end = std::min(bytes_.find('\n', pos_), bytes_.size());
    line_ = bytes_.substr(pos_, end - pos_);
    if (line_.ends_with('\r')) line_.remove_suffix(1);
    pos_ = end + 1;
    ++line_number_;
    std::vector<std::string_view> words;
    detail::Tokens tokens(line_);
    while (auto word = tokens.next()) words.push_back(*word);
    return words;
  }

  void keyword_line(const std::vector<std::string_view>& w) {
    if (w[0] == "element") {
      element_line(w);
      return;
    }
    if (w[0] == "property") {
      property_line(w);
      return;
    }
    // Any other line inside an element ends its property list for assimp (HeaderRules).
    if (!header_.elements.empty() && other_line_number_ == 0) {
      other_line_number_ = line_number_;
      other_line_ = line_;
    }
    if (w[0] == "comment" || w[0] == "obj_info") return;
    if (w[0] == "format" && (w.size() >= 2 || !rules_.unknown_lines)) {
      format_line(w);
    } else if (!rules_.unknown_lines) {
      fail(fmt::format("unknown PLY header keyword '{}'", w[0]));
    }
    // Other lines are skipped (HeaderRules::unknown_lines).
  }

  void format_line(const std::vector<std::string_view>& w) {
    if (!rules_.unknown_lines && (w.size() != 3 || w[2] != "1.0")) {
      fail("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
    }
    if (w[1] == "ascii") {
      header_.encoding = Encoding::Ascii;
    } else if (w[1] == "binary_little_endian") {
      header_.encoding = Encoding::BinaryLittleEndian;
    } else if (w[1] == "binary_big_endian") {
      if (!rules_.big_endian)
        fail("format binary_big_endian is not supported (use binary_little_endian or ascii)");
      header_.encoding = Encoding::BinaryBigEndian;
    } else {
      fail(fmt::format("unknown PLY format '{}'", w[1]));
    }
    has_format_ = true;
  }

  void element_line(const std::vector<std::string_view>& w) {
    if (w.size() != 3) malformed("");
    const auto count = detail::parse_integer(w[2]);
    if (!count || *count < 0) fail(fmt::format("element '{}' has an invalid count '{}'", w[1], w[2]));
    header_.elements.push_back({std::string(w[1]), static_cast<std::uint64_t>(*count), {}});
    other_line_number_ = 0;
  }

  // "property TYPE NAME" or "property list LENGTH_TYPE ITEM_TYPE NAME".
  void property_line(const std::vector<std::string_view>& w) {
    if (header_.elements.empty()) malformed("property before any element");
    if (other_line_number_ != 0 && !rules_.lines_between_properties) {
      fail(fmt::format(
          "'{}' follows line {} ('{}') inside element '{}': assimp ends an element's properties at "
          "the first other line and would misread the data; move that line above the element line",
          line_, other_line_number_, other_line_, header_.elements.back().name));
    }
    const bool list = w.size() == 5 && w[1] == "list";
    if (!list && w.size() != 3) malformed("");
    Property p{std::string(w.back()), Scalar::Float32, std::nullopt};
    p.type = known_type(w[list ? 3 : 1]);
    if (list) p.list_length = known_type(w[2]);
    header_.elements.back().properties.push_back(std::move(p));
  }

  Scalar known_type(std::string_view name) const {
    const auto type = scalar_from_name(name);
    if (!type) malformed(fmt::format("unknown type '{}'", name));
    return *type;
  }

  [[noreturn]] void malformed(const std::string& why) const {
    fail(fmt::format("malformed PLY header line '{}'{}", line_, why.empty() ? "" : ": " + why));
  }
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(file_, fmt::format("line {}: {}", line_number_, problem));
  }

  const fs::path& file_;
  std::string_view bytes_;
  HeaderRules rules_;
  std::size_t pos_ = 0;          // bytes: the start of the next line
  std::size_t line_number_ = 0;  // of line_
  std::string_view line_;
  std::size_t other_line_number_ = 0;  // the first line since the last element line that is not a property
  std::string_view other_line_;
  bool has_format_ = false;
  Header header_;
};

}  // namespace

std::optional<Scalar> scalar_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kScalars.size(); ++i) {
    if (kScalars[i].names[0] == name || kScalars[i].names[1] == name) return static_cast<Scalar>(i);
  }
  return std::nullopt;
}

std::size_t size_of(Scalar type) { return info(type).size; }

std::optional<std::size_t> Element::scalar_property(std::string_view property_name) const {
  for (std::size_t i = 0; i < properties.size(); ++i) {
    if (properties[i].name == property_name && !properties[i].is_list()) return i;
  }
  return std::nullopt;
}

Header parse_header(const fs::path& file, std::string_view bytes, const HeaderRules& rules) {
  return HeaderParser(file, bytes, rules).parse();
}

DataReader::DataReader(const fs::path& file, std::string_view bytes, const Header& header)
    : file_(file),
      bytes_(bytes),
      encoding_(header.encoding),
      pos_(header.data_offset),
      tokens_(bytes, header.data_offset, header.data_line) {}

void DataReader::read_row(const Element& element, std::uint64_t row, std::span<double> values,
                          const ListItems& items) {
  assert(values.size() >= element.properties.size());
  row_line_ = 0;
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    const Property& property = element.properties[p];
    if (!property.is_list()) {
      const auto value = next(property.type);
      if (!value) truncated(element, row);
      values[p] = *value;
      continue;
    }
    const std::uint64_t length = list_length(element, row, *property.list_length);
    values[p] = static_cast<double>(length);
    for (std::uint64_t k = 0; k < length; ++k) {
      const auto item = next(property.type);
      if (!item) truncated(element, row);
      if (items) items(p, *item);
    }
  }
}

void DataReader::skip_element(const Element& element) {
  if (element.properties.empty()) return;  // its rows hold no data
  const bool has_list = std::any_of(element.properties.begin(), element.properties.end(),
                                    [](const Property& p) { return p.is_list(); });
  if (encoding_ != Encoding::Ascii && !has_list) {
    std::size_t stride = 0;  // bytes per row
    for (const Property& p : element.properties) stride += size_of(p.type);
    const std::uint64_t whole_rows = remaining_bytes() / stride;
    if (element.count > whole_rows) truncated(element, whole_rows);
    pos_ += static_cast<std::size_t>(element.count) * stride;
    return;
  }
  std::vector<double> values(element.properties.size());
  for (std::uint64_t row = 0; row < element.count; ++row) read_row(element, row, values);
}

std::size_t DataReader::line() const { return encoding_ == Encoding::Ascii ? tokens_.line() : 0; }

std::size_t DataReader::remaining_bytes() const {
  return bytes_.size() - (encoding_ == Encoding::Ascii ? tokens_.position() : pos_);
}

std::optional<double> DataReader::next(Scalar type) {
  return encoding_ == Encoding::Ascii ? next_ascii() : next_binary(type);
}

std::optional<double> DataReader::next_binary(Scalar type) {
  const ScalarInfo& t = info(type);
  if (bytes_.size() - pos_ < t.size) return std::nullopt;
  // Assemble the value from the file's byte order, whatever the host's.
  const bool big = encoding_ == Encoding::BinaryBigEndian;
  std::uint64_t u = 0;
  for (std::size_t k = 0; k < t.size; ++k) {
    const auto byte = static_cast<unsigned char>(bytes_[pos_ + (big ? t.size - 1 - k : k)]);
    u |= static_cast<std::uint64_t>(byte) << (8 * k);
  }
  pos_ += t.size;
  if (t.is_float) {
    return t.size == 4 ? static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(u)))
                       : std::bit_cast<double>(u);
  }
  if (t.is_signed && ((u >> (8 * t.size - 1)) & 1u)) {
    return static_cast<double>(static_cast<std::int64_t>(u | (~std::uint64_t{0} << (8 * t.size))));
  }
  return static_cast<double>(u);
}

std::optional<double> DataReader::next_ascii() {
  const auto token = tokens_.next();
  if (!token) return std::nullopt;
  if (row_line_ == 0) row_line_ = tokens_.line();
  const auto value = detail::parse_number(*token);
  if (!value)
    throw InputError(file_, fmt::format("line {}: \"{}\" in the PLY data is not a number", line(), *token));
  return value;
}

std::uint64_t DataReader::list_length(const Element& element, std::uint64_t row, Scalar type) {
  // A length is a count: binary bits are read as unsigned whatever the declared integer type (a
  // "char" 0xff is 255 items, not -1).
  const Scalar as_count = type == Scalar::Int8    ? Scalar::UInt8
                          : type == Scalar::Int16 ? Scalar::UInt16
                          : type == Scalar::Int32 ? Scalar::UInt32
                                                  : type;
  const auto value = next(as_count);
  if (!value) truncated(element, row);
  // 2^63 bounds what a length can be (and keeps the comparison clear of undefined conversions).
  if (!(*value >= 0 && *value < 0x1p63) || *value != std::floor(*value)) {
    const std::string where = line() ? fmt::format("line {}: ", line()) : "";
    throw InputError(
        file_, fmt::format("{}'{}' {} has an invalid list length {}", where, element.name, row, *value));
  }
  return static_cast<std::uint64_t>(*value);
}

void DataReader::truncated(const Element& element, std::uint64_t row) const {
  throw InputError(
      file_, fmt::format("truncated: the header declares {} '{}' elements but the file ends in number {}",
                         element.count, element.name, row));
}

}  // namespace ts::ply
