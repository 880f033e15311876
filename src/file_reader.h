// Positioned reads of a file (the bag and MCAP readers): never the whole
// file in memory, a count of the bytes read for the benchmarks.
#ifndef ALLANVAR_FILE_READER_H
#define ALLANVAR_FILE_READER_H

#include "bytes.h"

#include <algorithm>
#include <cstdint>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <string>
#include <vector>

#ifndef _WIN32
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>
#endif

namespace allanvar {

class FileReader {
 public:
  explicit FileReader(const std::string& path) {
    if (!open_file(path)) throw format_error("cannot open the file");
  }
  ~FileReader() { close_file(); }
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;

  std::uint64_t size() const { return size_; }
  double bytes_read() const { return bytes_; }

  // n bytes at `off` into `out`; false when the file ends first. Small
  // reads (record headers between skipped record data) are served from a
  // window of kWindow bytes, refilled with one read; large ones go direct.
  bool read(std::uint64_t off, std::size_t n, unsigned char* out) {
    if (off > size_ || n > size_ - off) return false;
    if (off >= win_off_ && off - win_off_ + n <= win_len_) {
      if (n) std::memcpy(out, win_.data() + (off - win_off_), n);
      return true;
    }
    if (n >= kWindow) return direct(off, n, out);
    const std::size_t len = static_cast<std::size_t>(std::min<std::uint64_t>(std::uint64_t{kWindow}, size_ - off));
    win_.resize(kWindow);
    win_len_ = 0;
    if (!direct(off, len, win_.data())) return false;
    win_off_ = off;
    win_len_ = len;
    if (n) std::memcpy(out, win_.data(), n);
    return true;
  }
  bool read(std::uint64_t off, std::size_t n, std::vector<unsigned char>& out) {
    out.resize(n);
    return read(off, n, out.data());
  }
  // The next `n` bytes at `off` will be read soon: the kernel may start
  // reading them (a hint; nothing on Windows).
  void will_need(std::uint64_t off, std::uint64_t n) {
#if !defined(_WIN32) && defined(POSIX_FADV_WILLNEED)
    if (off < size_) posix_fadvise(fd_, static_cast<off_t>(off), static_cast<off_t>(std::min(n, size_ - off)), POSIX_FADV_WILLNEED);
#else
    (void)off;
    (void)n;
#endif
  }

 private:
  static const std::size_t kWindow = 16384;
  std::uint64_t size_ = 0;
  double bytes_ = 0;
  std::vector<unsigned char> win_;
  std::uint64_t win_off_ = 0;
  std::size_t win_len_ = 0;

#ifdef _WIN32
  std::FILE* f_ = nullptr;
  bool open_file(const std::string& path) {
    f_ = std::fopen(path.c_str(), "rb");
    if (!f_) return false;
    std::setvbuf(f_, nullptr, _IONBF, 0);
    if (_fseeki64(f_, 0, SEEK_END) != 0) return false;
    size_ = static_cast<std::uint64_t>(_ftelli64(f_));
    return true;
  }
  void close_file() {
    if (f_) std::fclose(f_);
  }
  bool direct(std::uint64_t off, std::size_t n, unsigned char* out) {
    if (_fseeki64(f_, static_cast<__int64>(off), SEEK_SET) != 0) return false;
    const std::size_t got = n ? std::fread(out, 1, n, f_) : 0;
    bytes_ += static_cast<double>(got);
    return got == n;
  }
#else
  // pread(): one system call a read, no seek.
  int fd_ = -1;
  bool open_file(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDONLY);
    if (fd_ < 0) return false;
    struct stat st;
    if (::fstat(fd_, &st) != 0) return false;
    size_ = static_cast<std::uint64_t>(st.st_size);
    return true;
  }
  void close_file() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool direct(std::uint64_t off, std::size_t n, unsigned char* out) {
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::pread(fd_, out + got, n - got, static_cast<off_t>(off + got));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    bytes_ += static_cast<double>(got);
    return got == n;
  }
#endif
};

}  // namespace allanvar

#endif
