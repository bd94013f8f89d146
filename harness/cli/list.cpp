// growbench list: the algorithms and their parameter tables.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/algorithm.hpp"
#include "harness/cli/command.hpp"
#include "harness/cli/param_table.hpp"

namespace growbench::cli {

namespace {

int list_algorithms() {
  for (const auto& e : algorithm_registry()) {
    const auto& info = e.info();
    fmt::print("{}\n  {}\n", info.name, info.summary);
    print_param_table(info.params);
    for (const auto& preset : info.presets) {
      std::vector<std::string> kv;
      for (const auto& [k, v] : preset.values) kv.push_back(fmt::format("{}={}", k, format_value(v)));
      fmt::print("    preset={}: {}\n", preset.name,
                 kv.empty() ? "the defaults above" : fmt::format("{}", fmt::join(kv, " ")));
    }
  }
  return 0;
}

}  // namespace

Command add_list(CLI::App& app) {
  return {app.add_subcommand("list", "List the algorithms and their parameter tables"), list_algorithms};
}

}  // namespace growbench::cli
