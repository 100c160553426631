#include "gpu/shader_library.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/error.h"

namespace ts::gpu {
namespace fs = std::filesystem;

namespace {

fs::path executable_directory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw GpuError("shader file not found: " + path.string() + " (set TETRASAND_SHADER_DIR?)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// ShaderLibrary::set_host_root's folder; empty: none.
fs::path& host_root() {
  static fs::path root;
  return root;
}

}  // namespace

void ShaderLibrary::set_host_root(fs::path root) { host_root() = std::move(root); }

fs::path ShaderLibrary::default_root() {
  if (const char* env = std::getenv("TETRASAND_SHADER_DIR"); env && *env) return env;
  std::error_code ec;
  if (!host_root().empty() && fs::is_directory(host_root(), ec)) return host_root();
  const fs::path beside = executable_directory() / ".." / "share" / "tetrasand" / "shaders";
  if (fs::is_directory(beside, ec)) return fs::weakly_canonical(beside, ec);
  // A program of another project, linked against the installed package, lives elsewhere: the prefix
  // this library was configured to install to holds the kernels of the same build.
#ifdef TETRASAND_SHADER_INSTALL_DIR
  if (fs::is_directory(TETRASAND_SHADER_INSTALL_DIR, ec)) return TETRASAND_SHADER_INSTALL_DIR;
#endif
#ifdef TETRASAND_SHADER_BUILD_DIR
  if (fs::is_directory(TETRASAND_SHADER_BUILD_DIR, ec)) return TETRASAND_SHADER_BUILD_DIR;
#endif
  return beside;
}

ShaderLibrary::ShaderLibrary(fs::path root) : root_(std::move(root)) {
  std::error_code ec;
  if (!fs::is_directory(root_, ec)) {
    throw GpuError("shader directory not found: " + root_.string() +
                   " (tetrasand looks beside its executable in ../share/tetrasand/shaders; set TETRASAND_SHADER_DIR)");
  }
}

ShaderSource ShaderLibrary::load(const std::string& relative, const std::vector<std::string>& defines) const {
  ShaderSource out;
  std::vector<fs::path> stack;
  append(root_ / relative, out, stack, true, defines);
  return out;
}

void ShaderLibrary::append(const fs::path& file, ShaderSource& out, std::vector<fs::path>& stack, bool is_root,
                           const std::vector<std::string>& defines) const {
  if (std::find(stack.begin(), stack.end(), file) != stack.end()) {
    throw GpuError("shader include cycle at " + file.string());
  }
  stack.push_back(file);
  const int file_number = static_cast<int>(out.files.size());
  out.files.push_back(file);
  std::istringstream lines(read_text(file));
  std::string line;
  int number = 0;
  static const std::regex include_re(R"(^\s*#\s*include\s+"([^"]+)\")");
  static const std::regex extension_re(R"(^\s*#\s*extension\s+GL_GOOGLE_include_directive)");
  static const std::regex version_re(R"(^\s*#\s*version\b)");
  while (std::getline(lines, line)) {
    ++number;
    std::smatch match;
    if (std::regex_search(line, match, include_re)) {
      fs::path target = file.parent_path() / match[1].str();
      if (!fs::exists(target)) target = root_ / match[1].str();
#ifdef TETRASAND_VENDOR_SHADER_DIR
      // A shader folder without the vendor headers (TETRASAND_SHADER_DIR at the source tree): the
      // package's own copy, where the build found it.
      if (!fs::exists(target)) target = fs::path(TETRASAND_VENDOR_SHADER_DIR) / match[1].str();
#endif
      append(target, out, stack, false, {});
      out.text += "#line " + std::to_string(number + 1) + " " + std::to_string(file_number) + "\n";
    } else if (std::regex_search(line, extension_re)) {
      out.text += "\n";  // only glslangValidator needs it; drivers do not know the extension
    } else if (std::regex_search(line, version_re)) {
      out.text += line + "\n";
      if (is_root) {
        for (const auto& d : defines) out.text += "#define " + d + "\n";
        out.text += "#line " + std::to_string(number + 1) + " " + std::to_string(file_number) + "\n";
      }
    } else {
      out.text += line + "\n";
    }
  }
  stack.pop_back();
}

std::string ShaderLibrary::annotate_log(const std::string& log, const ShaderSource& source, const fs::path& root) {
  // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error C1234: ...".
  static const std::regex mesa(R"((\d+):(\d+)\((\d+)\))");
  static const std::regex nvidia(R"((\d+)\((\d+)\) :)");
  std::istringstream lines(log);
  std::string line, out;
  auto name_of = [&](int index) {
    if (index < 0 || index >= static_cast<int>(source.files.size())) return std::to_string(index);
    std::error_code ec;
    const fs::path rel = fs::relative(source.files[static_cast<std::size_t>(index)], root, ec);
    return ec ? source.files[static_cast<std::size_t>(index)].string() : rel.string();
  };
  while (std::getline(lines, line)) {
    std::smatch m;
    if (std::regex_search(line, m, mesa)) {
      line = m.prefix().str() + name_of(std::stoi(m[1].str())) + ":" + m[2].str() + ":" + m[3].str() + m.suffix().str();
    } else if (std::regex_search(line, m, nvidia)) {
      line = m.prefix().str() + name_of(std::stoi(m[1].str())) + ":" + m[2].str() + ":" + m.suffix().str();
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace ts::gpu
