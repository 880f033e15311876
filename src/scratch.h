// Large scratch memory for the kernels. The first touch of fresh memory
// costs a page fault per 4 KiB page: on the development machine, writing
// 8 MB of fresh memory took 4.5 ms against 0.55 ms for rewriting it (sum(x)
// at 1e6 takes about 2 ms), a large share of the kernels' time at 1e6
// samples. On Linux a block of 2 MiB or more therefore gets a mapping of
// its own, 2 MiB aligned and advised as transparent huge pages
// (madvise(MADV_HUGEPAGE), granted where the system allows them on
// request, its "madvise" mode): one fault per 2 MiB, 8 MB in 1-1.5 ms.
// Elsewhere, or when the advice is refused, it is plain memory.
// Scratch: an array of doubles, not initialised unless assign() is used;
// BigAllocator: the same memory for a std::vector (src/fft.h's buffers).
#ifndef ALLANVAR_SCRATCH_H
#define ALLANVAR_SCRATCH_H

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

// Own mappings on Linux, but not under AddressSanitizer: its bounds checks
// cover malloc's blocks only
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ALLANVAR_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define ALLANVAR_ASAN 1
#endif
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(ALLANVAR_ASAN)
#define ALLANVAR_BIG_MAP 1
#endif

namespace allanvar {

// Memory of `bytes` for a kernel: large blocks in a mapping of their own,
// 2 MiB aligned and advised as huge pages (Linux), others from malloc.
// Release with big_free(p, bytes) (the same bytes).
inline void* big_alloc(std::size_t bytes) {
#if defined(ALLANVAR_BIG_MAP)
  const std::size_t huge = std::size_t(2) << 20;
  if (bytes >= huge) {
    const std::size_t len = (bytes + huge - 1) / huge * huge;
    void* m = mmap(nullptr, len + huge, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    // keep the aligned len bytes, unmap the rest
    const std::size_t a = reinterpret_cast<std::size_t>(m);
    const std::size_t start = (a + huge - 1) / huge * huge;
    if (start > a) munmap(m, start - a);
    if (a + huge > start) {
      munmap(reinterpret_cast<void*>(start + len), a + huge - start);
    }
    void* p = reinterpret_cast<void*>(start);
    madvise(p, len, MADV_HUGEPAGE);  // advice only
    return p;
  }
#endif
  void* p = std::malloc(bytes > 0 ? bytes : 1);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

inline void big_free(void* p, std::size_t bytes) {
  if (p == nullptr) return;
#if defined(ALLANVAR_BIG_MAP)
  const std::size_t huge = std::size_t(2) << 20;
  if (bytes >= huge) {
    munmap(p, (bytes + huge - 1) / huge * huge);
    return;
  }
#endif
  (void)bytes;
  std::free(p);
}

// An allocator for std::vector on big_alloc (FFT buffers).
template <class T>
struct BigAllocator {
  typedef T value_type;
  BigAllocator() = default;
  template <class U>
  BigAllocator(const BigAllocator<U>&) {}
  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_alloc();
    return static_cast<T*>(big_alloc(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t n) { big_free(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const BigAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const BigAllocator<U>&) const { return false; }
};

class Scratch {
 public:
  Scratch() = default;
  explicit Scratch(std::size_t n) { resize(n); }
  ~Scratch() { release(); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  Scratch(Scratch&& o) noexcept : p_(o.p_), n_(o.n_), cap_(o.cap_) {
    o.p_ = nullptr;
    o.n_ = o.cap_ = 0;
  }
  Scratch& operator=(Scratch&& o) noexcept {
    if (this != &o) {
      release();
      p_ = o.p_;
      n_ = o.n_;
      cap_ = o.cap_;
      o.p_ = nullptr;
      o.n_ = o.cap_ = 0;
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
  double* allocate(std::size_t n) {
    if (n == 0) return nullptr;
    if (n > static_cast<std::size_t>(-1) / sizeof(double)) throw std::bad_alloc();
    return static_cast<double*>(big_alloc(n * sizeof(double)));
  }
  void release() {
    big_free(p_, cap_ * sizeof(double));
    p_ = nullptr;
  }

  double* p_ = nullptr;
  std::size_t n_ = 0, cap_ = 0;
};

}  // namespace allanvar

#endif
