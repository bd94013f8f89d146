// How much more memory this process may take, for work that can estimate its size before it starts
// (the distance field) and refuse with a clear message rather than fail inside a library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace growbench {

// The least of what is known: the address-space limit (ulimit -v) less the address space the process
// has mapped, the cgroup's memory.max less its memory.current, and the kernel's MemAvailable. nullopt
// when none of them is known.
std::optional<std::uint64_t> memory_headroom();

// "1.5 GiB", "300 MiB": a byte count for messages.
std::string format_bytes(double bytes);

}  // namespace growbench
