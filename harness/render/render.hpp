// Rendering with POV-Ray: one scene writer for every algorithm (the same materials, camera, light, sky
// and ground), POV-Ray run as a child process with its time recorded apart from the algorithm's, and
// comparison grids composed with cairo.
//
// Coordinates: growbench is right-handed with Y up; POV-Ray is left-handed with Y up. The writer
// negates Z everywhere (points, normals, instance matrices, camera and light), which mirrors nothing
// in the image. The scene camera's fov_deg is the vertical field of view. The camera a render uses is the
// scene's or one framing the plant (camera.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "algorithms/plant.hpp"
#include "harness/output/mesher.hpp"
#include "harness/render/camera.hpp"
#include "scenes/scene.hpp"

namespace growbench {

enum class RenderQuality { Preview, Paper };
// "preview" or "paper"; anything else is an InputError naming the option.
RenderQuality parse_render_quality(const std::string& text, const std::string& option = "--quality");
const char* to_string(RenderQuality q);

// What stands behind the plant: the scene's sky and ground plane, or a studio sweep (a seamless grey
// floor curving up into a wall behind the plant, turned to face the camera) in their place, with only the
// scene meshes a plant climbs on (and those its decals lie on) kept.
enum class Backdrop { Scene, Studio };
// "scene" or "studio"; anything else is an InputError naming the option.
Backdrop parse_backdrop(const std::string& text, const std::string& option = "--backdrop");
const char* to_string(Backdrop b);

struct RenderOptions {
  // preview: 480x360, no anti-aliasing, one sun with hard shadows and a weak fill light (CI, quick looks).
  // paper: 1600x1200, adaptive anti-aliasing, an area light for soft shadows and radiosity.
  RenderQuality quality = RenderQuality::Preview;
  int width = 0, height = 0;  // 0: the preset's size
  int threads = 1;            // POV-Ray's +WT for one render
  // "cones": each segment a cone with a sphere at each joint (POV-Ray's own primitives, exactly round);
  // "mesh": the shared mesher's tubes as one mesh2. Cones are the default: see CONTRIBUTING.md for the
  // measured render times.
  std::string branches = "cones";
  // Branches narrower on screen than this many pixels are drawn this wide (branches=cones), so that a thin
  // stem far from the camera stays in the picture rather than falling between pixels, as production
  // renderers' minimum pixel width for curves does; 0 draws true widths.
  float min_branch_px = 1.0f;
  bool draw_plant = true;  // false: the scene alone (the tests compare renders with and without the plant)
  double timeout_s = 900.0;
  MesherOptions mesher;                  // tube sides (branches=mesh) and the leaf shape
  CameraMode camera = CameraMode::Auto;  // camera.hpp's choose_camera
  // Depth of field (paper quality only: check_render_options): in focus at the plant's centre, the
  // aperture from camera.hpp's focal_blur.
  bool dof = false;
  Backdrop backdrop = Backdrop::Scene;
  // A turntable frame (turns > 0): frame `turn` of `turns`, camera.hpp's turntable_camera; the light
  // turns with the camera. The camera option does not apply: every frame is framed.
  int turn = 0, turns = 0;
  // The box the camera frames and focuses on, when not empty; else the plant's own (plant_bounds). A
  // growth frame takes the grown plant's, so the animation's camera stands still.
  Aabb subject;
  // The plant-pixel mask pass (render_plant's, for plant_pixel_share): POV-Ray reads the file with GB_Mask
  // declared, which draws the plant glowing and the rest black, without lights.
  bool mask = false;
  // Called every few seconds while POV-Ray renders, with the share of the image's pixels done (negative
  // while it parses or traces radiosity's pretrace) and the seconds since it started; empty: no progress.
  std::function<void(double done, double elapsed_s)> progress;
};

// InputError naming the option for options that cannot render: depth of field in preview quality (a
// preview stays quick: focal blur traces many rays a pixel).
void check_render_options(const RenderOptions& o);

[[nodiscard]] int render_width(const RenderOptions& o);
[[nodiscard]] int render_height(const RenderOptions& o);

// The camera and light a render uses: the scene's camera or one framing the plant (options.camera), or a
// turntable frame's orbit, and the scene's light (turned with a turntable's camera).
struct RenderView {
  Camera camera;
  Light light;
  Aabb subject;            // what is framed and focused on: the plant's bounds (options.subject if set)
  bool fitted = false;     // the camera was moved to frame the subject
  float scene_extent = 0;  // the subject's projected extent with the scene camera (camera.hpp)
  float extent = 0;        // ... and with this camera
  Sight seen;              // the share of the plant's points in this camera's frame, and visible past the scene
  float turn_deg = 0, raise_deg = 0;           // a fitted camera's turn about the plant and rise above the scene's view
  [[nodiscard]] std::string describe() const;  // a line for the .pov file's header
};
RenderView render_view(const Scene& scene, const Plant& plant, const RenderOptions& options);
// `base` (render_view's) with each of camera.hpp's camera_ring cameras in turn (auto mode's candidates).
std::vector<RenderView> ring_views(const Scene& scene, const Plant& plant, const RenderOptions& options,
                                   const RenderView& base);
// An auto-camera render whose plant shows on fewer of its pixels than this tries every ring camera as a
// small mask render and keeps the one that shows the plant on the most pixels (render_plant).
constexpr double kFewPlantPixels = 0.01;

// Writes a POV-Ray 3.7 scene file (`#version 3.7`, `assumed_gamma 1.0`): the scene's meshes as mesh2,
// the plant's branches, its leaves and flowers instanced from one declared mesh each, render_view's
// camera and light, a sky and a ground plane (or the studio backdrop). Returns the bytes written.
// A plant with decals is drawn by them instead: each image is a texture layer on top of the meshes it
// lies on (through a mesh's texture coordinates, or projected onto every climbable mesh), its alpha
// showing the surface below. Their names are written as they are, so POV-Ray reads them from its working
// directory, the image's (run_povray); InputError when a decal cannot be drawn (decal_problem).
std::uint64_t write_pov(const std::string& path, const Scene& scene, const Plant& plant, const RenderOptions& options);
// Why the plant's decals cannot be drawn in `scene`: a mesh it does not have, or one without texture
// coordinates, or a planar decal whose axes span no plane. "" when they can.
std::string decal_problem(const Scene& scene, const Plant& plant);

struct RenderResult {
  std::string status = "ok";          // ok | failed | timeout | no_povray
  std::string message;                // why it failed, with POV-Ray's own error lines
  std::vector<std::string> warnings;  // POV-Ray's warning lines (a clean scene has none)
  std::string pov, png, log;          // the files (paths as given)
  int width = 0, height = 0;
  std::string camera;      // "scene" or "fitted" (RenderView::fitted); "" when nothing was written
  float scene_extent = 0;  // RenderView's
  Sight seen;              // RenderView's
  // The share of the image's pixels that show the plant (a render of the same file as a mask, at a quarter
  // of the size); negative when not measured (a growth or turntable frame, no plant drawn, a failed render).
  double plant_pixel_share = -1.0;
  std::uint64_t pov_bytes = 0;
  double write_s = 0.0;              // writing the .pov file
  double wall_s = 0.0, cpu_s = 0.0;  // the POV-Ray process (parse + render), apart from the trial's time
  [[nodiscard]] bool ok() const { return status == "ok"; }
  [[nodiscard]] nlohmann::json to_json() const;
};

// The povray binary on PATH ("" when there is none).
std::string find_povray();
// `povray --version`'s first line ("" when there is no povray).
std::string povray_version();

// Runs POV-Ray on POV_PATH writing PNG_PATH (its log beside the PNG, .log). Never throws for a POV-Ray
// failure: the result's status and message say what happened. Safe to call from several threads.
// POV-Ray runs in WORK_DIR (PNG_PATH's directory when empty), where it reads decal images; the .pov file
// and the image must be in it or below it (Debian's povray.conf allows no other).
RenderResult run_povray(const std::string& pov_path, const std::string& png_path, const RenderOptions& options,
                        const std::string& work_dir = "");

// write_pov, then run_povray. The .pov file is kept beside the image for inspection. The images of the
// plant's decals must be in WORK_DIR (PNG_PATH's directory when empty): when one is missing or cannot be
// drawn, the result is "failed" with a message saying which, and POV-Ray is not run.
RenderResult render_plant(const Scene& scene, const Plant& plant, const std::string& pov_path,
                          const std::string& png_path, const RenderOptions& options, const std::string& work_dir = "");

// A grid is drawn to be read when printed kGridPrintWidthIn wide: its labels are then at least
// kGridMinLabelPt high (their pixel size grows with the image's width).
constexpr double kGridPrintWidthIn = 7.0, kGridMinLabelPt = 8.0;
// growbench render splits a suite's grid into pages of at most this many scenes (columns).
constexpr std::size_t kGridPageScenes = 4;

// Where each cell's image lies in a grid image, in pixels (for an image map linking cells to trials).
struct GridCell {
  int row = 0, col = 0, x = 0, y = 0, w = 0, h = 0;
};
struct GridLayout {
  int width = 0, height = 0;
  double label_px = 0.0;  // the labels' font size
  std::vector<GridCell> cells;
};

// One labelled image: `cells` is rows x cols PNG paths (an empty path or a missing file draws a grey
// box with `notes[r][c]`, if given). A non-empty `badges[r][c]` is written in a band across the top of that
// cell's image (a plant left out of comparisons: "degenerate" in red, anything else in grey). Throws
// std::runtime_error naming the file it cannot write.
GridLayout write_grid(const std::string& png_path, const std::string& title, const std::vector<std::string>& row_labels,
                      const std::vector<std::string>& col_labels, const std::vector<std::vector<std::string>>& cells,
                      const std::vector<std::vector<std::string>>& notes = {},
                      const std::vector<std::vector<std::string>>& badges = {}, int cell_width = 320);

// The same for a list of images each with its own caption above it, `per_row` to a row (a scene's
// entries): no row labels to repeat the title. notes[k] and badges[k] as in write_grid.
GridLayout write_captioned_grid(const std::string& png_path, const std::string& title,
                                const std::vector<std::string>& captions, const std::vector<std::string>& images,
                                const std::vector<std::string>& notes, const std::vector<std::string>& badges,
                                int per_row = 4, int cell_width = 320);

}  // namespace growbench
