#include "core/input_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "core/error.h"

namespace ts {

namespace {

// What a file type that is not a regular file is, for the message.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

[[noreturn]] void not_regular(const std::filesystem::path& path, mode_t mode) {
  throw InputError(path, fmt::format("is {}, not a regular file", kind_of(mode)));
}

[[noreturn]] void cannot_read(const std::filesystem::path& path, int error) {
  if (error == ENOENT || error == ENOTDIR) throw InputError(path, "no such file");
  throw InputError(path, fmt::format("cannot be read: {}", std::system_category().message(error)));
}

// Closes the descriptor on every way out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::uint64_t require_regular_file(const std::filesystem::path& path) {
  struct stat s {};
  if (::stat(path.c_str(), &s) != 0) cannot_read(path, errno);
  if (!S_ISREG(s.st_mode)) not_regular(path, s.st_mode);
  return static_cast<std::uint64_t>(s.st_size);
}

std::string read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                              std::string_view why) {
  require_regular_file(path);
  // O_NONBLOCK: a FIFO swapped in after the check must not block the open.
  const Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)};
  if (file.fd < 0) cannot_read(path, errno);
  struct stat s {};
  if (::fstat(file.fd, &s) != 0) cannot_read(path, errno);
  if (!S_ISREG(s.st_mode)) not_regular(path, s.st_mode);
  const auto size = static_cast<std::uint64_t>(s.st_size);
  if (size > max_bytes) {
    throw InputError(path, fmt::format("is {} bytes; at most {} can be read{}{}", size, max_bytes,
                                       why.empty() ? "" : ": ", why));
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(file.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) cannot_read(path, errno);
    if (n == 0) break;  // the file shrank while it was read
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace ts
