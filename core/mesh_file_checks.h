#pragma once
// Strict checks of OFF, PLY and GLB files before assimp reads them. Assimp's readers are lenient where it
// hurts: an OFF or PLY header that declares billions of elements makes them reserve memory for all
// of them (the machine swaps or the process is killed), and face indices out of range are silently
// clamped or replaced, so a broken file loads as a plausible but wrong mesh. These checks stream
// through the file (a PLY through the one PLY parser, core/ply.h), never trusting a declared count
// for an allocation, and throw ts::InputError naming the file, the line (text files) and the problem.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>

namespace ts::detail {

// Node trees are read to this depth and this many nodes: assimp's readers and the flattening of
// core/mesh_io.cpp recurse once per level, and a tree tens of thousands of levels deep overflowed
// assimp's stack before any check of the imported scene could run (issue 46).
inline constexpr std::size_t kMostNodeDepth = 1000;
inline constexpr std::size_t kMostNodes = 100000;
// JSON and XML nest at most this deep (assimp's JSON and XML readers recurse per level too).
inline constexpr std::size_t kMostNesting = 2000;

// `text` is the whole file. Accepts OFF, COFF, NOFF, CNOFF (extra per-vertex values are ignored).
void check_off_file(const std::filesystem::path& path, std::string_view text);

// `bytes` is the whole file: ascii, binary_little_endian or binary_big_endian.
void check_ply_file(const std::filesystem::path& path, std::string_view bytes);

// `bytes` is the whole file: a binary glTF (GLB) of version 2. Checks the structure assimp's GLB
// reader trusts: the header's total length is the file's, and every chunk lies inside the file
// (assimp read a chunk length past the end of the file into its JSON parser, an over-read ASan
// reports; fuzz_mesh, 2026-12-04). Other versions are left to assimp.
// Its JSON then goes through check_gltf_json with the BIN chunk's length.
void check_glb_file(const std::filesystem::path& path, std::string_view bytes);

// `json` is a glTF 2.0 document (a .gltf file, or a GLB's JSON chunk whose BIN chunk has `glb_binary`
// bytes). Checks what assimp's glTF 2 reader copies from without looking: every buffer holds the bytes
// it declares (the BIN chunk, a data: URI, a file beside `path`), every bufferView lies inside its
// buffer, and every accessor (sparse ones too) reads only inside its bufferView. An accessor 5 bytes
// past its view made assimp read past the BIN chunk's block (fuzz_mesh, 2026-12-05). The indices the
// meshes name exist, and every primitive has positions. glTF 1.0 documents are left to assimp.
// Then the node graph: a forest of at most kMostNodes nodes and kMostNodeDepth levels.
void check_gltf_json(const std::filesystem::path& path, std::string_view json,
                     std::optional<std::uint64_t> glb_binary = std::nullopt);

// A streaming pass over JSON text: arrays and objects nest at most kMostNesting deep (before any
// parser that recurses sees it).
void check_json_nesting(const std::filesystem::path& path, std::string_view json);

// A streaming pass over an XML document (Collada and assimp's other XML formats): elements nest at
// most kMostNesting deep, <node> elements at most kMostNodeDepth deep and kMostNodes in all.
void check_xml_nesting(const std::filesystem::path& path, std::string_view xml);

}  // namespace ts::detail
