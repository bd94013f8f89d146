// growbench lsystem: derive an L-system's string without drawing it.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/algorithm.hpp"
#include "harness/cli/command.hpp"
#include "harness/record/files.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench::cli {

namespace {

struct LsystemArgs {
  std::string file;
  std::vector<std::string> sets;
  std::string generations;
  std::string scene;
  std::string write_rules;
  std::uint64_t seed = 1;
  bool print = false, examples = false;
  std::size_t limit = 0;
};

Outcome derive(const LsystemArgs& a) {
  const AlgorithmEntry& entry = find_algorithm("lsystem");
  if (!entry.rewriting) throw std::logic_error("the lsystem algorithm registered no string rewriting");
  if (a.examples) {
    for (const auto& name : entry.rewriting->examples()) fmt::print("{}\n", name);
    return Outcome::ok;
  }
  Params params = default_params(entry);
  if (!a.file.empty()) params.set("grammar", a.file);
  if (!a.generations.empty()) params.set("generations", a.generations);
  for (const auto& s : a.sets) params.set_assignment(s);
  std::optional<Scene> scene;
  std::unique_ptr<SceneQuery> query;
  if (!a.scene.empty()) {
    scene = load_scene(a.scene);
    query = std::make_unique<SceneQuery>(*scene);
  }
  const DerivedString d = entry.rewriting->derive(params, a.seed, scene ? &*scene : nullptr, query.get(),
                                                  a.print ? std::optional(a.limit) : std::nullopt);
  if (a.print) {
    fmt::print("{}", d.text);
    if (a.limit && d.modules > a.limit) fmt::print(" ... ({} more modules)", d.modules - a.limit);
    fmt::print("\n");
  }
  fmt::print(stderr, "generation {}: {} modules, {} parameters, {:.1f} MiB, derived in {:.6f} s ({:.6f} s CPU)\n",
             d.generations, d.modules, d.params, d.bytes / (1024.0 * 1024.0), d.seconds, d.cpu_seconds);
  for (const auto& [c, n] : d.counts) fmt::print(stderr, "  {}  {}\n", c, n);
  if (!a.write_rules.empty()) {
    // Houdini's Write Rule Parameters to File: the rules as read, one per line, for rules_file.
    std::string text = fmt::format("# the rules of {}, written by growbench lsystem --write-rules\n",
                                   a.file.empty() ? "the parameters" : a.file);
    for (const auto& r : d.rules) text += r + "\n";
    write_file_atomic(a.write_rules, text);
    fmt::print(stderr, "wrote {} rules to {}\n", d.rules.size(), a.write_rules);
  }
  return Outcome::ok;
}

}  // namespace

Command add_lsystem(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "lsystem", "Derive an L-system's string without drawing it: symbol counts, and the string with --print");
  auto a = std::make_shared<LsystemArgs>();
  cmd->add_option("grammar", a->file, "a .lsys grammar file or an example name (see --examples)");
  cmd->add_option("-g,--generations", a->generations, "generations (default: the grammar's)");
  cmd->add_option("--set", a->sets, "L-system parameter key=value (repeatable; see `growbench list`)");
  cmd->add_option("--seed", a->seed, "random seed")->default_val(1)->check(integer_in(0, UINT64_MAX));
  cmd->add_option("--scene", a->scene, "scene for in() and the start point (default: none; in() is 0)");
  cmd->add_flag("-p,--print", a->print, "print the derived string");
  cmd->add_option("--limit", a->limit, "print at most this many modules (0: all)")
      ->default_val(0)
      ->check(integer_in(0, SIZE_MAX));
  cmd->add_flag("--examples", a->examples, "list the example grammars");
  cmd->add_option("--write-rules", a->write_rules,
                  "write the rules it rewrote with to this file, one per line, which rules_file=FILE reads "
                  "(Houdini's Write Rule Parameters to File)");
  return {cmd, [a] { return derive(*a); }};
}

}  // namespace growbench::cli
