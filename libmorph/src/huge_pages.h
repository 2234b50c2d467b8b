// An allocator for the largest arrays of an operation (tens of megabytes: a vertex per
// dual triangle, a plane per facet), which are made afresh for each operation and touched
// all over. glibc maps such blocks anew each time, and a first touch of a 4 KiB page cost
// about 2 us on the machines we measured on: 17,000 faults for the 68 MB of vertices of an
// icosphere of 327,680 facets eroded, more than its triangulation. Blocks of at least
// kHugeBlock are mapped here with madvise(MADV_HUGEPAGE), so that where transparent huge
// pages are enabled in `madvise` mode (Debian's default) they fault in 2 MiB at a time;
// elsewhere the advice does nothing. Smaller blocks come from operator new.
#pragma once

#include <cstddef>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace morph::detail {

constexpr std::size_t kHugeBlock = std::size_t{8} << 20;

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= kHugeBlock) {
      void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::bad_alloc();
      madvise(p, bytes, MADV_HUGEPAGE);  // (advice: its failure changes nothing)
      return static_cast<T*>(p);
    }
#endif
    return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= kHugeBlock) {
      munmap(p, bytes);
      return;
    }
#endif
    ::operator delete (p, std::align_val_t{alignof(T)});
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

}  // namespace morph::detail
