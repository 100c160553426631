#include "core/atomic_file.h"

#include <openssl/evp.h>
#include <unistd.h>

#include <array>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

#include "core/error.h"

namespace ts {
namespace fs = std::filesystem;

namespace {

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

// A temporary name in the target's directory, so the final rename never crosses file systems.
fs::path temporary_sibling(const fs::path& target) {
  std::random_device device;
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "." + std::string temporaries.
  std::string name(".");
  name.append(target.filename().string());
  name.append(".tmp.");
  name.append(std::to_string(::getpid()));
  name.append(".");
  name.append(std::to_string(device() & 0xffffff));
  return target.parent_path() / name;
}

}  // namespace

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write,
                      const std::vector<fs::path>& inputs) {
  for (const auto& input : inputs) {
    if (same_file(target, input)) throw InputError(target, "output would overwrite an input file; choose another output path");
  }
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw InputError(target, "output path is a directory");
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError(target, "cannot create output directory " + dir.string());

  const fs::path tmp = temporary_sibling(target.parent_path().empty() ? fs::path(".") / target : target);
  try {
    write(tmp);
    fs::rename(tmp, target);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_file_atomically(const fs::path& target, std::string_view contents, const std::vector<fs::path>& inputs) {
  write_atomically(
      target,
      [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
        out.close();
        if (!out) throw InputError(target, "cannot write file (disk full or no permission?)");
      },
      inputs);
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "no such file");
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file for reading (permission?)");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string sha256_file(const fs::path& path) {
  const std::string bytes = read_file(path);
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr) != 1) {
    throw Error(ExitCode::Internal, "SHA-256 failed for " + path.string());
  }
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

}  // namespace ts
