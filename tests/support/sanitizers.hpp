#pragma once
// ISOFLEX_TEST_ASAN is defined in builds with AddressSanitizer (GCC defines __SANITIZE_ADDRESS__,
// clang has __has_feature(address_sanitizer)): tests that limit the address space skip there.
#if defined(__SANITIZE_ADDRESS__)
#define ISOFLEX_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ISOFLEX_TEST_ASAN 1
#endif
#endif
