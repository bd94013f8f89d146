// How much more memory this process may take, for work that can estimate its size before it starts
// (the distance field) and refuse with a clear message rather than fail inside a library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace growbench {

// AddressSanitizer reserves terabytes of shadow address space at start-up, so under it an address-space
// limit (RLIMIT_AS) kills the process before it runs: sanitizer builds run trials without one.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSpaceLimitWorks = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSpaceLimitWorks = false;
#else
inline constexpr bool kAddressSpaceLimitWorks = true;
#endif
#else
inline constexpr bool kAddressSpaceLimitWorks = true;
#endif

// The least of what is known: the address-space limit (ulimit -v) less the address space the process
// has mapped, the cgroup's memory.max less its memory.current, and the kernel's MemAvailable. nullopt
// when none of them is known.
std::optional<std::uint64_t> memory_headroom();

// "1.5 GiB", "300 MiB": a byte count for messages.
std::string format_bytes(double bytes);

}  // namespace growbench
