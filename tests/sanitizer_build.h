// Whether the tests run in the sanitizer build (PT_SANITIZE: AddressSanitizer and
// UndefinedBehaviorSanitizer at -O1, docs/errors.md), where everything runs several times
// slower and some tests take fewer samples or rays. PT_TEST_SANITIZED for the preprocessor,
// kSanitizerBuild for code. GCC defines __SANITIZE_ADDRESS__; clang answers __has_feature.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define PT_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PT_TEST_SANITIZED 1
#endif
#endif
#ifndef PT_TEST_SANITIZED
#define PT_TEST_SANITIZED 0
#endif

namespace pt::test {
inline constexpr bool kSanitizerBuild = PT_TEST_SANITIZED != 0;
}  // namespace pt::test
