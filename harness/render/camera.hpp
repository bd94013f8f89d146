// The render's camera: the scene's, or one that frames the plant; the turntable's orbit; the depth of
// field that keeps the plant sharp. All in growbench's coordinates (right-handed, Y up); the POV-Ray
// writer converts them. A camera's fov_deg is vertical, and POV-Ray's camera is set up as camera_frame
// says (look_at, sky +Y, square pixels), so project() is where a point lands in the image.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/plant.hpp"
#include "scenes/scene.hpp"

namespace growbench {

enum class CameraMode { Auto, Scene };
// "auto" or "scene"; anything else is an InputError naming the option.
CameraMode parse_camera_mode(const std::string& text, const std::string& option = "--camera");
const char* to_string(CameraMode m);

// The margin a fitted camera leaves between the plant's projected box and each edge of the frame, as a
// fraction of the frame's width (left and right) and height (top and bottom).
constexpr float kFrameMargin = 0.1f;

// What of the plant a render draws, as a box: each node a sphere of its radius, each organ a sphere of its
// size times `organ_reach` (the organ shape's farthest point from its stem at unit size), the polygons'
// vertices. A plant with decals is drawn by them alone, so it is their bounds instead: the scene mesh a
// decal's image follows, and a planar decal's rectangle. Empty for an empty plant.
Aabb plant_bounds(const Scene& scene, const Plant& plant, float organ_reach = 1.0f);

// A camera's axes as POV-Ray sets them up from location, look_at and the default sky +Y: unit right, up
// and forward.
struct CameraFrame {
  glm::vec3 right, up, forward;
};
CameraFrame camera_frame(const Camera& camera);

// Where p lands in the image of `camera` at `aspect` (width / height): x from -1 (left edge) to 1 (right),
// y from -1 (bottom) to 1 (top), z its depth along the view direction (not positive: behind the camera).
glm::vec3 project(const Camera& camera, float aspect, const glm::vec3& p);

// The box's 8 corners (none for an empty box).
std::vector<glm::vec3> corners(const Aabb& box);

// How much of the frame `box` covers: its projected corners' extent, clipped to the frame, as a fraction
// of the frame's width or of its height, whichever is larger. 0 for an empty box or one with a corner
// behind the camera.
float projected_extent(const Camera& camera, float aspect, const Aabb& box);

// The camera with `camera`'s view direction and vertical field of view, moved along and across that
// direction, that frames `points`: each lies at least `margin` of the frame's width and height inside the
// frame's edges, and on the tighter axis their projection spans the rest of the frame, centred. An exact
// fit of the perspective projection, not of a bounding sphere. `camera` itself when there are no points.
Camera fit_camera(const Camera& camera, float aspect, const std::vector<glm::vec3>& points,
                  float margin = kFrameMargin);

// The plant as the points a camera must show: its nodes (at most `max_points`, evenly spaced in the node
// order), organs and polygon vertices; a plant drawn by decals, the corners of plant_bounds. Empty for an
// empty plant.
std::vector<glm::vec3> plant_points(const Scene& scene, const Plant& plant, std::size_t max_points = 2048);

// Whether a scene surface lies between the two points (the render's scene meshes; harness/render's
// SceneQuery casts the ray). Null: nothing ever blocks the view.
using SightBlocked = std::function<bool(const glm::vec3& eye, const glm::vec3& p)>;

// What a camera shows of a set of points: the share in front of it and inside the frame, and the share
// inside the frame with no scene surface in the way (visible). 1 and 1 for no points.
struct Sight {
  float in_frame = 1.0f, visible = 1.0f;
};
Sight sight(const Camera& camera, float aspect, const std::vector<glm::vec3>& points, const SightBlocked& blocked);

// The camera a render uses, and why.
struct RenderCamera {
  Camera camera;
  bool fitted = false;                      // moved to frame the plant
  float scene_extent = 0.f;                 // the plant's projected_extent with the scene camera
  Sight seen;                               // what this camera shows of the plant's points
  float turn_deg = 0.0f, raise_deg = 0.0f;  // how far a fitted camera turned about the plant and rose
};

// The `auto` rule, in one place. The scene camera, when it shows the whole plant (every point in frame),
// sees at least kVisibleEnough of it past the scene, and the plant's box spans at least kSmallPlantExtent
// of the frame: it frames its scene as the author meant, and grids stay comparable across algorithms.
// Otherwise a camera fitted to the plant's points (fit_camera, never cropping), with some of the scene
// around it for context (the frame at least kContextShare of the scene's diagonal across), looking from
// the scene camera's side when enough is visible from there, else from the first of a ring of turns about
// the plant and rises above it that sees kVisibleEnough, else the one that sees most. `scene` always keeps
// the scene camera; no points keep it too.
constexpr float kSmallPlantExtent = 0.65f, kVisibleEnough = 0.9f, kContextShare = 0.05f;
// The ring choose_camera searches, in its order, each fitted as it fits them and with what it sees of the
// plant; candidates under the scene's ground are left out. Empty for no points.
std::vector<RenderCamera> camera_ring(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& plant,
                                      const Aabb& scene_bounds, const SightBlocked& blocked = {});
RenderCamera choose_camera(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& plant,
                           const Aabb& scene_bounds, CameraMode mode, const SightBlocked& blocked = {});

// Turntable frame `frame` of `frames`: the scene camera turned by 2 pi frame / frames about the vertical
// axis through the plant box's centre (so frame 0 looks as the scene camera does), at the distance from
// that axis at which the plant stays in frame at every angle: fitted to a prism around the cylinder the
// plant's box sweeps, turned with the view, so every frame has the same fit. An empty `plant` box orbits the
// scene camera about the vertical through its look_at, unfitted. `angle` is the turn, in radians about +Y
// (the light turns with the camera: the plant turns as on a turntable under fixed lights).
struct Orbit {
  Camera camera;
  glm::vec3 axis_point{0.0f};  // a point of the vertical axis
  float angle = 0.0f;
};
Orbit turntable_camera(const Camera& scene_camera, float aspect, const Aabb& plant, int frame, int frames);

// A point rotated by `angle` radians about the vertical axis through `axis_point`.
glm::vec3 turn_about_vertical(const glm::vec3& p, const glm::vec3& axis_point, float angle);

// Depth of field for `subject` (the plant's box) seen by `camera`: in focus at the box's centre, with the
// widest aperture (world units, POV-Ray's `aperture`) that keeps the box's nearest and farthest corners
// within kSharpBlur of the frame's height of blur, and no wider than blurs the far background (at
// infinity) by kMaxBlur of it. A deep plant stays sharp with a little background blur; a flat one (on a
// wall) lets the background soften more.
constexpr float kSharpBlur = 0.0025f, kMaxBlur = 0.03f;
struct FocalBlur {
  glm::vec3 focal_point{0.0f};
  float aperture = 0.0f;
};
FocalBlur focal_blur(const Camera& camera, const Aabb& subject);

}  // namespace growbench
