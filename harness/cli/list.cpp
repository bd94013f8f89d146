// growbench list: the algorithms and their parameter tables, as text or (--markdown) as the Markdown
// the algorithms' READMEs carry.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/plugins/loader.hpp"
#include "harness/cli/command.hpp"
#include "harness/cli/param_table.hpp"
#include "harness/organs/options.hpp"
#include "harness/report/columns.hpp"
#include "algorithms/organ_shapes.hpp"

namespace growbench::cli {

namespace {

struct ListArgs {
  std::string name;
  bool markdown = false;
  std::vector<std::string> plugins;
};

// A plugin's provenance, as its records name it.
std::string plugin_line(const AlgorithmEntry& e) {
  if (!e.plugin) return "";
  const PluginOrigin& p = *e.plugin;
  return fmt::format("plugin {} (version {}, ABI {}, xxh3 {})", p.path, p.version.empty() ? "-" : p.version,
                     p.abi_version, p.hash);
}

void print_text(const AlgorithmEntry& e) {
  const AlgorithmInfo& info = e.info();
  fmt::print("{}{}\n{}", info.name, e.plugin ? "  [plugin]" : "", wrap_text(info.summary, "  ", "  "));
  if (e.plugin) fmt::print("{}", wrap_text(plugin_line(e), "  ", "    "));
  print_param_table(info.params);
  for (const auto& preset : info.presets) {
    std::vector<std::string> kv;
    for (const auto& [k, v] : preset.values) kv.push_back(fmt::format("{}={}", k, format_value(v)));
    fmt::print("{}", wrap_text(fmt::format("preset={}: {}", preset.name,
                                           kv.empty() ? "the defaults above" : fmt::format("{}", fmt::join(kv, " "))),
                               "    ", "      "));
  }
}

// The table, then the presets as a list (each one's values are defaults too).
std::string markdown_of(const AlgorithmInfo& info) {
  std::string out = param_table_markdown(info.params);
  if (!info.presets.empty()) out += "\nPresets (`preset=NAME` sets these defaults; a value set explicitly wins):\n\n";
  for (const auto& preset : info.presets) {
    std::vector<std::string> kv;
    for (const auto& [k, v] : preset.values) kv.push_back(markdown_code(fmt::format("{}={}", k, format_value(v))));
    out += fmt::format("- {}: {}\n", markdown_code(preset.name),
                       kv.empty() ? "the defaults above" : fmt::format("{}", fmt::join(kv, " ")));
  }
  return out;
}

// The organ pass's table and the built-in organ shapes: every algorithm's plant goes through them.
void print_organs(bool markdown) {
  const auto& names = builtin_organ_shape_names();
  const auto& docs = builtin_organ_shape_docs();
  if (markdown) {
    fmt::print("{}\nBuilt-in organ shapes (organ_j=NAME, or NAME:key=value,... to change a setting):\n\n",
               param_table_markdown(organ_param_specs()));
    for (std::size_t i = 0; i < names.size(); ++i) fmt::print("- {}: {}\n", markdown_code(names[i]), docs[i]);
    return;
  }
  fmt::print("organs  [every algorithm]\n{}",
             wrap_text("the organ pass after growth: --organ key=value (a suite entry's \"organs\")", "  ", "  "));
  print_param_table(organ_param_specs());
  fmt::print("  built-in organ shapes (NAME, or NAME:key=value,... to change a setting):\n");
  for (std::size_t i = 0; i < names.size(); ++i)
    fmt::print("{}", wrap_text(docs[i], fmt::format("    {:<12} ", names[i]), std::string(17, ' ')));
}

Outcome list_algorithms(const ListArgs& a) {
  load_plugins(a.plugins);
  if (a.name == "organs") {
    print_organs(a.markdown);
    return Outcome::ok;
  }
  if (!a.name.empty()) {
    const AlgorithmEntry& e = find_algorithm(a.name);
    if (a.markdown)
      fmt::print("{}", markdown_of(e.info()));
    else
      print_text(e);
    return Outcome::ok;
  }
  bool first = true;
  for (const AlgorithmEntry* e : all_algorithms()) {
    const std::string origin = e->plugin ? fmt::format("\n\n{}", markdown_text(plugin_line(*e))) : "";
    if (a.markdown)
      fmt::print("{}## {}\n\n{}{}\n\n{}", first ? "" : "\n", markdown_text(e->info().name),
                 markdown_text(e->info().summary), origin, markdown_of(e->info()));
    else
      print_text(*e);
    first = false;
  }
  if (!a.markdown) print_organs(false);
  return Outcome::ok;
}

}  // namespace

Command add_list(CLI::App& app) {
  auto* cmd = app.add_subcommand("list", "List the algorithms and their parameter tables");
  auto a = std::make_shared<ListArgs>();
  cmd->add_option("name", a->name, "only this algorithm (or organs: the organ pass and shapes every algorithm shares)");
  add_plugin_option(cmd, a->plugins);
  cmd->add_flag("--markdown", a->markdown,
                "the parameter tables as Markdown (name, type, default, allowed, unit, doc), as the algorithms' "
                "READMEs carry them (scripts/readme-params)");
  return {cmd, [a] { return list_algorithms(*a); }};
}

}  // namespace growbench::cli
