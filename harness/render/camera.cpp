#include "harness/render/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "core/params.hpp"
#include "core/errors.hpp"

namespace growbench {

CameraMode parse_camera_mode(const std::string& text, const std::string& option) {
  if (text == "auto") return CameraMode::Auto;
  if (text == "scene") return CameraMode::Scene;
  throw_unknown_choice(option, text, {"auto", "scene"});
}

const char* to_string(CameraMode m) {
  return m == CameraMode::Scene ? "scene" : "auto";
}

Aabb plant_bounds(const Scene& scene, const Plant& plant, float organ_reach) {
  Aabb b;
  if (!plant.decals.empty()) {
    for (const SurfaceDecal& d : plant.decals) {
      if (d.mesh == kPlanarDecal) {
        for (const glm::vec3& p : {d.origin, d.origin + d.u_axis, d.origin + d.v_axis, d.origin + d.u_axis + d.v_axis})
          b.extend(p);
      } else if (d.mesh >= 0 && static_cast<std::size_t>(d.mesh) < scene.meshes.size()) {
        b.extend(scene.meshes[static_cast<std::size_t>(d.mesh)].bounds());
      }
    }
    return b;
  }
  for (const PlantNode& n : plant.nodes) {
    b.extend(n.position - glm::vec3(n.radius));
    b.extend(n.position + glm::vec3(n.radius));
  }
  for (const Organ& o : plant.organs) {
    const glm::vec3 reach(std::max(o.size, 0.0f) * organ_reach);
    b.extend(o.position - reach);
    b.extend(o.position + reach);
  }
  for (const PlantPolygon& poly : plant.polygons)
    for (const glm::vec3& v : poly.vertices) b.extend(v);
  return b;
}

CameraFrame camera_frame(const Camera& camera) {
  glm::vec3 f = camera.look_at - camera.position;
  f = glm::length(f) > 0.0f ? glm::normalize(f) : glm::vec3(0.0f, 0.0f, -1.0f);
  // POV-Ray's right is sky x direction, here (left-handed there, right-handed here) direction x sky.
  glm::vec3 r = glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f));
  r = glm::length(r) > 1e-6f ? glm::normalize(r) : glm::vec3(1.0f, 0.0f, 0.0f);  // looking straight up or down
  return {r, glm::cross(r, f), f};
}

glm::vec3 project(const Camera& camera, float aspect, const glm::vec3& p) {
  const CameraFrame c = camera_frame(camera);
  const float tv = std::tan(0.5f * glm::radians(camera.fov_deg)), th = tv * aspect;
  const glm::vec3 d = p - camera.position;
  const float z = glm::dot(d, c.forward);
  return {glm::dot(d, c.right) / (z * th), glm::dot(d, c.up) / (z * tv), z};
}

std::vector<glm::vec3> corners(const Aabb& box) {
  std::vector<glm::vec3> out;
  if (box.empty()) return out;
  for (int i = 0; i < 8; ++i)
    out.emplace_back(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z);
  return out;
}

float projected_extent(const Camera& camera, float aspect, const Aabb& box) {
  if (box.empty()) return 0.0f;
  glm::vec2 lo(1.0f), hi(-1.0f);
  for (const glm::vec3& c : corners(box)) {
    const glm::vec3 p = project(camera, aspect, c);
    if (!(p.z > 0.0f)) return 0.0f;
    lo = glm::min(lo, glm::clamp(glm::vec2(p), -1.0f, 1.0f));
    hi = glm::max(hi, glm::clamp(glm::vec2(p), -1.0f, 1.0f));
  }
  const glm::vec2 span = glm::max(hi - lo, 0.0f) * 0.5f;  // the frame is 2 across in both
  return std::max(span.x, span.y);
}

Camera fit_camera(const Camera& camera, float aspect, const std::vector<glm::vec3>& points, float margin) {
  if (points.empty()) return camera;
  const CameraFrame c = camera_frame(camera);
  Aabb box;
  for (const glm::vec3& p : points) box.extend(p);
  const glm::vec3 centre = box.center();
  // Each point q, relative to the centre, has (x, y, z) along right, up and forward. With the camera at
  // centre + a right + b up - t forward, q is in the frame less the margin when |x - a| <= sx (z + t) and
  // |y - b| <= sy (z + t), sx and sy the half-frame's tangents less the margin. For one axis that is
  // L - sx t <= a <= R + sx t with L = max(x - sx z) and R = min(x + sx z): the least t is (L - R) / 2 sx,
  // where a = (L + R) / 2. The larger of the two axes' t fits both; a and b stay at their midpoints,
  // centring the looser axis.
  const float tv = std::tan(0.5f * glm::radians(camera.fov_deg));
  const float sy = (1.0f - 2.0f * margin) * tv, sx = sy * aspect;
  float lx = -INFINITY, rx = INFINITY, ly = -INFINITY, ry = INFINITY, near = INFINITY;
  for (const glm::vec3& q : points) {
    const glm::vec3 d = q - centre;
    const float x = glm::dot(d, c.right), y = glm::dot(d, c.up), z = glm::dot(d, c.forward);
    lx = std::max(lx, x - sx * z);
    rx = std::min(rx, x + sx * z);
    ly = std::max(ly, y - sy * z);
    ry = std::min(ry, y + sy * z);
    near = std::min(near, z);
  }
  const float size = std::max(glm::length(box.size()), 1e-3f);
  // Never closer than a hundredth of the box's diagonal in front of its nearest point (a box flat across
  // the view fits at any distance on one axis).
  const float t = std::max({(lx - rx) / (2.0f * sx), (ly - ry) / (2.0f * sy), -near + 0.01f * size});
  Camera out = camera;
  out.position = centre + 0.5f * (lx + rx) * c.right + 0.5f * (ly + ry) * c.up - t * c.forward;
  out.look_at = out.position + t * c.forward;
  return out;
}

std::vector<glm::vec3> plant_points(const Scene& scene, const Plant& plant, std::size_t max_points) {
  std::vector<glm::vec3> out;
  if (!plant.decals.empty()) return corners(plant_bounds(scene, plant));
  const std::size_t n = plant.nodes.size(),
                    stride = std::max<std::size_t>(1, (n + max_points - 1) / std::max<std::size_t>(max_points, 1));
  for (std::size_t i = 0; i < n; i += stride) out.push_back(plant.nodes[i].position);
  if (n > 0 && (n - 1) % stride != 0) out.push_back(plant.nodes.back().position);  // the last tip too
  for (const Organ& o : plant.organs) out.push_back(o.position);
  for (const PlantPolygon& poly : plant.polygons)
    for (const glm::vec3& v : poly.vertices) out.push_back(v);
  return out;
}

Sight sight(const Camera& camera, float aspect, const std::vector<glm::vec3>& points, const SightBlocked& blocked) {
  if (points.empty()) return {};
  std::size_t in = 0, seen = 0;
  for (const glm::vec3& p : points) {
    const glm::vec3 q = project(camera, aspect, p);
    if (!(q.z > 0.0f) || std::abs(q.x) > 1.0f || std::abs(q.y) > 1.0f) continue;
    ++in;
    if (!blocked || !blocked(camera.position, p)) ++seen;
  }
  const float n = static_cast<float>(points.size());
  return {static_cast<float>(in) / n, static_cast<float>(seen) / n};
}

namespace {

// The scene camera's view turned by `turn` radians about the vertical through `centre` and tilted down by
// `raise` more radians (looking from higher up), aimed at `centre`; fitted to `points` and to a square of
// `context` half-width across the view around the centre.
Camera turned_fit(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& points,
                  const glm::vec3& centre, float context, float turn, float raise) {
  glm::vec3 d = scene_camera.look_at - scene_camera.position;
  d = glm::length(d) > 0.0f ? glm::normalize(d) : glm::vec3(0.0f, 0.0f, -1.0f);
  const float pitch = std::asin(std::clamp(d.y, -1.0f, 1.0f)) - raise;
  const float yaw = std::atan2(d.x, -d.z) + turn;
  const float p = std::clamp(pitch, -1.4f, 1.4f);
  d = glm::vec3(std::cos(p) * std::sin(yaw), std::sin(p), -std::cos(p) * std::cos(yaw));
  Camera c = scene_camera;
  c.look_at = centre;
  c.position = centre - d;
  std::vector<glm::vec3> fit = points;
  const CameraFrame f = camera_frame(c);
  for (const float sx : {-1.0f, 1.0f})
    for (const float sy : {-1.0f, 1.0f}) fit.push_back(centre + context * (sx * f.right + sy * f.up));
  return fit_camera(c, aspect, fit);
}

}  // namespace

namespace {

// The ring: the scene camera's side first, then turns either way, then the same from higher up.
constexpr float kTurns[] = {0, 30, -30, 60, -60, 90, -90, 135, -135, 180};
constexpr float kRaises[] = {0, 25, 50};

// Ring candidate `k` (raise-major), or nothing when it stands under the ground.
std::optional<RenderCamera> ring_camera(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& plant,
                                        const Aabb& scene_bounds, const SightBlocked& blocked, std::size_t k) {
  Aabb box;
  for (const glm::vec3& p : plant) box.extend(p);
  const float context = 0.5f * kContextShare * (scene_bounds.empty() ? 0.0f : glm::length(scene_bounds.size()));
  const float turn = kTurns[k % std::size(kTurns)], raise = kRaises[k / std::size(kTurns)];
  const Camera c =
      turned_fit(scene_camera, aspect, plant, box.center(), context, glm::radians(turn), glm::radians(raise));
  if (!scene_bounds.empty() && c.position.y < scene_bounds.min.y) return std::nullopt;
  return RenderCamera{c,    true, projected_extent(scene_camera, aspect, box), sight(c, aspect, plant, blocked),
                      turn, raise};
}

constexpr std::size_t kRingSize = std::size(kTurns) * std::size(kRaises);

}  // namespace

std::vector<RenderCamera> camera_ring(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& plant,
                                      const Aabb& scene_bounds, const SightBlocked& blocked) {
  std::vector<RenderCamera> out;
  if (plant.empty()) return out;
  for (std::size_t k = 0; k < kRingSize; ++k)
    if (auto c = ring_camera(scene_camera, aspect, plant, scene_bounds, blocked, k)) out.push_back(*c);
  return out;
}

RenderCamera choose_camera(const Camera& scene_camera, float aspect, const std::vector<glm::vec3>& plant,
                           const Aabb& scene_bounds, CameraMode mode, const SightBlocked& blocked) {
  Aabb box;
  for (const glm::vec3& p : plant) box.extend(p);
  RenderCamera rc{scene_camera, false, projected_extent(scene_camera, aspect, box),
                  sight(scene_camera, aspect, plant, blocked)};
  if (mode == CameraMode::Scene || plant.empty()) return rc;
  if (rc.seen.in_frame >= 1.0f && rc.seen.visible >= kVisibleEnough && rc.scene_extent >= kSmallPlantExtent) return rc;
  RenderCamera best = rc;
  best.seen.visible = -1.0f;
  // Candidates one at a time: the first that sees enough ends the search.
  for (std::size_t k = 0; k < kRingSize; ++k) {
    const auto c = ring_camera(scene_camera, aspect, plant, scene_bounds, blocked, k);
    if (!c) continue;
    if (c->seen.visible > best.seen.visible) best = *c;
    if (c->seen.visible >= kVisibleEnough) return best;
  }
  return best.seen.visible < 0.0f ? rc : best;  // every candidate under the ground: the scene's
}

glm::vec3 turn_about_vertical(const glm::vec3& p, const glm::vec3& axis_point, float angle) {
  const glm::vec3 d = p - axis_point;
  const float c = std::cos(angle), s = std::sin(angle);
  // Counter-clockwise seen from above (+Y): x toward -z.
  return axis_point + glm::vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

Orbit turntable_camera(const Camera& scene_camera, float aspect, const Aabb& plant, int frame, int frames) {
  const float angle =
      2.0f * std::numbers::pi_v<float> * static_cast<float>(frame) / static_cast<float>(std::max(frames, 1));
  Orbit o;
  o.angle = angle;
  o.axis_point = plant.empty() ? scene_camera.look_at : plant.center();
  o.camera = scene_camera;
  o.camera.position = turn_about_vertical(scene_camera.position, o.axis_point, angle);
  o.camera.look_at = turn_about_vertical(scene_camera.look_at, o.axis_point, angle);
  if (plant.empty()) return o;
  // The plant's box sweeps a vertical cylinder about the axis. Fitted instead: the prism of a polygon around
  // that cylinder's circle, its corners placed relative to the (horizontal) view direction, so it is the
  // same in every frame's view, and so is its fit.
  constexpr int kSides = 32;
  const float rho = glm::length(glm::vec2(0.5f * plant.size().x, 0.5f * plant.size().z)) /
                    std::cos(std::numbers::pi_v<float> / kSides);
  glm::vec3 h = o.camera.look_at - o.camera.position;
  h.y = 0.0f;
  h = glm::length(h) > 1e-6f ? glm::normalize(h) : glm::vec3(0.0f, 0.0f, -1.0f);
  const glm::vec3 side = glm::normalize(glm::cross(h, glm::vec3(0.0f, 1.0f, 0.0f)));
  std::vector<glm::vec3> prism;
  for (const float y : {plant.min.y, plant.max.y})
    for (int k = 0; k < kSides; ++k) {
      const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / kSides;
      prism.push_back(glm::vec3(o.axis_point.x, y, o.axis_point.z) + rho * (std::cos(a) * side + std::sin(a) * h));
    }
  o.camera = fit_camera(o.camera, aspect, prism);
  return o;
}

FocalBlur focal_blur(const Camera& camera, const Aabb& subject) {
  const CameraFrame c = camera_frame(camera);
  FocalBlur fb;
  fb.focal_point = subject.empty() ? camera.look_at : subject.center();
  const float focus = glm::dot(fb.focal_point - camera.position, c.forward);
  if (!(focus > 0.0f)) return fb;  // nothing in front to focus on: no blur
  // A point at depth d, with the lens `lens` across and focused at depth `focus`, blurs to a disc
  // lens |d - focus| / d across on the focal plane, whose frame is 2 focus tan(fov / 2) high.
  float worst = 0.0f;  // the largest |d - focus| / d over the subject's corners
  for (const glm::vec3& p : corners(subject)) {
    const float d = glm::dot(p - camera.position, c.forward);
    worst = std::max(worst, d > 0.0f ? std::abs(d - focus) / d : 1e3f);
  }
  const float frame_h = 2.0f * focus * std::tan(0.5f * glm::radians(camera.fov_deg));
  const float lens = std::min(worst > 0.0f ? kSharpBlur * frame_h / worst : INFINITY, kMaxBlur * frame_h);
  // POV-Ray moves the eye over a disc a quarter of `aperture` in radius (JitterCameraRay: half the
  // aperture times sample offsets within +-0.5), so its lens is half the aperture across.
  fb.aperture = 2.0f * lens;
  return fb;
}

}  // namespace growbench
