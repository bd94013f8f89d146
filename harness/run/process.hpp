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
  // SIGKILL the child when the forking thread dies: a suite or render killed in any way (kill -9 too)
  // takes its trials and POV-Ray processes with it, so that none writes into a folder a resumed run owns.
  // The signal follows the thread, not the process; run_forked's thread waits for its child, so it
  // outlives it.
  bool die_with_parent = true;
};

struct ChildResult {
  int exit_code = -1;      // when it exited
  int signal = 0;          // when a signal ended it
  bool timed_out = false;  // killed by the parent after timeout_s
  double wall_s = 0.0;     // from spawn to reaping
  // Steady-clock nanoseconds just before the child was started: its fork, or (a Launcher's job) the
  // hand-over of the job to a child forked ahead.
  std::int64_t spawn_ns = 0;
  double user_s = 0.0, system_s = 0.0;
  std::uint64_t max_rss_bytes = 0;  // wait4's ru_maxrss
};

// Threads in this process (from /proc/self/status).
int process_thread_count();

// A std::bad_alloc that escapes where nothing can catch it (a noexcept function in a library, a library's
// own thread) makes std::terminate abort the process: a crash that is really the memory limit. After this
// call such a terminate writes `message` and a newline to stderr, and to `file` when it is not empty, and
// exits with `status` instead; any other terminate still aborts.
void exit_on_escaped_bad_alloc(int status, const std::string& message, const std::string& file = "");

// Runs `body` in a forked child (stdout and stderr appended to `log_path` when given) and waits for it.
// The child exits with body's return value (an escaping exception exits 70). Forking rather than exec'ing
// keeps the launch to the fork and the child's first page faults and syscalls: exec'ing growbench would
// spend far longer in the dynamic linker relocating OpenVDB, TBB and Embree. The caller must not have
// started threads (TBB, Embree) before forking: only the calling thread exists in the child. Throws
// std::runtime_error when the process cannot be started.
ChildResult run_forked(const std::function<int()>& body, const ChildLimits& limits, const std::string& log_path);

// The same, with a report channel: body gets the write end of a pipe, and may write one report of at most
// PIPE_BUF bytes with a single write() before it finishes. on_report gets it as soon as it arrives, while
// the child may still be exiting (the kernel freeing a large trial's memory takes milliseconds), so the
// caller can read the child's results in parallel with that teardown.
ChildResult run_forked(const std::function<int(int report_fd)>& body, const ChildLimits& limits,
                       const std::string& log_path, const std::function<void(const std::string&)>& on_report);

// A small process, forked before its owner builds up state, that forks each job's child on request.
// A child forked straight from a long-running suite process inherits all of that process's heap (the
// results of every trial so far): the inherited pages count in the child's peak RSS, which then grows
// over a suite, and each one the child writes costs a copy-on-write fault, slow on a paravirtualised
// VM. The launcher's heap stays as small and unfragmented as it was when it was forked.
class Launcher {
 public:
  struct Job {
    std::function<int(int report_fd)> body;  // runs in the job's child
    std::string log_path;                    // its stdout and stderr ("" : inherited)
  };
  // Turns a job description (sent by run) into the job. The launcher calls it to check the description
  // (an exception is run's error), and the job's child calls it again to run the job: the child is
  // forked before its job is known (see the constructor).
  using Prepare = std::function<Job(const std::string& description)>;
  // Forks the launcher. The caller must be single-threaded (see run_forked). The launcher keeps one
  // job's child forked ahead, waiting for its job: at first, and again as soon as the running job's
  // child reports (while the kernel frees that child's memory and the owner reads its results), so a
  // job's launch is a pipe write, not a fork.
  explicit Launcher(Prepare prepare);
  ~Launcher();  // the launcher exits when its request pipe closes, and is reaped here
  Launcher(const Launcher&) = delete;
  Launcher& operator=(const Launcher&) = delete;
  // Runs one job to its end under `limits`. on_report receives the child's report (see run_forked)
  // before the child has exited. Throws std::runtime_error when the launcher cannot prepare the job or
  // fork, or has died.
  ChildResult run(const std::string& description, const ChildLimits& limits,
                  const std::function<void(const std::string&)>& on_report);

 private:
  int pid_ = -1;
  int request_fd_ = -1, reply_fd_ = -1;
};

// "signal 11 (Segmentation fault)": what ended a child.
std::string signal_name(int sig);

// The executable NAME on PATH ("" when there is none).
std::string find_program(const std::string& name);

// Runs the program args[0] (a path) with `args`, in directory `cwd` ("" : this one), its output appended
// to `log_path` (exit status 127: it could not be started). With `write_only_under`, the program can
// create, change or remove files only under that folder (Landlock; where the kernel has none, it runs
// unconfined: landlock_abi() says which; exit status 126: the confinement failed). Only
// async-signal-safe calls run between fork and exec, so this is safe from a process with threads, and
// from several threads at once.
ChildResult run_program(const std::vector<std::string>& args, const std::string& cwd, const ChildLimits& limits,
                        const std::string& log_path, const std::string& write_only_under = "");

// The kernel's Landlock ABI version, 0 when it has none (then run_program cannot confine writes).
long landlock_abi();

}  // namespace growbench
