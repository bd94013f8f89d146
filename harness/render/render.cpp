#include "harness/render/render.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <cstdio>
#include <thread>
#include <mutex>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include <cairo.h>
#include <fmt/format.h>

#include "core/params.hpp"
#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "core/utf8.hpp"
#include "harness/output/exporters.hpp"
#include "harness/record/files.hpp"
#include "harness/run/process.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace fs = std::filesystem;

RenderQuality parse_render_quality(const std::string& text, const std::string& option) {
  if (text == "preview") return RenderQuality::Preview;
  if (text == "paper") return RenderQuality::Paper;
  throw_unknown_choice(option, text, {"preview", "paper"});
}

const char* to_string(RenderQuality q) {
  return q == RenderQuality::Paper ? "paper" : "preview";
}

Backdrop parse_backdrop(const std::string& text, const std::string& option) {
  if (text == "scene") return Backdrop::Scene;
  if (text == "studio") return Backdrop::Studio;
  throw_unknown_choice(option, text, {"scene", "studio"});
}

const char* to_string(Backdrop b) {
  return b == Backdrop::Studio ? "studio" : "scene";
}

void check_render_options(const RenderOptions& o) {
  if (o.dof && o.quality != RenderQuality::Paper)
    throw InputError(
        "--dof: depth of field is a paper-quality option (a preview stays quick, and focal blur traces many rays a "
        "pixel); render at paper quality (--render paper, or --quality paper) or leave --dof out");
  if (o.turns < 0 || (o.turns > 0 && (o.turn < 0 || o.turn >= o.turns)))
    throw InputError(fmt::format("turntable frame {} of {}: expected 0 <= frame < frames", o.turn, o.turns));
}

int render_width(const RenderOptions& o) {
  return o.width > 0 ? o.width : o.quality == RenderQuality::Paper ? 1600 : 480;
}
int render_height(const RenderOptions& o) {
  return o.height > 0 ? o.height : o.quality == RenderQuality::Paper ? 1200 : 360;
}

namespace {

using Out = std::back_insert_iterator<fmt::memory_buffer>;

// growbench (right-handed) to POV-Ray (left-handed): negate Z.
glm::vec3 pov(const glm::vec3& v) {
  return {v.x, v.y, -v.z};
}

void vec(Out out, const glm::vec3& v) {
  fmt::format_to(out, "<{:.6g},{:.6g},{:.6g}>", v.x, v.y, v.z);
}

// Radii below this are drawn at it: a zero radius is a degenerate POV-Ray primitive.
constexpr float kMinRadius = 1e-4f;

// Texture coordinates for write_mesh2: corner k of triangle t has uvs[triangles[t][k]] (TriangleMesh's).
struct MeshUvs {
  const std::vector<glm::vec2>& uvs;
  const std::vector<glm::uvec3>& triangles;
};

// The items triangles[first, first + count) use, renumbered in order of first use: `used` lists them, and
// the result maps an item to its new number (-1: unused).
std::vector<std::int64_t> renumber(std::size_t items, const std::vector<glm::uvec3>& triangles, std::uint32_t first,
                                   std::uint32_t count, std::vector<std::uint32_t>& used) {
  std::vector<std::int64_t> remap(items, -1);
  for (std::uint32_t t = first; t < first + count; ++t)
    for (int k = 0; k < 3; ++k)
      if (remap[triangles[t][k]] < 0) {
        remap[triangles[t][k]] = static_cast<std::int64_t>(used.size());
        used.push_back(triangles[t][k]);
      }
  return remap;
}

// `uv_vectors` and `uv_indices`, the two parts of a mesh2's texture coordinates, the used ones renumbered.
void write_uv_vectors(Out out, const MeshUvs& uv, std::uint32_t first, std::uint32_t count) {
  std::vector<std::uint32_t> used;
  renumber(uv.uvs.size(), uv.triangles, first, count, used);
  fmt::format_to(out, "  uv_vectors {{ {}", used.size());
  for (std::size_t i = 0; i < used.size(); ++i)
    fmt::format_to(out, "{}<{:.7g},{:.7g}>", i % 6 == 0 ? ",\n    " : ", ", uv.uvs[used[i]].x, uv.uvs[used[i]].y);
  fmt::format_to(out, "\n  }}\n");
}
void write_uv_indices(Out out, const MeshUvs& uv, std::uint32_t first, std::uint32_t count) {
  std::vector<std::uint32_t> used;
  const std::vector<std::int64_t> remap = renumber(uv.uvs.size(), uv.triangles, first, count, used);
  fmt::format_to(out, "  uv_indices {{ {}", count);
  for (std::uint32_t t = first; t < first + count; ++t)
    fmt::format_to(out, "{}<{},{},{}>", (t - first) % 6 == 0 ? ",\n    " : ", ", remap[uv.triangles[t].x],
                   remap[uv.triangles[t].y], remap[uv.triangles[t].z]);
  fmt::format_to(out, "\n  }}\n");
}

// An open mesh2 (the caller adds its texture and the closing brace), with texture coordinates when `uv`
// is given.
void write_mesh2(Out out, const std::vector<glm::vec3>& vertices, const std::vector<glm::vec3>& normals,
                 const std::vector<glm::uvec3>& triangles, std::uint32_t first, std::uint32_t count,
                 const MeshUvs* uv = nullptr) {
  // Only the vertices the triangles use, renumbered.
  std::vector<std::uint32_t> used;
  const std::vector<std::int64_t> remap = renumber(vertices.size(), triangles, first, count, used);
  fmt::format_to(out, "mesh2 {{\n  vertex_vectors {{ {}", used.size());
  for (std::size_t i = 0; i < used.size(); ++i) {
    fmt::format_to(out, "{}", i % 4 == 0 ? ",\n    " : ", ");
    vec(out, pov(vertices[used[i]]));
  }
  fmt::format_to(out, "\n  }}\n");
  if (!normals.empty()) {
    fmt::format_to(out, "  normal_vectors {{ {}", used.size());
    for (std::size_t i = 0; i < used.size(); ++i) {
      const glm::vec3 v = pov(normals[used[i]]);
      fmt::format_to(out, "{}<{:.4f},{:.4f},{:.4f}>", i % 4 == 0 ? ",\n    " : ", ", v.x, v.y, v.z);
    }
    fmt::format_to(out, "\n  }}\n");
  }
  if (uv) write_uv_vectors(out, *uv, first, count);  // POV-Ray's order: after the normals, before the faces
  fmt::format_to(out, "  face_indices {{ {}", count);
  for (std::uint32_t t = first; t < first + count; ++t)
    fmt::format_to(out, "{}<{},{},{}>", (t - first) % 6 == 0 ? ",\n    " : ", ", remap[triangles[t].x],
                   remap[triangles[t].y], remap[triangles[t].z]);
  fmt::format_to(out, "\n  }}\n");
  if (uv) write_uv_indices(out, *uv, first, count);
}

// A name from input in a `//` comment: one line, so that a newline in a shared scene file's names cannot
// end the comment and have the lines after it read as POV-Ray directives.
std::string pov_comment(std::string_view text) {
  return escape_utf8(text, true);
}

// A group of objects with one texture: a union when there are two or more (POV-Ray warns about a union
// of one), the object itself when there is one, nothing when there are none. The members are written
// into a buffer first, so the group's form is known before it starts.
template <class F>
void group(Out out, const char* comment, const std::string& texture, F&& members) {
  fmt::memory_buffer body;
  const std::size_t n = members(std::back_inserter(body));
  if (n == 0) return;
  fmt::format_to(out, "// {}: {}\n", comment, n);
  if (n == 1)
    fmt::format_to(out, "object {{\n{}  texture {{ {} }}\n}}\n", fmt::to_string(body), texture);
  else
    fmt::format_to(out, "union {{\n{}  texture {{ {} }}\n}}\n", fmt::to_string(body), texture);
}

glm::vec3 any_perpendicular(const glm::vec3& d) {
  const glm::vec3 a = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(d, a));
}

// The plant-pixel mask (plant_pixel_share): the same file rendered with GB_Mask declared draws the plant
// glowing in its colours and everything else black, without lights, so a pixel that is not black is the
// plant's (a decal's image included).
void write_mask_materials(Out out) {
  fmt::format_to(out,
                 "#ifdef (GB_Mask)\n"
                 "  #declare GB_Glow = finish {{ emission 1 diffuse 0 ambient 0 specular 0 }}\n"
                 "  #declare GB_Bark = texture {{ pigment {{ srgb 1 }} finish {{ GB_Glow }} }}\n"
                 "  #declare GB_Leaf = GB_Bark #declare GB_YoungLeaf = GB_Bark\n"
                 "  #declare GB_Flower = GB_Bark #declare GB_Bud = GB_Bark #declare GB_OrganFinish = GB_Glow\n"
                 "  #declare GB_DecalFinish = GB_Glow\n"
                 "  #declare GB_Surface = texture {{ pigment {{ srgb 0 }} finish {{ emission 0 diffuse 0 ambient 0 "
                 "specular 0 }} }}\n"
                 "  #declare GB_Ground = GB_Surface #declare GB_Studio = GB_Surface\n"
                 "  background {{ rgb 0 }}\n"
                 "#end\n");
}

// The file's first line, the global settings (radiosity in paper quality), the materials and the sky.
void write_settings(Out out, const Scene& scene, const Plant& plant, const RenderOptions& o, float diag,
                    const glm::vec3& centre) {
  const bool paper = o.quality == RenderQuality::Paper;
  fmt::format_to(out,
                 "// growbench render: scene '{}', {} nodes, {} organs{}, quality {}\n"
                 "#version 3.7;\n"
                 "global_settings {{\n  assumed_gamma 1.0\n  max_trace_level 8\n",
                 pov_comment(scene.name), plant.nodes.size(), plant.organs.size(),
                 plant.decals.empty() ? "" : fmt::format(", {} decals", plant.decals.size()), to_string(o.quality));
  if (paper)  // not in the plant-pixel mask (GB_Mask), which needs no light
    fmt::format_to(out,
                   "  #ifndef (GB_Mask)\n"
                   "  radiosity {{ pretrace_start 0.08 pretrace_end 0.01 count 60 nearest_count 5 error_bound 0.8\n"
                   "              recursion_limit 1 low_error_factor 0.5 gray_threshold 0 brightness 1 }}\n"
                   "  #end\n");
  fmt::format_to(out, "}}\n");
  const glm::vec3 bark = material_srgb("bark");
  // One material set for every algorithm. Colours are sRGB; with radiosity the sky lights the scene, so
  // ambient is off; in the preview a little ambient stands in for it.
  fmt::format_to(
      out,
      "#default {{ finish {{ ambient {} diffuse 0.75 }} }}\n"
      "#declare GB_Bark = texture {{ pigment {{ srgb <{:.3g},{:.3g},{:.3g}> }} finish {{ specular 0.05 roughness 0.1 "
      "}} }}\n"
      "#declare GB_Leaf = texture {{ pigment {{ srgb <0.24,0.52,0.16> }} finish {{ specular 0.15 roughness 0.04 }} }}\n"
      "#declare GB_YoungLeaf = texture {{ pigment {{ srgb <0.52,0.72,0.24> }} finish {{ specular 0.15 roughness 0.04 "
      "}} }}\n"
      "#declare GB_OrganFinish = finish {{ specular 0.1 roughness 0.05 }}\n"
      "#declare GB_Flower = texture {{ pigment {{ srgb <0.95,0.80,0.88> }} finish {{ GB_OrganFinish }} }}\n"
      "#declare GB_Bud = texture {{ pigment {{ srgb <0.85,0.36,0.50> }} finish {{ GB_OrganFinish }} }}\n"
      "#declare GB_Surface = texture {{ pigment {{ srgb <0.80,0.78,0.74> }} }}\n"
      "#declare GB_DecalFinish = finish {{ specular 0 }}\n",
      paper ? 0.0 : 0.12, bark.r, bark.g, bark.b);
  // The ground's checker fades into its mean colour away from the scene (a spherical pattern, 1 at the
  // centre, 0 from `fade` out), so that its squares never shrink below a pixel toward the horizon, where
  // they would alias into moire.
  const float square = std::max(0.25f, 0.05f * diag), fade = 1.5f * diag;
  fmt::format_to(out,
                 "#declare GB_Ground = texture {{ pigment {{ spherical pigment_map {{ [0.0 srgb <0.59,0.58,0.55>]\n"
                 "  [0.6 checker srgb <0.56,0.55,0.52> srgb <0.62,0.61,0.58> scale {:.4g}] }}\n"
                 "  scale {:.4g} translate <{:.4g},{:.4g},{:.4g}> }} }}\n",
                 square / fade, fade, centre.x, centre.y, -centre.z);
  if (o.backdrop == Backdrop::Studio) {
    // A neutral grey: the sweep, and the background behind it (which radiosity sees as the sky).
    fmt::format_to(out,
                   "#declare GB_Studio = texture {{ pigment {{ srgb <0.80,0.80,0.80> }} }}\n"
                   "background {{ srgb <0.80,0.80,0.80> }}\n");
  } else {
    fmt::format_to(
        out,
        "#ifndef (GB_Mask)\n"
        "sky_sphere {{ pigment {{ gradient y color_map {{ [0.0 srgb <0.93,0.94,0.95>] [0.5 srgb <0.93,0.94,0.95>]\n"
        "  [1.0 srgb <0.50,0.66,0.86>] }} scale 2 translate -1 }} }}\n"
        "#end\n");
  }
  write_mask_materials(out);
}

// The render's camera, with its vertical field of view kept at the image's aspect; with depth of field,
// focused on the subject's centre (camera.hpp's focal_blur). Focal blur samples each pixel at jittered
// points, so it is anti-aliased without POV-Ray's anti-aliasing (povray_args leaves it off).
void write_camera(Out out, const RenderView& view, float aspect, bool dof) {
  const Camera& camera = view.camera;
  const float vfov = glm::radians(camera.fov_deg);
  const float hfov = 2.0f * std::atan(std::tan(0.5f * vfov) * aspect);
  fmt::format_to(out, "camera {{ perspective location ");
  vec(out, pov(camera.position));
  fmt::format_to(out, " look_at ");
  vec(out, pov(camera.look_at));
  fmt::format_to(out, " right x*{:.6g} up y angle {:.6g}", aspect, glm::degrees(hfov));
  if (const FocalBlur fb = focal_blur(camera, view.subject); dof && fb.aperture > 0.0f) {
    fmt::format_to(out, "\n  aperture {:.6g} blur_samples 16, 64 confidence 0.95 variance 1/256 focal_point ",
                   fb.aperture);
    vec(out, pov(fb.focal_point));
  }
  fmt::format_to(out, " }}\n");
}

// A parallel light from far along `towards` (unit, from the scene to the light), aimed at `centre`; soft
// (a square area light about 2 degrees across as seen from the scene) or shadowless when asked.
void write_parallel_light(Out out, const glm::vec3& centre, const glm::vec3& towards, float diag, float srgb, bool soft,
                          bool shadowless) {
  const glm::vec3 lpos = centre + towards * (20.0f * diag);
  fmt::format_to(out, "light_source {{ ");
  vec(out, pov(lpos));
  fmt::format_to(out, " color srgb <{:.3g},{:.3g},{:.3g}> parallel point_at ", srgb, 0.98f * srgb, 0.94f * srgb);
  vec(out, pov(centre));
  if (soft) {
    const float side = 0.035f * glm::length(lpos - centre);
    const glm::vec3 u = any_perpendicular(towards) * side, v = glm::cross(towards, any_perpendicular(towards)) * side;
    fmt::format_to(out, " area_light ");
    vec(out, pov(u));
    fmt::format_to(out, ", ");
    vec(out, pov(v));
    fmt::format_to(out, ", 5, 5 adaptive 1 jitter");
  }
  fmt::format_to(out, "{} }}\n", shadowless ? " shadowless" : "");
}

// The lights. Paper quality: a studio's key and fill placed from the render's camera, so that a plant on
// a wall facing the camera is lit across its surface and shows its relief: the key from the camera's right,
// high and a little in front, with soft shadows; a weak shadowless fill from its left; radiosity adds the
// sky. Preview: the scene's light (turned with a turntable's camera), the sun as a parallel light or the
// point light, and a dim shadowless light at the camera. None in the plant-pixel mask.
void write_lights(Out out, const RenderView& view, const glm::vec3& centre, float diag, bool paper) {
  fmt::format_to(out, "#ifndef (GB_Mask)\n");
  if (paper) {
    const CameraFrame f = camera_frame(view.camera);
    const glm::vec3 aim = view.subject.empty() ? centre : view.subject.center();
    write_parallel_light(out, aim, glm::normalize(0.9f * f.right + 0.9f * f.up - 0.5f * f.forward), diag, 1.0f, true,
                         false);
    write_parallel_light(out, aim, glm::normalize(-0.8f * f.right + 0.3f * f.up - 0.6f * f.forward), diag, 0.3f, false,
                         true);
    fmt::format_to(out, "#end\n");
    return;
  }
  const Light& light = view.light;
  if (light.kind == Light::Kind::Sun) {
    write_parallel_light(out, centre, glm::normalize(light.direction), diag, 1.0f, false, false);
  } else {
    fmt::format_to(out, "light_source {{ ");
    vec(out, pov(light.position));
    fmt::format_to(out, " color srgb <1.0,0.98,0.94> }}\n");
  }
  fmt::format_to(out, "light_source {{ ");
  vec(out, pov(view.camera.position));
  fmt::format_to(out, " color srgb 0.35 shadowless }}\n#end\n");
}

// True when every triangle of `m` has texture coordinates that exist.
bool has_valid_uvs(const TriangleMesh& m) {
  if (!m.has_uvs() || m.uv_triangles.size() != m.triangles.size()) return false;
  for (const auto& t : m.uv_triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] >= m.uvs.size()) return false;
  return true;
}

// The decal layer's finish: the default's, with no highlight, which would shine through where the image
// is transparent (a layer's highlight is not weighted by its transparency).
constexpr const char* kDecalFinish = "finish { GB_DecalFinish }";

// A decal laid over a scene mesh: the image through the mesh's texture coordinates, on top of the
// textures before it; its transparent pixels show them (POV-Ray reads a PNG's alpha as transmit).
// uv_mapping modifies the pigment: on the texture it would make a patterned texture, which POV-Ray
// refuses as a layer.
void write_uv_decal_layer(Out out, const SurfaceDecal& d) {
  std::string rect;  // the image moved from the unit square onto its rectangle of the mesh's coordinates
  const bool unit = d.origin.x == 0.0f && d.origin.y == 0.0f && d.u_axis.x == 1.0f && d.v_axis.y == 1.0f;
  if (d.mesh >= 0 && d.u_axis.x > 0.0f && d.v_axis.y > 0.0f && !unit)
    rect = fmt::format(" scale <{:.9g},{:.9g},1> translate <{:.9g},{:.9g},0>", d.u_axis.x, d.v_axis.y, d.origin.x,
                       d.origin.y);
  fmt::format_to(out, "  texture {{ pigment {{ uv_mapping image_map {{ png \"{}\" once interpolate 2 }}{} }} {} }}\n",
                 d.image, rect, kDecalFinish);
}

// A planar decal: image_map's projection of the unit square in x-y along z, carried by the matrix to
// (x, y, z) -> origin + x u_axis + y v_axis + z n (n the unit normal u_axis x v_axis), all in POV-Ray's
// coordinates. Row i of POV-Ray's matrix is the image of axis i.
void write_planar_decal_layer(Out out, const SurfaceDecal& d) {
  // Negated zeros written as 0, for the reader of the file.
  auto row = [](const glm::vec3& a) {
    return glm::vec3(a.x == 0.0f ? 0.0f : a.x, a.y == 0.0f ? 0.0f : a.y, a.z == 0.0f ? 0.0f : a.z);
  };
  const glm::vec3 u = row(pov(d.u_axis)), v = row(pov(d.v_axis));
  const glm::vec3 n = row(pov(glm::normalize(glm::cross(d.u_axis, d.v_axis)))), o = row(pov(d.origin));
  fmt::format_to(
      out,
      "  texture {{ pigment {{ image_map {{ png \"{}\" once interpolate 2 }} }} {}\n"
      "    matrix <{:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}> }}\n",
      d.image, kDecalFinish, u.x, u.y, u.z, v.x, v.y, v.z, n.x, n.y, n.z, o.x, o.y, o.z);
}

// Whether the studio backdrop keeps scene mesh i: the plant climbs it, or a decal follows it.
bool kept_in_studio(const Scene& scene, std::size_t i, const std::vector<SurfaceDecal>& decals) {
  if (!scene.meshes[i].visible) return false;
  return scene.meshes[i].climbable || std::any_of(decals.begin(), decals.end(), [&](const SurfaceDecal& d) {
           return d.mesh >= 0 && static_cast<std::size_t>(d.mesh) == i;
         });
}

// The scene's meshes, each with its texture and, on top, the decals laid over it: those that follow its
// texture coordinates and, on a climbable mesh, the planar ones. write_pov has checked the decals. The
// studio backdrop keeps only the meshes kept_in_studio.
void write_scene_meshes(Out out, const Scene& scene, const std::vector<SurfaceDecal>& decals, bool studio) {
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const TriangleMesh& m = scene.meshes[i];
    if (m.triangles.empty() || !m.visible || (studio && !kept_in_studio(scene, i, decals))) continue;
    std::vector<const SurfaceDecal*> uv_decals, planar;
    for (const auto& d : decals) {
      if (d.mesh == kPlanarDecal && m.climbable) planar.push_back(&d);
      if (d.mesh >= 0 && static_cast<std::size_t>(d.mesh) == i) uv_decals.push_back(&d);
    }
    fmt::format_to(out, "// scene mesh '{}': {} triangles", pov_comment(m.name), m.triangles.size());
    if (!uv_decals.empty() || !planar.empty())
      fmt::format_to(out, ", {} decal{} on top", uv_decals.size() + planar.size(),
                     uv_decals.size() + planar.size() == 1 ? "" : "s");
    fmt::format_to(out, "\n");
    const MeshUvs uv{m.uvs, m.uv_triangles};
    const geom::ShadedMesh shaded = geom::crease_shaded(m);
    write_mesh2(out, shaded.vertices, shaded.normals, shaded.triangles, 0,
                static_cast<std::uint32_t>(shaded.triangles.size()), uv_decals.empty() ? nullptr : &uv);
    // Layered textures: the first is the bottom layer, each later one lies on top of those before it.
    fmt::format_to(out, "  texture {{ {} }}\n", m.climbable ? "GB_Surface" : "GB_Ground");
    for (const SurfaceDecal* d : uv_decals) write_uv_decal_layer(out, *d);
    for (const SurfaceDecal* d : planar) write_planar_decal_layer(out, *d);
    fmt::format_to(out, "}}\n");
  }
}

// In a scene with nothing to climb a planar decal stands free: its rectangle itself wears the image, seen
// through where the image is transparent.
void write_free_decals(Out out, const Scene& scene, const std::vector<SurfaceDecal>& decals) {
  if (std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const TriangleMesh& m) { return m.climbable; })) return;
  for (const SurfaceDecal& d : decals) {
    if (d.mesh != kPlanarDecal) continue;
    const std::vector<glm::vec3> corners = {d.origin, d.origin + d.u_axis, d.origin + d.u_axis + d.v_axis,
                                            d.origin + d.v_axis};
    const std::vector<glm::uvec3> triangles = {{0, 1, 2}, {0, 2, 3}};
    const std::vector<glm::vec2> uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const MeshUvs uv{uvs, triangles};
    fmt::format_to(out, "// decal '{}' standing free: the scene has nothing to climb\n", pov_comment(d.image));
    write_mesh2(out, corners, {}, triangles, 0, 2, &uv);
    write_uv_decal_layer(out, d);
    fmt::format_to(out, "}}\n");
  }
}

// The studio backdrop: a grey sweep, a floor under `content` that curves up into a wall behind it as the
// camera sees it, as one smooth mesh2 (a profile swept sideways), so no edge or horizon shows. The bend
// starts behind the content's farthest point, and the sweep reaches past the frame's edges and top.
void write_studio(Out out, const Camera& camera, float aspect, const Aabb& content) {
  const CameraFrame c = camera_frame(camera);
  glm::vec3 h(c.forward.x, 0.0f, c.forward.z);  // the sweep faces the camera's horizontal view
  h = glm::length(h) > 1e-6f ? glm::normalize(h) : glm::vec3(0.0f, 0.0f, -1.0f);
  const glm::vec3 up(0.0f, 1.0f, 0.0f), side = glm::normalize(glm::cross(h, up));
  const float radius = std::max(0.5f * glm::length(content.size()), 0.05f);
  const float floor_y = content.min.y, bend = 0.5f * radius;
  float back = 0.0f;  // the content's farthest corner, along h from the camera
  for (const glm::vec3& p : corners(content)) back = std::max(back, glm::dot(p - camera.position, h));
  back += bend;
  // The wall rises past the frame's top edge (its steepest ray, the top middle), up to about 83 degrees.
  const float tv = std::tan(0.5f * glm::radians(camera.fov_deg));
  const float top_elevation = std::asin(std::clamp(c.forward.y, -1.0f, 1.0f)) + std::atan(tv) + 0.1f;
  const float top = std::max({camera.position.y + back * std::tan(std::min(top_elevation, 1.45f)),
                              floor_y + 2.0f * bend, content.max.y + radius});
  const float front = -std::max(back, 2.0f * std::abs(camera.position.y - floor_y));
  const float half_w = 2.0f * glm::length(glm::vec2(back, top - camera.position.y)) * tv * aspect + radius;
  // The profile, (along h from the camera, height) with its normal: the floor, a quarter circle, the wall.
  std::vector<glm::vec2> at = {{front, floor_y}}, normal = {{0.0f, 1.0f}};
  constexpr int kArc = 12;
  for (int k = 0; k <= kArc; ++k) {
    const float a = 0.5f * std::numbers::pi_v<float> * static_cast<float>(k) / kArc;
    at.emplace_back(back - bend + bend * std::sin(a), floor_y + bend - bend * std::cos(a));
    normal.emplace_back(-std::sin(a), std::cos(a));
  }
  at.emplace_back(back, top);
  normal.emplace_back(-1.0f, 0.0f);
  const glm::vec3 base(camera.position.x, 0.0f, camera.position.z);
  std::vector<glm::vec3> vertices, normals;
  std::vector<glm::uvec3> triangles;
  for (std::size_t i = 0; i < at.size(); ++i)
    for (const float w : {-half_w, half_w}) {
      vertices.push_back(base + at[i].x * h + at[i].y * up + w * side);
      normals.push_back(normal[i].x * h + normal[i].y * up);
    }
  for (std::uint32_t i = 0; i + 1 < at.size(); ++i)
    triangles.insert(triangles.end(), {{2 * i, 2 * i + 1, 2 * i + 3}, {2 * i, 2 * i + 3, 2 * i + 2}});
  fmt::format_to(out, "// studio backdrop: a sweep from the floor up behind the plant, facing the camera\n");
  write_mesh2(out, vertices, normals, triangles, 0, static_cast<std::uint32_t>(triangles.size()));
  fmt::format_to(out, "  texture {{ GB_Studio }}\n}}\n");
}

// The least radius a branch at `p` is drawn with: `px` pixels across at its depth before `camera`.
using RadiusFloor = std::function<float(const glm::vec3& p)>;
RadiusFloor pixel_radius_floor(const Camera& camera, int height_px, float px) {
  const CameraFrame f = camera_frame(camera);
  // A pixel at depth z is 2 z tan(fov / 2) / height high.
  const float per_depth = px * std::tan(0.5f * glm::radians(camera.fov_deg)) / static_cast<float>(height_px);
  return [f, eye = camera.position, per_depth](const glm::vec3& p) {
    return std::max(glm::dot(p - eye, f.forward), 0.0f) * per_depth;
  };
}

// Branches as cones between each node and its parent, with a sphere at each joint and tip, none narrower
// than `floor` gives. A plant with the attribute Cd (the L-system's a("Cd", r, g, b), linear RGB) colours
// each cone and sphere by its node (a segment by its child, as its tube is): the bark texture with that
// pigment.
void write_cones(Out out, const Plant& plant, const RadiusFloor& floor) {
  std::vector<std::uint8_t> has_child(plant.nodes.size(), 0);
  for (const auto& n : plant.nodes)
    if (n.parent != kNoParent) has_child[static_cast<std::size_t>(n.parent)] = 1;
  const auto cd = std::find_if(plant.node_attributes.begin(), plant.node_attributes.end(),
                               [](const NodeAttribute& a) { return a.name == "Cd"; });
  const NodeAttribute* colour = cd == plant.node_attributes.end() ? nullptr : &*cd;
  auto texture = [&](Out o2, std::size_t node) {
    if (!colour) return;
    const auto c = static_cast<std::size_t>(colour->components);
    float rgb[3] = {0.0f, 0.0f, 0.0f};
    for (std::size_t k = 0; k < 3 && k < c; ++k) rgb[k] = std::clamp(colour->values[node * c + k], 0.0f, 1.0f);
    fmt::format_to(o2, " texture {{ GB_Bark pigment {{ rgb <{:.4g},{:.4g},{:.4g}> }} }}", rgb[0], rgb[1], rgb[2]);
  };
  group(out,
        colour ? "branches: cones with a sphere at each joint, coloured by Cd"
               : "branches: cones with a sphere at each joint",
        "GB_Bark", [&](Out o2) {
          std::size_t count = 0;
          for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
            const PlantNode& n = plant.nodes[i];
            const float r = std::max({n.radius, kMinRadius, floor(n.position)});
            if (n.parent != kNoParent) {
              const PlantNode& p = plant.nodes[static_cast<std::size_t>(n.parent)];
              if (glm::length(n.position - p.position) > 1e-5f) {
                fmt::format_to(o2, "  cone {{ ");
                vec(o2, pov(p.position));
                // A lateral branch starts with its own radius, as the mesher's tubes do, not its parent's.
                const float base = n.shoot != p.shoot ? std::min(p.radius, n.radius) : p.radius;
                fmt::format_to(o2, ",{:.5g},", std::max({base, kMinRadius, floor(p.position)}));
                vec(o2, pov(n.position));
                fmt::format_to(o2, ",{:.5g}", r);
                texture(o2, i);
                fmt::format_to(o2, " }}\n");
                ++count;
              }
            }
            // Joints and tips are rounded; a root without children is a lone point and is skipped.
            if (n.parent != kNoParent || has_child[i]) {
              fmt::format_to(o2, "  sphere {{ ");
              vec(o2, pov(n.position));
              fmt::format_to(o2, ",{:.5g}", r);
              texture(o2, i);
              fmt::format_to(o2, " }}\n");
              ++count;
            }
          }
          return count;
        });
}

// Whether some tube's sections leave its straight segment (TubeStyle), which cones cannot draw.
bool curved_tubes(const Plant& plant) {
  return plant.tube_style.curved() && std::any_of(plant.node_tubes.begin(), plant.node_tubes.end(),
                                                  [](const TubeShape& t) { return t.sections > 1; });
}

// Branches as RenderOptions::branches asks: cone chains, or the mesher's tubes as one mesh2. Curved tubes
// are drawn as the mesh either way, so that the picture shows what the files hold.
void write_branches(Out out, const Plant& plant, const RenderOptions& o, const Camera& camera) {
  if (o.branches != "cones" && o.branches != "mesh")
    throw InputError(fmt::format("render branches '{}': expected cones or mesh", o.branches));
  if (o.branches == "mesh" || curved_tubes(plant)) {
    Plant branches;  // the tubes alone, with the cross sections, divisions and style F(l,w,s,d) gave them
    branches.nodes = plant.nodes;
    branches.node_tubes = plant.node_tubes;
    branches.tube_style = plant.tube_style;
    branches.tube_style.uvs = false;
    const OutputMesh tubes = mesh_plant(branches, o.mesher);
    if (!tubes.triangles.empty()) {
      fmt::format_to(out, "// branches: {} nodes as one mesh2\n", plant.nodes.size());
      write_mesh2(out, tubes.positions, tubes.normals, tubes.triangles, 0,
                  static_cast<std::uint32_t>(tubes.triangles.size()));
      fmt::format_to(out, "  texture {{ GB_Bark }}\n}}\n");
    }
  } else {
    write_cones(out, plant, pixel_radius_floor(camera, render_height(o), o.min_branch_px));
  }
}

// Leaves and flowers: one declared mesh per shape (algorithms/organ_shapes.hpp), instanced with matrices
// (column i of the instance's linear map is row i of POV-Ray's matrix; both sides converted to
// POV-Ray's handedness). An organ whose colour is not its kind's plain material (a blossom's petals,
// colour jitter) carries its own pigment.
void write_organs(Out out, const Plant& plant, const MesherOptions& mesher) {
  if (plant.organs.empty()) return;
  const OrganShapes shapes = organ_shapes(plant, mesher);
  std::vector<std::uint8_t> used(shapes.size(), 0);
  for (const auto& organ : plant.organs) used[shapes.index_of(organ)] = 1;
  for (std::size_t k = 0; k < used.size(); ++k) {
    if (!used[k]) continue;
    const TriangleMesh& m = shapes.at(k).mesh;
    fmt::format_to(out, "#declare GB_Organ{} =  // {}\n", k, pov_comment(shapes.at(k).name));
    write_mesh2(out, m.vertices, shapes.at(k).normals, m.triangles, 0, static_cast<std::uint32_t>(m.triangles.size()));
    fmt::format_to(out, "}}\n");
  }
  const glm::mat3 flip(glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, -1));
  auto organs = [&](std::initializer_list<OrganKind> kinds, const char* comment, const char* texture) {
    group(out, comment, texture, [&](Out o2) {
      std::size_t count = 0;
      for (const auto& organ : plant.organs) {
        if (std::find(kinds.begin(), kinds.end(), organ.kind) == kinds.end() || !(organ.size > 0.0f)) continue;
        const glm::mat3 a = flip * glm::mat3_cast(organ.orientation) * flip * organ.size;
        const glm::vec3 t = pov(organ.position);
        const OrganShape& shape = shapes.of(organ);
        std::string pigment;
        if (organ.tint != glm::vec3(1.0f) || (shape.has_color && shape.srgb != organ_kind_srgb(organ.kind))) {
          const glm::vec3 c = shapes.linear_color(organ);
          pigment = fmt::format(" texture {{ pigment {{ rgb <{:.4f},{:.4f},{:.4f}> }} finish {{ GB_OrganFinish }} }}",
                                c.x, c.y, c.z);
        }
        fmt::format_to(o2,
                       "  object {{ GB_Organ{}{} matrix <{:.5g},{:.5g},{:.5g}, {:.5g},{:.5g},{:.5g}, "
                       "{:.5g},{:.5g},{:.5g}, {:.6g},{:.6g},{:.6g}> }}\n",
                       shapes.index_of(organ), pigment, a[0].x, a[0].y, a[0].z, a[1].x, a[1].y, a[1].z, a[2].x, a[2].y,
                       a[2].z, t.x, t.y, t.z);
        ++count;
      }
      return count;
    });
  };
  organs({OrganKind::Leaf}, "leaves", "GB_Leaf");
  organs({OrganKind::YoungLeaf}, "young leaves", "GB_YoungLeaf");
  organs({OrganKind::Flower}, "flowers", "GB_Flower");
  organs({OrganKind::Bud}, "buds", "GB_Bud");
}

// L-system polygons: one mesh2 of fans.
void write_polygons(Out out, const Plant& plant) {
  std::vector<glm::vec3> pv;
  std::vector<glm::uvec3> pt;
  for (const auto& poly : plant.polygons) {
    if (poly.vertices.size() < 3) continue;
    const auto base = static_cast<std::uint32_t>(pv.size());
    pv.insert(pv.end(), poly.vertices.begin(), poly.vertices.end());
    for (std::uint32_t i = 1; i + 1 < poly.vertices.size(); ++i) {
      const glm::vec3 e = glm::cross(poly.vertices[i] - poly.vertices[0], poly.vertices[i + 1] - poly.vertices[0]);
      if (glm::length(e) > 1e-12f) pt.emplace_back(base, base + i, base + i + 1);  // POV-Ray warns on degenerate ones
    }
  }
  if (pt.empty()) return;
  fmt::format_to(out, "// polygons: {}\n", plant.polygons.size());
  write_mesh2(out, pv, {}, pt, 0, static_cast<std::uint32_t>(pt.size()));
  fmt::format_to(out, "  texture {{ GB_Leaf }}\n}}\n");
}

}  // namespace

std::string decal_problem(const Scene& scene, const Plant& plant) {
  for (std::size_t i = 0; i < plant.decals.size(); ++i) {
    const SurfaceDecal& d = plant.decals[i];
    // The name goes into a POV-Ray string as it is.
    if (has_control_char(d.image)) return fmt::format("decal {}: its image name has a control character", i);
    if (d.mesh == kPlanarDecal) {
      if (!(glm::length(glm::cross(d.u_axis, d.v_axis)) > 0.0f))
        return fmt::format("decal {} ({}): its u_axis and v_axis span no plane", i, d.image);
    } else if (d.mesh < 0 || static_cast<std::size_t>(d.mesh) >= scene.meshes.size()) {
      return fmt::format("decal {} ({}) is on mesh {}, but scene '{}' has {} meshes", i, d.image, d.mesh, scene.name,
                         scene.meshes.size());
    } else if (!has_valid_uvs(scene.meshes[static_cast<std::size_t>(d.mesh)])) {
      return fmt::format("decal {} ({}) follows the texture coordinates of mesh {} ('{}'), which has none", i, d.image,
                         d.mesh, scene.meshes[static_cast<std::size_t>(d.mesh)].name);
    }
  }
  return "";
}

namespace {

float aspect_of(const RenderOptions& o) {
  return static_cast<float>(render_width(o)) / static_cast<float>(render_height(o));
}

// How far the plant's organ shapes reach from their stems at unit size (plant_bounds' organ_reach).
float organ_reach(const Plant& plant, const MesherOptions& mesher) {
  float reach = 0.0f;
  const OrganShapes shapes = organ_shapes(plant, mesher);
  for (std::size_t k = 0; k < shapes.size(); ++k)
    for (const glm::vec3& v : shapes.at(k).mesh.vertices) reach = std::max(reach, glm::length(v));
  return reach > 0.0f ? reach : 1.0f;
}

// What the studio backdrop stands behind: the subject and the scene meshes it keeps.
Aabb studio_content(const Scene& scene, const Plant& plant, const RenderView& view, bool decals) {
  Aabb content = view.subject;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i)
    if (kept_in_studio(scene, i, decals ? plant.decals : std::vector<SurfaceDecal>{}))
      content.extend(scene.meshes[i].bounds());
  if (content.empty()) content.extend(glm::vec3(0.0f));
  return content;
}

std::uint64_t write_pov_view(const std::string& path, const Scene& scene, const Plant& plant, const RenderOptions& o,
                             const RenderView& view) {
  check_render_options(o);
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  Aabb bounds = scene.bounds();
  for (const auto& n : plant.nodes) bounds.extend(n.position);
  if (bounds.empty()) bounds.extend(glm::vec3(0.0f));
  const float diag = std::max(glm::length(bounds.size()), 1.0f);
  const bool studio = o.backdrop == Backdrop::Studio;

  write_settings(out, scene, plant, o, diag, bounds.center());
  fmt::format_to(out, "// camera: {}\n", view.describe());
  write_camera(out, view, aspect_of(o), o.dof);
  write_lights(out, view, bounds.center(), diag, o.quality == RenderQuality::Paper);
  const bool decals = o.draw_plant && !plant.decals.empty();
  if (decals)
    if (const std::string bad = decal_problem(scene, plant); !bad.empty())
      throw InputError(fmt::format("{}: cannot draw the plant's decals: {}", path, bad));
  if (studio)
    write_studio(out, view.camera, aspect_of(o), studio_content(scene, plant, view, decals));
  else  // Ground: a plane under everything (the scene's own ground mesh, when it has one, sits on it).
    fmt::format_to(out, "plane {{ y, {:.6g} texture {{ GB_Ground }} }}\n", bounds.min.y - 1e-3f);
  const std::vector<SurfaceDecal> no_decals;
  write_scene_meshes(out, scene, decals ? plant.decals : no_decals, studio);
  write_free_decals(out, scene, decals ? plant.decals : no_decals);
  // A plant with decals is drawn by them (CONTRIBUTING.md, Rendering): its branches, organs and polygons
  // are not drawn again on top.
  if (o.draw_plant && !decals) {
    write_branches(out, plant, o, view.camera);
    write_organs(out, plant, o.mesher);
    write_polygons(out, plant);
  }
  make_directories(fs::path(path).parent_path().string());
  return write_file_atomic(path, b.data(), b.size());
}

}  // namespace

std::string RenderView::describe() const {
  if (subject.empty()) return "the scene's (the plant is empty)";
  const std::string how =
      !fitted ? "the scene's"
      : turn_deg == 0.0f && raise_deg == 0.0f
          ? "fitted to the plant"
          : fmt::format("fitted to the plant, turned {:g} deg about it and raised {:g} deg", turn_deg, raise_deg);
  return fmt::format(
      "{}: the plant's box spans {:.3f} of the frame with the scene camera, {:.3f} with this one; {:.3f} of its "
      "points in frame, {:.3f} visible past the scene",
      how, scene_extent, extent, seen.in_frame, seen.visible);
}

namespace {

// The view's occlusion test: a ray from the eye to the point against the scene's meshes (Embree alone, no
// distance field), stopped 1% short so that a point on a surface is not hidden by that surface.
SightBlocked scene_sight(const Scene& scene) {
  SceneQueryOptions qo;
  qo.build_sdf = false;
  auto query = std::make_shared<SceneQuery>(scene, qo);
  return [query](const glm::vec3& eye, const glm::vec3& p) { return query->occluded(eye, p - eye, 0.99f); };
}

void take_camera(RenderView& v, const RenderCamera& rc) {
  v.camera = rc.camera;
  v.fitted = rc.fitted;
  v.seen = rc.seen;
  v.turn_deg = rc.turn_deg;
  v.raise_deg = rc.raise_deg;
}

}  // namespace

RenderView render_view(const Scene& scene, const Plant& plant, const RenderOptions& o) {
  const float aspect = aspect_of(o);
  RenderView v;
  v.light = scene.light;
  v.subject = o.subject.empty() ? plant_bounds(scene, plant, organ_reach(plant, o.mesher)) : o.subject;
  if (o.turns > 0) {
    const Orbit orbit = turntable_camera(scene.camera, aspect, v.subject, o.turn, o.turns);
    v.camera = orbit.camera;
    v.fitted = !v.subject.empty();
    // The light turns with the camera, as if the plant turned on a turntable under fixed lights: every
    // frame is lit as the first.
    v.light.direction = turn_about_vertical(scene.light.direction, glm::vec3(0.0f), orbit.angle);
    v.light.position = turn_about_vertical(scene.light.position, orbit.axis_point, orbit.angle);
  } else {
    // The plant's own points, or the subject's corners when the caller fixed the subject (a growth frame).
    const std::vector<glm::vec3> points = o.subject.empty() ? plant_points(scene, plant) : corners(v.subject);
    take_camera(v, choose_camera(scene.camera, aspect, points, scene.bounds(), o.camera, scene_sight(scene)));
  }
  v.scene_extent = projected_extent(scene.camera, aspect, v.subject);
  v.extent = projected_extent(v.camera, aspect, v.subject);
  return v;
}

std::vector<RenderView> ring_views(const Scene& scene, const Plant& plant, const RenderOptions& o,
                                   const RenderView& base) {
  const float aspect = aspect_of(o);
  std::vector<RenderView> out;
  for (const RenderCamera& rc :
       camera_ring(scene.camera, aspect, plant_points(scene, plant), scene.bounds(), scene_sight(scene))) {
    RenderView v = base;
    take_camera(v, rc);
    v.extent = projected_extent(v.camera, aspect, v.subject);
    out.push_back(v);
  }
  return out;
}

std::uint64_t write_pov(const std::string& path, const Scene& scene, const Plant& plant, const RenderOptions& o) {
  return write_pov_view(path, scene, plant, o, render_view(scene, plant, o));
}

nlohmann::json RenderResult::to_json() const {
  nlohmann::json j = {
      {"status", status},       {"png", png},         {"pov", pov},       {"width", width}, {"height", height},
      {"pov_bytes", pov_bytes}, {"write_s", write_s}, {"wall_s", wall_s}, {"cpu_s", cpu_s}, {"warnings", warnings}};
  if (!message.empty()) j["message"] = message;
  if (!camera.empty()) {
    j["camera"] = camera;
    j["scene_extent"] = scene_extent;
    j["in_frame_share"] = seen.in_frame;
    j["visible_share"] = seen.visible;
  }
  if (plant_pixel_share >= 0.0) j["plant_pixel_share"] = plant_pixel_share;
  return j;
}

std::string find_povray() {
  return find_program("povray");
}

std::string povray_version() {
  const std::string bin = find_povray();
  if (bin.empty()) return "";
  std::string out;
  if (FILE* p = popen(fmt::format("'{}' --version 2>&1", bin).c_str(), "r")) {
    char buf[256];
    // The first line that starts with "POV-Ray" (it may first complain about a missing user config).
    while (std::fgets(buf, sizeof(buf), p))
      if (out.empty() && std::string(buf).rfind("POV-Ray", 0) == 0) out = buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

namespace {

// The share of the pixels POV-Ray has rendered, from the last "Rendered N of M pixels" of its log (+V);
// negative before the first.
double rendered_share(const std::string& log) {
  std::ifstream in(log, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(std::max<std::streamoff>(0, size - 4096));
  const std::string tail((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = tail.rfind("Rendered ");
  unsigned long long done = 0, total = 0;
  if (at == std::string::npos || std::sscanf(tail.c_str() + at, "Rendered %llu of %llu", &done, &total) != 2 ||
      total == 0)
    return -1.0;
  return static_cast<double>(done) / static_cast<double>(total);
}

// While it lives, reports POV-Ray's progress every few seconds from a thread of its own.
class ProgressWatch {
 public:
  ProgressWatch(std::function<void(double, double)> report, std::string log, std::chrono::steady_clock::time_point t0) {
    if (!report) return;
    thread_ = std::thread([this, report = std::move(report), log = std::move(log), t0] {
      std::unique_lock lock(mutex_);
      while (!stop_.wait_for(lock, std::chrono::seconds(3), [this] { return done_; }))
        report(rendered_share(log), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    });
  }
  ~ProgressWatch() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    stop_.notify_all();
    thread_.join();
  }
  ProgressWatch(const ProgressWatch&) = delete;
  ProgressWatch& operator=(const ProgressWatch&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable stop_;
  bool done_ = false;
  std::thread thread_;
};

// A private folder for one POV-Ray run, removed with this object: the only folder POV-Ray may write
// (run_program's Landlock confinement), its image moved out after. POV-Ray's own I/O restriction
// (povray.conf) does not stop a scene file's #fopen from writing anywhere in Debian's 3.7, so a directive
// that escaped into a scene file is stopped by the kernel instead.
class PovSandbox {
 public:
  explicit PovSandbox(const fs::path& image_dir) {
    std::string pattern = (image_dir / ".povray-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error(
          fmt::format("cannot make POV-Ray's private folder in {}: {}", image_dir.string(), std::strerror(errno)));
    dir = pattern;
  }
  ~PovSandbox() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  PovSandbox(const PovSandbox&) = delete;
  PovSandbox& operator=(const PovSandbox&) = delete;

  fs::path dir;
};

// POV-Ray's command line, the file names relative to the directory it runs in.
std::vector<std::string> povray_args(const std::string& bin, const fs::path& pov_abs, const fs::path& png_abs,
                                     const fs::path& dir, const RenderResult& r, const RenderOptions& o) {
  std::vector<std::string> args = {bin,
                                   "+I" + pov_abs.lexically_relative(dir).string(),
                                   "+O" + png_abs.lexically_relative(dir).string(),
                                   fmt::format("+W{}", r.width),
                                   fmt::format("+H{}", r.height),
                                   "+FN",
                                   "-D",                      // no display window (and no ASCII-art preview in the log)
                                   o.progress ? "+V" : "-V",  // +V: "Rendered N of M pixels" lines
                                   "-P",
                                   fmt::format("+WT{}", std::max(1, o.threads))};
  if (o.mask) args.push_back("Declare=GB_Mask=1");
  if (o.quality == RenderQuality::Paper && !o.dof && !o.mask) {  // focal blur anti-aliases itself (write_camera)
    args.insert(args.end(), {"+A0.1", "+AM2", "+R3"});
  } else {
    args.push_back("-A");
  }
  return args;
}

// The log's warning lines into `warnings`; returns its error lines.
std::vector<std::string> scan_log(const std::string& log, std::vector<std::string>& warnings) {
  std::vector<std::string> errors;
  std::stringstream ss(log);
  for (std::string line; std::getline(ss, line);) {
    // "Parse Warning: ...", "Possible Parse Error: ...", "Parse Error: ..." (the banner's "Warning Stream
    // to console" lines have no colon after the word).
    if (line.find("Warning:") != std::string::npos) warnings.push_back(line);
    if (line.find("Error:") != std::string::npos || line.find("error:") != std::string::npos) errors.push_back(line);
  }
  return errors;
}

}  // namespace

RenderResult run_povray(const std::string& pov_path, const std::string& png_path, const RenderOptions& o,
                        const std::string& work_dir) {
  RenderResult r;
  r.pov = pov_path;
  r.png = png_path;
  r.log = png_path + ".log";
  r.width = render_width(o);
  r.height = render_height(o);
  const std::string bin = find_povray();
  if (bin.empty()) {
    r.status = "no_povray";
    r.message = "povray is not installed (scripts/install-deps installs Debian's povray package)";
    return r;
  }
  // POV-Ray runs in the output directory with relative file names, and writes its image into a private
  // folder (PovSandbox) the image is moved out of.
  const fs::path png_abs = fs::absolute(png_path), pov_abs = fs::absolute(pov_path);
  const fs::path dir = work_dir.empty() ? png_abs.parent_path() : fs::absolute(work_dir);
  std::error_code ec;
  fs::remove(png_abs, ec);
  fs::remove(r.log, ec);
  std::optional<PovSandbox> box;
  try {
    box.emplace(png_abs.parent_path());
  } catch (const std::exception& e) {
    r.status = "failed";
    r.message = e.what();
    return r;
  }
  const fs::path drawn = box->dir / png_abs.filename();
  const std::vector<std::string> args = povray_args(bin, pov_abs, drawn, dir, r, o);
  const auto t0 = std::chrono::steady_clock::now();
  ChildResult cr;
  ProgressWatch watch(o.progress, fs::absolute(r.log).string(), t0);
  try {
    cr = run_program(args, dir.string(), {o.timeout_s, 0}, fs::absolute(r.log).string(), box->dir.string());
  } catch (const std::exception& e) {
    r.status = "failed";
    r.message = e.what();
    return r;
  }
  if (fs::is_regular_file(drawn)) fs::rename(drawn, png_abs, ec);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpu_s = cr.user_s + cr.system_s;
  const std::vector<std::string> errors =
      scan_log(fs::exists(r.log) ? read_text_file(r.log) : std::string(), r.warnings);
  if (cr.timed_out) {
    r.status = "timeout";
    r.message = fmt::format("POV-Ray was stopped after {:.0f} s", o.timeout_s);
  } else if (cr.exit_code != 0 || cr.signal != 0 || !fs::exists(png_abs)) {
    r.status = "failed";
    std::string why =
        cr.signal != 0 ? fmt::format("killed by signal {}", cr.signal) : fmt::format("exit status {}", cr.exit_code);
    if (cr.exit_code == 127) why = fmt::format("cannot run {}", bin);
    r.message = fmt::format("POV-Ray failed on {} ({})", pov_path, why);
    for (std::size_t i = 0; i < errors.size() && i < 6; ++i) r.message += "\n  " + errors[i];
    if (errors.empty()) r.message += fmt::format("; see {}", r.log);
  }
  return r;
}

namespace {

// The share of the pixels that are not black in a PNG (cairo reads it); negative when it cannot be read.
double lit_share(const std::string& png) {
  cairo_surface_t* img = cairo_image_surface_create_from_png(png.c_str());
  double share = -1.0;
  if (cairo_surface_status(img) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(img);
    const int w = cairo_image_surface_get_width(img), h = cairo_image_surface_get_height(img);
    const int stride = cairo_image_surface_get_stride(img);
    const unsigned char* data = cairo_image_surface_get_data(img);
    std::size_t lit = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        std::uint32_t px;
        std::memcpy(&px, data + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(x), 4);
        // Any channel above a few levels: the glow of the darkest bark, not a black pixel's rounding.
        if (((px >> 16) & 0xFF) > 6 || ((px >> 8) & 0xFF) > 6 || (px & 0xFF) > 6) ++lit;
      }
    if (w > 0 && h > 0) share = static_cast<double>(lit) / (static_cast<double>(w) * h);
  }
  cairo_surface_destroy(img);
  return share;
}

// plant_pixel_share: the .pov file rendered again as the mask (RenderOptions::mask) at a quarter of the
// size, at least 80 pixels wide, without anti-aliasing; the mask image and its log are removed after.
double plant_pixel_share(const std::string& pov_path, const std::string& png_path, const RenderOptions& o,
                         const std::string& work_dir) {
  RenderOptions mo = o;
  mo.mask = true;
  mo.progress = nullptr;
  mo.quality = RenderQuality::Preview;
  mo.dof = false;
  mo.width = std::max(80, render_width(o) / 4);
  mo.height = std::max(1, static_cast<int>(std::lround(mo.width * static_cast<double>(render_height(o)) /
                                                       std::max(1, render_width(o)))));
  const std::string mask =
      (fs::path(png_path).parent_path() / (fs::path(png_path).stem().string() + ".mask.png")).string();
  const RenderResult r = run_povray(pov_path, mask, mo, work_dir);
  const double share = r.ok() ? lit_share(mask) : -1.0;
  std::error_code ec;
  fs::remove(mask, ec);
  fs::remove(r.log, ec);
  return share;
}

// Why the plant's decals cannot be rendered ("" when they can): a decal the scene cannot hold, or an
// image missing from `dir`, where POV-Ray runs and reads them.
std::string decal_render_problem(const Scene& scene, const Plant& plant, const fs::path& dir, const RenderOptions& o) {
  if (!o.draw_plant || plant.decals.empty()) return "";
  if (std::string bad = decal_problem(scene, plant); !bad.empty()) return bad;
  for (std::size_t i = 0; i < plant.decals.size(); ++i) {
    // Written into a POV-Ray string and read under the render's I/O restriction: a plain relative name.
    const std::string& image = plant.decals[i].image;
    const fs::path rel(image);
    const bool plain = !image.empty() && rel.is_relative() &&
                       std::none_of(rel.begin(), rel.end(), [](const fs::path& p) { return p == ".."; }) &&
                       image.find_first_of("\"\\") == std::string::npos && !has_control_char(image);
    if (!plain)
      return fmt::format(
          "decal {}: its image '{}' is not a plain file name inside the render's directory (expected a "
          "relative path with no '..', quote, backslash or control character)",
          i, pov_comment(image));
    if (!fs::is_regular_file(dir / plant.decals[i].image))
      return fmt::format("decal {}: its image {} is missing (a render reads decal images from its own directory)", i,
                         (dir / plant.decals[i].image).string());
  }
  return "";
}

// The ring view (ring_views) whose small mask render shows the plant on the most pixels, with that share,
// when it is clearly more than `share` (`first`'s); each probe's .pov, mask and log are removed after.
std::optional<std::pair<RenderView, double>> view_showing_most(const Scene& scene, const Plant& plant,
                                                               const std::string& pov_path, const std::string& png_path,
                                                               const RenderOptions& o, const std::string& work_dir,
                                                               const RenderView& first, double share) {
  const fs::path probe_pov = fs::path(pov_path).replace_extension(".probe.pov");
  const std::string probe_png = fs::path(png_path).replace_extension(".probe.png").string();
  std::optional<std::pair<RenderView, double>> best;
  double most = share * 1.25;  // a probe within noise of the first camera does not replace it
  for (const RenderView& v : ring_views(scene, plant, o, first)) {
    write_pov_view(probe_pov.string(), scene, plant, o, v);
    const double s = plant_pixel_share(probe_pov.string(), probe_png, o, work_dir);
    if (s > most) {
      most = s;
      best = {v, s};
    }
  }
  std::error_code ec;
  fs::remove(probe_pov, ec);
  return best;
}

RenderResult failed_render(const std::string& pov_path, const std::string& png_path, const RenderOptions& o,
                           std::string message) {
  RenderResult r;
  r.status = "failed";
  r.message = std::move(message);
  r.pov = pov_path;
  r.png = png_path;
  r.width = render_width(o);
  r.height = render_height(o);
  return r;
}

}  // namespace

RenderResult render_plant(const Scene& scene, const Plant& plant, const std::string& pov_path,
                          const std::string& png_path, const RenderOptions& o, const std::string& work_dir) {
  // A decal that cannot be drawn fails the render rather than leaving the plant out of it: a render
  // without the plant would pass for one of a plant that grew nothing.
  const fs::path dir = work_dir.empty() ? fs::absolute(png_path).parent_path() : fs::absolute(work_dir);
  if (const std::string bad = decal_render_problem(scene, plant, dir, o); !bad.empty()) {
    std::error_code ec;
    fs::remove(png_path, ec);  // an earlier render's image would pass for this one's
    return failed_render(pov_path, png_path, o, fmt::format("cannot render {}: {}", png_path, bad));
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t bytes = 0;
  double write_s = 0.0;  // the first view's file; probing other views is the mask's cost, not the writer's
  RenderView view = render_view(scene, plant, o);
  // The mask goes first: a plant on too few pixels is looked at from the ring's cameras before the
  // (possibly long) render of the image.
  double share = -1.0;
  try {
    bytes = write_pov_view(pov_path, scene, plant, o, view);
    write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.draw_plant && o.turns == 0 && o.subject.empty()) {
      share = plant_pixel_share(pov_path, png_path, o, work_dir);
      if (share >= 0.0 && share < kFewPlantPixels && o.camera == CameraMode::Auto)
        if (auto better = view_showing_most(scene, plant, pov_path, png_path, o, work_dir, view, share)) {
          std::tie(view, share) = *better;
          bytes = write_pov_view(pov_path, scene, plant, o, view);
        }
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    return failed_render(pov_path, png_path, o, fmt::format("cannot write {}: {}", pov_path, e.what()));
  }
  RenderResult r = run_povray(pov_path, png_path, o, work_dir);
  r.pov_bytes = bytes;
  r.write_s = write_s;
  r.camera = view.fitted ? "fitted" : "scene";
  r.scene_extent = view.scene_extent;
  r.seen = view.seen;
  if (r.ok()) r.plant_pixel_share = share;
  return r;
}

namespace {

// The cells' height over width: the first image's read, trying on while it reads 4:3 (the default, when
// there is no image).
double image_aspect(const std::vector<std::vector<std::string>>& cells) {
  double aspect = 0.75;
  for (const auto& row : cells)
    for (const auto& c : row)
      if (!c.empty() && fs::exists(c) && aspect == 0.75) {
        cairo_surface_t* s = cairo_image_surface_create_from_png(c.c_str());
        if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS)
          aspect = static_cast<double>(cairo_image_surface_get_height(s)) / cairo_image_surface_get_width(s);
        cairo_surface_destroy(s);
      }
  return aspect;
}

// `s` centred on (x, y), shrunk to fit within max_w.
void centred_text(cairo_t* c, const std::string& s, double x, double y, double size, double max_w) {
  cairo_set_font_size(c, size);
  cairo_text_extents_t e;
  cairo_text_extents(c, s.c_str(), &e);
  if (e.width > max_w && e.width > 0) {
    cairo_set_font_size(c, size * max_w / e.width);
    cairo_text_extents(c, s.c_str(), &e);
  }
  cairo_move_to(c, x - e.width / 2 - e.x_bearing, y - e.height / 2 - e.y_bearing);
  cairo_show_text(c, s.c_str());
}

// The PNG `file` scaled into the w x h cell at (x0, y0); false when it cannot be read.
bool draw_image(cairo_t* c, const std::string& file, double x0, double y0, int w, int h) {
  if (file.empty() || !fs::exists(file)) return false;
  cairo_surface_t* img = cairo_image_surface_create_from_png(file.c_str());
  const bool ok = cairo_surface_status(img) == CAIRO_STATUS_SUCCESS;
  if (ok) {
    const double sx = w / static_cast<double>(cairo_image_surface_get_width(img));
    const double sy = h / static_cast<double>(cairo_image_surface_get_height(img));
    cairo_save(c);
    cairo_translate(c, x0, y0);
    cairo_scale(c, sx, sy);
    cairo_set_source_surface(c, img, 0, 0);
    cairo_pattern_set_filter(cairo_get_source(c), CAIRO_FILTER_GOOD);
    cairo_paint(c);
    cairo_restore(c);
  }
  cairo_surface_destroy(img);
  return ok;
}

// A grey cell with `note` in it, where an image is missing.
void draw_missing(cairo_t* c, const std::string& note, double x0, double y0, int w, int h, double px) {
  cairo_set_source_rgb(c, 0.85, 0.85, 0.85);
  cairo_rectangle(c, x0, y0, w, h);
  cairo_fill(c);
  cairo_set_source_rgb(c, 0.35, 0.35, 0.35);
  centred_text(c, note, x0 + w / 2.0, y0 + h / 2.0, px, w - 12);
}

// A band across the top of a cell's image with `text` in white: red for a degenerate plant, dark grey for
// one otherwise left out (not applicable).
void draw_badge(cairo_t* c, const std::string& text, double x0, double y0, int w, double px) {
  const double band = 1.5 * px;
  if (text.rfind("degenerate", 0) == 0)
    cairo_set_source_rgba(c, 0.78, 0.1, 0.1, 0.9);
  else
    cairo_set_source_rgba(c, 0.25, 0.25, 0.25, 0.85);
  cairo_rectangle(c, x0, y0, w, band);
  cairo_fill(c);
  cairo_set_source_rgb(c, 1, 1, 1);
  centred_text(c, text, x0 + w / 2.0, y0 + band / 2.0, px, w - 8);
}

void write_png(cairo_surface_t* surface, const std::string& png_path) {
  cairo_surface_flush(surface);
  AtomicFile png(png_path);
  const auto sink = [](void* f, const unsigned char* data, unsigned int n) {
    static_cast<AtomicFile*>(f)->bytes(data, n);
    return CAIRO_STATUS_SUCCESS;
  };
  if (cairo_surface_write_to_png_stream(surface, sink, &png) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(fmt::format("{}: cannot write the grid image", png_path));
  png.finish();
}

// Element (i, j) of a ragged table, or "" beyond its rows and columns.
std::string at(const std::vector<std::vector<std::string>>& table, int i, int j) {
  const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
  return ui < table.size() && uj < table[ui].size() ? table[ui][uj] : std::string();
}

}  // namespace

namespace {

// The label size that reads kGridMinLabelPt when an image `width` pixels wide is printed kGridPrintWidthIn.
double label_px_for(double width) {
  return std::max(15.0, kGridMinLabelPt * width / (kGridPrintWidthIn * 72.0));
}

double text_width(cairo_t* c, const std::string& s, double size) {
  cairo_set_font_size(c, size);
  cairo_text_extents_t e;
  cairo_text_extents(c, s.c_str(), &e);
  return e.x_advance;
}

using Surface = std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)>;
using Context = std::unique_ptr<cairo_t, void (*)(cairo_t*)>;

// A cell: its image with its badge, or a grey box with the note.
void draw_cell(cairo_t* c, const std::string& image, const std::string& note, const std::string& badge, double x0,
               double y0, int w, int h, double px) {
  if (draw_image(c, image, x0, y0, w, h)) {
    if (!badge.empty()) draw_badge(c, badge, x0, y0, w, px);
    return;
  }
  draw_missing(c, note.empty() ? "no render" : note, x0, y0, w, h, px);
}

// A grid's blank page: white, the labels' font and colour, and the title centred in its band.
void start_grid(cairo_t* c, const GridLayout& g, const std::string& title, int title_h) {
  cairo_set_source_rgb(c, 1, 1, 1);
  cairo_paint(c);
  cairo_select_font_face(c, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_source_rgb(c, 0.1, 0.1, 0.1);
  if (!title.empty()) centred_text(c, title, g.width / 2.0, title_h / 2.0, 1.2 * g.label_px, g.width - 20);
}

}  // namespace

GridLayout write_grid(const std::string& png_path, const std::string& title, const std::vector<std::string>& row_labels,
                      const std::vector<std::string>& col_labels, const std::vector<std::vector<std::string>>& cells,
                      const std::vector<std::vector<std::string>>& notes,
                      const std::vector<std::vector<std::string>>& badges, int cell_width) {
  const int rows = static_cast<int>(row_labels.size()), cols = static_cast<int>(col_labels.size());
  const double aspect = image_aspect(cells);
  const int cw = cell_width, ch = static_cast<int>(std::lround(cell_width * aspect)), pad = 6;
  // The labels' size follows the image's width, which follows the row labels' width at that size: a few
  // rounds settle both.
  Surface probe(cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1), &cairo_surface_destroy);
  Context pc(cairo_create(probe.get()), &cairo_destroy);
  cairo_select_font_face(pc.get(), "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  GridLayout g;
  int label_w = 0;
  for (int round = 0; round < 4; ++round) {
    g.width = label_w + cols * (cw + pad) + pad;
    g.label_px = label_px_for(g.width);
    double widest = 0.0;
    for (const auto& l : row_labels) widest = std::max(widest, text_width(pc.get(), l, g.label_px));
    label_w = static_cast<int>(std::ceil(widest + g.label_px));
  }
  g.width = label_w + cols * (cw + pad) + pad;
  const double px = g.label_px;
  const int header_h = static_cast<int>(std::ceil(2.0 * px)),
            title_h = title.empty() ? 0 : static_cast<int>(std::ceil(2.4 * px));
  g.height = title_h + header_h + rows * (ch + pad) + pad;
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, g.width, g.height), &cairo_surface_destroy);
  Context cr(cairo_create(surface.get()), &cairo_destroy);
  cairo_t* c = cr.get();
  start_grid(c, g, title, title_h);
  for (int j = 0; j < cols; ++j)
    centred_text(c, col_labels[static_cast<std::size_t>(j)], label_w + pad + j * (cw + pad) + cw / 2.0,
                 title_h + header_h / 2.0, px, cw - 8);
  for (int i = 0; i < rows; ++i) {
    const double y0 = title_h + header_h + i * (ch + pad);
    cairo_set_source_rgb(c, 0.1, 0.1, 0.1);
    centred_text(c, row_labels[static_cast<std::size_t>(i)], label_w / 2.0, y0 + ch / 2.0, px, label_w);
    for (int j = 0; j < cols; ++j) {
      const double x0 = label_w + pad + j * (cw + pad);
      draw_cell(c, at(cells, i, j), at(notes, i, j), at(badges, i, j), x0, y0, cw, ch, px);
      g.cells.push_back({i, j, static_cast<int>(x0), static_cast<int>(y0), cw, ch});
    }
  }
  write_png(surface.get(), png_path);
  return g;
}

GridLayout write_captioned_grid(const std::string& png_path, const std::string& title,
                                const std::vector<std::string>& captions, const std::vector<std::string>& images,
                                const std::vector<std::string>& notes, const std::vector<std::string>& badges,
                                int per_row, int cell_width) {
  const int n = static_cast<int>(images.size()), cols = std::max(1, std::min(per_row, n));
  const int rows = (n + cols - 1) / cols;
  const double aspect = image_aspect({images});
  const int cw = cell_width, ch = static_cast<int>(std::lround(cell_width * aspect)), pad = 6;
  GridLayout g;
  g.width = cols * (cw + pad) + pad;
  g.label_px = label_px_for(g.width);
  const double px = g.label_px;
  const int caption_h = static_cast<int>(std::ceil(1.8 * px)),
            title_h = title.empty() ? 0 : static_cast<int>(std::ceil(2.4 * px));
  g.height = title_h + rows * (caption_h + ch + pad) + pad;
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, g.width, g.height), &cairo_surface_destroy);
  Context cr(cairo_create(surface.get()), &cairo_destroy);
  cairo_t* c = cr.get();
  start_grid(c, g, title, title_h);
  auto item = [](const std::vector<std::string>& v, int k) {
    return static_cast<std::size_t>(k) < v.size() ? v[static_cast<std::size_t>(k)] : std::string();
  };
  for (int k = 0; k < n; ++k) {
    const int i = k / cols, j = k % cols;
    const double x0 = pad + j * (cw + pad), y0 = title_h + i * (caption_h + ch + pad);
    cairo_set_source_rgb(c, 0.1, 0.1, 0.1);
    centred_text(c, item(captions, k), x0 + cw / 2.0, y0 + caption_h / 2.0, px, cw - 4);
    draw_cell(c, item(images, k), item(notes, k), item(badges, k), x0, y0 + caption_h, cw, ch, px);
    g.cells.push_back({i, j, static_cast<int>(x0), static_cast<int>(y0 + caption_h), cw, ch});
  }
  write_png(surface.get(), png_path);
  return g;
}

}  // namespace growbench
