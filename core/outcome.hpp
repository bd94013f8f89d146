// How a piece of work ended, in one numbering for every boundary that reports it. Each mapping is written
// here once: the command line's exit status (README, "Exit status"), the exit code a trial's own process
// reports to the suite or `ab` that ran it, and a suite sample's status. The plugin ABI's statuses map
// onto it in algorithms/plugins/plugin_algorithm.cpp, and exceptions in harness/run/trial.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace growbench {

enum class Outcome : std::uint8_t {
  ok,
  regression,     // compare or ab found one
  invalid_input,  // the input cannot work (InputError)
  out_of_memory,  // an allocation was refused
  failed,         // anything else: an internal error, a bug
  timeout,        // a trial killed at its time limit
  crashed,        // a trial killed by a signal
  plugin_error,   // a plugin algorithm failed, or handed over an invalid plant (PluginError)
};

struct OutcomeCodes {
  Outcome outcome;
  std::string_view status;  // a suite sample's status
  int exit_status;          // the command line's
  int trial_exit;           // a trial process's report (-1: a trial never reports it itself)
};

// A sample's statuses: a trial that failed (an internal error) is recorded as crashed, as a signal is.
inline constexpr std::array<OutcomeCodes, 8> kOutcomes = {{
    {Outcome::ok, "ok", 0, 0},
    {Outcome::regression, "regression", 1, -1},
    {Outcome::invalid_input, "invalid_input", 2, 2},
    {Outcome::out_of_memory, "out_of_memory", 2, 3},  // the input asks for more memory than the process may use
    {Outcome::failed, "crashed", 3, 4},
    {Outcome::timeout, "timeout", 3, -1},
    {Outcome::crashed, "crashed", 3, -1},
    {Outcome::plugin_error, "plugin_error", 2, 5},  // a plugin is input the user brought
}};

static_assert(
    [] {
      for (std::size_t i = 0; i < kOutcomes.size(); ++i)
        if (static_cast<std::size_t>(kOutcomes[i].outcome) != i) return false;
      return true;
    }(),
    "kOutcomes is indexed by Outcome");

// The statuses a suite records for a trial, each once.
inline constexpr std::array<std::string_view, 6> kTrialStatuses = {
    "ok", "crashed", "timeout", "out_of_memory", "invalid_input", "plugin_error"};

constexpr const OutcomeCodes& codes_of(Outcome o) {
  return kOutcomes[static_cast<std::size_t>(o)];
}
constexpr int exit_status(Outcome o) {
  return codes_of(o).exit_status;
}
constexpr int trial_exit_code(Outcome o) {
  return codes_of(o).trial_exit;
}
constexpr std::string_view status_name(Outcome o) {
  return codes_of(o).status;
}
// What a trial process's exit code reports; a code no trial reports is a failure.
constexpr Outcome outcome_of_trial_exit(int code) {
  for (const auto& c : kOutcomes)
    if (c.trial_exit == code && code >= 0) return c.outcome;
  return Outcome::failed;
}

// Throws the exception the harness reads back as `o` (InputError, std::bad_alloc, PluginError or
// std::runtime_error).
[[noreturn]] inline void throw_as(Outcome o, const std::string& message) {
  if (o == Outcome::invalid_input) throw InputError(message);
  if (o == Outcome::plugin_error) throw PluginError(message);
  if (o == Outcome::out_of_memory) throw std::bad_alloc();
  throw std::runtime_error(message);
}

}  // namespace growbench
