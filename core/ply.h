#pragma once
// PLY files (Turk 1994, paulbourke.net/dataformats/ply): the header, and a reader of the values in the
// data after it, in any of the three encodings and on a host of either byte order. This is the one
// PLY parser: the strict check before assimp loads a mesh (core/mesh_file_checks.h) and the particle
// file of a body (body/particles_ply.h) both read through it, with their differences in strictness
// as HeaderRules. A declared count is only ever compared with the data at hand, never used to size an
// allocation, so a lying header fails where the data ends instead of exhausting memory. Errors are
// ts::InputError naming the file and, in the header and in ascii data, the line.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/text_tokens.h"

namespace ts::ply {

enum class Encoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

// The eight PLY scalar types; each has two names in headers (char or int8, ..., double or float64).
enum class Scalar : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

// The type a header names, or nullopt for an unknown name.
std::optional<Scalar> scalar_from_name(std::string_view name);
// Bytes of one value in binary data.
std::size_t size_of(Scalar type);

struct Property {
  std::string name;
  Scalar type = Scalar::Float32;      // of the value, or of each item of a list
  std::optional<Scalar> list_length;  // a list's length type; nullopt for a scalar property
  bool is_list() const { return list_length.has_value(); }
};

struct Element {
  std::string name;
  std::uint64_t count = 0;  // rows the header declares: a claim about the data, not an allocation size
  std::vector<Property> properties;

  // Index of the scalar (not list) property `property_name` in `properties`, or nullopt.
  std::optional<std::size_t> scalar_property(std::string_view property_name) const;
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;  // in the order of their data
  std::size_t data_offset = 0;    // bytes from the start of the file to the data (after end_header)
  std::size_t data_line = 1;      // line the data starts on, for messages about ascii data
};

// What a header may hold besides the PLY essentials (a first line "ply", a format line, element and
// property lines, comment and obj_info lines, end_header). The defaults accept what assimp reads as
// this parser does, and nothing it would read differently.
struct HeaderRules {
  // binary_big_endian data (the reader converts it on any host); false: such a file is an error.
  bool big_endian = true;
  // Lines with another keyword, and format lines other than "format ENCODING 1.0", are skipped, as
  // assimp does (exporters wrap long comments onto lines of their own); false: they are errors.
  bool unknown_lines = true;
  // Lines other than property lines (comment, obj_info, unknown) between the properties of one
  // element; false: a property line after such a line is an error. Assimp ends an element's
  // property list at the first line that is not a property and skips the properties after it, so
  // it would read the data with fewer columns than it has: y and z as 0 in ascii data, a crash on
  // binary data. Lines before an element's first property count too; blank lines are harmless.
  bool lines_between_properties = false;
};

// Parses the header of the PLY file `bytes` (the whole file; `file` names it in messages).
Header parse_header(const std::filesystem::path& file, std::string_view bytes, const HeaderRules& rules = {});

// Reads the data of a PLY file value by value, element after element in header order.
class DataReader {
 public:
  // Called with each item of a list property as it is read: the property's index, the item.
  using ListItems = std::function<void(std::size_t property, double item)>;

  // `bytes` is the whole file (it must outlive the reader), `header` parsed from it.
  DataReader(const std::filesystem::path& file, std::string_view bytes, const Header& header);

  // Reads row `row` of `element` (the row the data is at): values[p] gets scalar property p's value
  // (exact: every PLY type fits a double) and list property p's length, whose items go to `items`
  // when given. Throws ts::InputError when the data ends inside the row ("truncated"), when a list
  // length is not a whole number >= 0, or when an ascii value is not a number.
  void read_row(const Element& element, std::uint64_t row, std::span<double> values,
                const ListItems& items = {});

  // Skips every row of `element` (the element the data is at), checking them as read_row does;
  // binary rows without lists are skipped in one step.
  void skip_element(const Element& element);

  // The line of the value last read in ascii data; 0 in binary data.
  std::size_t line() const;
  // The line of the first value of the row last read by read_row, in ascii data; 0 in binary data
  // and for a row without values.
  std::size_t row_line() const { return row_line_; }
  // Bytes of data after the current position.
  std::size_t remaining_bytes() const;

 private:
  std::optional<double> next(Scalar type);  // nullopt at the end of the data
  std::optional<double> next_binary(Scalar type);
  std::optional<double> next_ascii();
  std::uint64_t list_length(const Element& element, std::uint64_t row, Scalar type);
  [[noreturn]] void truncated(const Element& element, std::uint64_t row) const;

  std::filesystem::path file_;
  std::string_view bytes_;
  Encoding encoding_;
  std::size_t pos_;        // binary: bytes into the file
  detail::Tokens tokens_;  // ascii
  std::size_t row_line_ = 0;
};

}  // namespace ts::ply
