// Static checks of the binding slots shared by GLSL and C++ (shaders/*/bindings.h): no shader or host
// call uses a bare slot number, no two blocks of one pass share a slot, and the simulator and the
// preview renderer, which share a context in `tetrasand sim`, use disjoint slots. Kernel parameters
// travel only in the typed blocks of shaders/common/params.h: no shader declares a loose uniform and
// no host code sets one by name. And one of the host sources: only the gpu layer, which counts them,
// makes the GL calls that wait for the GPU. Reads the sources only; no GL context.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "gpu/shader_library.h"

namespace ts::gpu {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = TETRASAND_SOURCE_DIR;

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// Every file below `dir` whose extension is in `extensions`, as paths relative to `dir`.
std::vector<fs::path> files_below(const fs::path& dir, const std::set<std::string>& extensions) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file() && extensions.count(entry.path().extension().string())) {
      out.push_back(fs::relative(entry.path(), dir));
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// "file:line: text" for each line of `text` that matches `pattern`.
std::vector<std::string> matching_lines(const std::string& text, const std::regex& pattern, const std::string& file) {
  std::vector<std::string> hits;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (std::regex_search(line, pattern)) hits.push_back(file + ":" + std::to_string(number) + ": " + line);
  }
  return hits;
}

// "file:line: text" of each line matching `pattern` in the C++ of the host folders, but for `except`
// (paths relative to the source root).
std::vector<std::string> host_lines_matching(const std::regex& pattern, const std::vector<std::string>& dirs,
                                             const std::set<std::string>& except = {}) {
  std::vector<std::string> hits;
  for (const std::string& dir : dirs) {
    for (const fs::path& file : files_below(kSource / dir, {".cpp", ".h"})) {
      const fs::path path = fs::path(dir) / file;
      if (except.count(path.generic_string())) continue;
      for (auto& hit : matching_lines(read_text(kSource / path), pattern, path.generic_string()))
        hits.push_back(hit);
    }
  }
  return hits;
}

// The slot namespaces GL keeps apart.
enum class SlotKind { StorageBuffer, UniformBuffer, Image, Texture };

struct Declaration {
  SlotKind kind;
  std::string block;  // block name, or the uniform's name for images and samplers
  std::string slot;   // as written: a macro name or (an error) a number
};

// Every `layout(... binding = X ...)` declaration of a resolved shader source.
std::vector<Declaration> declarations(const std::string& text) {
  static const std::regex buffer(R"(layout\s*\(([^)]*)\)\s*(?:\w+\s+)*buffer\s+(\w+))");
  static const std::regex uniform_block(R"(layout\s*\(([^)]*)\)\s*uniform\s+(\w+)\s*\{)");
  static const std::regex opaque(R"(layout\s*\(([^)]*)\)\s*(?:\w+\s+)*uniform\s+(?:\w+\s+)*(\w*(?:image|sampler)\w*)\s+(\w+))");
  static const std::regex binding(R"(binding\s*=\s*(\w+))");
  std::vector<Declaration> out;
  auto scan = [&](const std::regex& pattern, auto kind_of) {
    for (auto it = std::sregex_iterator(text.begin(), text.end(), pattern); it != std::sregex_iterator(); ++it) {
      const std::string qualifiers = (*it)[1];
      std::smatch slot;
      if (!std::regex_search(qualifiers, slot, binding)) continue;
      out.push_back({kind_of(*it), (*it)[it->size() - 1], slot[1]});
    }
  };
  scan(buffer, [](const std::smatch&) { return SlotKind::StorageBuffer; });
  scan(uniform_block, [](const std::smatch&) { return SlotKind::UniformBuffer; });
  scan(opaque, [](const std::smatch& m) {
    return m[2].str().find("image") != std::string::npos ? SlotKind::Image : SlotKind::Texture;
  });
  return out;
}

// `#define NAME VALUE` of a resolved source, aliases followed to a number (-1 when undefined).
class Macros {
 public:
  explicit Macros(const std::string& text) {
    static const std::regex define(R"(^\s*#define\s+(\w+)\s+(\w+))");
    std::istringstream lines(text);
    std::string line;
    std::smatch m;
    while (std::getline(lines, line)) {
      if (std::regex_search(line, m, define)) values_[m[1]] = m[2];
    }
  }
  long value(std::string name) const {
    for (int hops = 0; hops < 8; ++hops) {
      if (!name.empty() && std::isdigit(static_cast<unsigned char>(name[0]))) return std::stol(name);
      const auto it = values_.find(name);
      if (it == values_.end()) return -1;
      name = it->second;
    }
    return -1;
  }

 private:
  std::map<std::string, std::string> values_;
};

// A pass is one program: the shader files of one folder that share a stem (raycast.vert + .frag).
std::map<fs::path, std::vector<fs::path>> passes() {
  std::map<fs::path, std::vector<fs::path>> out;
  for (const fs::path& file : files_below(kSource / "shaders", {".comp", ".vert", ".geom", ".frag"})) {
    out[file.parent_path() / file.stem()].push_back(file);
  }
  return out;
}

// kind and slot number -> the names of the blocks a pass declares there.
using SlotUse = std::map<std::pair<SlotKind, long>, std::set<std::string>>;

SlotUse slots_of_pass(const std::vector<fs::path>& files) {
  const ShaderLibrary library(kSource / "shaders");
  SlotUse use;
  for (const fs::path& file : files) {
    // Both branches of #ifdef TS_FP64 are read; a block declared twice keeps one name, so it counts once.
    const std::string text = library.load(file.generic_string()).text;
    const Macros macros(text);
    for (const Declaration& d : declarations(text)) {
      const long slot = macros.value(d.slot);
      EXPECT_GE(slot, 0) << file << ": block " << d.block << " binds to " << d.slot << ", which no header defines";
      use[{d.kind, slot}].insert(d.block);
    }
  }
  return use;
}

TEST(Bindings, NoShaderUsesABareSlotNumber) {
  const std::regex bare(R"(binding\s*=\s*[0-9])");
  std::vector<std::string> hits;
  for (const fs::path& file : files_below(kSource / "shaders", {".comp", ".vert", ".geom", ".frag", ".glsl", ".h"})) {
    for (auto& hit : matching_lines(read_text(kSource / "shaders" / file), bare, file.generic_string())) hits.push_back(hit);
  }
  EXPECT_TRUE(hits.empty()) << "name the slot in the stage's bindings.h:\n" << ::testing::PrintToString(hits);
}

TEST(Bindings, NoHostCallBindsABareSlotNumber) {
  // Buffer::bind, and the GL calls that take a binding point or unit first.
  const std::regex bare(R"((\.bind\(\s*[0-9])|(glBindBuffer(Base|Range)\(\s*\w+\s*,\s*[0-9])|(glBind(TextureUnit|ImageTexture|Sampler)\(\s*[0-9]))");
  const auto hits =
      host_lines_matching(bare, {"core", "gpu", "sdf", "sampler", "sim", "preview", "app", "bench", "tests"});
  EXPECT_TRUE(hits.empty()) << "use the slot's name from shaders/*/bindings.h:\n" << ::testing::PrintToString(hits);
}

// `text` without its comments, line breaks kept (so line numbers stay).
std::string without_comments(const std::string& text) {
  static const std::regex comment(R"(//[^\n]*|/\*[\s\S]*?\*/)");
  std::string out;
  auto last = text.cbegin();
  for (auto it = std::sregex_iterator(text.begin(), text.end(), comment); it != std::sregex_iterator(); ++it) {
    out.append(last, (*it)[0].first);
    for (char c : it->str()) if (c == '\n') out += '\n';
    last = (*it)[0].second;
  }
  out.append(last, text.cend());
  return out;
}

// "file:line: name" of each loose uniform in `text`: a `uniform` declaration that is neither a block
// (`uniform Name {`) nor an opaque type (sampler*, image*), which GL would let a host set by name.
std::vector<std::string> loose_uniforms(const std::string& text, const std::string& file) {
  static const std::regex declaration(
      R"(\buniform\s+(?:(?:lowp|mediump|highp|precise|invariant|readonly|writeonly|coherent|volatile|restrict)\s+)*)"
      R"((\w+)\s*(\{|\w+))");
  const std::string code = without_comments(text);
  std::vector<std::string> hits;
  for (auto it = std::sregex_iterator(code.begin(), code.end(), declaration); it != std::sregex_iterator(); ++it) {
    const std::string type = (*it)[1], next = (*it)[2];
    if (next == "{" || type.find("sampler") != std::string::npos || type.find("image") != std::string::npos) continue;
    const auto line = std::count(code.cbegin(), (*it)[0].first, '\n') + 1;
    hits.push_back(file + ":" + std::to_string(line) + ": uniform " + type + " " + next);
  }
  return hits;
}

TEST(Params, TheLooseUniformScanFindsWhatItMustAndOnlyThat) {
  const std::string sample =
      "layout(std140, binding = TS_X) uniform Block { ItemCount params; };\n"
      "layout(binding = TS_UNIT) uniform sampler2D albedo;  // uniform float not_this;\n"
      "/* uniform int nor_this; */ uniform highp\n  vec3 gravity;\n"
      "layout(binding = 0, r32f) uniform writeonly image2D target;\n";
  EXPECT_EQ(loose_uniforms(sample, "x"), std::vector<std::string>{"x:3: uniform vec3 gravity"});
}

TEST(Params, NoShaderDeclaresALooseUniform) {
  std::vector<std::string> hits;
  std::size_t blocks = 0;
  const std::regex block(R"(\buniform\s+\w+\s*\{)");
  for (const fs::path& file : files_below(kSource / "shaders", {".comp", ".vert", ".geom", ".frag", ".glsl", ".h"})) {
    const std::string text = read_text(kSource / "shaders" / file);
    for (auto& hit : loose_uniforms(text, file.generic_string())) hits.push_back(hit);
    blocks += static_cast<std::size_t>(std::distance(std::sregex_iterator(text.begin(), text.end(), block),
                                                     std::sregex_iterator()));
  }
  EXPECT_GE(blocks, 30u);  // the check must see the parameter blocks it stands beside
  EXPECT_TRUE(hits.empty()) << "put kernel parameters in a struct of shaders/common/params.h, read from a "
                               "uniform block and uploaded with gpu::ParamBlock:\n"
                            << ::testing::PrintToString(hits);
}

// With no gpu::Program::set left, a by-name uniform could only come back through the GL calls that
// take a uniform location; product code makes none (tests may).
TEST(Params, NoProductCodeSetsAUniformByName) {
  const std::regex by_name(R"(^[^/]*\bgl(Program)?Uniform(\d|Matrix)\w*\s*\(|^[^/]*\bglGetUniformLocation\s*\()");
  std::vector<std::string> dirs;
  for (const auto& entry : fs::directory_iterator(kSource)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name != "tests" && name != "shaders" && name[0] != '.' && name.rfind("build", 0) != 0)
      dirs.push_back(name);
  }
  ASSERT_GE(dirs.size(), 6u);
  const auto hits = host_lines_matching(by_name, dirs);
  EXPECT_TRUE(hits.empty()) << "upload a struct of shaders/common/params.h with gpu::ParamBlock instead:\n"
                            << ::testing::PrintToString(hits);
}

// Reads of GPU memory, finishes, fence waits and query results drain the GPU's queue; gpu/host_sync.h
// counts each where the gpu layer makes it, so no other host code may call them (tests may).
TEST(HostSources, OnlyTheGpuLayerMakesTheGlCallsThatWait) {
  // No '/' before the call on its line: comments that name a call do not count.
  const std::regex waits(
      R"(^[^/]*\bgl(Finish|ClientWaitSync|GetQueryObject\w*|GetQueryBufferObject\w*|Get(Named)?BufferSubData|)"
      R"(Map(Named)?Buffer\w*|GetTexImage|GetTextureImage|GetTextureSubImage|Readn?Pixels)\s*\()");
  const std::set<std::string> counted{"gpu/gl.cpp", "gpu/graphics.cpp", "gpu/context.cpp"};
  ASSERT_GE(host_lines_matching(waits, {"gpu"}).size(), 3u);  // the counted calls: the check sees them
  const auto hits = host_lines_matching(
      waits, {"core", "gpu", "sdf", "sampler", "sim", "preview", "app", "bench"}, counted);
  EXPECT_TRUE(hits.empty()) << "read or wait through gpu::Buffer, gpu::Texture, Queue or Context:\n"
                            << ::testing::PrintToString(hits);
}

// Past GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] groups the queue lays a dispatch out as a 2D grid, where
// gl_GlobalInvocationID.x and gl_WorkGroupID.x no longer number items and groups: kernels go through
// shaders/common/dispatch.glsl (tests/gpu/context_test.cpp runs a dispatch past the limit).
TEST(Dispatch, KernelsNumberItemsAndGroupsOnlyThroughDispatchGlsl) {
  const std::regex raw(R"(gl_(GlobalInvocationID|WorkGroupID))");
  const std::regex through(R"(dispatch_(item|group)\(\))");
  std::vector<std::string> hits;
  std::size_t users = 0;
  for (const fs::path& file : files_below(kSource / "shaders", {".comp", ".glsl"})) {
    if (file.generic_string() == "common/dispatch.glsl") continue;
    const std::string text = read_text(kSource / "shaders" / file);
    for (auto& hit : matching_lines(text, raw, file.generic_string())) hits.push_back(hit);
    if (std::regex_search(text, through)) ++users;
  }
  EXPECT_GE(users, 20u);  // the check must see the kernels it guards
  EXPECT_TRUE(hits.empty()) << "number items with dispatch_item() and groups with dispatch_group():\n"
                            << ::testing::PrintToString(hits);
}

TEST(Bindings, NoTwoBlocksOfOnePassShareASlot) {
  const auto all = passes();
  ASSERT_GT(all.size(), 20u);  // the check must see the kernels it guards
  for (const auto& [pass, files] : all) {
    for (const auto& [slot, blocks] : slots_of_pass(files)) {
      EXPECT_EQ(blocks.size(), 1u) << pass << ": slot " << slot.second << " holds " << ::testing::PrintToString(blocks);
    }
  }
}

TEST(Bindings, TheSimulatorAndThePreviewKeepClearOfEachOthersBuffers) {
  // `tetrasand sim` renders frames in the simulator's context: a preview pass must not leave a buffer
  // where the simulator expects its state, whatever order the passes bind in.
  std::map<long, std::string> sim, preview;
  for (const auto& [pass, files] : passes()) {
    const std::string stage = pass.begin()->string();
    if (stage != "sim" && stage != "preview") continue;
    for (const auto& [slot, blocks] : slots_of_pass(files)) {
      if (slot.first != SlotKind::StorageBuffer) continue;
      (stage == "sim" ? sim : preview)[slot.second] = pass.generic_string() + " " + *blocks.begin();
    }
  }
  ASSERT_FALSE(sim.empty());
  ASSERT_FALSE(preview.empty());
  for (const auto& [slot, user] : preview) {
    EXPECT_EQ(sim.count(slot), 0u) << "slot " << slot << ": " << user << " and " << sim[slot];
  }
}

}  // namespace
}  // namespace ts::gpu
