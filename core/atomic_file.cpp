#include "core/atomic_file.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
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

// Refuses `target` where it is one of `inputs` or a directory; makes the directory it goes in.
void prepare_target(const fs::path& target, const std::vector<fs::path>& inputs) {
  for (const auto& input : inputs) {
    if (same_file(target, input))
      throw InputError(target, "output would overwrite an input file; choose another output path");
  }
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw InputError(target, "output path is a directory");
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError(target, "cannot create output directory " + dir.string());
}

fs::path directory_of(const fs::path& file) {
  return file.parent_path().empty() ? fs::path(".") : file.parent_path();
}

// A file system error while writing `target` is the user's to fix (read-only, no permission, no space).
[[noreturn]] void cannot_write(const fs::path& target, const fs::filesystem_error& e) {
  throw InputError(target, fmt::format("cannot write file: {}", e.code().message()));
}

bool process_is_dead(long pid) {
  return pid > 0 && pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// The writer's process id in the temporary name `name` of `target` (".TARGET.tmp.PID.N"), or 0.
long temporary_owner(const std::string& name, const fs::path& target) {
  std::string prefix(".");  // piece by piece, as in temporary_sibling (GCC 12's -Wrestrict)
  prefix.append(target.filename().string());
  prefix.append(".tmp.");
  if (!name.starts_with(prefix)) return 0;
  long pid = 0;
  const char* first = name.data() + prefix.size();
  const auto [end, error] = std::from_chars(first, name.data() + name.size(), pid);
  return error == std::errc() && end != first && *end == '.' ? pid : 0;
}

// Removes the temporary files that dead processes left beside `target` (best effort: a directory
// that cannot be changed keeps them).
void remove_dead_temporaries(const fs::path& target) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(directory_of(target), ec)) {
    if (process_is_dead(temporary_owner(entry.path().filename().string(), target)))
      fs::remove(entry.path(), ec);
  }
}

// A journal of write_files_atomically: its writer, then one line per file, "TMP\tTARGET" (names in
// the journal's directory).
struct Journal {
  long pid = 0;
  std::vector<std::pair<std::string, std::string>> renames;
};

constexpr std::string_view kJournalFirstLine = "tetrasand journal 1";

std::string journal_text(const std::vector<std::pair<fs::path, fs::path>>& renames) {
  std::string text = fmt::format("{}\npid {}\n", kJournalFirstLine, ::getpid());
  for (const auto& [tmp, target] : renames)
    text += tmp.filename().string() + "\t" + target.filename().string() + "\n";
  return text;
}

Journal parse_journal(const fs::path& path) {
  std::istringstream in(read_file(path));
  std::string line;
  Journal journal;
  const auto malformed = [&] {
    return InputError(path, "not a journal of tetrasand (delete it if it is yours)");
  };
  if (!std::getline(in, line) || line != kJournalFirstLine) throw malformed();
  if (!std::getline(in, line) || !line.starts_with("pid ")) throw malformed();
  journal.pid = std::atol(line.c_str() + 4);
  while (std::getline(in, line)) {
    const auto tab = line.find('\t');
    if (tab == std::string::npos || tab == 0 || tab + 1 == line.size()) throw malformed();
    journal.renames.emplace_back(line.substr(0, tab), line.substr(tab + 1));
  }
  return journal;
}

// The renames of a published journal, then the journal removed; each rename done at most once
// (a temporary file already renamed is gone), so a completion that is itself killed can be redone.
void complete_journal(const fs::path& journal_path, const Journal& journal) {
  const fs::path dir = directory_of(journal_path);
  try {
    for (const auto& [tmp, target] : journal.renames) {
      if (fs::exists(dir / tmp)) fs::rename(dir / tmp, dir / target);
    }
    fs::remove(journal_path);
  } catch (const fs::filesystem_error& e) {
    throw InputError(journal_path, fmt::format("a replacement that process {} began cannot be finished: {}",
                                               journal.pid, e.code().message()));
  }
}

void check_plain_name(const fs::path& target) {
  if (target.filename().string().find_first_of("\t\n") != std::string::npos) {
    throw InputError(target, "a file name with a tab or a line break cannot be written");
  }
}

// Writes each file under its temporary name; their paths.
std::vector<std::pair<fs::path, fs::path>> write_temporaries(const std::vector<FileWrite>& files) {
  std::vector<std::pair<fs::path, fs::path>> renames;
  try {
    for (const FileWrite& file : files) {
      renames.emplace_back(temporary_sibling(directory_of(file.target) / file.target.filename()),
                           file.target);
      file.write(renames.back().first);
    }
  } catch (...) {
    std::error_code ec;
    for (const auto& written : renames) fs::remove(written.first, ec);
    throw;
  }
  return renames;
}

}  // namespace

bool complete_interrupted_writes(const fs::path& journal, const std::vector<fs::path>& targets) {
  bool completed = false;
  std::error_code ec;
  if (fs::exists(journal, ec)) {
    const Journal pending = parse_journal(journal);
    if (!process_is_dead(pending.pid)) {
      throw InputError(journal,
                       fmt::format("process {} is replacing these files right now; try again when it "
                                   "has finished",
                                   pending.pid));
    }
    complete_journal(journal, pending);
    completed = true;
  }
  remove_dead_temporaries(journal);
  for (const fs::path& target : targets) remove_dead_temporaries(target);
  return completed;
}

void write_files_atomically(const fs::path& journal, const std::vector<FileWrite>& files,
                            const std::vector<fs::path>& inputs) {
  std::vector<fs::path> targets;
  for (const FileWrite& file : files) {
    check_plain_name(file.target);
    prepare_target(file.target, inputs);
    targets.push_back(file.target);
  }
  complete_interrupted_writes(journal, targets);
  try {
    const auto renames = write_temporaries(files);
    try {
      write_file_atomically(journal, journal_text(renames));  // the set changes here
    } catch (...) {
      std::error_code ec;
      for (const auto& written : renames) fs::remove(written.first, ec);
      throw;
    }
    for (const auto& [tmp, target] : renames) fs::rename(tmp, target);
    fs::remove(journal);
  } catch (const fs::filesystem_error& e) {
    cannot_write(targets.front(), e);
  }
}

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write,
                      const std::vector<fs::path>& inputs) {
  prepare_target(target, inputs);
  std::error_code ec;
  const fs::path tmp = temporary_sibling(target.parent_path().empty() ? fs::path(".") / target : target);
  try {
    write(tmp);
    fs::rename(tmp, target);
  } catch (const fs::filesystem_error& e) {
    // An unwritable place (read-only file system, no permission, no space) is the user's to fix.
    fs::remove(tmp, ec);
    cannot_write(target, e);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_file_atomically(const fs::path& target, std::string_view contents,
                           const std::vector<fs::path>& inputs) {
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
