// Running one trial in a child process: its own address space (so its peak memory is its own), an
// address-space limit, and a wall-clock timeout enforced by the parent.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace growbench {

struct ChildLimits {
  double timeout_s = 0.0;                 // 0: none
  std::uint64_t address_space_bytes = 0;  // 0: none (RLIMIT_AS)
};

struct ChildResult {
  int exit_code = -1;       // when it exited
  int signal = 0;           // when a signal ended it
  bool timed_out = false;   // killed by the parent after timeout_s
  double wall_s = 0.0;      // from spawn to reaping
  double user_s = 0.0, system_s = 0.0;
  std::uint64_t max_rss_bytes = 0;  // wait4's ru_maxrss
};

// Runs `body` in a forked child (stdout and stderr appended to `log_path` when given) and waits for it.
// The child exits with body's return value (an escaping exception exits 70). Forking rather than
// exec'ing keeps the launch cost near a millisecond: exec'ing growbench spends ~80 ms in the dynamic
// linker relocating OpenVDB, TBB and Embree. The caller must not have started threads (TBB, Embree)
// before forking: only the calling thread exists in the child.
// Throws std::runtime_error when the process cannot be started.
// Threads in this process (from /proc/self/status).
int process_thread_count();

ChildResult run_forked(const std::function<int()>& body, const ChildLimits& limits, const std::string& log_path);

// The executable NAME on PATH ("" when there is none).
std::string find_program(const std::string& name);

// Runs the program args[0] (a path) with `args`, in directory `cwd` ("" : this one), its output appended
// to `log_path` (exit status 127: it could not be started). Only async-signal-safe calls run between
// fork and exec, so this is safe from a process with threads, and from several threads at once.
ChildResult run_program(const std::vector<std::string>& args, const std::string& cwd, const ChildLimits& limits,
                        const std::string& log_path);

}  // namespace growbench
