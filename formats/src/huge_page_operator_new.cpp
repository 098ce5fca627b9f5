// The global operator new of the programs that link this object (the `bake` and
// `exitance-relight` tools; never the libraries an engine links): every allocation of at least
// kHugePageAdvisedFrom bytes is advised into transparent huge pages before its first touch (huge_pages.h:
// only the whole 2 MiB pages inside the block; no rounding, so no memory is added). The tools'
// stages allocate gigabytes of fresh per-texel arrays whose first touch was one kernel fault per
// 4 KiB page: on the open city's CPU bake (9.6 M texels) 1.3 M faults, 15 % of its CPU time in the
// kernel (bench/results/host-stages.md). Under AddressSanitizer the sanitizer's own operator new
// stays, so its new/delete checks keep working.
#include <cstddef>
#include <cstdlib>
#include <new>

#include "exitance/formats/huge_page_operator_new.h"
#include "exitance/formats/huge_pages.h"

#if !defined(EXITANCE_SANITIZER_ALLOCATOR)

namespace {

void* allocate(std::size_t bytes) noexcept {
  void* block = std::malloc(bytes ? bytes : 1);
  if (block && bytes >= exitance::formats::kHugePageAdvisedFrom) exitance::formats::advise_huge_pages(block, bytes);
  return block;
}

void* allocate_or_throw(std::size_t bytes) {
  // The standard's loop: on failure, the installed new-handler may free memory and try again.
  for (;;) {
    if (void* block = allocate(bytes)) return block;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate_or_throw(bytes); }
void* operator new[](std::size_t bytes) { return allocate_or_throw(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept { return allocate(bytes); }
void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept { return allocate(bytes); }
void operator delete(void* block) noexcept { std::free(block); }
void operator delete[](void* block) noexcept { std::free(block); }
void operator delete(void* block, std::size_t) noexcept { std::free(block); }
void operator delete[](void* block, std::size_t) noexcept { std::free(block); }
void operator delete(void* block, const std::nothrow_t&) noexcept { std::free(block); }
void operator delete[](void* block, const std::nothrow_t&) noexcept { std::free(block); }

#endif
