#pragma once
// Loads GLSL kernels by name from the shader directory (shaders/<stage>/<kernel>.<stage-ext>), resolves
// `#include "..."` (GL_GOOGLE_include_directive, the form glslangValidator checks at build time), and
// maps compiler messages back to the original file and line.
#include <filesystem>
#include <string>
#include <vector>

namespace ts::gpu {

struct ShaderSource {
  std::string text;                          // ready for glShaderSource
  std::vector<std::filesystem::path> files;  // #line source-string numbers index this table
};

class ShaderLibrary {
 public:
  // TETRASAND_SHADER_DIR, else the host's folder (set_host_root), else <exe>/../share/tetrasand/shaders
  // (build tree and install tree alike), else <CMAKE_INSTALL_PREFIX>/share/tetrasand/shaders as
  // configured (programs of other projects linking the installed package), else the build tree this
  // binary was configured in.
  static std::filesystem::path default_root();
  // Where a host that is not beside bin/ finds its shaders: the Python module (python/) sets its
  // installed folder at import, since <exe> is then the Python interpreter. An existing folder only
  // counts; TETRASAND_SHADER_DIR still wins. Set before any context is made (not thread-safe).
  static void set_host_root(std::filesystem::path root);

  explicit ShaderLibrary(std::filesystem::path root = default_root());
  const std::filesystem::path& root() const { return root_; }

  // `relative` like "sdf/scan_convert.geom". `defines` are injected after #version ("NAME VALUE").
  ShaderSource load(const std::string& relative, const std::vector<std::string>& defines = {}) const;

  // Rewrites "0:12(3): error ..." / "0(12) : error ..." into "sdf/scan_convert.geom:12: error ...".
  static std::string annotate_log(const std::string& log, const ShaderSource& source,
                                  const std::filesystem::path& root);

 private:
  void append(const std::filesystem::path& file, ShaderSource& out, std::vector<std::filesystem::path>& stack,
              bool is_root, const std::vector<std::string>& defines) const;
  std::filesystem::path root_;
};

}  // namespace ts::gpu
