// The helpers of the exit-status contract (command.hpp): numeric checks, so that every number a command
// takes is checked where it is parsed, and the statuses of the Python scripts commands run.
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/utf8.hpp"
#include "harness/cli/command.hpp"

namespace growbench::cli {

CLI::Validator number_in(double lo, double hi, bool lo_open, bool zero_or) {
  const std::string range = fmt::format("{}{:g}, {:g}]", lo_open ? "(" : "[", lo, hi);
  const char* zero = zero_or ? "0 or " : "";
  return {[=](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            const bool ok = !text.empty() && end == text.c_str() + text.size() && std::isfinite(v) &&
                            ((zero_or && v == 0.0) || ((lo_open ? v > lo : v >= lo) && v <= hi));
            return ok ? std::string() : fmt::format("expected {}a finite number in {}, got '{}'", zero, range, text);
          },
          fmt::format("{}NUMBER in {}", zero, range)};
}

CLI::Validator integer_in(long long lo, unsigned long long hi) {
  const std::string range = fmt::format("[{}, {}]", lo, hi);
  return {[=](std::string& text) -> std::string {
            const char* first = text.data();
            const char* last = first + text.size();
            bool ok = false;
            if (!text.empty() && text[0] == '-') {
              long long v = 0;
              const auto r = std::from_chars(first, last, v);
              ok = r.ec == std::errc() && r.ptr == last && v >= lo;
            } else {
              unsigned long long v = 0;
              const auto r = std::from_chars(first + (!text.empty() && text[0] == '+' ? 1 : 0), last, v);
              ok = r.ec == std::errc() && r.ptr == last && v <= hi &&
                   (lo <= 0 || v >= static_cast<unsigned long long>(lo));
            }
            return ok ? std::string() : fmt::format("expected an integer in {}, got '{}'", range, text);
          },
          "INTEGER in " + range};
}

CLI::Validator path_named(const std::string& what) {
  return {[=](std::string& text) -> std::string {
            if (text.empty()) return fmt::format("expected {}, got an empty name", what);
            if (has_control_char(text))
              return fmt::format("expected {} without control characters (a line break or a tab)", what);
            return {};
          },
          "PATH"};
}

Outcome script_status(int status, const std::string& script) {
  if (status == exit_status(Outcome::ok)) return Outcome::ok;
  if (status == exit_status(Outcome::invalid_input)) return Outcome::invalid_input;
  fmt::print(stderr,
             "growbench: internal error: {} ended with status {}\n"
             "This is a bug in growbench: please report it with the command line and the input that caused it.\n",
             script, status);
  return Outcome::failed;
}

}  // namespace growbench::cli
