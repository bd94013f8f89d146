// Rendering what trials grew, after the fact: every trial of a suite's results directory (or the one
// trial of a `growbench run` directory) from its plant snapshot (plant.gbplant) and its scene, several
// POV-Ray processes at once; then the comparison grids and, where frames were captured, the growth
// animation.
#pragma once

#include <string>

#include "harness/record/record.hpp"
#include "harness/render/render.hpp"

namespace growbench {

struct RenderDirOptions {
  RenderOptions render;  // render.threads is set per job from `jobs`
  int jobs = 0;          // POV-Ray processes at once (0: one per core)
  bool quiet = false;    // no progress lines
  int turntable = 0;     // frames of a turntable per trial (0: none)
};

// DIR holds results.json (a suite: renders each trial to trials/ID/render.png, writes grid.png with
// algorithms as rows and scenes as columns, grid-SCENE.png per scene, and records every render in
// results.json under "renders" and each trial's "render") or record.json (one run: render.png, recorded
// in record.json). Frames captured with --frames (frames/step_NNNNNN.gbplant) become frames/step_NNNNNN.png
// and, when ffmpeg is installed, animation.mp4, every frame framed as the grown plant is. With a turntable
// of N frames, each trial's turntable/frame_NNNN.png (the camera orbiting the plant: RenderOptions::turn)
// and turntable.mp4, recorded as its "turntable". A failed render is recorded, never fatal; results already
// written are kept. Throws InputError when DIR is neither (or its file does not read as one). Returns the
// "renders" summary.
RenderSummary render_directory_record(const std::string& dir, const RenderDirOptions& options);

}  // namespace growbench
