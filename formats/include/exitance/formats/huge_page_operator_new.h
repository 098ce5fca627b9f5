// Whether formats/src/huge_page_operator_new.cpp replaces the global operator new in the programs
// that link it (`bake`, `exitance-relight`): not under a sanitizer, whose own operator new stays
// so that its new/delete checks keep working. GCC says it by __SANITIZE_ADDRESS__, clang (14) only
// by __has_feature.
#pragma once
#include <cstddef>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define EXITANCE_SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define EXITANCE_SANITIZER_ALLOCATOR 1
#endif
#endif

namespace exitance::formats {

#if defined(EXITANCE_SANITIZER_ALLOCATOR)
inline constexpr bool kHugePageOperatorNew = false;
#else
inline constexpr bool kHugePageOperatorNew = true;
#endif
// Allocations of at least this many bytes are advised into huge pages.
inline constexpr std::size_t kHugePageAdvisedFrom = std::size_t(4) << 20;

}  // namespace exitance::formats
