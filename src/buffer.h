// A large uninitialised double buffer shared by the estimator kernels
// (src/allan.cpp, src/dynamic.cpp). On Linux it is 2 MiB aligned and marked
// for transparent huge pages: a fresh 100 MB prefix array otherwise costs
// tens of thousands of page faults, more than the sums themselves.
#ifndef ALLANVAR_BUFFER_H
#define ALLANVAR_BUFFER_H

#include <Rcpp.h>
#include <cstdlib>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace allanvar {

class Buffer {
 public:
  Buffer() {}
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { std::free(p_); }
  void resize(R_xlen_t n) {
    std::free(p_);
    p_ = nullptr;
    n_ = n;
    const size_t bytes = static_cast<size_t>(n > 0 ? n : 1) * sizeof(double);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t align = static_cast<size_t>(1) << 21;
    if (bytes >= align) {
      void* q = nullptr;
      if (posix_memalign(&q, align, bytes) == 0) {
        madvise(q, bytes, MADV_HUGEPAGE);
        p_ = static_cast<double*>(q);
      }
    }
#endif
    if (!p_) p_ = static_cast<double*>(std::malloc(bytes));
    if (!p_) throw std::bad_alloc();
  }
  double* data() { return p_; }
  const double* data() const { return p_; }
  double& operator[](R_xlen_t i) { return p_[i]; }
  const double& operator[](R_xlen_t i) const { return p_[i]; }
  R_xlen_t size() const { return n_; }

 private:
  double* p_ = nullptr;
  R_xlen_t n_ = 0;
};

}  // namespace allanvar

#endif
