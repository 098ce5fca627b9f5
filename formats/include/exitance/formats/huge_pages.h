// Large per-texel arrays asked to be backed by transparent huge pages where the kernel leaves that
// to the program (Linux's "madvise" mode, Debian's and Ubuntu's default). Their first touch is then
// one fault per 2 MiB instead of one per 4 KiB: on a 2-core VM, zeroing 25 MB took 64 ms in 4 KiB
// pages and 7 ms in huge pages. Only advice: elsewhere, or when the kernel has no huge page free,
// nothing changes. Here, the lowest of the libraries, for the readers and the runtime alike. For
// arrays made once (loading, a bake's results), not on a frame's path: where the kernel's THP
// defrag setting compacts memory at such a fault, the first touch can stall for a while.
#pragma once
#include <vector>
#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace exitance::formats {

// The whole 2 MiB pages inside [data, data + bytes), before they are first written.
inline void advise_huge_pages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHugePage = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data, (void)bytes;
#endif
}

// `values` with room for `count` in storage in huge pages (its elements kept), for push_back.
template <class T>
void reserve_in_huge_pages(std::vector<T>& values, size_t count) {
  if (count <= values.capacity()) return;
  std::vector<T> fresh;
  fresh.reserve(count);
  advise_huge_pages(fresh.data(), count * sizeof(T));
  fresh.assign(values.begin(), values.end());
  values.swap(fresh);
}

// A copy of `values` in huge pages.
template <class T>
std::vector<T> copy_in_huge_pages(const std::vector<T>& values) {
  std::vector<T> copy;
  reserve_in_huge_pages(copy, values.size());
  copy.assign(values.begin(), values.end());
  return copy;
}

// `values` resized to `count` (zeros) with its new storage in huge pages: for arrays about to be
// filled whole (a file's records).
template <class T>
void resize_in_huge_pages(std::vector<T>& values, size_t count) {
  reserve_in_huge_pages(values, count);
  values.resize(count);
}

}  // namespace exitance::formats
