// growbench schema (internal): results.schema.json as this binary declares it, for `make schema`.
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/record/record.hpp"

namespace growbench::cli {

Command add_schema(CLI::App& app) {
  auto* cmd = app.add_subcommand("schema", "Print results.schema.json as this binary declares its records (internal)");
  cmd->group("");  // not listed in --help: `make schema` writes harness/record/results.schema.json with it
  return {cmd, [] {
            fmt::print("{}", json_text(results_schema(), 2));
            return Outcome::ok;
          }};
}

}  // namespace growbench::cli
