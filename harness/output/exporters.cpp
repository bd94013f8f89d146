#include "harness/output/exporters.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>
#include <tiny_gltf.h>

#include "core/errors.hpp"
#include "harness/record/files.hpp"

namespace growbench {
namespace {

static_assert(std::endian::native == std::endian::little, "the PLY writer assumes a little-endian host");

// Formatted text streamed through an AtomicFile: records are formatted into a small buffer that is handed
// on whenever it passes 64 KiB. Building a whole OBJ in memory first (hundreds of MB for a big plant) cost
// more in page faults and reallocation copies than the formatting itself.
class TextFile {
 public:
  explicit TextFile(const std::string& path) : file_(std::make_unique<AtomicFile>(path)) {}
  template <class... Args>
  void print(fmt::format_string<Args...> f, Args&&... args) {
    fmt::format_to(std::back_inserter(buf_), f, std::forward<Args>(args)...);
    if (buf_.size() >= kDrain) drain();
  }
  std::uint64_t finish() {
    drain();
    return file_->finish();
  }
  // format(i, buffer) appends record i for i in [0, n): chunks of records are formatted in parallel and
  // written in order, so the file is the same byte for byte as a serial loop's. Formatting is most of
  // an OBJ's cost.
  template <class Format>
  void records(std::size_t n, const Format& format) {
    constexpr std::size_t kChunk = 8192;
    if (n <= kChunk) {
      for (std::size_t i = 0; i < n; ++i) {
        format(i, buf_);
        if (buf_.size() >= kDrain) drain();
      }
      return;
    }
    drain();
    // At most `tokens` chunks are in flight and they leave in order, so chunk c + tokens cannot start
    // before chunk c is written: chunk c can use buffer c % tokens. The buffers are reused, not
    // reallocated per chunk, and the allocation count depends only on the records and the thread count.
    const auto tokens = 2 * static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
    std::vector<fmt::memory_buffer> slots(tokens);
    std::size_t next = 0;
    tbb::parallel_pipeline(tokens, tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                                                       [&](tbb::flow_control& fc) -> std::size_t {
                                                                         if (next >= n) fc.stop();
                                                                         const std::size_t first = next;
                                                                         next += kChunk;
                                                                         return first;
                                                                       }) &
                                       tbb::make_filter<std::size_t, fmt::memory_buffer*>(
                                           tbb::filter_mode::parallel,
                                           [&](std::size_t first) {
                                             fmt::memory_buffer& text = slots[first / kChunk % tokens];
                                             text.clear();
                                             const std::size_t last = std::min(n, first + kChunk);
                                             for (std::size_t i = first; i < last; ++i) format(i, text);
                                             return &text;
                                           }) &
                                       tbb::make_filter<fmt::memory_buffer*, void>(
                                           tbb::filter_mode::serial_in_order, [&](fmt::memory_buffer* text) {
                                             file_->bytes(text->data(), text->size());
                                           }));
  }

 private:
  static constexpr std::size_t kDrain = 1 << 16;
  void drain() {
    file_->bytes(buf_.data(), buf_.size());
    buf_.clear();
  }
  std::unique_ptr<AtomicFile> file_;  // its 64 KiB buffer on the heap, not on a worker's stack
  fmt::memory_buffer buf_;
};

// Linear to sRGB-encoded, clamped to [0, 1]: OBJ and PLY readers show vertex colours as they are given.
float srgb_encode(float linear) {
  const float x = std::clamp(linear, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
std::uint8_t srgb_byte(float linear) {
  return static_cast<std::uint8_t>(std::lround(255.0f * srgb_encode(linear)));
}

// An attribute's name as a word for PLY properties and glTF attributes: characters other than letters,
// digits and '_' become '_'.
std::string attribute_word(const std::string& name) {
  std::string w = name.empty() ? "attribute" : name;
  for (char& c : w)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) c = '_';
  return w;
}

// The PLY float properties of an attribute: its name for one component, NAME_0, NAME_1, ... for more. A
// name the writer uses itself (x, red, ...) gets a leading '_'.
std::vector<std::string> ply_properties(const std::string& name, int components) {
  std::string w = attribute_word(name);
  for (const char* own : {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "width", "generation", "arc", "age",
                          "group", "sections", "divisions"})
    if (w == own) w = "_" + w;
  if (components == 1) return {w};
  std::vector<std::string> out;
  for (int c = 0; c < components; ++c) out.push_back(fmt::format("{}_{}", w, c));
  return out;
}

// Little-endian records packed into a reused buffer and handed to the file when it is full.
class PackedRecords {
 public:
  explicit PackedRecords(AtomicFile& f) : f_(f) { buf_.reserve(kFlush + 256); }
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&v);
    buf_.insert(buf_.end(), p, p + sizeof(T));
  }
  void end_record() {
    if (buf_.size() >= kFlush) flush();
  }
  void flush() {
    f_.bytes(buf_.data(), buf_.size());
    buf_.clear();
  }

 private:
  static constexpr std::size_t kFlush = 1 << 16;
  AtomicFile& f_;
  std::vector<char> buf_;
};

}  // namespace

std::uint64_t write_obj(const std::string& path, const OutputMesh& m) {
  const std::filesystem::path p(path);
  const std::string mtl_name = p.stem().string() + ".mtl";
  TextFile mtl((p.parent_path() / mtl_name).string());
  mtl.print("# growbench materials\n");
  const auto& materials = material_colors();
  for (std::size_t k = 0; k < materials.size(); ++k) {
    const MaterialColor& c = materials[k];
    const bool bark = std::string_view(c.material) == "bark";
    mtl.print("{}newmtl {}\nKd {:.2f} {:.2f} {:.2f}\nKa 0 0 0\nKs {}\nNs {}\n", k == 0 ? "" : "\n", c.material, c.r,
              c.g, c.b, bark ? "0.05 0.05 0.05" : "0.1 0.1 0.1", bark ? 10 : 20);
  }
  std::uint64_t bytes = mtl.finish();

  TextFile out(path);
  out.print("# growbench plant: {} vertices, {} triangles\nmtllib {}\n", m.positions.size(), m.triangles.size(),
            mtl_name);
  using Buf = fmt::memory_buffer;
  if (m.colors.empty()) {
    out.records(m.positions.size(), [&](std::size_t i, Buf& b) {
      const glm::vec3& v = m.positions[i];
      fmt::format_to(std::back_inserter(b), "v {:.6g} {:.6g} {:.6g}\n", v.x, v.y, v.z);
    });
  } else {  // the common `v x y z r g b` extension, sRGB-encoded as its readers show it
    out.records(m.positions.size(), [&](std::size_t i, Buf& b) {
      const glm::vec3& v = m.positions[i];
      const glm::vec3& c = m.colors[i];
      fmt::format_to(std::back_inserter(b), "v {:.6g} {:.6g} {:.6g} {:.4g} {:.4g} {:.4g}\n", v.x, v.y, v.z,
                     srgb_encode(c.x), srgb_encode(c.y), srgb_encode(c.z));
    });
  }
  out.records(m.normals.size(), [&](std::size_t i, Buf& b) {
    const glm::vec3& n = m.normals[i];
    fmt::format_to(std::back_inserter(b), "vn {:.4f} {:.4f} {:.4f}\n", n.x, n.y, n.z);
  });
  for (const auto& g : m.groups) {
    if (g.plant_group.empty())
      out.print("g {}\nusemtl {}\n", g.name, g.material);
    else  // in both groups: the part and the plant's own
      out.print("g {} {}\nusemtl {}\n", g.name, g.plant_group, g.material);
    out.records(g.triangle_count, [&](std::size_t i, Buf& b) {
      const glm::uvec3 f = m.triangles[g.first_triangle + i] + glm::uvec3(1);
      fmt::format_to(std::back_inserter(b), "f {0}//{0} {1}//{1} {2}//{2}\n", f.x, f.y, f.z);
    });
    out.records(g.line_count, [&](std::size_t i, Buf& b) {
      const glm::uvec2 l = m.lines[g.first_line + i] + glm::uvec2(1);
      fmt::format_to(std::back_inserter(b), "l {} {}\n", l.x, l.y);
    });
  }
  return bytes + out.finish();
}

std::uint64_t write_ply(const std::string& path, const OutputMesh& m) {
  auto file = std::make_unique<AtomicFile>(path);
  AtomicFile& f = *file;
  const bool extras = !m.colors.empty() || !m.attributes.empty();
  std::string vertex_extras, edges;
  if (!m.colors.empty()) vertex_extras += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (const auto& a : m.attributes)
    for (const auto& name : ply_properties(a.name, a.components))
      vertex_extras += fmt::format("property float {}\n", name);
  if (!m.lines.empty())
    edges = fmt::format("element edge {}\nproperty int vertex1\nproperty int vertex2\n", m.lines.size());
  const std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment growbench plant\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n{}"
      "element face {}\nproperty list uchar int vertex_indices\n{}end_header\n",
      m.positions.size(), vertex_extras, m.triangles.size(), edges);
  f.bytes(header.data(), header.size());
  if (!extras) {
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      f.bytes(&m.positions[i], sizeof(glm::vec3));
      f.bytes(&m.normals[i], sizeof(glm::vec3));
    }
  } else {
    PackedRecords r(f);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      r.put(m.positions[i]);
      r.put(m.normals[i]);
      if (!m.colors.empty())
        for (int c = 0; c < 3; ++c) r.put(srgb_byte(m.colors[i][c]));
      for (const auto& a : m.attributes)
        for (int c = 0; c < a.components; ++c) r.put(a.values[i * static_cast<std::size_t>(a.components) + c]);
      r.end_record();
    }
    r.flush();
  }
  for (const auto& t : m.triangles) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {static_cast<std::int32_t>(t.x), static_cast<std::int32_t>(t.y),
                                 static_cast<std::int32_t>(t.z)};
    f.bytes(&three, 1);
    f.bytes(idx, sizeof(idx));
  }
  for (const auto& l : m.lines) {
    const std::int32_t idx[2] = {static_cast<std::int32_t>(l.x), static_cast<std::int32_t>(l.y)};
    f.bytes(idx, sizeof(idx));
  }
  return f.finish();
}

namespace {

// The glTF document being filled: one binary buffer, its views and accessors.
struct GltfBuilder {
  tinygltf::Model model;
  tinygltf::Buffer buffer;

  std::size_t append(const void* p, std::size_t n) {
    const auto off = buffer.data.size();
    buffer.data.insert(buffer.data.end(), static_cast<const unsigned char*>(p),
                       static_cast<const unsigned char*>(p) + n);
    while (buffer.data.size() % 4 != 0) buffer.data.push_back(0);
    return off;
  }
  int view(const void* p, std::size_t length, int target) {
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = append(p, length);
    v.byteLength = length;
    v.target = target;
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size() - 1);
  }
  int accessor(int view, int component_type, std::size_t count, int type) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component_type;
    a.count = count;
    a.type = type;
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }
  // Floats per vertex (COLOR_0, _NAME attributes): `components` of them, a glTF SCALAR or VECn.
  int vertex_floats(const float* values, std::size_t vertices, int components) {
    const std::size_t bytes = vertices * static_cast<std::size_t>(components) * sizeof(float);
    static constexpr int kTypes[] = {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
    return accessor(view(values, bytes, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT, vertices,
                    kTypes[std::clamp(components, 1, 4) - 1]);
  }
  int indices(const void* p, std::size_t count) {
    const int v = view(p, count * sizeof(std::uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    return accessor(v, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count, TINYGLTF_TYPE_SCALAR);
  }
};

// The vertex attributes every primitive shares: POSITION and NORMAL, COLOR_0 when the mesh has colours
// (clamped to [0, 1], as glTF's colours are), and each other attribute as _NAME (application-specific
// attributes start with '_').
std::map<std::string, int> shared_attributes(GltfBuilder& b, const OutputMesh& m) {
  const std::size_t nv = m.positions.size();
  Aabb box;
  for (const auto& p : m.positions) box.extend(p);
  std::map<std::string, int> attrs;
  attrs["POSITION"] = b.accessor(b.view(m.positions.data(), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                                 TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
  if (nv > 0) {
    tinygltf::Accessor& pos = b.model.accessors.back();
    pos.minValues = {box.min.x, box.min.y, box.min.z};
    pos.maxValues = {box.max.x, box.max.y, box.max.z};
  }
  attrs["NORMAL"] = b.accessor(b.view(m.normals.data(), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                               TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
  if (!m.colors.empty()) {
    std::vector<glm::vec3> clamped(m.colors);
    for (auto& c : clamped) c = glm::clamp(c, glm::vec3(0.0f), glm::vec3(1.0f));
    attrs["COLOR_0"] = b.vertex_floats(&clamped[0].x, nv, 3);
  }
  for (const auto& a : m.attributes) {
    std::string name = "_" + attribute_word(a.name);
    while (attrs.count(name)) name += "_";
    attrs[name] = b.vertex_floats(a.values.data(), nv, a.components);
  }
  return attrs;
}

}  // namespace

// Long because tinygltf's model is filled field by field: buffers, views, accessors, materials, then the
// meshes and nodes. Without plant groups there is one mesh "plant" (a primitive and material per part) on
// one node; with them, the ungrouped parts stay there and each plant group is a mesh and a child node of
// its own, named as the group.
std::uint64_t write_glb(const std::string& path, const OutputMesh& m) {
  GltfBuilder b;
  tinygltf::Model& model = b.model;
  model.asset.version = "2.0";
  model.asset.generator = "growbench";
  // One allocation for the whole binary chunk (positions, normals, indices, each padded to 4 bytes).
  std::size_t vertex_floats = m.colors.empty() ? 6 : 9;
  for (const auto& a : m.attributes) vertex_floats += static_cast<std::size_t>(a.components);
  b.buffer.data.reserve(vertex_floats * m.positions.size() * sizeof(float) + m.triangles.size() * sizeof(glm::uvec3) +
                        m.lines.size() * sizeof(glm::uvec2) + 4 * (2 * m.groups.size() + 2 + m.attributes.size()));
  const std::map<std::string, int> attributes = shared_attributes(b, m);
  std::map<std::string, std::vector<double>> colours;
  for (const auto& c : material_colors()) colours[c.material] = {c.r, c.g, c.b, 1.0};
  std::vector<tinygltf::Mesh> meshes(1);
  meshes[0].name = "plant";
  std::map<std::string, std::size_t> mesh_of_group;  // plant group -> index in meshes
  for (const auto& g : m.groups) {
    tinygltf::Material mat;
    mat.name = g.material;
    const auto c = colours.find(g.material);
    if (c != colours.end()) mat.pbrMetallicRoughness.baseColorFactor = c->second;
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.doubleSided = g.material != "bark";
    model.materials.push_back(mat);
    std::size_t mesh = 0;
    if (!g.plant_group.empty()) {
      const auto [it, added] = mesh_of_group.try_emplace(g.plant_group, meshes.size());
      if (added) {
        meshes.emplace_back();
        meshes.back().name = g.plant_group;
      }
      mesh = it->second;
    }
    auto primitive = [&](int indices, int mode) {
      tinygltf::Primitive prim;
      prim.attributes = attributes;
      prim.indices = indices;
      prim.material = static_cast<int>(model.materials.size() - 1);
      prim.mode = mode;
      meshes[mesh].primitives.push_back(prim);
    };
    if (g.triangle_count > 0 || g.line_count == 0)
      primitive(b.indices(&m.triangles[g.first_triangle], std::size_t{g.triangle_count} * 3), TINYGLTF_MODE_TRIANGLES);
    if (g.line_count > 0)
      primitive(b.indices(&m.lines[g.first_line], std::size_t{g.line_count} * 2), TINYGLTF_MODE_LINE);
  }
  model.buffers.push_back(std::move(b.buffer));
  tinygltf::Node root;
  root.name = "plant";
  if (!meshes[0].primitives.empty() || meshes.size() == 1) {
    model.meshes.push_back(meshes[0]);
    root.mesh = 0;
  }
  model.nodes.push_back(root);
  for (std::size_t k = 1; k < meshes.size(); ++k) {
    model.meshes.push_back(meshes[k]);
    tinygltf::Node node;
    node.name = meshes[k].name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    model.nodes.push_back(node);
    model.nodes[0].children.push_back(static_cast<int>(model.nodes.size() - 1));
  }
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  // Streamed to the file: a string stream of the whole file and its copy cost several times its size in
  // fresh pages. tinygltf still copies the binary chunk once.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", tmp));
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, false, true))
      throw std::runtime_error(fmt::format("{}: glTF serialisation failed", path));
    out.close();
    if (!out) throw std::runtime_error(fmt::format("{}: write failed", tmp));
  }
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(tmp, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot read its size: {}", tmp, ec.message()));
  rename_into_place(tmp, path);
  return bytes;
}

std::uint64_t write_skeleton_obj(const std::string& path, const Plant& plant) {
  TextFile out(path);
  out.print("# growbench skeleton: {} nodes; vertex i+1 is node i; '#r' gives the radius of the next vertex\n",
            plant.nodes.size());
  for (const auto& n : plant.nodes)
    out.print("#r {:.6g}\nv {:.6g} {:.6g} {:.6g}\n", n.radius, n.position.x, n.position.y, n.position.z);
  for (const auto& chain : plant_chains(plant)) {
    out.print("l");
    for (const auto i : chain) out.print(" {}", i + 1);
    out.print("\n");
  }
  return out.finish();
}

std::uint64_t write_skeleton_ply(const std::string& path, const Plant& plant) {
  const std::size_t n = plant.nodes.size();
  std::vector<float> arc(n, 0.0f);  // parents precede children
  std::uint32_t newest = 0;
  std::size_t edges = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const PlantNode& nd = plant.nodes[i];
    newest = std::max(newest, nd.birth_step);
    if (nd.parent == kNoParent) continue;
    const auto p = static_cast<std::size_t>(nd.parent);
    arc[i] = arc[p] + glm::length(nd.position - plant.nodes[p].position);
    ++edges;
  }
  const NodeAttribute* cd = nullptr;
  std::string extras;
  if (!plant.node_groups.empty()) extras += "property int group\n";
  if (!plant.node_tubes.empty()) extras += "property ushort sections\nproperty ushort divisions\n";
  for (const auto& a : plant.node_attributes) {
    if (a.name == "Cd" && !cd) {
      cd = &a;
      extras += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
      continue;
    }
    for (const auto& name : ply_properties(a.name, a.components)) extras += fmt::format("property float {}\n", name);
  }
  const std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\n"
      "comment growbench skeleton: vertex i is node i; width is twice the radius; generation is the branch order; "
      "arc the length from the root; age the growth steps since the node appeared, counted to step {}\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float width\n"
      "property ushort generation\nproperty float arc\nproperty uint age\n{}"
      "element edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n",
      newest, n, extras, edges);
  auto file = std::make_unique<AtomicFile>(path);
  file->bytes(header.data(), header.size());
  PackedRecords r(*file);
  for (std::size_t i = 0; i < n; ++i) {
    const PlantNode& nd = plant.nodes[i];
    r.put(nd.position);
    r.put(2.0f * nd.radius);
    r.put(nd.order);
    r.put(arc[i]);
    r.put(newest - nd.birth_step);
    if (!plant.node_groups.empty()) r.put(plant.node_groups[i]);
    if (!plant.node_tubes.empty()) {
      r.put(plant.node_tubes[i].sections);
      r.put(plant.node_tubes[i].divisions);
    }
    for (const auto& a : plant.node_attributes) {
      const auto c = static_cast<std::size_t>(a.components);
      if (&a == cd) {
        for (std::size_t k = 0; k < 3; ++k) r.put(srgb_byte(k < c ? a.values[i * c + k] : 0.0f));
        continue;
      }
      for (std::size_t k = 0; k < c; ++k) r.put(a.values[i * c + k]);
    }
    r.end_record();
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (plant.nodes[i].parent == kNoParent) continue;
    r.put(plant.nodes[i].parent);
    r.put(static_cast<std::int32_t>(i));
    r.end_record();
  }
  r.flush();
  return file->finish();
}

}  // namespace growbench

namespace growbench {
namespace {

constexpr char kSnapshotMagic[8] = {'G', 'B', 'P', 'L', 'A', 'N', 'T', '1'};

template <class T>
void put(AtomicFile& b, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  b.bytes(&v, sizeof(T));
}

class SnapshotReader {
 public:
  SnapshotReader(std::string path, std::string data) : path_(std::move(path)), data_(std::move(data)) {}
  template <class T>
  T get() {
    T v{};
    if (pos_ + sizeof(T) > data_.size())
      throw InputError(fmt::format("{}: plant snapshot cut short at byte {} of {}", path_, pos_, data_.size()));
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  glm::vec3 vec3() {
    const float x = get<float>(), y = get<float>(), z = get<float>();
    return {x, y, z};
  }
  // A count that the rest of the file can hold (each item at least `item_bytes`), so a corrupt
  // count is an error instead of a huge allocation.
  std::size_t count(std::size_t item_bytes) {
    const auto n = get<std::uint64_t>();
    if (n > (data_.size() - pos_) / std::max<std::size_t>(item_bytes, 1))
      throw InputError(fmt::format("{}: plant snapshot count {} at byte {} exceeds the file", path_, n, pos_ - 8));
    return static_cast<std::size_t>(n);
  }
  // Consumes `tag` when the next bytes are it.
  template <std::size_t N>
  bool tag(const char (&t)[N]) {
    if (data_.size() - pos_ < N || std::memcmp(data_.data() + pos_, t, N) != 0) return false;
    pos_ += N;
    return true;
  }
  // `n` bytes as a string; n comes from count(1), so it is within the file.
  std::string text(std::size_t n) {
    if (pos_ + n > data_.size())
      throw InputError(fmt::format("{}: plant snapshot cut short at byte {} of {}", path_, pos_, data_.size()));
    std::string s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  [[nodiscard]] bool at_end() const { return pos_ == data_.size(); }
  [[nodiscard]] std::size_t position() const { return pos_; }
  [[nodiscard]] std::size_t remaining() const { return data_.size() - pos_; }
  void skip(std::size_t n) {
    if (n > data_.size() - pos_)
      throw InputError(fmt::format("{}: plant snapshot cut short at byte {} of {}", path_, pos_, data_.size()));
    pos_ += n;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: plant snapshot {} at byte {}", path_, what, pos_));
  }

 private:
  std::string path_, data_;
  std::size_t pos_ = 0;
};

// The smallest record of a decal: an empty name's length, mesh, origin and both axes.
constexpr std::size_t kDecalMinBytes = 8 + 4 + 3 * 12;

// The sections after the decals, each a 4-byte tag, a u64 length and that many bytes, for what a plant
// has beyond nodes, organs, polygons and decals. A reader skips a tag it does not know.
constexpr char kGroupsTag[4] = {'G', 'R', 'P', 'S'};      // u64 n, n i32 groups, u64 prefix length, prefix
constexpr char kAttributesTag[4] = {'A', 'T', 'T', 'R'};  // u64 n, per attribute: u64 name length, name,
                                                          // i32 components, u64 value count, floats
constexpr char kTubesTag[4] = {'T', 'U', 'B', 'E'};       // u64 n, per node u16 sections, u16 divisions
constexpr char kGeometryTag[4] = {'G', 'E', 'O', 'M'};    // u8 branch geometry
constexpr char kOrganStyleTag[4] = {'O', 'R', 'G', 'N'};  // u64 n, per shape name: u64 length, name;
                                                          // per organ u16 shape, 3 f32 tint

bool has_sections(const Plant& p) {
  return !p.node_groups.empty() || !p.node_attributes.empty() || !p.node_tubes.empty() ||
         p.branch_geometry != BranchGeometry::Tube || p.organs_styled();
}

void put_tag(AtomicFile& b, const char (&tag)[4], std::size_t length) {
  b.bytes(tag, 4);
  put<std::uint64_t>(b, length);
}

void write_sections(AtomicFile& b, const Plant& plant) {
  if (!plant.node_groups.empty()) {
    put_tag(b, kGroupsTag, 8 + 4 * plant.node_groups.size() + 8 + plant.group_prefix.size());
    put<std::uint64_t>(b, plant.node_groups.size());
    b.bytes(plant.node_groups.data(), 4 * plant.node_groups.size());
    put<std::uint64_t>(b, plant.group_prefix.size());
    b.bytes(plant.group_prefix.data(), plant.group_prefix.size());
  }
  if (!plant.node_attributes.empty()) {
    std::size_t length = 8;
    for (const auto& a : plant.node_attributes) length += 8 + a.name.size() + 4 + 8 + 4 * a.values.size();
    put_tag(b, kAttributesTag, length);
    put<std::uint64_t>(b, plant.node_attributes.size());
    for (const auto& a : plant.node_attributes) {
      put<std::uint64_t>(b, a.name.size());
      b.bytes(a.name.data(), a.name.size());
      put<std::int32_t>(b, a.components);
      put<std::uint64_t>(b, a.values.size());
      b.bytes(a.values.data(), 4 * a.values.size());
    }
  }
  if (!plant.node_tubes.empty()) {
    put_tag(b, kTubesTag, 8 + 4 * plant.node_tubes.size());
    put<std::uint64_t>(b, plant.node_tubes.size());
    for (const auto& t : plant.node_tubes) {
      put(b, t.sections);
      put(b, t.divisions);
    }
  }
  if (plant.branch_geometry != BranchGeometry::Tube) {
    put_tag(b, kGeometryTag, 1);
    put(b, static_cast<std::uint8_t>(plant.branch_geometry));
  }
  if (plant.organs_styled()) {
    std::size_t length = 8 + plant.organs.size() * (2 + 12);
    for (const auto& name : plant.organ_shapes) length += 8 + name.size();
    put_tag(b, kOrganStyleTag, length);
    put<std::uint64_t>(b, plant.organ_shapes.size());
    for (const auto& name : plant.organ_shapes) {
      put<std::uint64_t>(b, name.size());
      b.bytes(name.data(), name.size());
    }
    for (const auto& o : plant.organs) {
      put(b, o.shape);
      put(b, o.tint);
    }
  }
}

void read_sections(SnapshotReader& r, Plant& plant) {
  while (!r.at_end()) {
    if (r.remaining() < 12) r.fail("has trailing bytes");
    const auto tag = r.get<std::array<char, 4>>();
    const std::size_t length = r.count(1);
    const std::size_t end = r.position() + length;
    auto is = [&](const char(&t)[4]) { return std::memcmp(tag.data(), t, 4) == 0; };
    if (is(kGroupsTag)) {
      plant.node_groups.resize(r.count(4));
      for (auto& g : plant.node_groups) g = r.get<std::int32_t>();
      plant.group_prefix = r.text(r.count(1));
    } else if (is(kAttributesTag)) {
      plant.node_attributes.resize(r.count(8 + 4 + 8));
      for (auto& a : plant.node_attributes) {
        a.name = r.text(r.count(1));
        a.components = r.get<std::int32_t>();
        a.values.resize(r.count(4));
        for (auto& v : a.values) v = r.get<float>();
      }
    } else if (is(kTubesTag)) {
      plant.node_tubes.resize(r.count(4));
      for (auto& t : plant.node_tubes) {
        t.sections = r.get<std::uint16_t>();
        t.divisions = r.get<std::uint16_t>();
      }
    } else if (is(kGeometryTag)) {
      const auto geometry = r.get<std::uint8_t>();
      if (geometry > static_cast<std::uint8_t>(BranchGeometry::Skeleton)) r.fail("has an unknown branch geometry");
      plant.branch_geometry = static_cast<BranchGeometry>(geometry);
    } else if (is(kOrganStyleTag)) {
      plant.organ_shapes.resize(r.count(8));
      for (auto& name : plant.organ_shapes) name = r.text(r.count(1));
      for (auto& o : plant.organs) {
        o.shape = r.get<std::uint16_t>();
        o.tint = r.vec3();
      }
    } else {
      r.skip(length);  // a section of a later build
    }
    if (r.position() != end) r.fail("has a section whose length does not match its content");
  }
}

}  // namespace

std::uint64_t write_plant_snapshot(const std::string& path, const Plant& plant, const std::string& image_prefix) {
  if (!image_prefix.empty() && !plant.decals.empty()) {
    // Checked before anything is written: the reader would refuse a name the prefix made invalid.
    Plant names;
    names.decals = plant.decals;
    for (auto& d : names.decals) d.image = image_prefix + d.image;
    if (const std::string bad = names.validate(); !bad.empty())
      throw std::invalid_argument(fmt::format("{}: image prefix '{}': {}", path, image_prefix, bad));
  }
  auto file = std::make_unique<AtomicFile>(path);  // its buffer on the heap, not on a worker's stack
  AtomicFile& b = *file;
  b.bytes(kSnapshotMagic, sizeof(kSnapshotMagic));
  put<std::uint64_t>(b, plant.nodes.size());
  for (const auto& n : plant.nodes) {
    put(b, n.position);
    put(b, n.radius);
    put(b, n.parent);
    put(b, n.order);
    put(b, n.shoot);
    put(b, n.birth_step);
  }
  put<std::uint64_t>(b, plant.organs.size());
  for (const auto& o : plant.organs) {
    put(b, o.position);
    put(b, o.orientation.w);
    put(b, o.orientation.x);
    put(b, o.orientation.y);
    put(b, o.orientation.z);
    put(b, o.size);
    put(b, static_cast<std::uint8_t>(o.kind));
    put(b, o.node);
    put(b, o.stamp);
  }
  put<std::uint64_t>(b, plant.polygons.size());
  for (const auto& p : plant.polygons) {
    put<std::uint64_t>(b, p.vertices.size());
    for (const auto& v : p.vertices) put(b, v);
  }
  if (!plant.decals.empty() || has_sections(plant)) {
    put<std::uint64_t>(b, plant.decals.size());
    for (const auto& d : plant.decals) {
      const std::string name = image_prefix + d.image;
      put<std::uint64_t>(b, name.size());
      b.bytes(name.data(), name.size());
      put(b, d.mesh);
      put(b, d.origin);
      put(b, d.u_axis);
      put(b, d.v_axis);
    }
  }
  write_sections(b, plant);
  return b.finish();
}

Plant read_plant_snapshot(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open plant snapshot", path));
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() < sizeof(kSnapshotMagic) || std::memcmp(data.data(), kSnapshotMagic, sizeof(kSnapshotMagic)) != 0)
    throw InputError(fmt::format("{}: not a growbench plant snapshot (expected the magic GBPLANT1)", path));
  SnapshotReader r(path, std::move(data));
  for (std::size_t i = 0; i < sizeof(kSnapshotMagic); ++i) r.get<char>();
  Plant plant;
  plant.nodes.resize(r.count(30));
  for (auto& n : plant.nodes) {
    n.position = r.vec3();
    n.radius = r.get<float>();
    n.parent = r.get<std::int32_t>();
    n.order = r.get<std::uint16_t>();
    n.shoot = r.get<std::uint32_t>();
    n.birth_step = r.get<std::uint32_t>();
  }
  plant.organs.resize(r.count(49));
  for (auto& o : plant.organs) {
    o.position = r.vec3();
    o.orientation.w = r.get<float>();
    o.orientation.x = r.get<float>();
    o.orientation.y = r.get<float>();
    o.orientation.z = r.get<float>();
    o.size = r.get<float>();
    const auto kind = r.get<std::uint8_t>();
    if (kind > static_cast<std::uint8_t>(OrganKind::Bud))
      throw InputError(fmt::format("{}: plant snapshot has an unknown organ kind {}", path, kind));
    o.kind = static_cast<OrganKind>(kind);
    o.node = r.get<std::int32_t>();
    o.stamp = r.get<std::array<float, 3>>();
  }
  plant.polygons.resize(r.count(8));
  for (auto& p : plant.polygons) {
    p.vertices.resize(r.count(12));
    for (auto& v : p.vertices) v = r.vec3();
  }
  // Snapshots written before decals end here.
  if (!r.at_end()) {
    plant.decals.resize(r.count(kDecalMinBytes));
    for (auto& d : plant.decals) {
      d.image = r.text(r.count(1));
      d.mesh = r.get<std::int32_t>();
      d.origin = r.vec3();
      d.u_axis = r.vec3();
      d.v_axis = r.vec3();
    }
  }
  read_sections(r, plant);
  if (const std::string bad = plant.validate(); !bad.empty())
    throw InputError(fmt::format("{}: plant snapshot holds an invalid plant: {}", path, bad));
  return plant;
}

}  // namespace growbench
