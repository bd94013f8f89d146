// The render options shared by run --render, suite --render and render (command.hpp's RenderFlags).
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/cli/command.hpp"
#include "harness/render/render_results.hpp"

namespace growbench::cli {

void add_render_flags(CLI::App* cmd, RenderFlags& f, CLI::Option* needs) {
  CLI::Option* camera =
      cmd->add_option("--camera", f.camera,
                      "auto: when the scene's camera shows the plant small (its box under 35% of the frame), a camera "
                      "that frames it with a 10% margin, keeping the view direction and field of view; scene: the "
                      "scene's camera")
          ->default_val("auto");
  CLI::Option* dof = cmd->add_flag("--dof", f.dof,
                                   "paper quality only: depth of field, in focus at the plant's centre, the plant "
                                   "sharp and the background softened");
  CLI::Option* backdrop =
      cmd->add_option("--backdrop", f.backdrop,
                      "scene: the sky and the ground plane; studio: a seamless grey sweep behind the plant instead, "
                      "keeping only the scene meshes the plant climbs on")
          ->default_val("scene");
  f.turntable_option = cmd->add_option("--turntable", f.turntable,
                                       "also render N frames with the camera orbiting the plant's vertical axis, "
                                       "framed at every angle (turntable/frame_NNNN.png) and, with ffmpeg, "
                                       "turntable.mp4");
  if (needs)
    for (CLI::Option* o : {camera, dof, backdrop, f.turntable_option}) o->needs(needs);
}

void apply_render_flags(const RenderFlags& f, RenderQuality quality, RenderDirOptions& o) {
  o.render.quality = quality;
  o.render.camera = parse_camera_mode(f.camera, "--camera");
  o.render.backdrop = parse_backdrop(f.backdrop, "--backdrop");
  o.render.dof = f.dof;
  if (f.turntable_option && f.turntable_option->count() > 0 && f.turntable < 1)
    throw InputError(fmt::format("--turntable {}: expected a number of frames >= 1", f.turntable));
  o.turntable = f.turntable;
  check_render_options(o.render);
}

}  // namespace growbench::cli
