// Large scratch memory for the kernels. The first touch of fresh memory
// costs a page fault per 4 KiB page: on the development machine, writing
// 8 MB of fresh memory took 4.5 ms against 0.55 ms for rewriting it (sum(x)
// at 1e6 takes about 2 ms), a large share of the kernels' time at 1e6
// samples. On Linux a block of 2 MiB or more therefore gets a mapping of
// its own, 2 MiB aligned and advised as transparent huge pages
// (madvise(MADV_HUGEPAGE), granted where the system allows them on
// request, its "madvise" mode): one fault per 2 MiB, 8 MB in 1-1.5 ms.
// Elsewhere, or when the advice is refused, it is plain memory.
// BasicScratch: an array (Scratch: of doubles), not initialised unless
// assign() is used, its values not kept when it grows; BigAllocator: the
// same memory for a std::vector.
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
// 2 MiB aligned and advised as huge pages (Linux), others (and any block
// when no mapping is to be had) from malloc. Each block starts with a
// header saying which, so big_free() releases it the right way.
const std::size_t kBigHeader = 64;
struct BigHeader {
  std::size_t mapped;  // length of the mapping, or 0: from malloc
};

inline void* big_alloc(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(-1) / 2) throw std::bad_alloc();
  const std::size_t total = bytes + kBigHeader;
#if defined(ALLANVAR_BIG_MAP)
  const std::size_t huge = std::size_t(2) << 20;
  if (total >= huge) {
    const std::size_t len = (total + huge - 1) / huge * huge;
    void* m = mmap(nullptr, len + huge, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m != MAP_FAILED) {  // else: malloc below
      // keep the aligned len bytes, unmap the rest
      const std::size_t a = reinterpret_cast<std::size_t>(m);
      const std::size_t start = (a + huge - 1) / huge * huge;
      if (start > a) munmap(m, start - a);
      if (a + huge > start) {
        munmap(reinterpret_cast<void*>(start + len), a + huge - start);
      }
      char* base = reinterpret_cast<char*>(start);
      madvise(base, len, MADV_HUGEPAGE);  // advice only
      reinterpret_cast<BigHeader*>(base)->mapped = len;
      return base + kBigHeader;
    }
  }
#endif
  char* base = static_cast<char*>(std::malloc(total));
  if (base == nullptr) throw std::bad_alloc();
  reinterpret_cast<BigHeader*>(base)->mapped = 0;
  return base + kBigHeader;
}

inline void big_free(void* p) {
  if (p == nullptr) return;
  char* base = static_cast<char*>(p) - kBigHeader;
  const std::size_t mapped = reinterpret_cast<BigHeader*>(base)->mapped;
#if defined(ALLANVAR_BIG_MAP)
  if (mapped > 0) {
    munmap(base, mapped);
    return;
  }
#endif
  (void)mapped;
  std::free(base);
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
  void deallocate(T* p, std::size_t) { big_free(p); }
  template <class U>
  bool operator==(const BigAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const BigAllocator<U>&) const { return false; }
};

template <class T>
class BasicScratch {
 public:
  BasicScratch() = default;
  explicit BasicScratch(std::size_t n) { resize(n); }
  ~BasicScratch() { release(); }
  BasicScratch(const BasicScratch&) = delete;
  BasicScratch& operator=(const BasicScratch&) = delete;
  BasicScratch(BasicScratch&& o) noexcept : p_(o.p_), n_(o.n_), cap_(o.cap_) {
    o.p_ = nullptr;
    o.n_ = o.cap_ = 0;
  }
  BasicScratch& operator=(BasicScratch&& o) noexcept {
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
  void assign(std::size_t n, const T& v) {
    resize(n);
    std::fill(p_, p_ + n, v);
  }
  T* data() { return p_; }
  const T* data() const { return p_; }
  std::size_t size() const { return n_; }
  T& operator[](std::size_t i) { return p_[i]; }
  const T& operator[](std::size_t i) const { return p_[i]; }
  T* begin() { return p_; }
  T* end() { return p_ + n_; }
  const T* begin() const { return p_; }
  const T* end() const { return p_ + n_; }

 private:
  T* allocate(std::size_t n) {
    if (n == 0) return nullptr;
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_alloc();
    return static_cast<T*>(big_alloc(n * sizeof(T)));
  }
  void release() {
    big_free(p_);
    p_ = nullptr;
  }

  T* p_ = nullptr;
  std::size_t n_ = 0, cap_ = 0;
};

// doubles (most kernels); src/fft.h holds complex transform buffers
using Scratch = BasicScratch<double>;

}  // namespace allanvar

#endif
