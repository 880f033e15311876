// Large scratch arrays of doubles for the kernels. The first touch of fresh
// memory costs a page fault per 4 KiB page: on the development machine,
// writing 8 MB of fresh memory took 4.5 ms against 0.55 ms for rewriting it
// (sum(x) at 1e6 takes about 2 ms), a large share of the kernels' time at
// 1e6 samples. On Linux an array of 2 MiB or more is therefore aligned to
// 2 MiB in a mapping of its own and advised as transparent huge pages
// (madvise(MADV_HUGEPAGE); taken
// where the system grants them on request, its "madvise" mode): one fault
// per 2 MiB, 8 MB in about 1 ms. Elsewhere, or when the advice is refused,
// it is plain memory. The contents are not initialised unless assign() is
// used.
#ifndef ALLANVAR_SCRATCH_H
#define ALLANVAR_SCRATCH_H

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace allanvar {

class Scratch {
 public:
  Scratch() = default;
  explicit Scratch(std::size_t n) { resize(n); }
  ~Scratch() { release(); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  Scratch(Scratch&& o) noexcept
      : p_(o.p_), n_(o.n_), cap_(o.cap_), map_(o.map_), map_len_(o.map_len_) {
    o.p_ = nullptr;
    o.map_ = nullptr;
    o.n_ = o.cap_ = o.map_len_ = 0;
  }
  Scratch& operator=(Scratch&& o) noexcept {
    if (this != &o) {
      release();
      p_ = o.p_;
      n_ = o.n_;
      cap_ = o.cap_;
      map_ = o.map_;
      map_len_ = o.map_len_;
      o.p_ = nullptr;
      o.map_ = nullptr;
      o.n_ = o.cap_ = o.map_len_ = 0;
    }
    return *this;
  }

  // n values, uninitialised (kept when the capacity suffices)
  void resize(std::size_t n) {
    if (n > cap_) {
      release();
      n_ = cap_ = 0;
      p_ = allocate(n);
      cap_ = n;
    }
    n_ = n;
  }
  void assign(std::size_t n, double v) {
    resize(n);
    std::fill(p_, p_ + n, v);
  }
  double* data() { return p_; }
  const double* data() const { return p_; }
  std::size_t size() const { return n_; }
  double& operator[](std::size_t i) { return p_[i]; }
  const double& operator[](std::size_t i) const { return p_[i]; }
  double* begin() { return p_; }
  double* end() { return p_ + n_; }
  const double* begin() const { return p_; }
  const double* end() const { return p_ + n_; }

 private:
  // large arrays: their own mapping, 2 MiB aligned, advised as huge pages
  // (from malloc, the advice was not taken inside R); the rest: malloc
  double* allocate(std::size_t n) {
    if (n == 0) return nullptr;
    if (n > static_cast<std::size_t>(-1) / sizeof(double) / 2) throw std::bad_alloc();
    const std::size_t bytes = n * sizeof(double);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const std::size_t huge = std::size_t(2) << 20;
    if (bytes >= huge) {
      const std::size_t len = (bytes + huge - 1) / huge * huge + huge;
      void* m = mmap(nullptr, len, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (m != MAP_FAILED) {
        const std::size_t a = reinterpret_cast<std::size_t>(m);
        const std::size_t start = (a + huge - 1) / huge * huge;
        madvise(reinterpret_cast<void*>(start), len - (start - a) - (len - (start - a)) % huge,
                MADV_HUGEPAGE);  // advice only
        map_ = m;
        map_len_ = len;
        return reinterpret_cast<double*>(start);
      }
    }
#endif
    void* p = std::malloc(bytes);
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<double*>(p);
  }
  void release() {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (map_ != nullptr) {
      munmap(map_, map_len_);
      map_ = nullptr;
      map_len_ = 0;
      p_ = nullptr;
      return;
    }
#endif
    std::free(p_);
    p_ = nullptr;
  }

  double* p_ = nullptr;
  std::size_t n_ = 0, cap_ = 0;
  void* map_ = nullptr;  // the mapping of a large array
  std::size_t map_len_ = 0;
};

}  // namespace allanvar

#endif
