#pragma once
// Whether this test binary (and so the daemon built beside it) runs under
// AddressSanitizer or ThreadSanitizer. Their allocators (shadow memory,
// redzones, a quarantine of freed blocks) take far more than a program asks
// for, so a resident-memory measurement means nothing under one.

namespace boicp {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kSanitizedBuild = true;
#else
constexpr bool kSanitizedBuild = false;
#endif
#else
constexpr bool kSanitizedBuild = false;
#endif

}  // namespace boicp
