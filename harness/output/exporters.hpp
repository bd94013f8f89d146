// Writing plants: OBJ (+MTL, one group per plant part), binary little-endian PLY, glTF, and the skeleton on
// its own (nodes as OBJ vertices, branches as `l` polylines; and as a PLY with per-node attributes). Every
// writer returns the bytes written.
//
// What a mesh carries beyond its triangles goes to every format that can hold it:
//  - plant groups (MeshGroup::plant_group, the L-system's g): OBJ `g PART GROUP` (the faces are in both
//    groups), glTF a child node and mesh named as the group;
//  - vertex colours (OutputMesh::colors, linear RGB): PLY uchar red/green/blue and OBJ's common
//    `v x y z r g b` extension, both sRGB-encoded and clamped as their readers show them as given; glTF
//    COLOR_0, linear floats clamped to [0, 1];
//  - other vertex attributes (OutputMesh::attributes): PLY float properties (NAME, or NAME_0, NAME_1, ...
//    for several components) and glTF attributes _NAME (application-specific ones start with '_'); names
//    keep letters, digits and '_', anything else becomes '_'. OBJ has no place for them;
//  - line segments (branch geometry skeleton): OBJ `l`, PLY `edge` elements (vertex1, vertex2), glTF LINES;
//  - birth steps (OutputMesh::birth_steps): glTF only, _BIRTH_STEP on every vertex and every organ instance
//    (EXT_mesh_gpu_instancing): the growth step its part appeared at, which a viewer plays growth from.
// A mesh without them is written byte for byte as before they existed.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "algorithms/plant.hpp"
#include "harness/output/mesher.hpp"
#include "harness/record/trial_spec.hpp"
#include "scenes/scene.hpp"

namespace growbench {

// Writes PATH (OBJ) and PATH with .mtl (materials); returns the bytes of both. Throws std::runtime_error
// naming the file when it cannot be written.
std::uint64_t write_obj(const std::string& path, const OutputMesh& mesh);
std::uint64_t write_ply(const std::string& path, const OutputMesh& mesh);
// Node i is vertex i+1; each chain of plant_chains() is one `l` record. A `#r` comment before each
// vertex gives its radius (comments are ignored by OBJ readers).
std::uint64_t write_skeleton_obj(const std::string& path, const Plant& plant);
// The skeleton with per-node attributes, binary little-endian PLY: vertex i is node i with x, y, z, width
// (twice the radius), generation (the branch order: no algorithm records the rewrite that made a node),
// arc (the length from its root along the parents) and age (growth steps from the node's birth_step to
// the newest node's), then, when the plant has them, group, sections and divisions (F(l,w,s,d)) and its
// attributes (Cd as sRGB red, green, blue bytes, the others as floats as in write_ply); each segment is an
// edge (vertex1 the parent, vertex2 the child).
std::uint64_t write_skeleton_ply(const std::string& path, const Plant& plant);

// The plant itself in a small binary file, so a trial can be rendered again later (`growbench render`)
// without growing it again. Little-endian: magic "GBPLANT1", then nodes, organs and polygons, each a u64
// count and fixed-size records; then, only when the plant has decals or any of the data below, a u64
// count and per decal its image name (u64 length and bytes), mesh (i32), origin, u_axis and v_axis (3
// floats each); then sections, each a 4-byte tag, a u64 length and its bytes, for the node groups and
// group prefix (GRPS), node attributes (ATTR), node tubes (TUBE) and a branch geometry other than tubes
// (GEOM); a reader skips tags it does not know. A plant with none of these keeps the layout snapshots had
// before decals, so older builds still read it.
// `image_prefix` is put before every decal's image name as stored: a growth frame's snapshot names the
// images written beside it with the frame's prefix (OutputRequest::prefix). The stored names must stay
// plain file names (std::invalid_argument otherwise).
std::uint64_t write_plant_snapshot(const std::string& path, const Plant& plant, const std::string& image_prefix = "");
// Throws InputError naming the file when it is not a snapshot, is cut short, or holds an invalid plant. A
// snapshot without the decal section or the sections after it reads as a plant without them.
Plant read_plant_snapshot(const std::string& path);

// How a plant is laid out in a .glb (`growbench run --glb`):
//  - plain: core glTF 2.0, every vertex as floats and uint32 indices; one mesh with a primitive (and
//    material) per group. Every glTF reader loads it.
//  - instanced: each organ shape (leaf, blossom, ...) one mesh drawn at every organ of that shape through
//    EXT_mesh_gpu_instancing (a float translation, a normalized int16 rotation and a float scale per
//    organ); the other parts quantized with KHR_mesh_quantization (see write_glb below). Requires
//    KHR_mesh_quantization; a reader without EXT_mesh_gpu_instancing draws each organ shape once.
//  - compact: instanced, with every buffer view compressed by meshoptimizer (EXT_meshopt_compression,
//    required: the file holds no uncompressed copy).
// (GlbLayout and its names are declared with the trial spec, harness/record/trial_spec.hpp.)
constexpr std::string_view glb_layout_name(GlbLayout layout) {
  return kGlbLayoutNames[static_cast<std::size_t>(layout)];
}

// Binary glTF 2.0 (.glb) in the plain layout: the JSON made by tinygltf, the binary chunk written as built.
std::uint64_t write_glb(const std::string& path, const OutputMesh& mesh);
// The bytes write_glb(path, mesh) would write, exactly, computed without building the binary chunk.
std::uint64_t plain_glb_bytes(const OutputMesh& mesh);
// `mesh` (made by mesh_plant from `plant` with these organ shapes) in `layout`. In the quantized layouts
// the branches and polygons are cut into pieces of at most 65535 vertices (uint16 indices below the
// primitive restart value), each a node whose translation and uniform scale turn its uint16 positions (the
// piece's bounds in 65535 steps of its longest side) back into metres; normals are normalized int8,
// colours normalized uint16, other attributes floats. Organs are instanced only when the mesh has no vertex
// colours or attributes (a per-organ colour has no place in an instance); otherwise they are quantized
// with the rest.
std::uint64_t write_glb(const std::string& path, const OutputMesh& mesh, GlbLayout layout, const Plant& plant,
                        const OrganShapes& shapes);
// What a plant grew on, for viewers (the report's 3D view): each scene mesh a node and mesh named as it
// (extras.climbable; materials "ground" and "surface"), smooth-shaded within its creases as renders shade
// it, in the plain layout; the scene's light (KHR_lights_punctual: "sun", directional, or "light", a
// point); its camera ("camera", perspective, the vertical fov); asset.extras the scene's name and
// content_hash.
std::uint64_t write_scene_glb(const std::string& path, const Scene& scene);
}  // namespace growbench
