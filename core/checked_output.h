#pragma once
// A file written through POSIX calls whose every write, flush, fsync and close is checked: the
// streams of the standard library and of libraries such as OpenVDB set a bit on a failed write
// (a full disk, a quota) that their callers do not look at, and a truncated file was then renamed
// over a good one (issue 46). Here the first failure is kept and finish() reports it.
#include <array>
#include <filesystem>
#include <ostream>
#include <streambuf>

namespace ts {

// A std::streambuf over a file descriptor: buffered writes, seeks (OpenVDB goes back to write a
// grid's offsets), and the errno of the first failed call, after which nothing more is written.
class CheckedFileBuf : public std::streambuf {
 public:
  explicit CheckedFileBuf(int fd);
  int error() const { return error_; }
  // Writes what is buffered; false (and error() set) when a write failed now or before.
  bool drain();

 protected:
  int_type overflow(int_type ch) override;
  int sync() override;
  std::streamsize xsputn(const char* s, std::streamsize n) override;
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override;
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override;

 private:
  bool write_all(const char* data, std::size_t size);
  void record(int error);

  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buffer_{};
};

// A new file (created exclusively: it never replaces anything) to write through `stream()`;
// finish() drains, fsyncs and closes it and throws ts::InputError naming `named` with the reason
// ("No space left on device", "Disk quota exceeded", "Permission denied") when any step failed.
// The destructor closes the file without reporting (an exception is already on its way).
class CheckedOutputFile {
 public:
  CheckedOutputFile(const std::filesystem::path& path, const std::filesystem::path& named);
  ~CheckedOutputFile();
  CheckedOutputFile(const CheckedOutputFile&) = delete;
  CheckedOutputFile& operator=(const CheckedOutputFile&) = delete;

  std::ostream& stream() { return stream_; }
  void finish();
  // Throws finish()'s InputError when a write has failed so far (nothing when none has).
  void throw_if_failed() const;

 private:
  [[noreturn]] void fail(int error) const;

  std::filesystem::path named_;
  int fd_ = -1;
  CheckedFileBuf buf_;
  std::ostream stream_;
};

// Flushes a file someone else wrote (an external program) to the disk: fsync, then close, each
// checked; ts::InputError naming `named` when the file is missing or the disk refuses it.
void sync_written_file(const std::filesystem::path& path, const std::filesystem::path& named);

// Flushes a directory's entries (a rename in it) to the disk. Best effort: some file systems refuse
// fsync on a directory, and the rename itself has already succeeded.
void sync_directory(const std::filesystem::path& dir);

}  // namespace ts
