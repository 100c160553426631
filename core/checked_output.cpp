#include "core/checked_output.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>
#include <utility>

#include "core/error.h"

namespace ts {

namespace {

[[noreturn]] void cannot_write(const std::filesystem::path& named, int error) {
  throw InputError(named, fmt::format("cannot write file: {}", std::system_category().message(error)));
}

// close() that is not retried on EINTR (Linux has released the descriptor either way).
int close_once(int fd) { return ::close(fd) == 0 ? 0 : errno; }

}  // namespace

CheckedFileBuf::CheckedFileBuf(int fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }

void CheckedFileBuf::record(int error) {
  if (error_ == 0) error_ = error;
}

bool CheckedFileBuf::write_all(const char* data, std::size_t size) {
  while (size > 0 && error_ == 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      record(n < 0 ? errno : ENOSPC);  // a write of 0 bytes makes no progress: the space is gone
      break;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return error_ == 0;
}

bool CheckedFileBuf::drain() {
  const bool ok = write_all(pbase(), static_cast<std::size_t>(pptr() - pbase()));
  setp(buffer_.data(), buffer_.data() + buffer_.size());
  return ok;
}

CheckedFileBuf::int_type CheckedFileBuf::overflow(int_type ch) {
  if (!drain()) return traits_type::eof();
  if (!traits_type::eq_int_type(ch, traits_type::eof())) {
    *pptr() = traits_type::to_char_type(ch);
    pbump(1);
  }
  return traits_type::not_eof(ch);
}

int CheckedFileBuf::sync() { return drain() ? 0 : -1; }

std::streamsize CheckedFileBuf::xsputn(const char* s, std::streamsize n) {
  if (n < static_cast<std::streamsize>(buffer_.size())) return std::streambuf::xsputn(s, n);
  // Large blocks go straight to the file.
  return drain() && write_all(s, static_cast<std::size_t>(n)) ? n : 0;
}

CheckedFileBuf::pos_type CheckedFileBuf::seekoff(off_type off, std::ios_base::seekdir dir,
                                                 std::ios_base::openmode) {
  if (!drain()) return pos_type(off_type(-1));
  const int whence = dir == std::ios_base::beg ? SEEK_SET : dir == std::ios_base::cur ? SEEK_CUR : SEEK_END;
  const off_t at = ::lseek(fd_, static_cast<off_t>(off), whence);
  if (at < 0) {
    record(errno);
    return pos_type(off_type(-1));
  }
  return pos_type(static_cast<off_type>(at));
}

CheckedFileBuf::pos_type CheckedFileBuf::seekpos(pos_type pos, std::ios_base::openmode which) {
  return seekoff(off_type(pos), std::ios_base::beg, which);
}

CheckedOutputFile::CheckedOutputFile(const std::filesystem::path& path, const std::filesystem::path& named)
    : named_(named),
      fd_(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666)),
      buf_(fd_),
      stream_(&buf_) {
  if (fd_ < 0) cannot_write(named_, errno);
}

CheckedOutputFile::~CheckedOutputFile() {
  if (fd_ >= 0) close_once(fd_);
}

void CheckedOutputFile::fail(int error) const { cannot_write(named_, error); }

void CheckedOutputFile::throw_if_failed() const {
  if (buf_.error() != 0) fail(buf_.error());
}

void CheckedOutputFile::finish() {
  stream_.flush();
  if (!buf_.drain()) fail(buf_.error());
  if (::fsync(fd_) != 0) fail(errno);  // a file system may report the lost space only here (NFS, ext4)
  const int fd = std::exchange(fd_, -1);
  if (const int error = close_once(fd); error != 0) fail(error);
}

void sync_written_file(const std::filesystem::path& path, const std::filesystem::path& named) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) cannot_write(named, errno);
  if (::fsync(fd) != 0) {
    const int error = errno;
    close_once(fd);
    cannot_write(named, error);
  }
  if (const int error = close_once(fd); error != 0) cannot_write(named, error);
}

void sync_directory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  close_once(fd);
}

}  // namespace ts
