// Positioned reads of a file (the bag and MCAP readers): never the whole
// file in memory, a count of the bytes read for the benchmarks.
#ifndef ALLANVAR_FILE_READER_H
#define ALLANVAR_FILE_READER_H

#include "bytes.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <string>
#include <vector>

namespace allanvar {

class FileReader {
 public:
  explicit FileReader(const std::string& path) : f_(std::fopen(path.c_str(), "rb")) {
    if (!f_) throw format_error("cannot open the file");
    // Unbuffered: small reads go through this class's own window.
    std::setvbuf(f_, nullptr, _IONBF, 0);
    if (!seek_end()) throw format_error("cannot seek in the file");
    size_ = tell();
  }
  ~FileReader() {
    if (f_) std::fclose(f_);
  }
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

 private:
  static const std::size_t kWindow = 16384;
  std::FILE* f_;
  std::uint64_t size_ = 0;
  double bytes_ = 0;
  std::vector<unsigned char> win_;
  std::uint64_t win_off_ = 0;
  std::size_t win_len_ = 0;

  bool direct(std::uint64_t off, std::size_t n, unsigned char* out) {
    if (!seek(off)) return false;
    const std::size_t got = n ? std::fread(out, 1, n, f_) : 0;
    bytes_ += static_cast<double>(got);
    return got == n;
  }

#ifdef _WIN32
  bool seek(std::uint64_t off) { return _fseeki64(f_, static_cast<__int64>(off), SEEK_SET) == 0; }
  bool seek_end() { return _fseeki64(f_, 0, SEEK_END) == 0; }
  std::uint64_t tell() { return static_cast<std::uint64_t>(_ftelli64(f_)); }
#else
  bool seek(std::uint64_t off) { return fseeko(f_, static_cast<off_t>(off), SEEK_SET) == 0; }
  bool seek_end() { return fseeko(f_, 0, SEEK_END) == 0; }
  std::uint64_t tell() { return static_cast<std::uint64_t>(ftello(f_)); }
#endif
};

}  // namespace allanvar

#endif
