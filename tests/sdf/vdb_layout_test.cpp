// The .vdb layout check (sdf/vdb_layout.h): every file OpenVDB writes passes it, whatever its
// compression, value type, transform and metadata; every cut-short file fails it; the files that
// made OpenVDB's reader overrun or over-allocate fail it with the reason; and a file it passes after
// a random byte change is read by OpenVDB without a fault (under the Sanitize build, without an
// ASan report).
#include "sdf/vdb_layout.h"

#include <gtest/gtest.h>
#include <openvdb/io/Compression.h>
#include <openvdb/math/Maps.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cstring>
#include <algorithm>
#include <fstream>
#include <tuple>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "sdf/vdb_io.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

std::filesystem::path bad_vdb(const std::string& name) {
  return std::filesystem::path(TETRASAND_SOURCE_DIR) / "tests/sdf/bad_vdb" / name;
}

void write_grids(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids, std::uint32_t compression) {
  openvdb::io::File file(path.string());
  file.setCompression(compression);
  file.write(grids);
  file.close();
}

std::string check_error(const std::filesystem::path& path) {
  try {
    check_vdb_layout(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "passed";
}

std::vector<char> bytes_of(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& path, const std::vector<char>& bytes, std::size_t count) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(count));
}

// A level set with root tiles, leaves whose inactive values take one, two and more than two
// distinct values (every mask-compression case of io::writeCompressedValues), and a named copy
// sharing its tree (written as an instance).
openvdb::GridCPtrVec level_set_grids(bool half) {
  ensure_openvdb_initialized();
  auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 0.1f, 3.0f);
  sphere->setName("surface");
  auto accessor = sphere->getAccessor();
  accessor.setValueOff(openvdb::Coord(0, 0, 0), 0.25f);          // a third inactive value in one leaf
  accessor.setValueOff(openvdb::Coord(40, 40, 40), 0.5f);        // a leaf with one non-background value
  sphere->tree().addTile(2, openvdb::Coord(4096, 0, 0), 0.3f, true);  // a root child holding only a tile
  sphere->tree().root().addTile(openvdb::Coord(-8192, 0, 0), -0.3f, true);  // a tile of the root itself
  sphere->setSaveFloatAsHalf(half);
  openvdb::GridBase::Ptr instance = sphere->copyGrid();  // shares the tree
  instance->setName("instance");
  return {sphere, instance};
}

template <class GridT>
typename GridT::Ptr small_grid(const typename GridT::ValueType& background, const typename GridT::ValueType& value,
                               const std::string& name) {
  ensure_openvdb_initialized();  // the registries the checks and the readers look types up in
  auto grid = GridT::create(background);
  grid->setName(name);
  auto accessor = grid->getAccessor();
  for (int i = 0; i < 40; ++i) accessor.setValue(openvdb::Coord(i, 2 * i, -i), value);
  accessor.setValueOff(openvdb::Coord(1, 1, 1), value);
  return grid;
}

TEST(VdbLayout, FilesOpenVdbWritesPassInEveryCompressionValueTypeAndHalfFloat) {
  using namespace openvdb::io;
  const auto dir = test::temp_dir();
  const std::uint32_t compressions[] = {COMPRESS_NONE,         COMPRESS_ZIP,   COMPRESS_ACTIVE_MASK,
                                        COMPRESS_ZIP | COMPRESS_ACTIVE_MASK, COMPRESS_BLOSC,
                                        COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK};
  for (const std::uint32_t compression : compressions) {
    for (const bool half : {false, true}) {
      openvdb::GridCPtrVec grids = level_set_grids(half);
      auto doubles = small_grid<openvdb::DoubleGrid>(2.0, -1.5, "doubles");
      auto ints = small_grid<openvdb::Int32Grid>(0, 7, "ints");
      auto longs = small_grid<openvdb::Int64Grid>(1, 1 << 20, "longs");
      auto vectors = small_grid<openvdb::Vec3SGrid>(openvdb::Vec3s(0.0f), openvdb::Vec3s(1, 2, 3), "vectors");
      auto dvectors = small_grid<openvdb::Vec3DGrid>(openvdb::Vec3d(1.0), openvdb::Vec3d(-1, 2, 3), "dvectors");
      auto ivectors = small_grid<openvdb::Vec3IGrid>(openvdb::Vec3i(0), openvdb::Vec3i(4, 5, 6), "ivectors");
      for (const openvdb::GridBase::Ptr& grid :
           std::initializer_list<openvdb::GridBase::Ptr>{doubles, ints, longs, vectors, dvectors, ivectors}) {
        grid->setSaveFloatAsHalf(half);
        grids.push_back(grid);
      }
      const auto path = dir / ("grids-" + std::to_string(compression) + (half ? "-half" : "") + ".vdb");
      write_grids(path, grids, compression);
      SCOPED_TRACE(path.filename().string());
      VdbLayout layout;
      ASSERT_NO_THROW(layout = check_vdb_layout(path)) << check_error(path);
      EXPECT_TRUE(layout.complete()) << layout.unchecked;
      EXPECT_EQ(layout.grid_count, static_cast<int>(grids.size()));
      EXPECT_EQ(layout.file_version, openvdb::OPENVDB_FILE_VERSION);
      const auto read = detail::read_grids_in_this_process(path, detail::UncheckedGrids::Refuse);
      EXPECT_EQ(read->size(), grids.size());
    }
  }
}

// The int64 pattern `value` in `bytes`, searched from `from`.
std::size_t find_bytes(const std::vector<char>& bytes, const std::string& pattern, std::size_t from = 0) {
  const auto it = std::search(bytes.begin() + static_cast<std::ptrdiff_t>(from), bytes.end(), pattern.begin(), pattern.end());
  return it == bytes.end() ? std::string::npos : static_cast<std::size_t>(it - bytes.begin());
}

std::string pod_bytes(const void* value, std::size_t size) { return {static_cast<const char*>(value), size}; }

// A map's type as OpenVDB writes it: a 32-bit length, then the name.
std::string type_name_field(const std::string& name) {
  const auto length = static_cast<std::uint32_t>(name.size());
  return pod_bytes(&length, 4) + name;
}

TEST(VdbLayout, EveryTransformTypePasses) {
  using namespace openvdb::math;
  const auto dir = test::temp_dir();
  Mat4d affine = Mat4d::identity();
  affine.setTranslation(Vec3d(1, 2, 3));
  affine.preRotate(Z_AXIS, 0.3);
  affine.preShear(X_AXIS, Y_AXIS, 0.2);
  // Transform's constructor simplifies a linear map to the simplest type that holds it, so these
  // six are what OpenVDB writes (a rotation becomes an AffineMap, a translation a
  // UniformScaleTranslateMap).
  const std::vector<MapBase::Ptr> maps = {
      std::make_shared<AffineMap>(affine),
      std::make_shared<ScaleMap>(Vec3d(0.5, 0.25, 2)),
      std::make_shared<UniformScaleMap>(0.1),
      std::make_shared<ScaleTranslateMap>(Vec3d(0.5, 0.25, 2), Vec3d(1, 2, 3)),
      std::make_shared<UniformScaleTranslateMap>(0.1, Vec3d(1, 2, 3)),
      std::make_shared<NonlinearFrustumMap>(openvdb::BBoxd(Vec3d(0), Vec3d(10)), 0.5, 2.0),
  };
  for (const auto& map : maps) {
    auto grid = small_grid<openvdb::FloatGrid>(1.0f, 0.5f, "f");
    grid->setTransform(std::make_shared<Transform>(map));
    ASSERT_EQ(grid->transform().baseMap()->type(), map->type());
    const auto path = dir / (map->type() + ".vdb");
    write_grids(path, {grid}, openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    SCOPED_TRACE(map->type());
    EXPECT_EQ(check_error(path), "passed");
    const auto read = detail::read_grids_in_this_process(path, detail::UncheckedGrids::Refuse);
    ASSERT_EQ(read->size(), 1u);
    EXPECT_EQ(read->front()->transform().baseMap()->type(), map->type());
  }
  // The two types no Transform keeps, written into a file by hand in place of a
  // UniformScaleTranslateMap (its name and 6 x 24 bytes): OpenVDB reads them, and so must the check.
  auto grid = small_grid<openvdb::FloatGrid>(1.0f, 0.5f, "f");
  grid->setTransform(std::make_shared<Transform>(std::make_shared<UniformScaleTranslateMap>(0.1, Vec3d(1, 2, 3))));
  write_grids(dir / "written.vdb", {grid}, openvdb::io::COMPRESS_BLOSC);
  const std::vector<char> written = bytes_of(dir / "written.vdb");
  const std::size_t at = find_bytes(written, type_name_field(UniformScaleTranslateMap::mapType()));
  ASSERT_NE(at, std::string::npos);
  const std::size_t after = at + 4 + UniformScaleTranslateMap::mapType().size() + 6 * 24;
  const Vec3d translation(1, 2, 3);
  Mat4d rotation = Mat4d::identity();
  rotation.setToRotation(Z_AXIS, 0.5);
  const std::vector<std::pair<std::string, std::string>> replacements = {
      {TranslationMap::mapType(), pod_bytes(translation.asPointer(), 24)},
      {UnitaryMap::mapType(), pod_bytes(rotation.asPointer(), 128)},
  };
  for (const auto& [type, data] : replacements) {
    std::vector<char> bytes(written.begin(), written.begin() + static_cast<std::ptrdiff_t>(at));
    const std::string field = type_name_field(type) + data;
    bytes.insert(bytes.end(), field.begin(), field.end());
    bytes.insert(bytes.end(), written.begin() + static_cast<std::ptrdiff_t>(after), written.end());
    const auto path = dir / (type + ".vdb");
    write_bytes(path, bytes, bytes.size());
    SCOPED_TRACE(type);
    EXPECT_EQ(check_error(path), "passed");
    const auto read = detail::read_grids_in_this_process(path, detail::UncheckedGrids::Refuse);
    ASSERT_EQ(read->size(), 1u);
    EXPECT_EQ(read->front()->transform().baseMap()->type(), type);
    EXPECT_EQ(openvdb::gridPtrCast<openvdb::FloatGrid>(read->front())->activeVoxelCount(), grid->activeVoxelCount());
  }
}

TEST(VdbLayout, EveryMetadataTypePasses) {
  using namespace openvdb;
  const auto dir = test::temp_dir();
  auto grid = small_grid<FloatGrid>(1.0f, 0.5f, "f");
  grid->insertMeta("bool", BoolMetadata(true));
  grid->insertMeta("int32", Int32Metadata(-3));
  grid->insertMeta("int64", Int64Metadata(1ll << 40));
  grid->insertMeta("float", FloatMetadata(0.5f));
  grid->insertMeta("double", DoubleMetadata(0.25));
  grid->insertMeta("string", StringMetadata("text"));
  grid->insertMeta("vec2i", Vec2IMetadata(Vec2i(1, 2)));
  grid->insertMeta("vec2s", Vec2SMetadata(Vec2s(1, 2)));
  grid->insertMeta("vec2d", Vec2DMetadata(Vec2d(1, 2)));
  grid->insertMeta("vec3i", Vec3IMetadata(Vec3i(1, 2, 3)));
  grid->insertMeta("vec3s", Vec3SMetadata(Vec3s(1, 2, 3)));
  grid->insertMeta("vec3d", Vec3DMetadata(Vec3d(1, 2, 3)));
  grid->insertMeta("vec4i", Vec4IMetadata(Vec4i(1, 2, 3, 4)));
  grid->insertMeta("vec4s", Vec4SMetadata(Vec4s(1, 2, 3, 4)));
  grid->insertMeta("vec4d", Vec4DMetadata(Vec4d(1, 2, 3, 4)));
  grid->insertMeta("mat4s", Mat4SMetadata(math::Mat4s::identity()));
  grid->insertMeta("mat4d", Mat4DMetadata(math::Mat4d::identity()));
  for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it)
    EXPECT_TRUE(Metadata::isRegisteredType(it->second->typeName())) << it->first;
  write_grids(dir / "meta.vdb", {grid}, io::COMPRESS_BLOSC);
  EXPECT_EQ(check_error(dir / "meta.vdb"), "passed");
}

TEST(VdbLayout, AGridTypeTheWalkDoesNotKnowStopsItAndIsRefusedOnlyWhenAsked) {
  const auto dir = test::temp_dir();
  ensure_openvdb_initialized();
  auto mask = openvdb::BoolGrid::create(false);
  mask->setName("mask");
  mask->getAccessor().setValue(openvdb::Coord(1, 2, 3), true);
  auto surface = small_grid<openvdb::FloatGrid>(1.0f, 0.5f, "surface");
  write_grids(dir / "mixed.vdb", {surface, mask}, openvdb::io::COMPRESS_BLOSC);
  const VdbLayout layout = check_vdb_layout(dir / "mixed.vdb");
  EXPECT_FALSE(layout.complete());
  EXPECT_EQ(layout.unchecked, "grid 'mask' of type 'Tree_bool_5_4_3'");
  EXPECT_EQ(detail::read_grids_in_this_process(dir / "mixed.vdb", detail::UncheckedGrids::Read)->size(), 2u);
  try {
    detail::read_grids_in_this_process(dir / "mixed.vdb", detail::UncheckedGrids::Refuse);
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds grid 'mask' of type 'Tree_bool_5_4_3', whose layout"), std::string::npos)
        << e.what();
  }
}

TEST(VdbLayout, EveryCutShortFileFails) {
  const auto dir = test::temp_dir();
  write_grids(dir / "whole.vdb", level_set_grids(false), openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  const std::vector<char> bytes = bytes_of(dir / "whole.vdb");
  ASSERT_EQ(check_error(dir / "whole.vdb"), "passed");
  // Every byte is a field the reader reads, so every prefix lacks one (every 7th length, and the
  // last 64 lengths, where the final leaf's chunk ends).
  for (std::size_t length = 0; length < bytes.size(); length += (length + 64 >= bytes.size() ? 1 : 7)) {
    write_bytes(dir / "cut.vdb", bytes, length);
    const std::string error = check_error(dir / "cut.vdb");
    ASSERT_NE(error, "passed") << "cut at " << length << " of " << bytes.size();
    EXPECT_EQ(error.rfind((dir / "cut.vdb").string() + ": is not a readable OpenVDB file (", 0), 0u) << error;
  }
}

// The three files fuzz_vdb found (each 64 KiB, libFuzzer's cut of a 78 kB seed). OpenVDB overran a
// buffer in the first, allocated 4 GiB for a name in the second (an earlier reading path) and read
// past the end of the third; the check refuses each before OpenVDB reads it.
TEST(VdbLayout, TheFilesThatBrokeOpenVdbsReaderFailWithTheReason) {
  EXPECT_NE(check_error(bad_vdb("uncompressed-chunk-overflow.vdb")).find("8 root children cannot fit in the 64477 bytes left"),
            std::string::npos)
      << check_error(bad_vdb("uncompressed-chunk-overflow.vdb"));
  EXPECT_NE(check_error(bad_vdb("transform-name-of-4-gib.vdb")).find("8 root children cannot fit in the 64483 bytes left"),
            std::string::npos)
      << check_error(bad_vdb("transform-name-of-4-gib.vdb"));
  // OpenVDB only warns about a file format version from the future and reads on; the check stops there.
  EXPECT_NE(check_error(bad_vdb("root-tile-count-in-billions.vdb")).find("at byte 12: file format version 1627390176"),
            std::string::npos)
      << check_error(bad_vdb("root-tile-count-in-billions.vdb"));
}

// The fault of fuzz/findings/ made on purpose in a whole file: a leaf's chunk stored uncompressed
// (zip leaves incompressible data so) whose length says more than the leaf holds. OpenVDB 10 would
// copy those bytes into the leaf's 2 kB buffer before comparing the lengths.
TEST(VdbLayout, AnUncompressedChunkLongerThanItsNodeFails) {
  const auto dir = test::temp_dir();
  auto grid = openvdb::Int32Grid::create(0);
  std::mt19937 random(7);  // random 32-bit words: zlib cannot shrink them
  std::uniform_int_distribution<std::int32_t> noise;
  auto accessor = grid->getAccessor();
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) accessor.setValue(openvdb::Coord(i, j, k), noise(random));
  write_grids(dir / "noise.vdb", {grid}, openvdb::io::COMPRESS_ZIP);
  std::vector<char> bytes = bytes_of(dir / "noise.vdb");
  ASSERT_EQ(check_error(dir / "noise.vdb"), "passed");
  const std::int64_t stored = -2048;  // 512 int32 values, uncompressed
  const std::size_t at = find_bytes(bytes, pod_bytes(&stored, 8));
  ASSERT_NE(at, std::string::npos);
  const std::int64_t longer = -(2048 + 1355);
  std::memcpy(bytes.data() + at, &longer, 8);
  write_bytes(dir / "longer.vdb", bytes, bytes.size());
  EXPECT_NE(check_error(dir / "longer.vdb").find("a leaf's values: an uncompressed chunk of 3403 bytes where the node holds 2048"),
            std::string::npos)
      << check_error(dir / "longer.vdb");
  EXPECT_THROW(read_level_set(dir / "longer.vdb"), InputError);
}

// blosc_decompress is given the chunk without its length: a header that claims more compressed
// bytes than the chunk has, or more bytes uncompressed than the node holds, fails.
TEST(VdbLayout, ABloscHeaderThatDisagreesWithItsChunkFails) {
  const auto dir = test::temp_dir();
  write_grids(dir / "whole.vdb", {level_set_grids(false).front()}, openvdb::io::COMPRESS_BLOSC);
  const std::vector<char> bytes = bytes_of(dir / "whole.vdb");
  // A leaf's chunk: an int64 length, then blosc's header (version 2, ..., nbytes 2048 for 512 floats).
  const std::uint32_t leaf_bytes = 2048;
  std::size_t at = 0;
  while ((at = find_bytes(bytes, pod_bytes(&leaf_bytes, 4), at + 1)) != std::string::npos)
    if (at >= 12 && bytes[at - 4] == 2) break;  // the header's first byte, blosc format 2
  ASSERT_NE(at, std::string::npos);
  const std::size_t header = at - 4;
  std::uint32_t cbytes = 0;
  std::memcpy(&cbytes, bytes.data() + header + 12, 4);
  for (const auto& [offset, value, reason] :
       {std::tuple<std::size_t, std::uint32_t, std::string>{12, cbytes + 1000, "compressed bytes, the chunk holds"},
        std::tuple<std::size_t, std::uint32_t, std::string>{4, 4096, "bytes uncompressed where the node holds 2048"}}) {
    std::vector<char> changed = bytes;
    std::memcpy(changed.data() + header + offset, &value, 4);
    write_bytes(dir / "changed.vdb", changed, changed.size());
    EXPECT_NE(check_error(dir / "changed.vdb").find(reason), std::string::npos) << check_error(dir / "changed.vdb");
  }
}

TEST(VdbLayout, FileFormatVersionsOutsideWhatTheReaderKnowsFail) {
  const auto dir = test::temp_dir();
  write_grids(dir / "v.vdb", level_set_grids(false), openvdb::io::COMPRESS_BLOSC);
  std::vector<char> bytes = bytes_of(dir / "v.vdb");
  for (const std::uint32_t version : {221u, openvdb::OPENVDB_FILE_VERSION + 1}) {
    std::memcpy(bytes.data() + 8, &version, 4);  // the version follows the 8-byte magic number
    write_bytes(dir / "v.vdb", bytes, bytes.size());
    EXPECT_NE(check_error(dir / "v.vdb").find("file format version " + std::to_string(version) + "; this build reads"),
              std::string::npos)
        << check_error(dir / "v.vdb");
  }
}

// A file the check passes is one OpenVDB reads without overrunning a buffer, also after a byte
// of it changed: the check either refuses the changed file or OpenVDB reads it (or refuses it
// with an exception, a blosc chunk that does not decode). Under the Sanitize build an overrun is
// an ASan report; in Release a fault would end the test.
TEST(VdbLayout, FilesWithAChangedByteFailTheCheckOrReadWithoutAFault) {
  const auto dir = test::temp_dir();
  openvdb::GridCPtrVec grids = level_set_grids(false);
  write_grids(dir / "whole.vdb", {grids.front()}, openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  const std::vector<char> bytes = bytes_of(dir / "whole.vdb");
  std::mt19937 random(20261205);
  std::uniform_int_distribution<std::size_t> position(0, bytes.size() - 1);
  std::uniform_int_distribution<int> value(0, 255);
  int passed = 0, refused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<char> changed = bytes;
    changed[position(random)] = static_cast<char>(value(random));
    write_bytes(dir / "changed.vdb", changed, changed.size());
    if (check_error(dir / "changed.vdb") != "passed") {
      ++refused;
      continue;
    }
    ++passed;
    try {
      detail::read_grids_in_this_process(dir / "changed.vdb", detail::UncheckedGrids::Refuse);
    } catch (const InputError&) {
    }
  }
  EXPECT_GT(passed, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace ts::sdf
