// growbench run: grow one plant, measure it, write its meshes and record, and optionally render it.
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/params.hpp"
#include "harness/output/exporters.hpp"
#include "harness/record/files.hpp"
#include "harness/cli/command.hpp"
#include "harness/record/record.hpp"
#include "harness/render/render_results.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"

namespace growbench::cli {

namespace {

struct RunArgs {
  TrialSpec spec;
  std::vector<std::string> seed_at;
  std::string out_dir;
  bool quiet = false;
  std::string render;
  RenderFlags render_flags;
};

// X,Y,Z as a point, as given (the trial rounds it to the float a scene's positions have).
std::array<double, 3> parse_point(const std::string& text) {
  Params p("--seed-at", {{"at", ParamType::Vec3, glm::dvec3(0.0), -kMaxCoordinate, kMaxCoordinate, "m", "", {}}});
  p.set("at", text);
  const glm::dvec3 v = p.vec3("at");
  return {v.x, v.y, v.z};
}

// out/ALGORITHM-SCENE, the scene named by a mesh's or a scene file's stem.
std::string default_out_dir(const TrialSpec& spec) {
  std::string name = spec.scene;
  if (name.rfind("mesh:", 0) == 0)
    name = std::filesystem::path(name.substr(5)).stem().string();
  else if (name.size() > 5 && name.substr(name.size() - 5) == ".json")
    name = std::filesystem::path(name).stem().string();
  return fmt::format("out/{}-{}", spec.algorithm, name);
}

void print_record(const TrialRecord& rec, const TrialSpec& spec, const std::string& out_dir) {
  const TrialResults& r = rec.results;
  fmt::print("{} on {} (seed {}, {} threads): {} steps ({}), {} nodes, {} leaves, {:.2f} m of branches\n",
             rec.algorithm, rec.scene.name, spec.seed, r.threads, r.steps, r.stopped_by, r.counts.nodes,
             r.counts.leaves, r.total_length_m);
  std::string times;  // each phase that ran, in pipeline order
  rec.phases.each(
      [&](Phase p, const PhaseMeasures& m) { times += fmt::format("{} {:.3f} s, ", phase_name(p), m.wall_s); });
  fmt::print("  time: {}peak RSS {:.1f} MiB\n", times, static_cast<double>(rec.peak_rss_bytes) / (1024.0 * 1024.0));
  std::string own;  // the algorithm's own files (the vines' texture), as the record lists them
  for (const auto& [name, bytes] : r.output_bytes.algorithm_files) own += ", " + name;
  fmt::print(
      "  wrote {}/plant.obj, plant.ply, plant.glb, plant.gbplant, skeleton.obj, skeleton.ply{}, record.json, scene.glb "
      "(geometry hash {})\n",
      out_dir, own, r.geometry_hash);
  if (rec.frames)
    fmt::print("  kept {} frames in {}/frames (capture took {:.3f} s, not counted in growth)\n", rec.frames->count,
               out_dir, rec.phases[Phase::growth].value().frame_capture_wall_s.value());
}

// What the record says of the render's camera: "" for the scene's, else how the plant was framed.
std::string camera_note(const RenderRecord& rr) {
  if (rr.camera.value_or("scene") != "fitted") return "";
  return fmt::format(", camera fitted: the plant spanned {:.2f} of the scene camera's frame",
                     rr.scene_extent.value_or(0.0));
}

// Renders the run directory and reports what the record says of it. A render that failed is POV-Ray failing
// on the scene file growbench wrote (its log says why): an internal error.
Outcome render_run(const std::string& out_dir, const RenderDirOptions& ro) {
  const RenderQuality quality = ro.render.quality;
  const RenderSummary r = render_directory_record(out_dir, ro);
  const std::string record_path = (std::filesystem::path(out_dir) / "record.json").string();
  const TrialRecord updated = read_trial_record(record_path);
  if (!updated.media.render)
    throw std::runtime_error(fmt::format("{}: at render: expected the render just made, found none", record_path));
  const RenderRecord& rr = *updated.media.render;
  auto video = [](const std::optional<AnimationRecord>& a, const char* what) {
    return a ? fmt::format(", {} {} frames: {}", a->frames, what, a->file.value_or(a->status)) : std::string();
  };
  if (rr.status == "ok")
    fmt::print("  rendered {}/render.png ({}x{}, {}{}) in {:.2f} s of POV-Ray{}{}\n", out_dir, rr.width, rr.height,
               to_string(quality), camera_note(rr), rr.wall_s, video(updated.media.animation, "growth"),
               ro.turntable > 0 ? video(updated.media.turntable, "turntable") : "");
  else
    fmt::print(stderr, "growbench: render failed: {}\n", rr.message.value_or(rr.status));
  return r.failed > 0 ? Outcome::failed : Outcome::ok;
}

Outcome run_one(RunArgs& a) {
  TrialSpec& spec = a.spec;
  for (const auto& s : a.seed_at) spec.seed_at.push_back(parse_point(s));
  if (a.out_dir.empty()) a.out_dir = default_out_dir(spec);
  spec.out_dir = a.out_dir;
  // The render's options are checked before the plant grows, so a bad one costs no growth.
  std::optional<RenderDirOptions> render;
  if (!a.render.empty()) {
    render.emplace();
    apply_render_flags(a.render_flags, parse_render_quality(a.render, "--render"), *render);
    render->quiet = a.quiet;
  }
  const bool tty = isatty(STDERR_FILENO) != 0;
  auto last = std::chrono::steady_clock::now();
  auto progress = [&](const Progress& p) {
    if (a.quiet) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last < std::chrono::seconds(1)) return;
    last = now;
    fmt::print(stderr, "{}growing: step {}, {} nodes, {:.1f} s{}", tty ? "\r" : "", p.step, p.nodes, p.growth_seconds,
               tty ? "   " : "\n");
  };
  const FolderLock lock = FolderLock::take(a.out_dir, "run");
  const TrialRecord rec = run_trial_record(spec, progress);
  // What the plant grew on, beside it, for viewers (not an output of the algorithm: not timed, not counted).
  write_scene_glb((std::filesystem::path(a.out_dir) / "scene.glb").string(), load_scene(spec.scene, spec.scene_params));
  if (!a.quiet && isatty(STDERR_FILENO)) fmt::print(stderr, "\r{:60}\r", "");
  print_record(rec, spec, a.out_dir);
  for (const auto& w : rec.results.warnings) fmt::print(stderr, "warning: {}\n", w);
  return render ? render_run(a.out_dir, *render) : Outcome::ok;
}

}  // namespace

Command add_run(CLI::App& app) {
  auto* run = app.add_subcommand("run", "Grow one plant: one algorithm on one scene, measured, written to --out");
  auto a = std::make_shared<RunArgs>();
  TrialSpec& spec = a->spec;
  run->add_option("-a,--algorithm", spec.algorithm, "algorithm name (see `growbench list`)")->required();
  run->add_option(
         "-s,--scene", spec.scene,
         "scene: a standard scene's name (see `growbench scenes`), a scene file *.json, mesh:PATH.obj, or mesh:NAME "
         "for a bundled mesh (e.g. mesh:stanford-bunny)")
      ->required();
  run->add_option("--scene-param", spec.scene_params, "scene parameter key=value (repeatable)");
  add_spec_option(run, "--seed", spec, "seed");
  run->add_option("--set", spec.params, "algorithm parameter key=value (repeatable)");
  add_plugin_option(run, spec.plugins);
  run->add_option("--seed-at", a->seed_at,
                  "seed position X,Y,Z, snapped to the nearest surface (repeatable; replaces the scene's seeds)");
  add_spec_option(run, "--max-steps", spec, "max_steps");
  add_spec_option(run, "--time-limit", spec, "time_limit_s");
  add_spec_option(run, "-t,--threads", spec, "threads");
  add_spec_option(run, "--voxel-size", spec, "voxel_size");
  add_spec_option(run, "--band-voxels", spec, "band_voxels");
  add_spec_option(run, "--sides", spec, "sides");
  add_spec_option(run, "--budget-nodes", spec, "budget_nodes");
  add_spec_option(run, "--budget-length", spec, "budget_length_m");
  add_spec_option(run, "--glb", spec, "glb",
                  "layout of plant.glb: compact (instanced organs, quantized and meshopt-compressed; the default), "
                  "instanced (no compression) or plain (core glTF, floats: every reader loads it)");
  add_spec_option(run, "--leaf-obj", spec, "leaf_obj",
                  "a custom organ for every leaf, flower and bud whose plant names no shape: an OBJ with the blade "
                  "along +Z from the stem at z = 0 and its upper side toward +Y (scaled to unit length; the organ's "
                  "size sizes it)");
  run->add_option("--organ", spec.organs,
                  "organ pass after growth, key=value (repeatable): placement=avoid, variation, fallbacks; "
                  "`growbench list organs` lists them");
  run->add_option("-o,--out", a->out_dir, "output directory (default: out/ALGORITHM-SCENE)")
      ->check(path_named("an output folder"));
  run->add_flag("-q,--quiet", a->quiet, "no progress line");
  CLI::Option* render =
      run->add_option("--render", a->render, "render the plant with POV-Ray afterwards: preview or paper (render.png)");
  add_render_flags(run, a->render_flags, render);
  add_spec_option(run, "--frames", spec, "frame_every",
                  "growth animation: keep the plant every K steps (frames/); with --render, render them and make "
                  "animation.mp4 with ffmpeg");
  // Test hook, not listed: fault=throw is an unexpected exception, which must exit 3 (README, "Exit status").
  run->add_option("--fault", spec.fault, "inject a fault into the trial (tests)")->group("");
  return {run, [a] { return run_one(*a); }};
}

}  // namespace growbench::cli
