// LargeArrayAllocator: a standard allocator for the per-row results of a fit (FitReport::rows)
// that backs large arrays with transparent huge pages.
//
// Why: a fit of 10^6 rows returns 56 MB of RowResult. From the ordinary allocator that memory is
// a fresh anonymous mapping faulted in 4 KiB at a time: 14 000 page faults, which on a virtual
// machine cost more than the whole York fit. In 2 MiB pages the same array faults 28 times.
//
// Contract: below kHugePageThreshold bytes, ::operator new/delete (no change for small fits).
// At or above it, an anonymous private mmap aligned to 2 MiB with madvise(MADV_HUGEPAGE); the
// kernel decides whether huge pages are used (/sys/kernel/mm/transparent_hugepage/enabled set
// to "madvise" or "always"; with "never" it is an ordinary mapping and nothing is lost but the
// alignment slack of < 2 MiB of address space, never touched). Throws std::bad_alloc when mmap
// fails. Stateless: all instances compare equal, so vectors move and swap freely.
// Caveat: with defrag = madvise (the common default) the first large allocation in a fragmented
// system may wait for the kernel to compact memory into huge pages.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <new>

namespace uphill {

inline constexpr std::size_t kHugePageThreshold = std::size_t{4} << 20;  // 4 MiB

template <typename T>
struct LargeArrayAllocator {
  using value_type = T;

  LargeArrayAllocator() noexcept = default;
  template <typename U>
  LargeArrayAllocator(const LargeArrayAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T) / 2) throw std::bad_alloc();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageThreshold) return static_cast<T*>(::operator new(bytes));
    // [mapping | header (start, length) | 2 MiB-aligned array ...]
    const std::size_t length = bytes + kHugePage + sizeof(Header);
    void* start = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (start == MAP_FAILED) throw std::bad_alloc();
    const std::uintptr_t first = reinterpret_cast<std::uintptr_t>(start) + sizeof(Header);
    const std::uintptr_t aligned = (first + kHugePage - 1) & ~std::uintptr_t{kHugePage - 1};
    madvise(reinterpret_cast<void*>(aligned), bytes, MADV_HUGEPAGE);  // a hint: ignore failure
    Header* header = reinterpret_cast<Header*>(aligned) - 1;
    header->start = start;
    header->length = length;
    return reinterpret_cast<T*>(aligned);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePageThreshold) {
      ::operator delete(p);
      return;
    }
    const Header* header = reinterpret_cast<const Header*>(p) - 1;
    munmap(header->start, header->length);
  }

  template <typename U>
  bool operator==(const LargeArrayAllocator<U>&) const noexcept {
    return true;
  }

 private:
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;
  struct Header {
    void* start;
    std::size_t length;
  };
};

}  // namespace uphill
