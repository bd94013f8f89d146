// Child processes: the report channel that lets the parent read a trial's results while the kernel is
// still tearing it down, and the launcher whose children inherit its small heap instead of their owner's.
#include "harness/run/process.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <csignal>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace growbench {
namespace {

using Clock = std::chrono::steady_clock;

// Touches `bytes` of fresh memory, so it is resident.
std::vector<char> resident(std::size_t bytes) {
  std::vector<char> v(bytes);
  for (std::size_t i = 0; i < v.size(); i += 4096) v[i] = static_cast<char>(i);
  return v;
}

constexpr std::uint64_t kMiB = 1024ull * 1024ull;

TEST(Process, ReportArrivesBeforeTheChildHasExited) {
  Clock::time_point reported{};
  std::string got;
  const auto t0 = Clock::now();
  const ChildResult r = run_forked(
      [](int fd) {
        const char msg[] = "123 456";
        if (write(fd, msg, sizeof msg - 1) != sizeof msg - 1) return 9;
        usleep(300 * 1000);  // still running: the report must not wait for this
        return 5;
      },
      {}, "",
      [&](const std::string& report) {
        got = report;
        reported = Clock::now();
      });
  const auto done = Clock::now();
  EXPECT_EQ(r.exit_code, 5);
  EXPECT_EQ(got, "123 456");
  EXPECT_LT(std::chrono::duration<double>(reported - t0).count(), 0.25) << "the report waited for the exit";
  EXPECT_GE(std::chrono::duration<double>(done - t0).count(), 0.3);
  EXPECT_GT(r.spawn_ns, 0);
}

// A std::bad_alloc that nothing can catch (thrown on a library's own thread, or through noexcept code) is the
// memory limit, not a crash: with exit_on_escaped_bad_alloc the process says so and exits with the status
// given, where std::terminate would abort it.
TEST(Process, ABadAllocThatEscapesIsOutOfMemoryNotAnAbort) {
  const std::string file = ::testing::TempDir() + "escaped_bad_alloc.txt";
  std::remove(file.c_str());
  auto escape = [] { std::thread([] { throw std::bad_alloc(); }).join(); };
  ChildResult r = run_forked(
      [&] {
        escape();
        return 0;
      },
      {}, "/dev/null");
  EXPECT_EQ(r.signal, SIGABRT);  // what happens without it
  r = run_forked(
      [&] {
        exit_on_escaped_bad_alloc(3, "out of memory (test)", file);
        escape();
        return 0;
      },
      {}, "/dev/null");
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exit_code, 3);
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "out of memory (test)");
  // Any other exception escaping still aborts: it is a bug, not the memory limit.
  r = run_forked(
      [&] {
        exit_on_escaped_bad_alloc(3, "out of memory (test)");
        std::thread([] { throw std::runtime_error("a bug"); }).join();
        return 0;
      },
      {}, "/dev/null");
  EXPECT_EQ(r.signal, SIGABRT);
}

TEST(Process, NoReportIsFine) {
  bool called = false;
  const ChildResult r = run_forked([](int) { return 0; }, {}, "", [&](const std::string&) { called = true; });
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_FALSE(called);
}

TEST(Process, LauncherChildrenInheritTheLauncherNotTheOwner) {
  // The launcher is forked while this process is small; then this process grows by 192 MiB (as a suite
  // process grows with its results). A child forked straight from here carries those pages in its
  // peak RSS; a child of the launcher does not.
  Launcher launcher([](const std::string& what) {
    return Launcher::Job{[what](int) { return what == "ok" ? 0 : 3; }, ""};
  });
  const std::vector<char> big = resident(192 * kMiB);
  const ChildResult direct = run_forked([] { return 0; }, {}, "");
  const ChildResult via = launcher.run("ok", {}, nullptr);
  EXPECT_EQ(direct.exit_code, 0);
  EXPECT_EQ(via.exit_code, 0);
  EXPECT_GE(direct.max_rss_bytes, 192 * kMiB) << "control: a direct child should carry its parent's heap";
  EXPECT_LT(via.max_rss_bytes, 96 * kMiB) << "the launcher's child carried its owner's heap";
  EXPECT_EQ(launcher.run("other", {}, nullptr).exit_code, 3);
  EXPECT_NE(big[4096], 1);  // keep `big` alive (and touched) until here
}

TEST(Process, LauncherRelaysReportsCrashesTimeoutsAndErrors) {
  Launcher launcher([](const std::string& what) -> Launcher::Job {
    if (what == "bad") throw std::runtime_error("no such job: bad");
    return Launcher::Job{[what](int fd) {
                           if (what == "report") {
                             [[maybe_unused]] const auto n = write(fd, "done", 4);
                             return 0;
                           }
                           if (what == "crash") {
                             std::signal(SIGSEGV, SIG_DFL);  // past a sanitizer's handler
                             raise(SIGSEGV);
                           }
                           if (what == "hang") sleep(30);
                           return 1;
                         },
                         ""};
  });
  std::string got;
  EXPECT_EQ(launcher.run("report", {}, [&](const std::string& r) { got = r; }).exit_code, 0);
  EXPECT_EQ(got, "done");
  EXPECT_EQ(launcher.run("crash", {}, nullptr).signal, SIGSEGV);
  ChildLimits quick;
  quick.timeout_s = 0.3;
  const auto t0 = Clock::now();
  EXPECT_TRUE(launcher.run("hang", quick, nullptr).timed_out);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 5.0);
  try {
    launcher.run("bad", {}, nullptr);
    ADD_FAILURE() << "expected the launcher's error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no such job: bad"), std::string::npos) << e.what();
  }
  EXPECT_EQ(launcher.run("other", {}, nullptr).exit_code, 1) << "the launcher goes on after an error";
}

// A job that reports its parent: the launcher.
Launcher::Job report_the_launcher(const std::string&) {
  return Launcher::Job{[](int fd) {
                         const std::string pid = std::to_string(getppid());
                         return write(fd, pid.data(), pid.size()) == static_cast<ssize_t>(pid.size()) ? 0 : 1;
                       },
                       ""};
}

TEST(Process, ADeadLauncherIsAnErrorNotTheEndOfItsOwner) {
  // The job reports its parent, the launcher; killed, the next run must throw, not die of SIGPIPE.
  Launcher launcher(report_the_launcher);
  std::string reported;
  ASSERT_EQ(launcher.run("x", {}, [&](const std::string& r) { reported = r; }).exit_code, 0);
  ASSERT_FALSE(reported.empty());
  ASSERT_EQ(kill(static_cast<pid_t>(std::stol(reported)), SIGKILL), 0);
  usleep(100 * 1000);
  EXPECT_THROW(launcher.run("x", {}, nullptr), std::runtime_error);
  EXPECT_THROW(launcher.run("x", {}, nullptr), std::runtime_error);
}

// The launcher keeps a job's process forked ahead; one that dies while it waits (killed from outside)
// is replaced, and the job runs.
TEST(Process, AJobsProcessKilledWhileWaitingIsReplaced) {
  Launcher launcher(report_the_launcher);
  std::string reported;
  ASSERT_EQ(launcher.run("x", {}, [&](const std::string& r) { reported = r; }).exit_code, 0);
  // The launcher's only child now is the process waiting for the next job.
  std::ifstream children("/proc/" + reported + "/task/" + reported + "/children");
  std::vector<pid_t> waiting;
  for (long pid = 0; children >> pid;) waiting.push_back(static_cast<pid_t>(pid));
  ASSERT_EQ(waiting.size(), 1u);
  ASSERT_EQ(kill(waiting[0], SIGKILL), 0);
  usleep(100 * 1000);
  for (int i = 0; i < 2; ++i) {
    const ChildResult r = launcher.run("x", {}, nullptr);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_EQ(r.signal, 0);
  }
}

// Whether process `pid` has ended: gone, or a zombie no one has reaped yet (a container's init may not).
bool ended(pid_t pid) {
  if (kill(pid, 0) != 0) return true;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const auto close = line.rfind(')');
  return close == std::string::npos || (close + 2 < line.size() && line[close + 2] == 'Z');
}
bool ends_within(pid_t pid, std::chrono::seconds limit) {
  for (const auto t0 = Clock::now(); Clock::now() - t0 < limit;) {
    if (ended(pid)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}
// The pid a shell wrote to `path`, waiting for it.
pid_t pid_from(const std::string& path) {
  for (const auto t0 = Clock::now(); Clock::now() - t0 < std::chrono::seconds(10);) {
    std::ifstream in(path);
    pid_t pid = 0;
    if (in >> pid && pid > 0) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return -1;
}

// A suite or render killed (SIGKILL too) left its POV-Ray processes running, which later overwrote the
// render.png of a resumed run: a program run_program starts dies with the process that started it.
TEST(Process, AProgramDiesWithTheProcessThatRanIt) {
  const std::string file = ::testing::TempDir() + "/growbench_program_pid_" + std::to_string(getpid());
  std::remove(file.c_str());
  const pid_t runner = fork();
  ASSERT_GE(runner, 0);
  if (runner == 0) {
    (void)run_program({"/bin/sh", "-c", "echo $$ > '" + file + "'; exec sleep 60"}, "", {}, "");
    _exit(0);
  }
  const pid_t program = pid_from(file);
  ASSERT_GT(program, 0);
  EXPECT_FALSE(ended(program));
  kill(runner, SIGKILL);
  waitpid(runner, nullptr, 0);
  EXPECT_TRUE(ends_within(program, std::chrono::seconds(5))) << "pid " << program << " outlived its runner";
  std::remove(file.c_str());
}

// What a trial starts in its process group (a plugin's helper) ends when the trial does.
TEST(Process, WhatAChildLeftInItsGroupEndsWithIt) {
  const std::string file = ::testing::TempDir() + "/growbench_helper_pid_" + std::to_string(getpid());
  std::remove(file.c_str());
  const ChildResult r = run_program({"/bin/sh", "-c", "sleep 60 & echo $! > '" + file + "'"}, "", {}, "");
  EXPECT_EQ(r.exit_code, 0);
  const pid_t helper = pid_from(file);
  ASSERT_GT(helper, 0);
  EXPECT_TRUE(ends_within(helper, std::chrono::seconds(5))) << "pid " << helper << " outlived its trial";
  std::remove(file.c_str());
}

// A suite's trial that started a daemon of its own (fork, then setsid: outside the trial's process group)
// left it running after the suite: the launcher, its subreaper, ends it with the trial.
TEST(Process, ADaemonATrialStartedEndsWithTheTrial) {
  const std::string file = ::testing::TempDir() + "/growbench_daemon_pid_" + std::to_string(getpid());
  std::remove(file.c_str());
  Launcher launcher([file](const std::string&) {
    return Launcher::Job{[file](int) {
                           if (fork() == 0) {
                             setsid();
                             if (fork() == 0) {  // the daemon: its parent ends at once
                               if (FILE* f = std::fopen(file.c_str(), "w"))
                                 std::fprintf(f, "%d\n", getpid()), std::fclose(f);
                               sleep(60);
                             }
                             _exit(0);
                           }
                           pid_from(file);
                           return 0;
                         },
                         ""};
  });
  const ChildResult r = launcher.run("go", {}, nullptr);
  EXPECT_EQ(r.exit_code, 0);
  const pid_t daemon = pid_from(file);
  ASSERT_GT(daemon, 0);
  EXPECT_TRUE(ends_within(daemon, std::chrono::seconds(5))) << "pid " << daemon << " outlived its trial";
  std::remove(file.c_str());
}

}  // namespace
}  // namespace growbench
