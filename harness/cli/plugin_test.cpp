// growbench plugin-test: the conformance checks every built-in passes, run on a plugin by its author.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/plugins/loader.hpp"
#include "core/errors.hpp"
#include "harness/cli/command.hpp"
#include "harness/gate/conformance.hpp"
#include "scenes/scene_library.hpp"

namespace growbench::cli {

namespace {

struct PluginTestArgs {
  std::string plugin;
  std::vector<std::string> scenes;
  ConformanceOptions options;
  bool quiet = false;
};

void print_scene(const SceneConformance& s) {
  fmt::print("{:<22} {}\n", s.scene, s.pass() ? "pass" : "FAIL");
  for (const auto& c : s.checks) fmt::print("  {:<4} {:<24} {}\n", c.pass ? "ok" : "FAIL", c.name, c.detail);
}

Outcome plugin_test(const PluginTestArgs& a) {
  const AlgorithmEntry& entry = load_plugin(a.plugin);
  const std::string& name = entry.info().name;
  std::vector<std::string> scenes = a.scenes;
  if (scenes.empty())
    for (const auto& s : standard_scenes()) scenes.push_back(s.name);
  // Every scene and parameter checked before the first trial: bad input is the user's, not the plugin's.
  for (const auto& s : scenes) (void)load_scene(s);
  Params params = default_params(entry);
  for (const auto& kv : entry.info().test_params) params.set_assignment(kv);
  for (const auto& kv : a.options.params) params.set_assignment(kv);
  const PluginOrigin& p = *entry.plugin;
  fmt::print("plugin-test {}: {} (version {}, ABI {}, xxh3 {}), {} scenes, test parameters: {}\n", name, p.path,
             p.version.empty() ? "-" : p.version, p.abi_version, p.hash, scenes.size(),
             entry.info().test_params.empty() ? "none" : fmt::format("{}", fmt::join(entry.info().test_params, " ")));
  std::vector<std::string> failed;
  for (const auto& scene : scenes) {
    if (!a.quiet) fmt::print(stderr, "plugin-test: {} on {}...\n", name, scene);
    const SceneConformance s = check_conformance(name, scene, a.options);
    print_scene(s);
    std::fflush(stdout);  // before the next scene's progress line on stderr
    if (!s.pass()) failed.push_back(scene);
  }
  if (failed.empty()) {
    fmt::print("plugin-test {}: passed on all {} scenes\n", name, scenes.size());
    return Outcome::ok;
  }
  throw PluginError(fmt::format("plugin-test {}: failed on {} of {} scenes: {}", name, failed.size(), scenes.size(),
                                fmt::join(failed, ", ")));
}

}  // namespace

Command add_plugin_test(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "plugin-test",
      "Run the conformance checks every built-in algorithm passes on a plugin: on every standard scene, a valid "
      "plant (finite, parents before children), one tree per seed, no node inside a solid, the same plant on 1 and "
      "2 threads and on a second run, and growth that stops at a time limit (host->cancelled()). Each trial runs "
      "in its own process; exit 0 when every check passes, 2 otherwise");
  auto a = std::make_shared<PluginTestArgs>();
  cmd->add_option("plugin", a->plugin, "the plugin's shared library")->required();
  cmd->add_option("-s,--scene", a->scenes, "a scene to check on (repeatable; default: every standard scene)");
  cmd->add_option("--set", a->options.params,
                  "parameter key=value after the plugin's own test parameters (repeatable)");
  cmd->add_option("--max-steps", a->options.max_steps, "steps per trial")
      ->default_val(a->options.max_steps)
      ->check(integer_in(1, INT32_MAX));
  cmd->add_option("--timeout", a->options.timeout_s, "seconds before a trial's process is killed")
      ->default_val(a->options.timeout_s)
      ->check(number_in(0.1, 1e6));
  cmd->add_flag("-q,--quiet", a->quiet, "no progress lines");
  return {cmd, [a] { return plugin_test(*a); }};
}

}  // namespace growbench::cli
