// How much more memory this process may take, for work that can estimate its size before it starts
// (the distance field) and refuse with a clear message rather than fail inside a library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace growbench {

// Whether this build is instrumented by AddressSanitizer (GCC defines the macro, clang has the feature).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif
// AddressSanitizer reserves terabytes of shadow address space at start-up, so under it an address-space
// limit (RLIMIT_AS) kills the process before it runs: sanitizer builds run trials without one.
inline constexpr bool kAddressSpaceLimitWorks = !kAddressSanitizer;

// The least of what is known: the address-space limit (ulimit -v) less the address space the process
// has mapped, the cgroup's memory.max less its memory.current, and the kernel's MemAvailable. nullopt
// when none of them is known.
std::optional<std::uint64_t> memory_headroom();

// "1.5 GiB", "300 MiB": a byte count for messages.
std::string format_bytes(double bytes);

}  // namespace growbench
