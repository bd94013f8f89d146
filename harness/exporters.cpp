#include "harness/exporters.hpp"

#include <bit>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <tiny_gltf.h>

namespace growbench {
namespace {

static_assert(std::endian::native == std::endian::little, "the PLY writer assumes a little-endian host");

// Writes a buffer to a file via a temporary and a rename, so a reader never sees half a file.
std::uint64_t write_file(const std::string& path, const char* data, std::size_t size) {
  const std::string tmp = path + ".tmp";
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(tmp.c_str(), "wb"), &std::fclose);
  if (!f) throw std::runtime_error(fmt::format("{}: cannot open for writing", tmp));
  if (size > 0 && std::fwrite(data, 1, size, f.get()) != size) throw std::runtime_error(fmt::format("{}: write failed", tmp));
  if (std::fclose(f.release()) != 0) throw std::runtime_error(fmt::format("{}: write failed", tmp));
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot rename into place: {}", path, ec.message()));
  return size;
}

std::uint64_t write_buffer(const std::string& path, const fmt::memory_buffer& b) {
  return write_file(path, b.data(), b.size());
}

}  // namespace

std::uint64_t write_obj(const std::string& path, const OutputMesh& m) {
  const std::filesystem::path p(path);
  const std::string mtl_name = p.stem().string() + ".mtl";
  fmt::memory_buffer mtl;
  fmt::format_to(std::back_inserter(mtl),
                 "# growbench materials\n"
                 "newmtl bark\nKd 0.36 0.25 0.17\nKa 0 0 0\nKs 0.05 0.05 0.05\nNs 10\n\n"
                 "newmtl leaf\nKd 0.22 0.50 0.16\nKa 0 0 0\nKs 0.1 0.1 0.1\nNs 20\n\n"
                 "newmtl flower\nKd 0.92 0.85 0.95\nKa 0 0 0\nKs 0.1 0.1 0.1\nNs 20\n");
  std::uint64_t bytes = write_buffer((p.parent_path() / mtl_name).string(), mtl);

  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "# growbench plant: {} vertices, {} triangles\nmtllib {}\n", m.positions.size(), m.triangles.size(),
                 mtl_name);
  for (const auto& v : m.positions) fmt::format_to(out, "v {:.6g} {:.6g} {:.6g}\n", v.x, v.y, v.z);
  for (const auto& n : m.normals) fmt::format_to(out, "vn {:.4f} {:.4f} {:.4f}\n", n.x, n.y, n.z);
  for (const auto& g : m.groups) {
    fmt::format_to(out, "g {}\nusemtl {}\n", g.name, g.material);
    for (std::uint32_t t = g.first_triangle; t < g.first_triangle + g.triangle_count; ++t) {
      const glm::uvec3 f = m.triangles[t] + glm::uvec3(1);
      fmt::format_to(out, "f {0}//{0} {1}//{1} {2}//{2}\n", f.x, f.y, f.z);
    }
  }
  return bytes + write_buffer(path, b);
}

std::uint64_t write_ply(const std::string& path, const OutputMesh& m) {
  fmt::memory_buffer b;
  fmt::format_to(std::back_inserter(b),
                 "ply\nformat binary_little_endian 1.0\ncomment growbench plant\n"
                 "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                 "property float nx\nproperty float ny\nproperty float nz\n"
                 "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                 m.positions.size(), m.triangles.size());
  auto put = [&](const void* p, std::size_t n) { b.append(static_cast<const char*>(p), static_cast<const char*>(p) + n); };
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    put(&m.positions[i], sizeof(glm::vec3));
    put(&m.normals[i], sizeof(glm::vec3));
  }
  for (const auto& t : m.triangles) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {static_cast<std::int32_t>(t.x), static_cast<std::int32_t>(t.y), static_cast<std::int32_t>(t.z)};
    put(&three, 1);
    put(idx, sizeof(idx));
  }
  return write_buffer(path, b);
}

std::uint64_t write_glb(const std::string& path, const OutputMesh& m) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "growbench";
  tinygltf::Buffer buffer;
  auto append = [&](const void* p, std::size_t n) {
    const auto off = buffer.data.size();
    buffer.data.insert(buffer.data.end(), static_cast<const unsigned char*>(p), static_cast<const unsigned char*>(p) + n);
    while (buffer.data.size() % 4 != 0) buffer.data.push_back(0);
    return off;
  };
  auto view = [&](std::size_t offset, std::size_t length, int target) {
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = offset;
    v.byteLength = length;
    v.target = target;
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size() - 1);
  };
  const std::size_t nv = m.positions.size();
  const int pos_view = view(append(m.positions.data(), nv * sizeof(glm::vec3)), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
  const int nrm_view = view(append(m.normals.data(), nv * sizeof(glm::vec3)), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
  Aabb b;
  for (const auto& p : m.positions) b.extend(p);
  tinygltf::Accessor pos;
  pos.bufferView = pos_view;
  pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  pos.count = nv;
  pos.type = TINYGLTF_TYPE_VEC3;
  if (nv > 0) {
    pos.minValues = {b.min.x, b.min.y, b.min.z};
    pos.maxValues = {b.max.x, b.max.y, b.max.z};
  }
  model.accessors.push_back(pos);
  tinygltf::Accessor nrm = pos;
  nrm.bufferView = nrm_view;
  nrm.minValues.clear();
  nrm.maxValues.clear();
  model.accessors.push_back(nrm);
  const std::map<std::string, std::vector<double>> colours = {
      {"bark", {0.36, 0.25, 0.17, 1.0}}, {"leaf", {0.22, 0.50, 0.16, 1.0}}, {"flower", {0.92, 0.85, 0.95, 1.0}}};
  tinygltf::Mesh mesh;
  mesh.name = "plant";
  for (const auto& g : m.groups) {
    const std::size_t bytes = std::size_t{g.triangle_count} * sizeof(glm::uvec3);
    const int idx_view = view(append(&m.triangles[g.first_triangle], bytes), bytes, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Accessor idx;
    idx.bufferView = idx_view;
    idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    idx.count = std::size_t{g.triangle_count} * 3;
    idx.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(idx);
    tinygltf::Material mat;
    mat.name = g.material;
    const auto c = colours.find(g.material);
    if (c != colours.end()) mat.pbrMetallicRoughness.baseColorFactor = c->second;
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.doubleSided = g.material != "bark";
    model.materials.push_back(mat);
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = 0;
    prim.attributes["NORMAL"] = 1;
    prim.indices = static_cast<int>(model.accessors.size() - 1);
    prim.material = static_cast<int>(model.materials.size() - 1);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    mesh.primitives.push_back(prim);
  }
  model.buffers.push_back(std::move(buffer));
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "plant";
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, false, true))
    throw std::runtime_error(fmt::format("{}: glTF serialisation failed", path));
  const std::string data = out.str();
  return write_file(path, data.data(), data.size());
}

std::uint64_t write_skeleton_obj(const std::string& path, const Plant& plant) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "# growbench skeleton: {} nodes; vertex i+1 is node i; '#r' gives the radius of the next vertex\n",
                 plant.nodes.size());
  for (const auto& n : plant.nodes)
    fmt::format_to(out, "#r {:.6g}\nv {:.6g} {:.6g} {:.6g}\n", n.radius, n.position.x, n.position.y, n.position.z);
  for (const auto& chain : plant_chains(plant)) {
    fmt::format_to(out, "l");
    for (const auto i : chain) fmt::format_to(out, " {}", i + 1);
    fmt::format_to(out, "\n");
  }
  return write_buffer(path, b);
}

}  // namespace growbench
