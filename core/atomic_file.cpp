#include "core/atomic_file.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/checked_output.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/temporary_name.h"

namespace ts {
namespace fs = std::filesystem;

namespace {

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

// A temporary name in the target's directory, so the final rename never crosses file systems; it
// carries this run's id (core/temporary_name.h), so a later clean-up removes it only once we are gone.
fs::path temporary_sibling(const fs::path& target) {
  return target.parent_path() / format_temporary_name(temporary_name_for(target.filename().string()));
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

// Removes the temporary files that dead processes left beside `target` (best effort: a directory
// that cannot be changed keeps them). Only names that parse as ours are looked at.
void remove_dead_temporaries_of(const fs::path& target) {
  remove_dead_temporaries(directory_of(target), target.filename().string());
}

// Writes a temporary file through a checked stream: every write, the flush, fsync and close.
void write_checked(const fs::path& tmp, const fs::path& target, const StreamWriter& write) {
  CheckedOutputFile file(tmp, target);
  try {
    write(file.stream());
  } catch (...) {
    // A writer that saw the failed write itself (NanoVDB's does) reports it without the reason.
    file.throw_if_failed();
    throw;
  }
  file.finish();
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
  const auto [end, error] = std::from_chars(line.data() + 4, line.data() + line.size(), journal.pid);
  if (error != std::errc() || end != line.data() + line.size()) throw malformed();
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
      write_checked(renames.back().first, file.target, file.write);
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
  remove_dead_temporaries_of(journal);
  for (const fs::path& target : targets) remove_dead_temporaries_of(target);
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
    sync_directory(directory_of(journal));
  } catch (const fs::filesystem_error& e) {
    cannot_write(targets.front(), e);
  }
}

namespace {

// The shared part of write_atomically and write_stream_atomically: `produce(tmp)` writes and syncs the
// temporary file; only then is it renamed over `target`, and the directory synced.
void replace_with(const fs::path& target, const std::function<void(const fs::path&)>& produce,
                  const std::vector<fs::path>& inputs) {
  prepare_target(target, inputs);
  std::error_code ec;
  const fs::path tmp = temporary_sibling(target.parent_path().empty() ? fs::path(".") / target : target);
  try {
    produce(tmp);
    fs::rename(tmp, target);
  } catch (const fs::filesystem_error& e) {
    // An unwritable place (read-only file system, no permission, no space) is the user's to fix.
    fs::remove(tmp, ec);
    cannot_write(target, e);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  sync_directory(directory_of(target));
}

}  // namespace

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write,
                      const std::vector<fs::path>& inputs) {
  replace_with(
      target,
      [&](const fs::path& tmp) {
        write(tmp);
        sync_written_file(tmp, target);
      },
      inputs);
}

void write_stream_atomically(const fs::path& target, const StreamWriter& write,
                             const std::vector<fs::path>& inputs) {
  replace_with(
      target, [&](const fs::path& tmp) { write_checked(tmp, target, write); }, inputs);
}

void write_file_atomically(const fs::path& target, std::string_view contents,
                           const std::vector<fs::path>& inputs) {
  write_stream_atomically(
      target,
      [&](std::ostream& out) { out.write(contents.data(), static_cast<std::streamsize>(contents.size())); },
      inputs);
}

std::string read_file(const fs::path& path, std::uint64_t max_bytes, std::string_view why) {
  return read_regular_file(path, max_bytes, why);
}

std::string sha256_file(const fs::path& path) { return sha256_hex(read_file(path)); }

std::string sha256_hex(std::string_view bytes) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr) != 1) {
    throw Error(ExitCode::Internal, "SHA-256 failed");
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
