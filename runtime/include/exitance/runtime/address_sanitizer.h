// EXITANCE_ADDRESS_SANITIZER: defined in AddressSanitizer builds, by GCC and clang alike (GCC defines
// __SANITIZE_ADDRESS__ under -fsanitize=address; clang 14 only answers __has_feature).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define EXITANCE_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define EXITANCE_ADDRESS_SANITIZER 1
#endif
#endif
