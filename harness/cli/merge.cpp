// growbench merge: join the results of a suite's shards into one results file.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "harness/suite/suite.hpp"

namespace growbench::cli {

namespace {

struct MergeArgs {
  std::vector<std::string> inputs;
  std::string out;
  bool mixed = false;
};

// A shard's files are named relative to its results file; the merged file names them relative to itself.
void rebase_scene_files(nlohmann::json& shard, const std::string& from, const std::string& to) {
  if (!shard.contains("scenes") || !shard["scenes"].is_object()) return;
  namespace fs = std::filesystem;
  const fs::path src = fs::weakly_canonical(fs::absolute(from)).parent_path();
  const fs::path dst = fs::weakly_canonical(fs::absolute(to)).parent_path();
  for (auto& [hash, file] : shard["scenes"].items())
    if (file.is_string()) file = (src / file.get<std::string>()).lexically_normal().lexically_relative(dst).string();
}

Outcome merge_shards(const MergeArgs& a) {
  std::vector<nlohmann::json> shards;
  for (const auto& f : a.inputs) {
    shards.push_back(read_json_file(f));
    rebase_scene_files(shards.back(), f, a.out);
  }
  const nlohmann::json merged = merge_results(shards, a.inputs, a.mixed);
  make_directories(std::filesystem::path(a.out).parent_path().string());
  write_file_atomic(a.out, json_text(merged, 1));
  if (merged["context"].value("mixed_machines", false))
    fmt::print(
        stderr,
        "growbench: warning: the shards ran on different machines or builds; their timings are not comparable\n");
  fmt::print("merged {} shards, {} cells, into {}\n", shards.size(), merged["trials"].size(), a.out);
  return Outcome::ok;
}

}  // namespace

Command add_merge(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "merge", "Join the results of a suite's shards (--shard I/N) into one results file, in the unsharded order");
  auto a = std::make_shared<MergeArgs>();
  cmd->add_option("shards", a->inputs, "results.json of every shard")->required();
  cmd->add_option("-o,--out", a->out, "the merged results.json")->check(path_named("a file name"))->required();
  cmd->add_flag("--mixed-machines", a->mixed,
                "merge shards that ran on different CPU models or builds (their timings are not comparable; the "
                "merged context is marked mixed_machines)");
  return {cmd, [a] { return merge_shards(*a); }};
}

}  // namespace growbench::cli
