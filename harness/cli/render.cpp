// growbench render: render a suite's results directory or a run directory with POV-Ray.
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/render/render_results.hpp"
#include "harness/run/trial.hpp"

namespace growbench::cli {

namespace {

struct RenderArgs {
  std::string dir, quality = "preview";
  RenderFlags flags;
  RenderDirOptions options;
};

Outcome render_dir(RenderArgs& a) {
  apply_render_flags(a.flags, parse_render_quality(a.quality), a.options);
  const RenderSummary r = render_directory_record(a.dir, a.options);
  fmt::print("rendered {} images ({} failed, {} POV-Ray warnings) in {:.1f} s with {} POV-Ray processes at once\n",
             r.renders, r.failed, r.warnings, r.wall_s, r.jobs);
  if (r.grid) fmt::print("grid: {}\n", (std::filesystem::path(a.dir) / *r.grid).string());
  // A failed render is POV-Ray failing on the scene file growbench wrote (the record's message and the log
  // say why): an internal error.
  return r.failed > 0 ? Outcome::failed : Outcome::ok;
}

}  // namespace

Command add_render(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render", "Render a suite's results directory (every trial, then grid.png) or a `run` directory with POV-Ray");
  auto a = std::make_shared<RenderArgs>();
  RenderOptions& ro = a->options.render;
  cmd->add_option("dir", a->dir, "a directory with results.json (suite) or record.json (run)")->required();
  cmd->add_option("--quality", a->quality,
                  "preview (480x360, no anti-aliasing) or paper (1600x1200, "
                  "anti-aliased, soft shadows, radiosity)")
      ->default_val("preview");
  cmd->add_option("-j,--jobs", a->options.jobs, "POV-Ray processes at once (0: one per core)")
      ->default_val(0)
      ->check(integer_in(0, kMaxThreads));
  cmd->add_option("--width", ro.width, "image width (0: the quality's)")->default_val(0)->check(integer_in(0, 16384));
  cmd->add_option("--height", ro.height, "image height (0: the quality's)")
      ->default_val(0)
      ->check(integer_in(0, 16384));
  cmd->add_option("--branches", ro.branches,
                  "branches as cones (cone and sphere chains) or mesh "
                  "(the mesher's tubes as mesh2; always for tubes an L-system's tension or branch_blend curves)")
      ->default_val("cones")
      ->check(CLI::IsMember({"cones", "mesh"}));
  cmd->add_option("--min-branch-px", ro.min_branch_px,
                  "draw cone branches at least this many pixels wide on screen, so that thin stems stay visible "
                  "(0: true widths)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 64.0f));
  add_render_flags(cmd, a->flags);
  cmd->add_flag("-q,--quiet", a->options.quiet, "no progress lines");
  return {cmd, [a] { return render_dir(*a); }};
}

}  // namespace growbench::cli
