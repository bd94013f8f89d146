// Options bound to trial spec fields, checked against their declarations (harness/record/trial_spec.hpp):
// the ranges a command line accepts are the ones a suite file and a spec made in code are held to.
#include <climits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/record/reflect.hpp"
#include "harness/record/trial_spec.hpp"

namespace growbench::cli {

namespace {

// The check of a numeric field's declared range.
template <class M, class F>
CLI::Validator range_check(const F& f) {
  if constexpr (std::is_integral_v<M>) {
    const auto hi = f.hi >= static_cast<double>(ULLONG_MAX) ? ULLONG_MAX : static_cast<unsigned long long>(f.hi);
    return integer_in(static_cast<long long>(f.lo), hi);
  } else {
    return number_in(f.lo, f.hi, false, f.has(kZeroOr));
  }
}

}  // namespace

CLI::Option* add_spec_option(CLI::App* cmd, const std::string& flags, TrialSpec& spec, std::string_view key,
                             const std::string& help) {
  CLI::Option* opt = nullptr;
  const bool found = with_field<TrialSpec>(key, [&](const auto& f) {
    using M = typename std::remove_cvref_t<decltype(f)>::Member;
    M& m = spec.*f.member;
    const std::string text = help.empty() ? std::string(f.doc) : help;
    if constexpr (NamedEnum<M>) {
      const auto names = enum_names(M{});
      opt = cmd->add_option_function<std::string>(
                   flags,
                   [&m, names](const std::string& v) {
                     for (std::size_t i = 0; i < names.size(); ++i)
                       if (names[i] == v) m = static_cast<M>(i);
                   },
                   text)
                ->check(CLI::IsMember(std::vector<std::string>(names.begin(), names.end())))
                ->default_str(std::string(names[static_cast<std::size_t>(m)]));
    } else {
      opt = cmd->add_option(flags, m, text);
      if constexpr (std::is_arithmetic_v<M> && !std::is_same_v<M, bool>) {
        if (f.bounded()) opt->check(range_check<M>(f));
        opt->capture_default_str();
      }
    }
  });
  if (!found) throw std::logic_error(fmt::format("add_spec_option: the trial spec has no field '{}'", key));
  return opt;
}

}  // namespace growbench::cli
