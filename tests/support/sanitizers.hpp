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

// Long physics runs (hundreds of steps of a Kirchhoff–Love patch, 10⁴ steps of a beam) take
// 30–80× their Release time in the ASan + UBSan build at -O1, which would put the sanitizer suite
// far beyond its 40 minutes. What they state about the physics is checked by the Release suite
// (ctest --preset release); under the sanitizers the same code runs in the short tests (element
// contracts, a few steps of every integrator with every element kind).
#if defined(ISOFLEX_TEST_ASAN)
#define ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN() \
  GTEST_SKIP() << "a long physics run: checked by the Release suite, not under ASan"
#else
#define ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN() static_cast<void>(0)
#endif
