// --plugin, shared by the commands that look algorithms up (list, run, suite, ab).
#include <CLI/CLI.hpp>

#include "harness/cli/command.hpp"

namespace growbench::cli {

void add_plugin_option(CLI::App* cmd, std::vector<std::string>& paths) {
  cmd->add_option("--plugin", paths,
                  "load an algorithm plugin (a shared library built with the growbench SDK; repeatable). "
                  "GROWBENCH_PLUGIN_PATH names directories whose *.so are loaded too (docs/plugins.md)");
}

}  // namespace growbench::cli
