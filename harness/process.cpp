#include "harness/process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <stdexcept>

#include <sstream>

#include <fmt/format.h>

namespace growbench {

int process_thread_count() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  return -1;
}

ChildResult run_forked(const std::function<int()>& body, const ChildLimits& limits, const std::string& log_path) {
  std::fflush(stdout);  // or the child would write the parent's buffered output again
  std::fflush(stderr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(fmt::format("cannot fork: {}", std::strerror(errno)));
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    setpgid(0, 0);  // its own process group, so a timeout kills any helpers it starts too
    if (!log_path.empty()) {
      const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fd >= 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
      }
    }
    if (limits.address_space_bytes > 0) {
      rlimit rl{limits.address_space_bytes, limits.address_space_bytes};
      setrlimit(RLIMIT_AS, &rl);
    }
    int code = 70;
    try {
      code = body();
    } catch (...) {
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);  // no atexit handlers or static destructors of the parent's state
  }
  ChildResult r;
  const int pidfd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
  int status = 0;
  rusage ru{};
  bool reaped = false;
  if (pidfd >= 0) {
    // Sleep until the child exits or the timeout passes: no polling delay added to every trial.
    pollfd pfd{pidfd, POLLIN, 0};
    const int timeout_ms = limits.timeout_s > 0 ? static_cast<int>(limits.timeout_s * 1000.0) : -1;
    int rc;
    do {
      rc = poll(&pfd, 1, timeout_ms);
    } while (rc < 0 && errno == EINTR);
    close(pidfd);
    if (rc == 0) {
      r.timed_out = true;
      kill(-pid, SIGKILL);
      kill(pid, SIGKILL);
    }
  } else {
    // No pidfd (old kernel): poll wait4 every millisecond.
    while (true) {
      const pid_t w = wait4(pid, &status, WNOHANG, &ru);
      if (w == pid) {
        reaped = true;
        break;
      }
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (limits.timeout_s > 0 && el > limits.timeout_s) {
        r.timed_out = true;
        kill(-pid, SIGKILL);
        kill(pid, SIGKILL);
        break;
      }
      usleep(1000);
    }
  }
  if (!reaped) {
    while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
    }
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.user_s = static_cast<double>(ru.ru_utime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_utime.tv_usec);
  r.system_s = static_cast<double>(ru.ru_stime.tv_sec) + 1e-6 * static_cast<double>(ru.ru_stime.tv_usec);
  r.max_rss_bytes = static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
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

ChildResult run_program(const std::vector<std::string>& args, const std::string& cwd, const ChildLimits& limits,
                        const std::string& log_path) {
  std::vector<std::string> copy = args;  // argv is built before the fork: no allocation in the child
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  return run_forked(
      [&]() -> int {
        if (!cwd.empty() && chdir(cwd.c_str()) != 0) return 126;
        execv(argv[0], argv.data());
        return 127;
      },
      limits, log_path);
}

}  // namespace growbench
