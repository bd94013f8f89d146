// growbench: the command line. CLI11 lives in this file only (a slow header).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "core/errors.hpp"
#include "harness/gate/ab.hpp"
#include "harness/gate/compare.hpp"
#include "harness/output/exporters.hpp"
#include "harness/gate/history.hpp"
#include "harness/render/render_results.hpp"
#include "harness/report/report.hpp"
#include "harness/report/summary.hpp"
#include "harness/record/files.hpp"
#include "harness/suite/suite.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"

namespace gb = growbench;

namespace {

void print_param_table(const std::vector<gb::ParamSpec>& specs) {
  std::size_t w = 4;
  for (const auto& s : specs) w = std::max(w, s.name.size());
  for (const auto& s : specs) {
    std::string range;
    if (s.type == gb::ParamType::Choice) range = fmt::format("{{{}}}", fmt::join(s.choices, "|"));
    else if (std::isfinite(s.min) || std::isfinite(s.max)) range = fmt::format("[{:g}, {:g}]", s.min, s.max);
    fmt::print("    {:<{}}  {:<6}  default {:<10} {:<18} {:<3}  {}\n", s.name, w, gb::to_string(s.type),
               gb::format_value(s.default_value).empty() ? "\"\"" : gb::format_value(s.default_value), range, s.unit,
               s.doc);
  }
}

glm::vec3 parse_point(const std::string& text) {
  gb::Params p("--seed-at", {{"at", gb::ParamType::Vec3, glm::dvec3(0.0), -1e9, 1e9, "m", "", {}}});
  p.set("at", text);
  return glm::vec3(p.vec3("at"));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"growbench: grow, measure and compare procedural plant growth algorithms on standard scenes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "growbench 0.1.0");

  auto* list = app.add_subcommand("list", "List the algorithms and their parameter tables");
  auto* scenes = app.add_subcommand("scenes", "List the standard scenes and their parameters");

  auto* run = app.add_subcommand("run", "Grow one plant: one algorithm on one scene, measured, written to --out");
  gb::TrialSpec spec;
  std::vector<std::string> seed_at;
  std::string sides_help = "tube sides of the branch mesh (3..64)";
  run->add_option("-a,--algorithm", spec.algorithm, "algorithm name (see `growbench list`)")->required();
  run->add_option("-s,--scene", spec.scene,
                  "scene: a standard scene's name (see `growbench scenes`), a scene file *.json, mesh:PATH.obj, or mesh:NAME "
                  "for a bundled mesh (e.g. mesh:stanford-bunny)")
      ->required();
  run->add_option("--scene-param", spec.scene_params, "scene parameter key=value (repeatable)");
  run->add_option("--seed", spec.seed, "random seed")->default_val(1);
  run->add_option("--set", spec.params, "algorithm parameter key=value (repeatable)");
  run->add_option("--seed-at", seed_at, "seed position X,Y,Z, snapped to the nearest surface (repeatable; replaces the scene's seeds)");
  run->add_option("--max-steps", spec.max_steps, "step cap")->default_val(5000);
  run->add_option("--time-limit", spec.time_limit_s, "stop growing after this many seconds (0: none)")->default_val(0);
  run->add_option("-j,--threads", spec.threads, "worker threads (0: all cores)")->default_val(0);
  run->add_option("--voxel-size", spec.voxel_size, "distance-field voxel size in metres (0: scene diagonal / 256)")->default_val(0);
  run->add_option("--sides", spec.mesher.sides, sides_help)->default_val(6)->check(CLI::Range(3, 64));
  run->add_option("--leaf-obj", spec.mesher.leaf_obj,
                  "a custom leaf for every leaf and flower: an OBJ with the blade along +Z from the stem at z = 0 and "
                  "its upper side toward +Y (scaled to unit length; the organ's size sizes it)");
  std::string out_dir;
  run->add_option("-o,--out", out_dir, "output directory (default: out/ALGORITHM-SCENE)");
  bool quiet = false;
  run->add_flag("-q,--quiet", quiet, "no progress line");
  std::string run_render;
  run->add_option("--render", run_render, "render the plant with POV-Ray afterwards: preview or paper (render.png)");
  run->add_option("--frames", spec.frame_every,
                  "growth animation: keep the plant every K steps (frames/); with --render, render them and make "
                  "animation.mp4 with ffmpeg")
      ->default_val(0);

  auto* suite_cmd = app.add_subcommand(
      "suite", "Run a suite: algorithms x scenes x seeds x sweeps x repetitions, each trial in its own process");
  std::string suite_file, suite_out, shard;
  bool resume = false, suite_quiet = false;
  suite_cmd->add_option("file", suite_file, "suite file (e.g. bench/suites/quick.json)")->required();
  suite_cmd->add_option("-o,--out", suite_out, "results directory (default: out/suites/NAME)");
  suite_cmd->add_flag("--resume", resume, "continue an interrupted run in --out, skipping finished trials");
  suite_cmd->add_option("--shard", shard, "run only shard I of N (I/N, 0-based): a deterministic slice of the cells");
  suite_cmd->add_flag("-q,--quiet", suite_quiet, "no progress lines");
  int suite_repetitions = 0;
  suite_cmd->add_option("--repetitions", suite_repetitions,
                        "repetitions per cell instead of the suite file's (recorded in results.json; a quicker look "
                        "with wider intervals)")
      ->check(CLI::Range(1, 1000));
  bool suite_instructions = false;
  suite_cmd->add_flag("--instructions", suite_instructions,
                      "run each trial once, single-threaded, under valgrind's callgrind, and record instructions per "
                      "phase (the deterministic regression gate: see `growbench compare`)");
  std::string suite_render;
  suite_cmd->add_option("--render", suite_render,
                        "render every trial with POV-Ray afterwards (preview or paper) and compose grid.png");
  std::string suite_history;
  suite_cmd->add_option("--history", suite_history,
                        "append the run to this history directory (MACHINE/SUITE/COMMIT.json; see growbench history)");

  auto* history_cmd = app.add_subcommand(
      "history", "Suite runs across commits: append runs to a history directory, plot each metric over commits");
  history_cmd->require_subcommand(1);
  auto* history_add = history_cmd->add_subcommand("add", "Append a results file's run (keyed by its commit and machine)");
  std::string hist_results, hist_dir = "out/history", hist_machine, hist_out = "out/history-report";
  history_add->add_option("results", hist_results, "results.json of growbench suite")->required();
  history_add->add_option("--dir", hist_dir, "the history directory")->default_val("out/history");
  history_add->add_option("--machine", hist_machine, "machine name (default: from the CPU model and thread count)");
  auto* history_plot = history_cmd->add_subcommand(
      "plot", "Plot every metric over commits per machine and suite, change points marked (PNG, PDF, index.html)");
  history_plot->add_option("--dir", hist_dir, "the history directory")->default_val("out/history");
  history_plot->add_option("-o,--out", hist_out, "output directory")->default_val("out/history-report");

  auto* render_cmd = app.add_subcommand(
      "render", "Render a suite's results directory (every trial, then grid.png) or a `run` directory with POV-Ray");
  std::string render_dir, render_quality = "preview";
  gb::RenderDirOptions render_opts;
  render_cmd->add_option("dir", render_dir, "a directory with results.json (suite) or record.json (run)")->required();
  render_cmd->add_option("--quality", render_quality, "preview (480x360, no anti-aliasing) or paper (1600x1200, "
                         "anti-aliased, soft shadows, radiosity)")->default_val("preview");
  render_cmd->add_option("-j,--jobs", render_opts.jobs, "POV-Ray processes at once (0: one per core)")->default_val(0);
  render_cmd->add_option("--width", render_opts.render.width, "image width (0: the quality's)")->default_val(0);
  render_cmd->add_option("--height", render_opts.render.height, "image height (0: the quality's)")->default_val(0);
  render_cmd->add_option("--branches", render_opts.render.branches, "branches as cones (cone and sphere chains) or mesh "
                         "(the mesher's tubes as mesh2)")->default_val("cones")->check(CLI::IsMember({"cones", "mesh"}));
  render_cmd->add_flag("-q,--quiet", render_opts.quiet, "no progress lines");

  auto* trial_cmd = app.add_subcommand("trial", "Run one trial from a spec file written by a suite (internal)");
  trial_cmd->group("");  // not listed in --help: suites call it under callgrind
  std::string trial_spec_file;
  trial_cmd->add_option("spec", trial_spec_file, "spec.json")->required();
  std::string trial_fault;
  // Test hook: a wrapper script that appends `--fault slow:N` turns this binary into a planted slowdown
  // for `growbench ab` (tests/harness/ab_test.sh).
  trial_cmd->add_option("--fault", trial_fault, "inject a fault into the trial (tests)");

  auto* ab_cmd = app.add_subcommand(
      "ab", "The statistical gate: run a suite's trials with two growbench binaries alternately (A B, B A, ...) and "
            "report, per cell, whether B is slower, faster, unchanged, or the noise is too high to tell; exit 1 only "
            "on a slowdown that a rerun confirms");
  gb::AbOptions ab_opts;
  std::string ab_suite;
  ab_cmd->add_option("a", ab_opts.a_binary, "the base growbench binary")->required();
  ab_cmd->add_option("b", ab_opts.b_binary, "the candidate growbench binary")->required();
  ab_cmd->add_option("suite", ab_suite, "suite file (its cells, seeds and limits; its repetitions are not used)")->required();
  ab_cmd->add_option("-o,--out", ab_opts.out_dir, "output directory: ab.json and the trials (default: out/ab/SUITE)");
  ab_cmd->add_option("--effect", ab_opts.effect, "the smallest median ratio B/A to detect")->default_val(1.03);
  ab_cmd->add_option("--alpha", ab_opts.alpha, "significance level of the Mann-Whitney U test")->default_val(0.01);
  ab_cmd->add_option("--min-reps", ab_opts.min_repetitions, "pilot repetitions per side")->default_val(6);
  ab_cmd->add_option("--max-reps", ab_opts.max_repetitions,
                     "at most this many per side and batch; noisier cells are 'inconclusive'")->default_val(30);
  ab_cmd->add_option("--phases", ab_opts.phases, "phases whose wall and CPU time are compared")
      ->default_val(std::vector<std::string>{"growth"})->delimiter(',');
  ab_cmd->add_flag("!--no-confirm", ab_opts.confirm, "do not rerun flagged cells (a flag is then 'unconfirmed')");
  ab_cmd->add_flag("-q,--quiet", ab_opts.quiet, "no progress lines");

  auto* compare_cmd = app.add_subcommand(
      "compare", "Compare two results files (or a baseline): behaviour, allocations, output bytes, instructions; exit 1 "
                 "on a regression");
  std::string cmp_base, cmp_new;
  gb::CompareOptions cmp_opts;
  compare_cmd->add_option("base", cmp_base, "the base: a results.json or a baseline (reports/baselines/*.json)")->required();
  compare_cmd->add_option("new", cmp_new, "the new results.json")->required();
  compare_cmd->add_option("--threshold", cmp_opts.instructions_threshold,
                          "fail when a phase's instruction count rises by more than this fraction")
      ->default_val(0.02);
  compare_cmd->add_option("--floor", cmp_opts.instructions_floor,
                          "... and by more than this many instructions (tiny phases move with the heap layout)")
      ->default_val(1e5);

  auto* merge_cmd = app.add_subcommand(
      "merge", "Join the results of a suite's shards (--shard I/N) into one results file, in the unsharded order");
  std::vector<std::string> merge_inputs;
  std::string merge_out;
  merge_cmd->add_option("shards", merge_inputs, "results.json of every shard")->required();
  merge_cmd->add_option("-o,--out", merge_out, "the merged results.json")->required();
  bool merge_mixed = false;
  merge_cmd->add_flag("--mixed-machines", merge_mixed,
                      "merge shards that ran on different CPU models or builds (their timings are not comparable; the "
                      "merged context is marked mixed_machines)");

  auto* baseline_cmd = app.add_subcommand("baseline", "Manage the committed baselines of the regression gate");
  auto* baseline_update = baseline_cmd->add_subcommand(
      "update", "Accept an intended change: rewrite the baseline from a results file and print what changed");
  baseline_cmd->require_subcommand(1);
  std::string bl_results, bl_file = "reports/baselines/quick.json";
  baseline_update->add_option("results", bl_results, "results.json of `growbench suite --instructions`")->required();
  baseline_update->add_option("--baseline", bl_file, "the baseline file to rewrite")->default_val("reports/baselines/quick.json");

  auto* report_cmd = app.add_subcommand(
      "report", "Figures (PNG, PDF), LaTeX and Markdown tables and index.html from a results file alone");
  std::string report_results, report_out;
  report_cmd->add_option("results", report_results, "results.json written by `growbench suite`")->required();
  report_cmd->add_option("-o,--out", report_out, "report directory (default: report/ beside the results file)");

  auto* lsys_cmd = app.add_subcommand(
      "lsystem", "Derive an L-system's string without drawing it: symbol counts, and the string with --print");
  std::string lsys_file;
  std::vector<std::string> lsys_sets;
  std::string lsys_generations;
  std::string lsys_scene;
  std::uint64_t lsys_seed = 1;
  bool lsys_print = false, lsys_examples = false;
  std::size_t lsys_limit = 0;
  lsys_cmd->add_option("grammar", lsys_file, "a .lsys grammar file or an example name (see --examples)");
  lsys_cmd->add_option("-g,--generations", lsys_generations, "generations (default: the grammar's)");
  lsys_cmd->add_option("--set", lsys_sets, "L-system parameter key=value (repeatable; see `growbench list`)");
  lsys_cmd->add_option("--seed", lsys_seed, "random seed")->default_val(1);
  lsys_cmd->add_option("--scene", lsys_scene, "scene for in() and the start point (default: none; in() is 0)");
  lsys_cmd->add_flag("-p,--print", lsys_print, "print the derived string");
  lsys_cmd->add_option("--limit", lsys_limit, "print at most this many modules (0: all)")->default_val(0);
  lsys_cmd->add_flag("--examples", lsys_examples, "list the example grammars");

  auto* summary_cmd = app.add_subcommand("summary", "Print the tables of a results file: per scene, cell by metric");
  std::string results_file;
  summary_cmd->add_option("results", results_file, "results.json written by `growbench suite`")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; any other command-line error is bad input, status 2 like every other.
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    if (*list) {
      for (const auto& e : gb::algorithm_registry()) {
        const auto& info = e.info();
        fmt::print("{}\n  {}\n", info.name, info.summary);
        print_param_table(info.params);
        for (const auto& preset : info.presets) {
          std::vector<std::string> kv;
          for (const auto& [k, v] : preset.values) kv.push_back(fmt::format("{}={}", k, gb::format_value(v)));
          fmt::print("    preset={}: {}\n", preset.name, kv.empty() ? "the defaults above" : fmt::format("{}", fmt::join(kv, " ")));
        }
      }
      return 0;
    }
    if (*scenes) {
      for (const auto& s : gb::standard_scenes()) {
        fmt::print("{}\n  {}\n", s.name, s.summary);
        print_param_table(s.params);
      }
      fmt::print("mesh:PATH.obj or mesh:NAME\n  any OBJ file, or a mesh the repository carries ({}); fitted to the "
                 "standard size unless size=0, on a ground slab unless ground=false; one seed at the foot of its lit "
                 "side (or --seed-at)\n",
                 fmt::join(gb::bundled_meshes(), ", "));
      print_param_table(gb::mesh_scene_params());
      fmt::print("FILE.json\n  a scene file (schema_version 1): meshes, seeds, light, envelope, zones, camera; see "
                 "scenes/README.md\n");
      return 0;
    }
    if (*suite_cmd) {
      // First, while this process is small: the launcher that forks the trials (harness/run/process.hpp).
      std::unique_ptr<gb::Launcher> launcher;
      if (!suite_instructions) launcher = gb::start_trial_launcher();
      gb::Suite suite = gb::load_suite(suite_file);
      if (suite_repetitions > 0) suite.repetitions = suite_repetitions;
      gb::SuiteRunOptions o;
      o.launcher = launcher.get();
      o.out_dir = suite_out;
      o.resume = resume;
      o.quiet = suite_quiet;
      o.instructions = suite_instructions;
      if (!shard.empty()) {
        const auto slash = shard.find('/');
        try {
          if (slash == std::string::npos) throw std::invalid_argument("no slash");
          o.shard_index = std::stoi(shard.substr(0, slash));
          o.shard_count = std::stoi(shard.substr(slash + 1));
        } catch (const std::exception&) {
          throw gb::InputError(fmt::format("--shard '{}': expected I/N with 0 <= I < N", shard));
        }
        if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
          throw gb::InputError(fmt::format("--shard '{}': expected I/N with 0 <= I < N", shard));
      }
      if (o.instructions)
        fmt::print("suite {}: {} cells, each once, single-threaded, under callgrind (instruction counts per phase)\n",
                   suite.name, suite.configs.size());
      else
        fmt::print("suite {}: {} cells x {} repetitions (+{} warm-up)\n", suite.name, suite.configs.size(),
                   suite.repetitions, suite.warmup);
      std::optional<gb::RenderQuality> quality;
      if (!suite_render.empty()) quality = gb::parse_render_quality(suite_render, "--render");
      const std::string path = gb::run_suite(suite, o);
      {
        std::ifstream in(path);
        const auto results = nlohmann::json::parse(in);
        fmt::print("{}", gb::summarize_results(results));
        fmt::print("\nwrote {} and results.csv beside it\n", path);
      }
      if (!suite_history.empty()) fmt::print("history: appended to {}\n", gb::history_add(path, suite_history));
      if (quality) {
        gb::RenderDirOptions ro;
        ro.render.quality = *quality;
        ro.quiet = suite_quiet;
        const auto r = gb::render_directory(std::filesystem::path(path).parent_path().string(), ro);
        fmt::print("rendered {} trials ({} failed) in {:.0f} s; grid: {}\n", r["renders"].get<int>(), r["failed"].get<int>(),
                   r["wall_s"].get<double>(), (std::filesystem::path(path).parent_path() / r.value("grid", "")).string());
      }
      return 0;
    }
    if (*lsys_cmd) {
      if (lsys_examples) {
        for (const auto& name : gb::lsystem_examples()) fmt::print("{}\n", name);
        return 0;
      }
      gb::Params params = gb::default_params(gb::find_algorithm("lsystem"));
      if (!lsys_file.empty()) params.set("grammar", lsys_file);
      if (!lsys_generations.empty()) params.set("generations", lsys_generations);
      for (const auto& a : lsys_sets) params.set_assignment(a);
      std::optional<gb::Scene> scene;
      std::unique_ptr<gb::SceneQuery> query;
      if (!lsys_scene.empty()) {
        scene = gb::load_scene(lsys_scene);
        query = std::make_unique<gb::SceneQuery>(*scene);
      }
      const auto t0 = std::chrono::steady_clock::now();
      const gb::DerivedString d = gb::derive_lsystem(params, lsys_seed, scene ? &*scene : nullptr, query.get(), lsys_limit);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (lsys_print) {
        fmt::print("{}", d.text);
        if (lsys_limit && d.modules > lsys_limit) fmt::print(" ... ({} more modules)", d.modules - lsys_limit);
        fmt::print("\n");
      }
      fmt::print(stderr, "generation {}: {} modules, {} parameters, {:.1f} MiB, derived in {:.3f} s\n", d.generations,
                 d.modules, d.params, d.bytes / (1024.0 * 1024.0), secs);
      for (const auto& [c, n] : d.counts) fmt::print(stderr, "  {}  {}\n", c, n);
      return 0;
    }
    if (*trial_cmd) {
      std::ifstream in(trial_spec_file);
      if (!in) throw gb::InputError(fmt::format("{}: cannot open", trial_spec_file));
      gb::TrialSpec ts = gb::trial_spec_from_json(nlohmann::json::parse(in));
      if (!trial_fault.empty()) ts.fault = trial_fault;
      return gb::run_trial_child(ts, ts.out_dir);
    }
    if (*ab_cmd) {
      const gb::Suite suite = gb::load_suite(ab_suite);
      const gb::AbResult r = gb::run_ab(suite, ab_opts);
      fmt::print("{}", r.table);
      return r.regression ? 1 : 0;
    }
    if (*compare_cmd) {
      const auto r = gb::compare_results(gb::read_results_file(cmp_base), gb::read_results_file(cmp_new), cmp_opts);
      fmt::print("{}", r.table());
      return r.fails() ? 1 : 0;
    }
    if (*merge_cmd) {
      std::vector<nlohmann::json> shards;
      for (const auto& f : merge_inputs) shards.push_back(gb::read_results_file(f));
      const auto merged = gb::merge_results(shards, merge_inputs, merge_mixed);
      const auto parent = std::filesystem::path(merge_out).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      const std::string text = merged.dump(1) + "\n";
      gb::write_file_atomic(merge_out, text.data(), text.size());
      if (merged["context"].value("mixed_machines", false))
        fmt::print(stderr, "growbench: warning: the shards ran on different machines or builds; their timings are not comparable\n");
      fmt::print("merged {} shards, {} cells, into {}\n", shards.size(), merged["trials"].size(), merge_out);
      return 0;
    }
    if (*history_add) {
      fmt::print("appended to {}\n", gb::history_add(hist_results, hist_dir, hist_machine));
      return 0;
    }
    if (*history_plot) return gb::history_plot(hist_dir, hist_out);
    if (*baseline_update) {
      const auto results = gb::read_results_file(bl_results);
      if (results.value("mode", "") != "instructions")
        fmt::print(stderr, "growbench: warning: {} was not run with --instructions: the baseline will hold no instruction "
                           "counts\n", bl_results);
      const auto fresh = gb::baseline_of(results);
      if (std::filesystem::exists(bl_file)) {
        const auto r = gb::compare_results(gb::read_results_file(bl_file), fresh, {});
        fmt::print("changes accepted into {}:\n{}", bl_file, r.changes.empty() && r.missing_cells.empty() && r.new_cells.empty()
                                                            ? std::string("(none)\n") : r.table());
      } else {
        fmt::print("new baseline {} with {} cells\n", bl_file, fresh["trials"].size());
      }
      std::filesystem::create_directories(std::filesystem::path(bl_file).parent_path().empty()
                                              ? std::filesystem::path(".") : std::filesystem::path(bl_file).parent_path());
      gb::write_file_atomic(bl_file, fresh.dump(1) + "\n");
      return 0;
    }
    if (*render_cmd) {
      render_opts.render.quality = gb::parse_render_quality(render_quality);
      const auto r = gb::render_directory(render_dir, render_opts);
      fmt::print("rendered {} images ({} failed, {} POV-Ray warnings) in {:.1f} s with {} POV-Ray processes at once\n",
                 r["renders"].get<int>(), r["failed"].get<int>(), r["warnings"].get<int>(), r["wall_s"].get<double>(),
                 r["jobs"].get<int>());
      if (r.contains("grid")) fmt::print("grid: {}\n", (std::filesystem::path(render_dir) / r["grid"].get<std::string>()).string());
      return r["failed"].get<int>() > 0 ? 1 : 0;
    }
    if (*report_cmd) {
      if (report_out.empty()) report_out = (std::filesystem::path(report_results).parent_path() / "report").string();
      return gb::run_report(report_results, report_out, {});
    }
    if (*summary_cmd) {
      std::ifstream in(results_file);
      if (!in) throw gb::InputError(fmt::format("{}: cannot open results file", results_file));
      nlohmann::json results;
      try {
        results = nlohmann::json::parse(in);
      } catch (const nlohmann::json::exception& e) {
        throw gb::InputError(fmt::format("{}: not valid JSON: {}", results_file, e.what()));
      }
      if (!results.contains("trials") || results.value("kind", "") != "growbench-results")
        throw gb::InputError(fmt::format("{}: not a growbench results file (no kind/trials)", results_file));
      fmt::print("{}", gb::summarize_results(results));
      return 0;
    }
    if (*run) {
      for (const auto& s : seed_at) spec.seed_at.push_back(parse_point(s));
      if (out_dir.empty()) {
        std::string name = spec.scene;
        if (name.rfind("mesh:", 0) == 0) name = std::filesystem::path(name.substr(5)).stem().string();
        else if (name.size() > 5 && name.substr(name.size() - 5) == ".json") name = std::filesystem::path(name).stem().string();
        out_dir = fmt::format("out/{}-{}", spec.algorithm, name);
      }
      spec.out_dir = out_dir;
      std::optional<gb::RenderQuality> quality;
      if (!run_render.empty()) quality = gb::parse_render_quality(run_render, "--render");
      const bool tty = isatty(STDERR_FILENO) != 0;
      auto last = std::chrono::steady_clock::now();
      auto progress = [&](const gb::Progress& p) {
        if (quiet) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - last < std::chrono::seconds(1)) return;
        last = now;
        fmt::print(stderr, "{}growing: step {}, {} nodes, {:.1f} s{}", tty ? "\r" : "", p.step, p.nodes, p.growth_seconds,
                   tty ? "   " : "\n");
      };
      const nlohmann::json rec = gb::run_trial(spec, progress);
      if (!quiet && isatty(STDERR_FILENO)) fmt::print(stderr, "\r{:60}\r", "");
      const auto& ph = rec["phases"];
      fmt::print("{} on {} (seed {}, {} threads): {} steps ({}), {} nodes, {} leaves, {:.2f} m of branches\n",
                 rec["algorithm"].get<std::string>(), rec["scene"]["name"].get<std::string>(), spec.seed,
                 rec["threads"].get<int>(), rec["steps"].get<int>(), rec["stopped_by"].get<std::string>(),
                 rec["counts"]["nodes"].get<std::size_t>(), rec["counts"]["leaves"].get<std::size_t>(),
                 rec["total_length_m"].get<double>());
      fmt::print("  time: scene {:.3f} s, query {:.3f} s, growth {:.3f} s, meshing {:.3f} s, export {:.3f} s; peak RSS {:.1f} MiB\n",
                 ph["scene_load"]["wall_s"].get<double>(), ph["query_build"]["wall_s"].get<double>(),
                 ph["growth"]["wall_s"].get<double>(), ph["meshing"]["wall_s"].get<double>(),
                 ph["export"]["wall_s"].get<double>(), rec["peak_rss_bytes"].get<double>() / (1024.0 * 1024.0));
      fmt::print("  wrote {}/plant.obj, plant.ply, plant.glb, skeleton.obj, record.json (geometry hash {})\n", out_dir,
                 rec["geometry_hash"].get<std::string>());
      if (rec.contains("frames"))
        fmt::print("  kept {} frames in {}/frames (capture took {:.3f} s, not counted in growth)\n",
                   rec["frames"]["count"].get<int>(), out_dir, ph["growth"]["frame_capture_wall_s"].get<double>());
      if (quality) {
        gb::RenderDirOptions ro;
        ro.render.quality = *quality;
        ro.quiet = quiet;
        const auto r = gb::render_directory(out_dir, ro);
        std::ifstream in(std::filesystem::path(out_dir) / "record.json");
        const auto updated = nlohmann::json::parse(in);
        const auto& rr = updated["render"];
        if (rr["status"] == "ok")
          fmt::print("  rendered {}/render.png ({}x{}, {}) in {:.2f} s of POV-Ray{}\n", out_dir, rr["width"].get<int>(),
                     rr["height"].get<int>(), gb::to_string(*quality), rr["wall_s"].get<double>(),
                     updated.contains("animation") ? fmt::format(", {} frames: {}", updated["animation"]["frames"].get<int>(),
                                                                 updated["animation"].value("file", updated["animation"]["status"].get<std::string>()))
                                                   : "");
        else
          fmt::print(stderr, "growbench: render failed: {}\n", rr.value("message", rr["status"].get<std::string>()));
        return r["failed"].get<int>() > 0 ? 1 : 0;
      }
      return 0;
    }
  } catch (const gb::InputError& e) {
    fmt::print(stderr, "growbench: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "growbench: failed: {}\n", e.what());
    return 1;
  }
  return 0;
}
