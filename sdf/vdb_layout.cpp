#include "sdf/vdb_layout.h"

#include <fmt/format.h>
#include <openvdb/Metadata.h>
#include <openvdb/io/Compression.h>
#include <openvdb/math/Maps.h>
#include <openvdb/openvdb.h>

#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "core/error.h"
#include "sdf/openvdb_init.h"

namespace ts::sdf {
namespace {

// Reads the file front to back, refusing any read or skip past its end. OpenVDB writes its fields in
// the host's byte order; tetrasand runs on little-endian hosts only, as OpenVDB's files are.
class Cursor {
 public:
  explicit Cursor(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw InputError(path, "cannot be opened for reading (permission?)");
    std::error_code ec;
    size_ = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path, "cannot be opened for reading (" + ec.message() + ")");
  }

  std::uint64_t offset() const { return offset_; }
  std::uint64_t remaining() const { return size_ - offset_; }

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(path_, fmt::format("is not a readable OpenVDB file (at byte {}: {})", offset_, problem));
  }

  void need(std::uint64_t bytes, const char* what) const {
    if (bytes > remaining())
      fail(fmt::format("{} needs {} bytes, the file has {} left: it is cut short or a length in it is wrong", what,
                       bytes, remaining()));
  }

  void read(void* out, std::uint64_t bytes, const char* what) {
    need(bytes, what);
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(bytes));
    if (!in_) fail(fmt::format("{} could not be read", what));
    offset_ += bytes;
  }

  template <class T>
  T pod(const char* what) {
    T value{};
    read(&value, sizeof value, what);
    return value;
  }

  void skip(std::uint64_t bytes, const char* what) {
    need(bytes, what);
    in_.seekg(static_cast<std::streamoff>(bytes), std::ios::cur);
    if (!in_) fail(fmt::format("{} could not be skipped", what));
    offset_ += bytes;
  }

  // OpenVDB's readString: a 32-bit length, then the characters.
  std::string string(const char* what) {
    const auto length = pod<std::uint32_t>(what);
    need(length, what);
    std::string text(length, '\0');
    if (length > 0) read(text.data(), length, what);
    return text;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

// A name from the file, fit for a message.
std::string printable(const std::string& name) {
  std::string out;
  for (const char c : name.substr(0, 80)) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? fmt::format("\\x{:02x}", byte) : std::string(1, c);
  }
  return "'" + out + (name.size() > 80 ? "...'" : "'");
}

// Blosc's chunk header (blosc.h, format 1-2): what blosc_decompress trusts without knowing the
// length of the buffer it was handed. A chunk passes when the header's lengths are the chunk's and
// the buffer's, and every block it points to lies inside the chunk.
// `padded`: compression::bloscCompress (the delayed-load metadata's) pads inputs under 128 bytes to
// 128, and its bloscDecompress accepts 128 for any expected size up to that.
void check_blosc_chunk(Cursor& cursor, std::uint64_t chunk_bytes, std::uint64_t expected_bytes, const char* what,
                       bool padded = false) {
  constexpr std::uint64_t kPadBytes = 128;
  constexpr std::uint64_t kHeader = 16;
  constexpr std::uint8_t kMemcpyed = 0x2;
  if (chunk_bytes < kHeader)
    cursor.fail(fmt::format("{}: a blosc chunk of {} bytes is shorter than blosc's 16-byte header", what, chunk_bytes));
  std::array<std::uint8_t, kHeader> header{};
  cursor.read(header.data(), kHeader, what);
  std::uint32_t nbytes = 0, blocksize = 0, cbytes = 0;
  std::memcpy(&nbytes, header.data() + 4, 4);
  std::memcpy(&blocksize, header.data() + 8, 4);
  std::memcpy(&cbytes, header.data() + 12, 4);
  const std::uint8_t version = header[0], flags = header[2];
  if (version < 1 || version > 2) cursor.fail(fmt::format("{}: blosc format version {} is unknown", what, version));
  if (cbytes != chunk_bytes)
    cursor.fail(fmt::format("{}: the blosc header says {} compressed bytes, the chunk holds {}", what, cbytes,
                            chunk_bytes));
  if (nbytes != expected_bytes && !(padded && nbytes == kPadBytes && expected_bytes <= kPadBytes))
    cursor.fail(fmt::format("{}: the blosc header says {} bytes uncompressed where the node holds {}", what, nbytes,
                            expected_bytes));
  std::uint64_t read = kHeader;
  if (flags & kMemcpyed) {
    if (cbytes != std::uint64_t{nbytes} + kHeader)
      cursor.fail(fmt::format("{}: a stored blosc chunk of {} bytes for {} bytes of data", what, cbytes, nbytes));
  } else if (nbytes > 0) {
    if (blocksize == 0) cursor.fail(fmt::format("{}: a blosc block size of 0", what));
    const std::uint64_t blocks = nbytes / blocksize + (nbytes % blocksize != 0 ? 1 : 0);
    const std::uint64_t first_data = kHeader + 4 * blocks;
    if (first_data > cbytes)
      cursor.fail(fmt::format("{}: {} blosc blocks do not fit their offsets in {} bytes", what, blocks, cbytes));
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const auto start = cursor.pod<std::int32_t>(what);
      if (start < 0 || static_cast<std::uint64_t>(start) < first_data || static_cast<std::uint64_t>(start) >= cbytes)
        cursor.fail(fmt::format("{}: blosc block {} starts at {}, outside the chunk's {} bytes", what, b, start,
                                cbytes));
    }
    read = first_data;
  }
  cursor.skip(chunk_bytes - read, what);
}

// io::readData's chunk of `expected_bytes`: bare bytes, or an int64 length and a zip or blosc
// chunk (a length of -N means N bytes stored uncompressed).
void check_data_chunk(Cursor& cursor, std::uint32_t compression, std::uint64_t expected_bytes, const char* what) {
  const bool blosc = compression & openvdb::io::COMPRESS_BLOSC;
  const bool zip = compression & openvdb::io::COMPRESS_ZIP;
  if (!blosc && !zip) {
    cursor.skip(expected_bytes, what);
    return;
  }
  const auto length = cursor.pod<std::int64_t>(what);
  if (length <= 0) {
    // The overflow of fuzz/findings/: OpenVDB reads -length bytes into a buffer of expected_bytes.
    if (length == std::numeric_limits<std::int64_t>::min() || static_cast<std::uint64_t>(-length) != expected_bytes)
      cursor.fail(fmt::format("{}: an uncompressed chunk of {} bytes where the node holds {}", what,
                              length == std::numeric_limits<std::int64_t>::min() ? std::string("2^63")
                                                                                  : std::to_string(-length),
                              expected_bytes));
    cursor.skip(expected_bytes, what);
  } else if (blosc) {
    cursor.need(static_cast<std::uint64_t>(length), what);
    check_blosc_chunk(cursor, static_cast<std::uint64_t>(length), expected_bytes, what);
  } else {
    cursor.skip(static_cast<std::uint64_t>(length), what);  // zlib's uncompress is told both lengths
  }
}

// How a tree's values are stored: the value's size, and its size when saved as half floats (the
// same for trees of integers, which are never halved).
struct ValueLayout {
  std::uint64_t bytes = 0;
  std::uint64_t half_bytes = 0;
};

std::optional<ValueLayout> value_layout_of_tree(const std::string& grid_type) {
  using namespace openvdb;
  static const std::map<std::string, ValueLayout> kTrees = {
      {FloatTree::treeType(), {4, 2}},   {DoubleTree::treeType(), {8, 2}},  {Int32Tree::treeType(), {4, 4}},
      {Int64Tree::treeType(), {8, 8}},   {Vec3STree::treeType(), {12, 6}}, {Vec3DTree::treeType(), {24, 6}},
      {Vec3ITree::treeType(), {12, 12}},
  };
  const auto it = kTrees.find(grid_type);
  if (it == kTrees.end()) return std::nullopt;
  return it->second;
}

// One node's mask as OpenVDB stores it (NodeMask::save: 64-bit words, bit i of word i / 64).
struct Mask {
  std::vector<std::uint64_t> words;

  std::uint64_t count_on() const {
    std::uint64_t n = 0;
    for (const auto w : words) n += static_cast<std::uint64_t>(std::popcount(w));
    return n;
  }
  bool is_on(std::uint64_t i) const { return (words[i / 64] >> (i % 64)) & 1u; }
};

Mask read_mask(Cursor& cursor, std::uint64_t bits, const char* what) {
  Mask mask;
  mask.words.resize(bits / 64);
  cursor.read(mask.words.data(), bits / 8, what);
  return mask;
}

// The stream's state for one grid, as io::readCompressedValues sees it.
struct GridReading {
  std::uint32_t compression = 0;
  ValueLayout value;
  bool half = false;
};

// io::readCompressedValues for a node of `values` values whose active ones `active` marks.
void check_compressed_values(Cursor& cursor, const GridReading& grid, std::uint64_t values, const Mask& active,
                             const char* what) {
  using namespace openvdb::io;
  const bool mask_compressed = grid.compression & COMPRESS_ACTIVE_MASK;
  const auto metadata = cursor.pod<std::int8_t>(what);
  const std::uint64_t value_bytes = grid.value.bytes;
  if (metadata == NO_MASK_AND_ONE_INACTIVE_VAL || metadata == MASK_AND_ONE_INACTIVE_VAL ||
      metadata == MASK_AND_TWO_INACTIVE_VALS)
    cursor.skip(metadata == MASK_AND_TWO_INACTIVE_VALS ? 2 * value_bytes : value_bytes, what);
  if (metadata == MASK_AND_NO_INACTIVE_VALS || metadata == MASK_AND_ONE_INACTIVE_VAL ||
      metadata == MASK_AND_TWO_INACTIVE_VALS)
    cursor.skip(values / 8, what);  // the selection mask
  const std::uint64_t stored = mask_compressed && metadata != NO_MASK_AND_ALL_VALS ? active.count_on() : values;
  const bool halved = grid.half && grid.value.half_bytes != grid.value.bytes;
  if (halved && stored < 1) return;  // HalfReader reads nothing at all then
  check_data_chunk(cursor, grid.compression, stored * (halved ? grid.value.half_bytes : value_bytes), what);
}

// Transforms (math::Transform::read: the map's type name, then the map as MapBase::read reads it).
void check_map(Cursor& cursor, int depth) {
  const std::string type = cursor.string("the transform's type name");
  static const std::map<std::string, std::uint64_t> kMapBytes = {
      {openvdb::math::AffineMap::mapType(), 128},
      {openvdb::math::UnitaryMap::mapType(), 128},
      {openvdb::math::ScaleMap::mapType(), 5 * 24},
      {openvdb::math::UniformScaleMap::mapType(), 5 * 24},
      {openvdb::math::TranslationMap::mapType(), 24},
      {openvdb::math::ScaleTranslateMap::mapType(), 6 * 24},
      {openvdb::math::UniformScaleTranslateMap::mapType(), 6 * 24},
  };
  if (const auto it = kMapBytes.find(type); it != kMapBytes.end()) {
    cursor.skip(it->second, "the transform");
  } else if (type == openvdb::math::NonlinearFrustumMap::mapType()) {
    if (depth >= 4) cursor.fail("a frustum transform nested more than 4 deep");
    cursor.skip(48 + 8 + 8, "the frustum transform");  // bounding box, taper, depth
    check_map(cursor, depth + 1);                       // the frustum's linear map
  } else {
    cursor.fail(fmt::format("transform type {} is {}", printable(type),
                            openvdb::math::MapRegistry::isRegistered(type) ? "not one this check knows"
                                                                           : "not registered"));
  }
}

// __delayedload metadata (io::DelayedLoadMetadata::readValue): a count, then per-leaf masks and
// compressed sizes, each stored plain or as one blosc chunk.
void check_delayed_load_metadata(Cursor& cursor, std::uint32_t declared_bytes) {
  if (declared_bytes == 0) return;
  const char* what = "the delayed-load metadata";
  const std::uint64_t start = cursor.offset();
  const auto count = cursor.pod<std::uint32_t>(what);
  if (count > cursor.offset() + cursor.remaining())  // one entry a leaf, and a leaf takes bytes
    cursor.fail(fmt::format("{} counts {} leaves, more than the file has bytes", what, count));
  for (const std::uint64_t element_bytes : {std::uint64_t{1}, std::uint64_t{8}}) {  // int8 masks, int64 sizes
    const auto bytes = cursor.pod<std::uint32_t>(what);
    if (element_bytes == 8 && bytes == std::numeric_limits<std::uint32_t>::max()) break;  // no sizes stored
    if (bytes > 0) {
      cursor.need(bytes, what);
      check_blosc_chunk(cursor, bytes, count * element_bytes, what, /*padded=*/true);
    } else {
      cursor.skip(count * element_bytes, what);
    }
  }
  // The reader counts what it read and skips any rest of the declared size.
  const std::uint64_t counted = cursor.offset() - start;
  if (counted < declared_bytes) cursor.skip(declared_bytes - counted, what);
}

// MetaMap::readMeta: a count, then (name, type name, size, value) for each entry.
void check_metadata(Cursor& cursor) {
  static const std::map<std::string, std::uint32_t> kFixedBytes = {
      {"bool", 1},   {"int32", 4},   {"int64", 8},   {"float", 4},   {"double", 8},  {"vec2i", 8},
      {"vec2s", 8},  {"vec2d", 16},  {"vec3i", 12},  {"vec3s", 12},  {"vec3d", 24},  {"vec4i", 16},
      {"vec4s", 16}, {"vec4d", 32},  {"mat4s", 64},  {"mat4d", 128},
  };
  const auto count = cursor.pod<std::uint32_t>("the metadata count");
  constexpr std::uint64_t kSmallestEntry = 12;  // three empty lengths
  if (std::uint64_t{count} * kSmallestEntry > cursor.remaining())
    cursor.fail(fmt::format("{} metadata entries cannot fit in the {} bytes left", count, cursor.remaining()));
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::string name = cursor.string("a metadata name");
    const std::string type = cursor.string("a metadata type name");
    const auto bytes = cursor.pod<std::uint32_t>("a metadata size");
    if (const auto it = kFixedBytes.find(type); it != kFixedBytes.end()) {
      // TypedMetadata reads its own size whatever the file says, so a different size would shift
      // everything after it.
      if (bytes != it->second)
        cursor.fail(fmt::format("metadata {} of type {} says {} bytes; the type has {}", printable(name), type, bytes,
                                it->second));
      cursor.skip(bytes, "a metadata value");
    } else if (type == "string") {
      cursor.skip(bytes, "a metadata value");
    } else if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
      check_delayed_load_metadata(cursor, bytes);
    } else if (openvdb::Metadata::isRegisteredType(type)) {
      cursor.fail(fmt::format("metadata {} has type {}, which this check does not know", printable(name), printable(type)));
    } else {
      cursor.skip(bytes, "a metadata value");  // UnknownMetadata keeps the bytes
    }
  }
}

// The tree's topology (Tree::readTopology): returns, for each child of the root in the order the
// reader reads their buffers (RootNode's std::map, by origin; a later child at the same origin
// replaces an earlier one), how many leaves it holds.
std::vector<std::uint64_t> check_topology(Cursor& cursor, const GridReading& grid) {
  cursor.skip(4, "the tree's buffer count");
  cursor.skip(grid.value.bytes, "the background value");
  const auto tiles = cursor.pod<std::uint32_t>("the root's tile count");
  const auto children = cursor.pod<std::uint32_t>("the root's child count");
  const std::uint64_t tile_bytes = 12 + grid.value.bytes + 1;
  if (std::uint64_t{tiles} * tile_bytes > cursor.remaining())
    cursor.fail(fmt::format("{} root tiles of {} bytes cannot fit in the {} bytes left", tiles, tile_bytes,
                            cursor.remaining()));
  cursor.skip(std::uint64_t{tiles} * tile_bytes, "the root's tiles");
  constexpr std::uint64_t kSmallestChild = 12 + 4096 + 4096 + 1;  // origin, two masks, one metadata byte
  if (std::uint64_t{children} * kSmallestChild > cursor.remaining())
    cursor.fail(fmt::format("{} root children cannot fit in the {} bytes left", children, cursor.remaining()));

  std::map<std::tuple<std::int32_t, std::int32_t, std::int32_t>, std::uint64_t> leaves_by_origin;
  for (std::uint32_t c = 0; c < children; ++c) {
    std::array<std::int32_t, 3> origin{};
    cursor.read(origin.data(), 12, "a root child's origin");
    // InternalNode<..., 5>: child mask, value mask, its 32^3 values, then its children.
    const Mask upper_children = read_mask(cursor, 32768, "an upper node's child mask");
    const Mask upper_values = read_mask(cursor, 32768, "an upper node's value mask");
    check_compressed_values(cursor, grid, 32768, upper_values, "an upper node's values");
    std::uint64_t leaves = 0;
    for (std::uint64_t i = 0; i < 32768; ++i) {
      if (!upper_children.is_on(i)) continue;
      // InternalNode<..., 4>: the same with 16^3 values; its children are leaves (their value masks).
      const Mask lower_children = read_mask(cursor, 4096, "a lower node's child mask");
      const Mask lower_values = read_mask(cursor, 4096, "a lower node's value mask");
      check_compressed_values(cursor, grid, 4096, lower_values, "a lower node's values");
      const std::uint64_t lower_leaves = lower_children.count_on();
      cursor.skip(lower_leaves * 64, "the leaves' value masks");
      leaves += lower_leaves;
    }
    leaves_by_origin[{origin[0], origin[1], origin[2]}] = leaves;
  }
  std::vector<std::uint64_t> leaves;
  for (const auto& [origin, count] : leaves_by_origin) leaves.push_back(count);
  return leaves;
}

// Tree::readBuffers: each leaf's value mask again (the one its values are decoded with), then its
// 8^3 values.
void check_buffers(Cursor& cursor, const GridReading& grid, const std::vector<std::uint64_t>& leaves_per_child) {
  constexpr std::uint64_t kSmallestLeaf = 64 + 1;
  std::uint64_t total = 0;
  for (const auto n : leaves_per_child) total += n;
  if (total * kSmallestLeaf > cursor.remaining())
    cursor.fail(fmt::format("{} leaves cannot fit in the {} bytes left", total, cursor.remaining()));
  for (std::uint64_t leaf = 0; leaf < total; ++leaf) {
    const Mask active = read_mask(cursor, 512, "a leaf's value mask");
    check_compressed_values(cursor, grid, 512, active, "a leaf's values");
  }
}

}  // namespace

VdbLayout check_vdb_layout(const std::filesystem::path& path) {
  ensure_openvdb_initialized();  // the registries of grid, map and metadata types
  Cursor cursor(path);
  VdbLayout layout;

  // Archive::readHeader.
  if (cursor.remaining() < 8 || cursor.pod<std::int64_t>("the magic number") != openvdb::OPENVDB_MAGIC)
    throw InputError(path, "is not a readable OpenVDB file (it does not start with OpenVDB's magic number)");
  layout.file_version = cursor.pod<std::uint32_t>("the file format version");
  if (layout.file_version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION ||
      layout.file_version > openvdb::OPENVDB_FILE_VERSION)
    cursor.fail(fmt::format("file format version {}; this build reads versions {} to {} (OpenVDB 2.0 to {}.{})",
                            layout.file_version, +openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION,
                            openvdb::OPENVDB_FILE_VERSION, openvdb::OPENVDB_LIBRARY_MAJOR_VERSION,
                            openvdb::OPENVDB_LIBRARY_MINOR_VERSION));
  cursor.skip(4 + 4 + 1 + 36, "the header");  // library version, grid offsets flag, UUID
  check_metadata(cursor);

  const auto grids = cursor.pod<std::int32_t>("the grid count");
  constexpr std::uint64_t kSmallestGrid = 4 + 4 + 4 + 24 + 4 + 4 + 4;  // 3 names, offsets, compression, meta, map
  if (grids < 0 || static_cast<std::uint64_t>(grids) * kSmallestGrid > cursor.remaining())
    cursor.fail(fmt::format("a grid count of {} (the file has {} bytes left)", grids, cursor.remaining()));
  layout.grid_count = grids;

  for (int g = 0; g < grids; ++g) {
    // GridDescriptor::read, then Archive::readGrid.
    const std::string name = cursor.string("a grid's name");
    std::string type = cursor.string("a grid's type name");
    GridReading grid;
    const std::string half_suffix = "_HalfFloat";
    if (type.size() >= half_suffix.size() && type.ends_with(half_suffix)) {
      grid.half = true;
      type.resize(type.size() - half_suffix.size());
    }
    const std::string instance_parent = cursor.string("a grid's instance parent name");
    if (!openvdb::GridBase::isRegistered(type))
      cursor.fail(fmt::format("grid {} has type {}, which OpenVDB does not know", printable(name), printable(type)));
    cursor.skip(3 * 8, "a grid's offsets");
    grid.compression = cursor.pod<std::uint32_t>("a grid's compression flags");
    check_metadata(cursor);
    check_map(cursor, 0);
    if (!instance_parent.empty()) continue;  // an instance shares its parent's tree: nothing stored
    const auto value = value_layout_of_tree(type);
    if (!value) {
      layout.unchecked = fmt::format("grid {} of type {}", printable(name), printable(type));
      return layout;
    }
    grid.value = *value;
    const auto leaves = check_topology(cursor, grid);
    check_buffers(cursor, grid, leaves);
  }
  return layout;
}

}  // namespace ts::sdf
