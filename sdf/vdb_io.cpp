#include "sdf/vdb_io.h"

#include <fmt/format.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/NanoToOpenVDB.h>
#include <openvdb/io/Stream.h>

#include <ext/stdio_filebuf.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "core/allocation_cap.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "sdf/vdb_layout.h"

namespace ts::sdf {
namespace {

// OpenVDB's message about a broken file, fit for one line: it quotes what it read (a type name of
// 64 kB from a fuzzed file), so it is cut at 200 characters and its control bytes escaped.
std::string openvdb_problem(const std::string& message) {
  constexpr std::size_t kMost = 200;
  std::string out;
  for (const char c : message.substr(0, kMost)) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? fmt::format("\\x{:02x}", byte) : std::string(1, c);
  }
  if (message.size() > kMost) out += fmt::format("... ({} characters)", message.size());
  return out;
}

// What openvdb::io::File::write writes (a seekable archive: grid offsets in the descriptors), but into
// a stream of ours: File opens a std::ofstream it never checks after writing, so a full disk left a
// truncated .vdb that was renamed over a good one (issue 46). core/atomic_file.h checks this stream.
class SeekableStreamArchive : public openvdb::io::Archive {
 public:
  void write_to(std::ostream& out, const openvdb::GridPtrVec& grids) const {
    Archive::write(out, grids, /*seekable=*/true);
  }
};

}  // namespace

void write_vdb(const std::filesystem::path& path, const openvdb::FloatGrid::Ptr& grid,
               const std::map<std::string, std::string>& metadata,
               const std::vector<std::filesystem::path>& inputs) {
  ensure_openvdb_initialized();
  for (const auto& [key, value] : metadata) grid->insertMeta(key, openvdb::StringMetadata(value));
  write_stream_atomically(
      path,
      [&](std::ostream& out) {
        try {
          SeekableStreamArchive().write_to(out, openvdb::GridPtrVec{grid});
        } catch (const openvdb::IoError& e) {  // the place is not writable (permission, space)
          throw InputError(path, std::string("cannot write file (") + e.what() + ")");
        }
      },
      inputs);
}

namespace {

// How the reader process ends (besides a signal, which is OpenVDB's reader crashing).
enum ReaderExit : int { kGridsStreamed = 0, kBadFile = 3, kReaderBug = 4 };

}  // namespace

openvdb::GridPtrVecPtr detail::read_grids_in_this_process(const std::filesystem::path& path,
                                                          UncheckedGrids unchecked) {
  // Every length, count and chunk OpenVDB's reader would trust, compared with the file first: the
  // reader overruns its buffers on some broken files (fuzz/findings/README.md).
  require_regular_file(path);  // also for the fuzz target, which calls this directly
  const VdbLayout layout = check_vdb_layout(path);
  if (!layout.complete() && unchecked == UncheckedGrids::Refuse)
    throw InputError(path, "holds " + layout.unchecked + ", whose layout tetrasand's check does not cover");
  std::error_code ec;
  // No single allocation of a sound read comes near the file's size; one far above it is a length
  // field the reader trusts (core/allocation_cap.h): refuse it at once instead of reserving it.
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  const std::size_t cap = static_cast<std::size_t>(ec ? 0 : file_bytes) * 4 + (std::size_t{64} << 20);
  try {
    const AllocationCap allocation_cap(cap);
    // Read through a stream that throws on the first read past its end: OpenVDB's reader does not
    // look at the stream's state inside its loops, so a count in the file of two billion root tiles
    // ran two billion failed reads (fuzz_vdb, 2026-12-04: a 64 kB file took 18 s).
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "cannot be opened for reading (permission?)");
    in.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    return stream.getGrids();
  } catch (const std::ios_base::failure&) {
    throw InputError(path, "is not a readable OpenVDB file (it ends before the data it declares: it is cut short "
                           "or a count in it is wrong)");
  } catch (const openvdb::Exception& e) {
    throw InputError(path, "is not a readable OpenVDB file (" + openvdb_problem(e.what()) + ")");
  } catch (const std::bad_alloc&) {  // a length in the file beyond the cap (or beyond memory)
    throw InputError(path, fmt::format("is not a readable OpenVDB file (a length in it asks for more than {} MiB, "
                                       "more than a file of {} bytes can hold)",
                                       cap >> 20, file_bytes));
  } catch (const std::length_error&) {
    throw InputError(path, "is not a readable OpenVDB file (a size in it is beyond any string or array)");
  }
}

openvdb::GridPtrVecPtr detail::read_nanovdb_grid_in_this_process(const std::filesystem::path& path) {
  require_regular_file(path);
  std::error_code ec;
  // As for .vdb: no allocation of a sound read is far above the file's size (an uncompressed grid is
  // the file less its headers), so a grid size beyond it is a length the reader would trust.
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  const std::size_t cap = static_cast<std::size_t>(ec ? 0 : file_bytes) * 4 + (std::size_t{64} << 20);
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    const AllocationCap allocation_cap(cap);
    handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(path.string());
  } catch (const std::bad_alloc&) {
    throw InputError(path, fmt::format("is not a readable NanoVDB file (its grid size asks for more than {} MiB, more "
                                       "than a file of {} bytes can hold)",
                                       cap >> 20, file_bytes));
  } catch (const std::exception& e) {
    throw InputError(path, fmt::format("is not a readable NanoVDB file ({})", e.what()));
  }
  const nanovdb::NanoGrid<float>* grid = handle.grid<float>();
  if (!grid) throw InputError(path, "holds no float grid first (a level set is a float grid)");
  // Every node offset is followed when the grid is converted: a grid whose own size or nodes lie
  // outside what was read is refused before that.
  if (grid->gridSize() > handle.size())
    throw InputError(path, "is a damaged NanoVDB file (its grid claims more bytes than the file holds)");
  if (const std::string problem = nanovdb::GridValidator<float>::check(*grid, /*detailed=*/true); !problem.empty())
    throw InputError(path, "is a damaged NanoVDB file (NanoVDB's validator: " + problem + ")");
  auto grids = std::make_shared<openvdb::GridPtrVec>();
  grids->push_back(nanovdb::nanoToOpenVDB(*grid));
  return grids;
}

namespace {

void write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd, bytes.data(), bytes.size());
    if (written <= 0 && errno != EINTR) return;
    if (written > 0) bytes.remove_prefix(static_cast<std::size_t>(written));
  }
}

// NanoVDB files start with the bytes "NanoVDB0" (nanovdb::io's file header magic), whatever their name.
bool is_nanovdb_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, sizeof magic) && std::string_view(magic, sizeof magic) == "NanoVDB0";
}

// The reader process: reads the file, streams its float grids back through `data_fd` as OpenVDB
// writes them (uncompressed, no statistics: nothing that needs TBB's threads, which a forked
// process does not have), and says what went wrong through `message_fd`. Never returns.
[[noreturn]] void run_reader_process(const std::filesystem::path& path, int data_fd, int message_fd) {
  int code = kGridsStreamed;
  std::string message;
  try {
    const openvdb::GridPtrVecPtr grids = is_nanovdb_file(path) ? detail::read_nanovdb_grid_in_this_process(path)
                                                               : detail::read_grids_in_this_process(path);
    openvdb::GridCPtrVec floats;
    for (const auto& grid : *grids)
      if (openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) floats.push_back(grid);
    __gnu_cxx::stdio_filebuf<char> buffer(data_fd, std::ios::out, std::size_t{1} << 16);
    std::ostream out(&buffer);
    openvdb::io::Stream stream(out);
    stream.setCompression(openvdb::io::COMPRESS_NONE);
    stream.setGridStatsMetadataEnabled(false);
    stream.write(floats);
    out.flush();
    if (!out) throw std::runtime_error("the pipe to the reading process broke");
  } catch (const InputError& e) {
    code = kBadFile;
    message = e.what();
  } catch (const std::exception& e) {
    code = kReaderBug;
    message = e.what();
  }
  // Short enough for the pipe's buffer, so the write never waits on the parent.
  write_all(message_fd, std::string_view(message).substr(0, 4000));
  ::_exit(code);
}

std::string read_all(int fd) {
  std::string text;
  char chunk[4096];
  for (ssize_t got; (got = ::read(fd, chunk, sizeof chunk)) != 0;) {
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) break;
    text.append(chunk, static_cast<std::size_t>(got));
  }
  return text;
}

// Both ends are closed when it goes, unless closed or handed over before (a failed fork, a throw).
struct Pipe {
  int read = -1, write = -1;
  Pipe() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    read = fds[0];
    write = fds[1];
  }
  ~Pipe() {
    close_end(read);
    close_end(write);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
  static void close_end(int& fd) {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  int release_read() { return std::exchange(read, -1); }
};

}  // namespace

openvdb::FloatGrid::Ptr read_level_set(const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  // A FIFO or a device would block or never end in the layout walk and in OpenVDB's reader.
  require_regular_file(path);
  // OpenVDB's reader is run on the file in a child process: some broken files make it write past
  // its buffers (fuzz/findings/: a segmentation fault in Release), which must not corrupt or end
  // this process. The child streams back what it read as OpenVDB itself writes it, a stream whose
  // lengths are right by construction, and this process reads that.
  Pipe data, message;
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error(std::string("cannot start the .vdb reading process: ") + std::strerror(errno));
  if (child == 0) {
    Pipe::close_end(data.read);
    Pipe::close_end(message.read);
    run_reader_process(path, data.write, message.write);
  }
  Pipe::close_end(data.write);
  Pipe::close_end(message.write);
  openvdb::GridPtrVecPtr grids;
  std::string stream_problem;
  try {
    // Closing the read end (the buffer's destructor) before waiting lets a child that still writes
    // die of SIGPIPE instead of waiting for a reader that stopped.
    __gnu_cxx::stdio_filebuf<char> buffer(data.release_read(), std::ios::in, std::size_t{1} << 16);
    std::istream in(&buffer);
    in.exceptions(std::ios::failbit | std::ios::badbit);
    const AllocationCap allocation_cap(std::size_t{1} << 30);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    grids = stream.getGrids();
  } catch (const std::exception& e) {
    stream_problem = e.what();
  }
  const std::string child_message = read_all(message.read);
  Pipe::close_end(message.read);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    throw InputError(path, fmt::format("is not a readable OpenVDB file (OpenVDB's reader crashed on it: {}; it ran "
                                       "in a separate process, so nothing else was harmed)",
                                       ::strsignal(WTERMSIG(status))));
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == kBadFile) throw InputError(child_message);
  if (code == kReaderBug) throw std::runtime_error(child_message);
  if (code != kGridsStreamed)  // a sanitizer's report in the child ends it with its own code
    throw InputError(path, fmt::format("is not a readable OpenVDB file (OpenVDB's reader stopped on it with exit code {})",
                                       code));
  if (!grids) throw std::runtime_error("reading the grids back from the .vdb reading process failed: " + stream_problem);
  bool any_float = false;
  for (const auto& base : *grids) {
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) continue;
    any_float = true;
    if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) continue;
    if (grid->activeVoxelCount() == 0)
      throw InputError(path, "its level set '" + grid->getName() + "' is empty");
    return grid;
  }
  throw InputError(path, any_float ? "holds float grids but none is a level set (class fog volume or unknown)"
                                   : "holds no float grid (a level set is a float grid)");
}

}  // namespace ts::sdf
