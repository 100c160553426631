#include "core/ply.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "tests/input_error.h"

namespace ts::ply {
namespace {

const std::filesystem::path kFile = "test.ply";

using test::input_error;

// Appends `value` in the given byte order.
template <typename T>
void put(std::string& bytes, T value, bool big_endian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian == (std::endian::native == std::endian::little)) std::reverse(raw, raw + sizeof(T));
  bytes.append(raw, sizeof(T));
}

// One row of every scalar type, at the ends of their ranges, then a list of two floats.
std::string every_type_file(bool big_endian) {
  std::string bytes =
      std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\nelement row 1\nproperty char a\nproperty uchar b\nproperty int16 c\nproperty ushort d\n"
      "property int e\nproperty uint32 f\nproperty float g\nproperty float64 h\n"
      "property list uint8 float i\nend_header\n";
  put(bytes, std::int8_t{-128}, big_endian);
  put(bytes, std::uint8_t{255}, big_endian);
  put(bytes, std::int16_t{-32768}, big_endian);
  put(bytes, std::uint16_t{65535}, big_endian);
  put(bytes, std::numeric_limits<std::int32_t>::min(), big_endian);
  put(bytes, std::numeric_limits<std::uint32_t>::max(), big_endian);
  put(bytes, -1.5e-7f, big_endian);
  put(bytes, 6.02214076e23, big_endian);
  put(bytes, std::uint8_t{2}, big_endian);
  put(bytes, 0.25f, big_endian);
  put(bytes, -3.0f, big_endian);
  return bytes;
}

std::vector<double> read_only_row(const std::string& bytes, std::vector<double>* items = nullptr) {
  const Header header = parse_header(kFile, bytes);
  DataReader reader(kFile, bytes, header);
  std::vector<double> values(header.elements[0].properties.size());
  reader.read_row(header.elements[0], 0, values, [&](std::size_t, double item) {
    if (items) items->push_back(item);
  });
  EXPECT_EQ(reader.remaining_bytes(), 0u);
  return values;
}

TEST(Ply, BigEndianDataReadsAsLittleEndianDoesForEveryType) {
  const std::vector<double> expected = {
      -128, 255, -32768, 65535, -2147483648.0, 4294967295.0, static_cast<double>(-1.5e-7f), 6.02214076e23, 2};
  std::vector<double> little_items, big_items;
  EXPECT_EQ(read_only_row(every_type_file(false), &little_items), expected);
  EXPECT_EQ(read_only_row(every_type_file(true), &big_items), expected);
  EXPECT_EQ(little_items, (std::vector<double>{0.25, -3.0}));
  EXPECT_EQ(big_items, little_items);
  EXPECT_EQ(parse_header(kFile, every_type_file(true)).encoding, Encoding::BinaryBigEndian);
}

TEST(Ply, AsciiHeaderAndDataAreParsedWithTheirLines) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info nothing\r\nelement vertex 2\r\n"
      "property double x\r\nproperty uchar red\r\nelement face 1\r\nproperty list uchar int "
      "vertex_indices\r\n"
      "end_header\r\n0.5 7\r\n-1e-3 255\r\n2 0 1\r\n";
  const Header header = parse_header(kFile, text);
  EXPECT_EQ(header.encoding, Encoding::Ascii);
  ASSERT_EQ(header.elements.size(), 2u);
  EXPECT_EQ(header.elements[0].name, "vertex");
  EXPECT_EQ(header.elements[0].count, 2u);
  EXPECT_EQ(header.elements[0].scalar_property("red"), 1u);
  EXPECT_FALSE(header.elements[1].scalar_property("vertex_indices").has_value()) << "a list is not a scalar";
  EXPECT_EQ(header.elements[1].properties[0].list_length, Scalar::UInt8);
  EXPECT_EQ(header.elements[1].properties[0].type, Scalar::Int32);
  EXPECT_EQ(header.data_line, 11u);
  DataReader reader(kFile, text, header);
  std::vector<double> values(2);
  reader.read_row(header.elements[0], 0, values);
  EXPECT_EQ(values, (std::vector<double>{0.5, 7}));
  EXPECT_EQ(reader.line(), 11u);
  reader.read_row(header.elements[0], 1, values);
  EXPECT_EQ(values, (std::vector<double>{-1e-3, 255}));
  EXPECT_EQ(reader.line(), 12u);
}

TEST(Ply, ListsAreSkippedOrVisitedItemByItem) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement tag 2\nproperty list uchar short values\nproperty float w\n"
      "element vertex 1\nproperty float x\nend_header\n3 1 2 3 9.5\n0 8.5\n42\n";
  const Header header = parse_header(kFile, text);
  DataReader reader(kFile, text, header);
  std::vector<double> values(2), items;
  reader.read_row(header.elements[0], 0, values, [&](std::size_t property, double item) {
    EXPECT_EQ(property, 0u);
    items.push_back(item);
  });
  EXPECT_EQ(values, (std::vector<double>{3, 9.5})) << "a list's slot holds its length";
  EXPECT_EQ(items, (std::vector<double>{1, 2, 3}));
  reader.read_row(header.elements[0], 1, values);
  EXPECT_EQ(values, (std::vector<double>{0, 8.5}));
  reader.read_row(header.elements[1], 0, values);
  EXPECT_EQ(values[0], 42.0);

  // Skipping the whole element lands on the same place, in ascii and in binary.
  DataReader skipper(kFile, text, header);
  skipper.skip_element(header.elements[0]);
  skipper.read_row(header.elements[1], 0, values);
  EXPECT_EQ(values[0], 42.0);
}

TEST(Ply, TruncatedDataNamesTheElementAndTheRow) {
  const std::string head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
      "y\nend_header\n";
  const std::string bytes = head + std::string(8 * 2 + 4, '\0');  // two rows and half of the third
  const Header header = parse_header(kFile, bytes);
  const std::string expected =
      "test.ply: truncated: the header declares 3 'vertex' elements but the file ends in number 2";
  DataReader skipper(kFile, bytes, header);
  EXPECT_EQ(input_error([&] { skipper.skip_element(header.elements[0]); }), expected);
  DataReader reader(kFile, bytes, header);
  std::vector<double> values(2);
  EXPECT_EQ(input_error([&] {
              for (std::uint64_t row = 0; row < 3; ++row) reader.read_row(header.elements[0], row, values);
            }),
            expected);
  const std::string text =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1\n";
  const Header ascii = parse_header(kFile, text);
  DataReader ascii_reader(kFile, text, ascii);
  EXPECT_NE(input_error([&] {
              ascii_reader.skip_element(ascii.elements[0]);
            }).find("1 'face' elements but the file ends in number 0"),
            std::string::npos);
}

TEST(Ply, LyingCountsFailWhereTheDataEndsWithoutAllocating) {
  // A row count and a list length far beyond the data: both are only compared with what is there.
  const std::string rows =
      "ply\nformat binary_little_endian 1.0\nelement vertex 9000000000000000000\n"
      "property double x\nend_header\n" +
      std::string(16, '\0');
  const Header header = parse_header(kFile, rows);
  EXPECT_EQ(header.elements[0].count, 9000000000000000000u);
  DataReader reader(kFile, rows, header);
  EXPECT_NE(input_error([&] { reader.skip_element(header.elements[0]); }).find("ends in number 2"),
            std::string::npos);

  std::string list =
      "ply\nformat binary_big_endian 1.0\nelement face 1\nproperty list uint int "
      "vertex_indices\nend_header\n";
  put(list, std::uint32_t{4'000'000'000u}, true);
  put(list, std::int32_t{7}, true);
  const Header list_header = parse_header(kFile, list);
  DataReader list_reader(kFile, list, list_header);
  std::size_t visited = 0;
  std::vector<double> values(1);
  EXPECT_NE(input_error([&] {
              list_reader.read_row(list_header.elements[0], 0, values,
                                   [&](std::size_t, double) { ++visited; });
            }).find("truncated"),
            std::string::npos);
  EXPECT_EQ(visited, 1u);
}

TEST(Ply, ListLengthsMustBeWholeNumbersAtLeastZero) {
  for (const char* length : {"-1", "2.5", "nan", "1e300"}) {
    const std::string text = std::string("ply\nformat ascii 1.0\ncomment x\nelement face 1\n") +
                             "property list float int vertex_indices\nend_header\n" + length + " 0 0 0\n";
    const Header header = parse_header(kFile, text);
    DataReader reader(kFile, text, header);
    std::vector<double> values(1);
    const std::string error = input_error([&] { reader.read_row(header.elements[0], 0, values); });
    EXPECT_NE(error.find("test.ply: line 7: 'face' 0 has an invalid list length"), std::string::npos)
        << error;
  }
}

TEST(Ply, BinaryListLengthsAreCountsWhateverTheirType) {
  // A signed length type's bits read as unsigned: "char" 0x81 is 129 items, as the mesh check always had it.
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement tag 1\nproperty list char uchar v\nend_header\n";
  bytes += '\x81';
  bytes += std::string(129, '\x07');
  const Header header = parse_header(kFile, bytes);
  DataReader reader(kFile, bytes, header);
  std::vector<double> values(1);
  std::size_t items = 0;
  reader.read_row(header.elements[0], 0, values, [&](std::size_t, double item) { items += item == 7.0; });
  EXPECT_EQ(values[0], 129.0);
  EXPECT_EQ(items, 129u);
  EXPECT_EQ(reader.remaining_bytes(), 0u);
}

TEST(Ply, AsciiValuesMustBeNumbers) {
  const std::string text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\nfive\n";
  const Header header = parse_header(kFile, text);
  DataReader reader(kFile, text, header);
  EXPECT_EQ(input_error([&] { reader.skip_element(header.elements[0]); }),
            "test.ply: line 7: \"five\" in the PLY data is not a number");
  // Beyond double's range is still a number (infinity): the callers judge values.
  const std::string huge = "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nend_header\n-1e999\n";
  std::vector<double> values(1);
  DataReader huge_reader(kFile, huge, parse_header(kFile, huge));
  huge_reader.read_row(parse_header(kFile, huge).elements[0], 0, values);
  EXPECT_EQ(values[0], -std::numeric_limits<double>::infinity());
}

TEST(Ply, StrictRulesRejectWhatTheDefaultsSkip) {
  const std::string odd = "ply\nformat ascii 1.0\nwrapped comment text\nelement vertex 0\nend_header\n";
  EXPECT_NO_THROW(parse_header(kFile, odd));
  const HeaderRules strict{.big_endian = false, .unknown_lines = false};
  EXPECT_EQ(input_error([&] { parse_header(kFile, odd, strict); }),
            "test.ply: line 3: unknown PLY header keyword 'wrapped'");
  const std::string big = "ply\nformat binary_big_endian 1.0\nend_header\n";
  EXPECT_NO_THROW(parse_header(kFile, big));
  EXPECT_NE(input_error([&] {
              parse_header(kFile, big, strict);
            }).find("line 2: format binary_big_endian is not supported"),
            std::string::npos);
  const std::string version = "ply\nformat ascii 2.0\nend_header\n";
  EXPECT_NO_THROW(parse_header(kFile, version));
  EXPECT_NE(input_error([&] { parse_header(kFile, version, strict); }).find("line 2: expected 'format"),
            std::string::npos);
}

TEST(Ply, LinesBetweenAnElementsPropertiesAreErrorsUnlessAllowed) {
  // Assimp ends the vertex element's properties at the comment and drops y: the default refuses.
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\ncomment c\nproperty float "
      "y\n\nend_header\n";
  EXPECT_EQ(
      input_error([&] { parse_header(kFile, text); }),
      "test.ply: line 6: 'property float y' follows line 5 ('comment c') inside element 'vertex': assimp "
      "ends "
      "an element's properties at the first other line and would misread the data; move that line above the "
      "element line");
  const HeaderRules own_reader{.lines_between_properties = true};
  EXPECT_EQ(parse_header(kFile, text, own_reader).elements[0].properties.size(), 2u);
  // Blank lines, and any line after the last property or outside elements, are harmless.
  const std::string fine =
      "ply\nformat ascii 1.0\ncomment top\nelement vertex 0\nproperty float x\n\nproperty float y\ncomment "
      "end\n"
      "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(parse_header(kFile, fine).elements.size(), 2u);
}

TEST(Ply, TheEndHeaderLineHoldsOnlyEndHeaderAndBlanks) {
  // assimp reads blanks around end_header and a CRLF ending as a plain end_header line, but a
  // vertical tab or data on that line crashed it (tests/core/bad_meshes/ply-data-on-the-end-header-line-binary.ply).
  const std::string top = "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n";
  for (const char* line : {"end_header\n", "end_header \n", "\tend_header\t\n", "end_header\r\n", "end_header"})
    EXPECT_EQ(parse_header(kFile, top + line).elements.size(), 1u) << line;
  using namespace std::string_literals;
  for (const std::string& line : {"end_header\v\n"s, "end_header\v"s, "end_header junk\n"s, "end_header \0\0\n"s})
    EXPECT_EQ(input_error([&] { parse_header(kFile, top + line); }),
              "test.ply: line 5: the end_header line holds more than 'end_header' (the data must start on the next "
              "line)")
        << line;
}

TEST(Ply, HeaderErrorsNameTheFileAndTheLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "test.ply: line 1: not a PLY file: it must start with the line 'ply'"},
      {"solid cube\n", "test.ply: line 1: not a PLY file: it must start with the line 'ply'"},
      {"ply\nformat ascii 1.0\n", "test.ply: the PLY header has no end_header line"},
      {"ply\nelement vertex 1\nend_header\n", "test.ply: the PLY header has no format line"},
      {"ply\nformat utf8 1.0\nend_header\n", "test.ply: line 2: unknown PLY format 'utf8'"},
      {"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n",
       "test.ply: line 3: element 'vertex' has an invalid count '-3'"},
      {"ply\nformat ascii 1.0\nelement vertex\nend_header\n",
       "test.ply: line 3: malformed PLY header line 'element vertex'"},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n",
       "test.ply: line 3: malformed PLY header line 'property float x': property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n",
       "test.ply: line 4: malformed PLY header line 'property quaternion x': unknown type 'quaternion'"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar vertex_indices\nend_header\n",
       "test.ply: line 4: malformed PLY header line 'property list uchar vertex_indices'"},
  };
  for (const auto& [text, expected] : cases) {
    EXPECT_EQ(input_error([&] { parse_header(kFile, text); }), expected) << text;
  }
}

TEST(Ply, EveryTypeHasBothOfItsNames) {
  const std::pair<const char*, const char*> names[] = {
      {"char", "int8"}, {"uchar", "uint8"}, {"short", "int16"},   {"ushort", "uint16"},
      {"int", "int32"}, {"uint", "uint32"}, {"float", "float32"}, {"double", "float64"}};
  std::size_t expected_size[] = {1, 1, 2, 2, 4, 4, 4, 8};
  for (std::size_t i = 0; i < 8; ++i) {
    ASSERT_TRUE(scalar_from_name(names[i].first).has_value());
    EXPECT_EQ(scalar_from_name(names[i].first), scalar_from_name(names[i].second));
    EXPECT_EQ(size_of(*scalar_from_name(names[i].first)), expected_size[i]);
  }
  EXPECT_FALSE(scalar_from_name("int64").has_value());
}

}  // namespace
}  // namespace ts::ply
