#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "harness/report/columns.hpp"
#include "scenes/scene.hpp"

namespace growbench::test {

// A fresh temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("growbench_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

// A scene with one mesh and one seed at the origin.
inline Scene scene_with(TriangleMesh mesh) {
  Scene s;
  s.name = "test";
  s.meshes.push_back(std::move(mesh));
  s.seeds.push_back({});
  return s;
}

// The message of the InputError that f throws, or "(no error)".
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// `text` as one paragraph: its words joined by single spaces, so that a wrapped line reads as unwrapped.
inline std::string one_paragraph(const std::string& text) {
  std::istringstream in(text);
  std::string flat;
  for (std::string w; in >> w;) flat += (flat.empty() ? "" : " ") + w;
  return flat;
}

// `text` without any whitespace: a word cut across lines (a long path) reads whole again.
inline std::string without_spaces(const std::string& text) {
  std::string s;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) s += c;
  return s;
}

// Every line of `text` fits a terminal of kTerminalColumns.
inline void expect_lines_fit(const std::string& text, const std::string& what) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    EXPECT_LE(display_width(line), kTerminalColumns) << what << ": " << line;
}

struct CommandResult {
  int status;       // exit status, -1 if it did not exit normally
  std::string out;  // stdout and stderr together
};

// Runs a shell command line, its output captured.
inline CommandResult run_command(const std::string& command) {
  const auto log = temp_dir("cmd") / "log.txt";
  const int rc = std::system((command + " > " + log.string() + " 2>&1").c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, ss.str()};
}

// Runs the growbench binary with `args` (a shell command line), as a user would.
inline CommandResult run_growbench(const std::string& args) {
  // Appended in place: GCC 12 at -O3 warns (-Warray-bounds) of the temporary that `a + " " + b` makes.
  std::string command = GROWBENCH_BINARY;
  command.append(" ").append(args);
  return run_command(command);
}

}  // namespace growbench::test
