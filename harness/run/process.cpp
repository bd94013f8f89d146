#include "harness/run/process.hpp"

#include <fcntl.h>
#include <linux/landlock.h>
#ifndef LANDLOCK_ACCESS_FS_TRUNCATE  // Landlock ABI 3, newer than Debian 12's kernel headers
#define LANDLOCK_ACCESS_FS_TRUNCATE (1ULL << 14)
#endif
#include <poll.h>
#include <signal.h>
#include <limits.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <sstream>

#include <fmt/format.h>

#include "core/memory.hpp"

namespace growbench {

namespace {

// What exit_on_escaped_bad_alloc set: kept ready, as the handler must not allocate.
struct EscapedBadAlloc {
  int status = 0;
  std::string message, file;
} g_escaped_bad_alloc;

[[noreturn]] void terminate_handler() {
  bool bad_alloc = false;
  if (const std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      bad_alloc = true;
    } catch (...) {
    }
  }
  if (!bad_alloc) std::abort();
  const EscapedBadAlloc& h = g_escaped_bad_alloc;
  [[maybe_unused]] ssize_t n = write(STDERR_FILENO, h.message.data(), h.message.size());
  n = write(STDERR_FILENO, "\n", 1);
  if (!h.file.empty()) {
    const int fd = open(h.file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd >= 0) {
      n = write(fd, h.message.data(), h.message.size());
      close(fd);
    }
  }
  _exit(h.status);
}

}  // namespace

void exit_on_escaped_bad_alloc(int status, const std::string& message, const std::string& file) {
  g_escaped_bad_alloc = {status, message, file};
  std::set_terminate(terminate_handler);
}

int process_thread_count() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  return -1;
}

namespace {
ChildResult monitor_child(pid_t pid, std::chrono::steady_clock::time_point t0, int report_fd, const ChildLimits& limits,
                          const std::function<void(const std::string&)>& on_report, const std::string& log_path);

// In a job's child, before its body: output appended to log_path (when given), the address-space
// limit. Async-signal-safe calls only.
void enter_job(const std::string& log_path, const ChildLimits& limits) {
  if (!log_path.empty()) {
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
  }
  if (limits.address_space_bytes > 0 && kAddressSpaceLimitWorks) {
    rlimit rl{limits.address_space_bytes, limits.address_space_bytes};
    setrlimit(RLIMIT_AS, &rl);
  }
}
}  // namespace

ChildResult run_forked(const std::function<int()>& body, const ChildLimits& limits, const std::string& log_path) {
  return run_forked([&](int) { return body(); }, limits, log_path, nullptr);
}

ChildResult run_forked(const std::function<int(int report_fd)>& body, const ChildLimits& limits,
                       const std::string& log_path, const std::function<void(const std::string&)>& on_report) {
  int report[2] = {-1, -1};
  if (on_report && pipe2(report, O_CLOEXEC) != 0)
    throw std::runtime_error(fmt::format("cannot create a pipe: {}", std::strerror(errno)));
  std::fflush(stdout);  // or the child would write the parent's buffered output again
  std::fflush(stderr);
  const pid_t parent = getpid();
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    const int err = errno;
    if (report[0] >= 0) close(report[0]), close(report[1]);
    throw std::runtime_error(fmt::format("cannot fork: {}", std::strerror(err)));
  }
  if (pid == 0) {
    // Child: only async-signal-safe calls until body.
    if (limits.die_with_parent) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(71);  // the parent died before the line above
    }
    setpgid(0, 0);  // its own process group, so a timeout kills any helpers it starts too
    if (report[0] >= 0) close(report[0]);
    enter_job(log_path, limits);
    int code = 70;
    try {
      code = body(report[1]);
    } catch (...) {
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);  // no atexit handlers or static destructors of the parent's state
  }
  if (report[1] >= 0) close(report[1]);
  return monitor_child(pid, t0, report[0], limits, on_report, log_path);
}

namespace {

// A child's log (its stdout and stderr, appended to a file) is kept to kMaxLogBytes: past it, what follows
// is cut and a line says how much was dropped. A trial flooding its stderr wrote 4 GB in 6 s.
constexpr off_t kMaxLogBytes = 64 << 20;
constexpr int kLogCheckMs = 250;  // how often the parent looks at the log's size while the child runs
class LogCap {
 public:
  explicit LogCap(const std::string& path) : path_(path) {}
  bool active() const { return !path_.empty(); }
  // Cuts the log back to kMaxLogBytes when it has passed it (the child appends, so it writes on after the
  // note); async with the child, so at most a check's worth of output lands past the note.
  void check() {
    struct stat st {};
    if (path_.empty() || stat(path_.c_str(), &st) != 0 || st.st_size <= kMaxLogBytes + kNoteRoom) return;
    dropped_ += st.st_size - kMaxLogBytes;
    if (truncate(path_.c_str(), kMaxLogBytes) != 0) return;
    const int fd = open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd < 0) return;
    char note[160];
    const int n = std::snprintf(note, sizeof note,
                                "\n[growbench: the log passed %lld bytes; %lld bytes after this point were dropped]\n",
                                static_cast<long long>(kMaxLogBytes), static_cast<long long>(dropped_));
    [[maybe_unused]] const ssize_t w = write(fd, note, static_cast<std::size_t>(std::max(n, 0)));
    close(fd);
  }

 private:
  static constexpr off_t kNoteRoom = 4096;
  std::string path_;
  off_t dropped_ = 0;
};

// The parent's half: waits for the child `pid` (started at t0, its report pipe's read end `report_fd`,
// or -1), enforcing the timeout and the log's cap, and reaps it.
ChildResult monitor_child(pid_t pid, std::chrono::steady_clock::time_point t0, int report_fd, const ChildLimits& limits,
                          const std::function<void(const std::string&)>& on_report, const std::string& log_path) {
  LogCap log(log_path);
  bool reported = false;
  // The report: one write of at most PIPE_BUF bytes arrives whole; EOF means there was none.
  auto read_report = [&] {
    char buf[PIPE_BUF];
    ssize_t n;
    do {
      n = read(report_fd, buf, sizeof buf);
    } while (n < 0 && errno == EINTR);
    if (n > 0 && !reported) {
      reported = true;
      on_report(std::string(buf, static_cast<std::size_t>(n)));
    }
    if (n <= 0) {
      close(report_fd);
      report_fd = -1;
    }
  };
  ChildResult r;
  r.spawn_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t0.time_since_epoch()).count();
  const int pidfd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
  int status = 0;
  rusage ru{};
  bool reaped = false, ended = false;
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  auto kill_child = [&] {
    r.timed_out = true;
    kill(-pid, SIGKILL);
    kill(pid, SIGKILL);
  };
  if (pidfd >= 0) {
    // Sleep until the child reports or exits, or the timeout passes: no polling delay added to a trial.
    while (true) {
      pollfd pfd[2] = {{pidfd, POLLIN, 0}, {report_fd, POLLIN, 0}};
      int timeout_ms = -1;
      if (limits.timeout_s > 0) timeout_ms = std::max(0, static_cast<int>((limits.timeout_s - elapsed()) * 1000.0) + 1);
      const bool log_due = log.active() && (timeout_ms < 0 || timeout_ms > kLogCheckMs);
      const int rc = poll(pfd, report_fd >= 0 ? 2 : 1, log_due ? kLogCheckMs : timeout_ms);
      if (rc < 0 && errno == EINTR) continue;
      if (rc < 0) break;  // cannot wait on it: the blocking wait4 below still reaps it
      log.check();
      if (rc == 0 && log_due) continue;
      if (rc == 0) {
        kill_child();
        break;
      }
      if (report_fd >= 0 && (pfd[1].revents & (POLLIN | POLLHUP)) != 0) read_report();
      if ((pfd[0].revents & POLLIN) != 0) {
        ended = true;
        break;
      }
    }
    close(pidfd);
    // The child has ended but is not reaped, so its pid (its group's id) cannot have been reused: whatever
    // it started in its group (a plugin's helpers, a shell's children) ends with it.
    if (ended) kill(-pid, SIGKILL);
  } else {
    // No pidfd (old kernel): poll wait4 every millisecond.
    while (true) {
      const pid_t w = wait4(pid, &status, WNOHANG, &ru);
      if (w == pid) {
        reaped = true;
        break;
      }
      if (limits.timeout_s > 0 && elapsed() > limits.timeout_s) {
        kill_child();
        break;
      }
      usleep(1000);
    }
  }
  if (!reaped) {
    while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
    }
  }
  r.wall_s = elapsed();
  log.check();
  // A report written just before the exit may still be in the pipe.
  if (report_fd >= 0 && !reported) {
    fcntl(report_fd, F_SETFL, O_NONBLOCK);
    read_report();
  }
  if (report_fd >= 0) close(report_fd);
  r.user_s = static_cast<double>(ru.ru_utime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_utime.tv_usec);
  r.system_s = static_cast<double>(ru.ru_stime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_stime.tv_usec);
  r.max_rss_bytes = static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
}

}  // namespace

static_assert(std::is_trivially_copyable_v<ChildResult> && std::is_trivially_copyable_v<ChildLimits>,
              "sent through a pipe as bytes");

namespace {

// The launcher's replies: a header, then `size` bytes.
enum class Reply : std::uint32_t { report = 1, result = 2, error = 3 };
struct ReplyHeader {
  Reply kind;
  std::uint32_t size;
};

bool write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

bool read_all(int fd, void* data, std::size_t n) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t r = read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

// A job request, on the owner's pipe to the launcher and on the launcher's pipe to a job's child: the
// description's length, the description, the limits.
bool write_request(int fd, const std::string& description, const ChildLimits& limits) {
  const auto size = static_cast<std::uint32_t>(description.size());
  return write_all(fd, &size, sizeof size) && write_all(fd, description.data(), size) &&
         write_all(fd, &limits, sizeof limits);
}
bool read_request(int fd, std::string& description, ChildLimits& limits) {
  std::uint32_t size = 0;
  if (!read_all(fd, &size, sizeof size)) return false;
  description.resize(size);
  return read_all(fd, description.data(), size) && read_all(fd, &limits, sizeof limits);
}

bool send_reply(int fd, Reply kind, const void* data, std::size_t n) {
  const ReplyHeader h{kind, static_cast<std::uint32_t>(n)};
  return write_all(fd, &h, sizeof h) && write_all(fd, data, n);
}

}  // namespace

namespace {

// A job's child forked in advance: it waits on `job_fd` for its description and limits.
struct Spare {
  pid_t pid = -1;
  int job_fd = -1;     // write end: the job goes here
  int report_fd = -1;  // read end of its report pipe
};

// While it waits, a job's child takes the page faults its job would otherwise take first (each one costly
// on a paravirtualised VM): the top of its stack, and copies of the launcher's heap pages that
// malloc writes (the arena's free lists and the chunks it hands out first).
__attribute__((noinline)) void warm_up() {
  volatile char stack[256 * 1024];
  for (std::size_t i = 0; i < sizeof stack; i += 4096) stack[i] = 0;
  std::vector<void*> blocks;
  for (const std::size_t n : {64u, 256u, 1024u, 4096u, 16384u})
    for (int k = 0; k < 16; ++k) {
      void* b = std::malloc(n);
      if (b) std::memset(b, 0, n);
      blocks.push_back(b);
    }
  for (void* b : blocks) std::free(b);
}

// In the launcher: forks a child that waits for a job, then prepares it and runs it as run_forked's
// children do (its own process group, its log, its address-space limit). It keeps only its two pipe
// ends: everything else the launcher has open (the suite's pipes, a running trial's report pipe) is
// closed, so no pipe's end lingers in a bystander.
Spare fork_spare(const Launcher::Prepare& prepare) {
  int job[2], rep[2];
  if (pipe2(job, O_CLOEXEC) != 0) return {};
  if (pipe2(rep, O_CLOEXEC) != 0) {
    close(job[0]), close(job[1]);
    return {};
  }
  std::fflush(stdout);  // or the child would write the launcher's buffered output again
  std::fflush(stderr);
  const pid_t launcher = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    for (int fd : {job[0], job[1], rep[0], rep[1]}) close(fd);
    return {};
  }
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != launcher) _exit(71);
    signal(SIGPIPE, SIG_DFL);  // the launcher ignores it; a job runs as any process would
    // Its two ends become fds 3 and 4, and every other descriptor above 2 is closed.
    const int in = fcntl(job[0], F_DUPFD_CLOEXEC, 10), out = fcntl(rep[1], F_DUPFD_CLOEXEC, 10);
    if (in < 0 || out < 0 || dup3(in, 3, O_CLOEXEC) < 0 || dup3(out, 4, O_CLOEXEC) < 0) _exit(71);
    close_range(5, ~0U, 0);
    warm_up();
    std::string description;
    ChildLimits limits;
    if (!read_request(3, description, limits)) _exit(0);  // the launcher is closing: no job
    close(3);
    setpgid(0, 0);
    int code = 70;
    try {
      const Launcher::Job job_spec = prepare(description);
      enter_job(job_spec.log_path, limits);
      code = job_spec.body(4);
    } catch (...) {
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);
  }
  close(job[0]);
  close(rep[1]);
  return {pid, job[1], rep[0]};
}

// In the launcher, the subreaper of its jobs: what a job's processes started outside the job's process
// group (a daemon that called setsid) came to the launcher when its parent ended, and is ended here once
// the job has been reaped. A process ended in one round may leave children of its own: they come next.
void end_orphans(pid_t spare) {
  const std::string list = fmt::format("/proc/self/task/{}/children", getpid());
  for (int round = 0; round < 64; ++round) {
    std::vector<pid_t> orphans;
    if (FILE* f = std::fopen(list.c_str(), "re")) {
      for (long p = 0; std::fscanf(f, "%ld", &p) == 1;)
        if (p != spare) orphans.push_back(static_cast<pid_t>(p));
      std::fclose(f);
    }
    if (orphans.empty()) break;
    for (pid_t p : orphans) kill(p, SIGKILL);
    for (pid_t p : orphans)
      while (waitpid(p, nullptr, 0) < 0 && errno == EINTR) {
      }
  }
  // Orphans that ended on their own, or that the list could not show (no /proc), are zombies until reaped.
  siginfo_t si{};
  while (waitid(P_ALL, 0, &si, WEXITED | WNOHANG | WNOWAIT) == 0 && si.si_pid != 0 && si.si_pid != spare) {
    waitpid(si.si_pid, nullptr, 0);
    si = {};
  }
}

}  // namespace

Launcher::Launcher(Prepare prepare) {
  int req[2], rep[2];
  if (pipe2(req, O_CLOEXEC) != 0)
    throw std::runtime_error(fmt::format("cannot create a pipe: {}", std::strerror(errno)));
  if (pipe2(rep, O_CLOEXEC) != 0) {
    close(req[0]), close(req[1]);
    throw std::runtime_error(fmt::format("cannot create a pipe: {}", std::strerror(errno)));
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t owner = getpid();
  pid_ = fork();
  if (pid_ < 0) {
    const int err = errno;
    for (int fd : {req[0], req[1], rep[0], rep[1]}) close(fd);
    throw std::runtime_error(fmt::format("cannot fork the trial launcher: {}", std::strerror(err)));
  }
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // the launcher never outlives its owner
    if (getppid() != owner) _exit(0);
    prctl(PR_SET_CHILD_SUBREAPER, 1);  // see end_orphans
    // A write to a child that died waiting for its job (or to an owner that died) fails with EPIPE
    // instead of ending the launcher.
    signal(SIGPIPE, SIG_IGN);
    close(req[1]);
    close(rep[0]);
    const int in = req[0], out = rep[1];
    // The next job's child is forked ahead, while the launcher waits: at first, and then as soon as the
    // running job's child has reported (its work is done; the kernel then spends milliseconds freeing
    // its memory, and the suite reads its record). The fork is off the launch's critical path and
    // overlaps nothing that is measured. Without a spare (a job that never reported) it forks on demand.
    Spare spare = fork_spare(prepare);
    std::string description;
    ChildLimits limits;
    while (read_request(in, description, limits)) {
      try {
        // A bad description is an error reply; the child prepares its own.
        const std::string log_path = prepare(description).log_path;
        limits.die_with_parent = true;  // the launcher is single-threaded
        auto t0 = std::chrono::steady_clock::now();
        auto hand_over = [&](const Spare& c) {
          const bool ok = c.pid > 0 && write_request(c.job_fd, description, limits);
          if (c.job_fd >= 0) close(c.job_fd);
          return ok;
        };
        auto discard = [](const Spare& c) {
          if (c.pid <= 0) return;
          close(c.report_fd);
          kill(c.pid, SIGKILL);
          while (waitpid(c.pid, nullptr, 0) < 0 && errno == EINTR) {
          }
        };
        Spare job = spare;
        spare = {};
        if (!hand_over(job)) {  // none waiting, or it died waiting (killed from outside): a fresh one
          discard(job);
          t0 = std::chrono::steady_clock::now();
          job = fork_spare(prepare);
          if (!hand_over(job)) {
            const int err = errno;
            discard(job);
            throw std::runtime_error(fmt::format("cannot start a trial process: {}", std::strerror(err)));
          }
        }
        const ChildResult cr = monitor_child(
            job.pid, t0, job.report_fd, limits,
            [&](const std::string& report) {
              send_reply(out, Reply::report, report.data(), report.size());
              if (spare.pid < 0) spare = fork_spare(prepare);
            },
            log_path);
        end_orphans(spare.pid);
        if (!send_reply(out, Reply::result, &cr, sizeof cr)) break;
      } catch (const std::exception& e) {
        const std::string what = e.what();
        if (!send_reply(out, Reply::error, what.data(), what.size())) break;
      }
    }
    if (spare.pid > 0) {  // its job pipe closes: it exits
      close(spare.job_fd);
      close(spare.report_fd);
      while (waitpid(spare.pid, nullptr, 0) < 0 && errno == EINTR) {
      }
    }
    _exit(0);
  }
  close(req[0]);
  close(rep[1]);
  request_fd_ = req[1];
  reply_fd_ = rep[0];
}

Launcher::~Launcher() {
  if (request_fd_ >= 0) close(request_fd_);
  if (reply_fd_ >= 0) close(reply_fd_);
  if (pid_ > 0) {
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

ChildResult Launcher::run(const std::string& description, const ChildLimits& limits,
                          const std::function<void(const std::string&)>& on_report) {
  // Writing to a launcher that has died raises SIGPIPE, which would end this process (and the suite
  // with it): it is blocked for the write, and one it raised is taken back before unblocking.
  sigset_t pipe_signal, before;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &before);
  const bool sent = write_request(request_fd_, description, limits);
  if (!sent) {
    const timespec now{0, 0};
    sigtimedwait(&pipe_signal, nullptr, &now);
  }
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
  if (!sent) throw std::runtime_error(fmt::format("the trial launcher (pid {}) has died", pid_));
  while (true) {
    ReplyHeader h{};
    std::string data;
    if (read_all(reply_fd_, &h, sizeof h)) {
      data.resize(h.size);
      if (read_all(reply_fd_, data.data(), data.size())) {
        if (h.kind == Reply::report) {
          if (on_report) on_report(data);
          continue;
        }
        if (h.kind == Reply::error) throw std::runtime_error(data);
        if (h.kind == Reply::result && data.size() == sizeof(ChildResult)) {
          ChildResult r;
          std::memcpy(&r, data.data(), sizeof r);
          return r;
        }
      }
    }
    throw std::runtime_error(fmt::format("the trial launcher (pid {}) has died", pid_));
  }
}

std::string signal_name(int sig) {
  const char* d = strsignal(sig);
  return fmt::format("signal {} ({})", sig, d ? d : "?");
}

std::string find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(ss, dir, ':');) {
    const std::filesystem::path p = std::filesystem::path(dir.empty() ? "." : dir) / name;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

namespace {

// Landlock's write rights for files and directories that this kernel knows (its ABI version `abi`):
// creating, changing, removing, renaming and linking anything.
std::uint64_t landlock_write_rights(long abi) {
  std::uint64_t rights = LANDLOCK_ACCESS_FS_WRITE_FILE | LANDLOCK_ACCESS_FS_REMOVE_DIR |
                         LANDLOCK_ACCESS_FS_REMOVE_FILE | LANDLOCK_ACCESS_FS_MAKE_CHAR | LANDLOCK_ACCESS_FS_MAKE_DIR |
                         LANDLOCK_ACCESS_FS_MAKE_REG | LANDLOCK_ACCESS_FS_MAKE_SOCK | LANDLOCK_ACCESS_FS_MAKE_FIFO |
                         LANDLOCK_ACCESS_FS_MAKE_BLOCK | LANDLOCK_ACCESS_FS_MAKE_SYM;
  if (abi >= 2) rights |= LANDLOCK_ACCESS_FS_REFER;
  if (abi >= 3) rights |= LANDLOCK_ACCESS_FS_TRUNCATE;
  return rights;
}

// In the child, before exec (raw system calls only): lets it and what it runs write nowhere but under
// `dir`. Returns false when the kernel cannot (no Landlock) or `dir` cannot be opened.
bool confine_writes(const char* dir, long abi) {
  landlock_ruleset_attr attr{};
  attr.handled_access_fs = landlock_write_rights(abi);
  const int ruleset = static_cast<int>(syscall(SYS_landlock_create_ruleset, &attr, sizeof attr, 0));
  if (ruleset < 0) return false;
  landlock_path_beneath_attr beneath{};
  beneath.allowed_access = attr.handled_access_fs;
  beneath.parent_fd = open(dir, O_PATH | O_CLOEXEC | O_DIRECTORY);
  const bool ok = beneath.parent_fd >= 0 &&
                  syscall(SYS_landlock_add_rule, ruleset, LANDLOCK_RULE_PATH_BENEATH, &beneath, 0) == 0 &&
                  prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) == 0 && syscall(SYS_landlock_restrict_self, ruleset, 0) == 0;
  if (beneath.parent_fd >= 0) close(beneath.parent_fd);
  close(ruleset);
  return ok;
}

}  // namespace

long landlock_abi() {
  static const long abi = [] {
    const long v = syscall(SYS_landlock_create_ruleset, nullptr, 0, LANDLOCK_CREATE_RULESET_VERSION);
    return v < 0 ? 0L : v;
  }();
  return abi;
}

ChildResult run_program(const std::vector<std::string>& args, const std::string& cwd, const ChildLimits& limits,
                        const std::string& log_path, const std::string& write_only_under) {
  std::vector<std::string> copy = args;  // argv is built before the fork: no allocation in the child
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const long abi = write_only_under.empty() ? 0 : landlock_abi();
  return run_forked(
      [&]() -> int {
        if (!cwd.empty() && chdir(cwd.c_str()) != 0) return 126;
        if (abi > 0 && !confine_writes(write_only_under.c_str(), abi)) return 126;
        execv(argv[0], argv.data());
        return 127;
      },
      limits, log_path);
}

}  // namespace growbench
