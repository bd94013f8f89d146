// Writing plants: OBJ (+MTL, one group per plant part), binary little-endian PLY, and the skeleton on
// its own (nodes as OBJ vertices, branches as `l` polylines). Every writer returns the bytes written.
#pragma once

#include <cstdint>
#include <string>

#include "algorithms/plant.hpp"
#include "harness/output/mesher.hpp"

namespace growbench {

// Writes PATH (OBJ) and PATH with .mtl (materials); returns the bytes of both. Throws std::runtime_error
// naming the file when it cannot be written.
std::uint64_t write_obj(const std::string& path, const OutputMesh& mesh);
std::uint64_t write_ply(const std::string& path, const OutputMesh& mesh);
// Node i is vertex i+1; each chain of plant_chains() is one `l` record. A `#r` comment before each
// vertex gives its radius (comments are ignored by OBJ readers).
std::uint64_t write_skeleton_obj(const std::string& path, const Plant& plant);

// The plant itself (nodes, organs, polygons, decals; not the optional per-node attributes) in a small
// binary file, so a trial can be rendered again later (`growbench render`) without growing it again.
// Little-endian: magic "GBPLANT1", then nodes, organs and polygons, each a u64 count and fixed-size
// records; then, only when the plant has decals, a u64 count and per decal its image name (u64 length
// and bytes), mesh (i32), origin, u_axis and v_axis (3 floats each). A plant without decals keeps the
// layout snapshots had before decals, so older builds still read it.
// `image_prefix` is put before every decal's image name as stored: a growth frame's snapshot names the
// images written beside it with the frame's prefix (OutputRequest::prefix). The stored names must stay
// plain file names (std::invalid_argument otherwise).
std::uint64_t write_plant_snapshot(const std::string& path, const Plant& plant, const std::string& image_prefix = "");
// Throws InputError naming the file when it is not a snapshot, is cut short, or holds an invalid plant. A
// snapshot without the decal section reads as a plant without decals.
Plant read_plant_snapshot(const std::string& path);

// Binary glTF 2.0 (.glb) written with tinygltf: one mesh with a primitive (and material) per group,
// float positions and normals, uint32 indices.
std::uint64_t write_glb(const std::string& path, const OutputMesh& mesh);
}  // namespace growbench
