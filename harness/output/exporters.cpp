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
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "core/errors.hpp"
#include "harness/record/files.hpp"
#include "scenes/geometry.hpp"

namespace growbench {
namespace {

// The glTF attribute that carries OutputMesh::birth_steps: per vertex, and per organ instance.
constexpr const char* kBirthStep = "_BIRTH_STEP";

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
// The glTF name of a vertex attribute called `name` on a primitive: _WORD, with '_' appended while it equals,
// ignoring case, a name the primitive already has (`taken(match)`: whether `match` holds for one of them).
// three.js's GLTFLoader lower-cases application attributes, so a user attribute "birth_step" would otherwise
// overwrite _BIRTH_STEP in a viewer.
template <class Taken>
std::string free_attribute_name(const std::string& name, const Taken& taken) {
  std::string out = std::string(1, '_').append(attribute_word(name));
  const auto same = [&](std::string_view k) {
    return k.size() == out.size() && std::equal(k.begin(), k.end(), out.begin(), [](char x, char y) {
             return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
  };
  while (taken(same)) out += "_";
  return out;
}

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
      fmt::format_to(fmt::appender(b), FMT_COMPILE("v {:.6g} {:.6g} {:.6g}\n"), v.x, v.y, v.z);
    });
  } else {  // the common `v x y z r g b` extension, sRGB-encoded as its readers show it
    out.records(m.positions.size(), [&](std::size_t i, Buf& b) {
      const glm::vec3& v = m.positions[i];
      const glm::vec3& c = m.colors[i];
      fmt::format_to(fmt::appender(b), FMT_COMPILE("v {:.6g} {:.6g} {:.6g} {:.4g} {:.4g} {:.4g}\n"), v.x, v.y, v.z,
                     srgb_encode(c.x), srgb_encode(c.y), srgb_encode(c.z));
    });
  }
  out.records(m.normals.size(), [&](std::size_t i, Buf& b) {
    const glm::vec3& n = m.normals[i];
    fmt::format_to(fmt::appender(b), FMT_COMPILE("vn {:.4f} {:.4f} {:.4f}\n"), n.x, n.y, n.z);
  });
  // Texture coordinates share the vertices' numbering, as the normals do.
  out.records(m.uvs.size(), [&](std::size_t i, Buf& b) {
    fmt::format_to(fmt::appender(b), FMT_COMPILE("vt {:.6g} {:.6g}\n"), m.uvs[i].x, m.uvs[i].y);
  });
  for (const auto& g : m.groups) {
    if (g.plant_group.empty())
      out.print("g {}\nusemtl {}\n", g.name, g.material);
    else  // in both groups: the part and the plant's own
      out.print("g {} {}\nusemtl {}\n", g.name, g.plant_group, g.material);
    out.records(g.triangle_count, [&](std::size_t i, Buf& b) {
      const glm::uvec3 f = m.triangles[g.first_triangle + i] + glm::uvec3(1);
      if (m.uvs.empty())
        fmt::format_to(fmt::appender(b), FMT_COMPILE("f {0}//{0} {1}//{1} {2}//{2}\n"), f.x, f.y, f.z);
      else
        fmt::format_to(fmt::appender(b), FMT_COMPILE("f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}\n"), f.x, f.y, f.z);
    });
    out.records(g.line_count, [&](std::size_t i, Buf& b) {
      const glm::uvec2 l = m.lines[g.first_line + i] + glm::uvec2(1);
      fmt::format_to(fmt::appender(b), FMT_COMPILE("l {} {}\n"), l.x, l.y);
    });
  }
  return bytes + out.finish();
}

std::uint64_t write_ply(const std::string& path, const OutputMesh& m) {
  auto file = std::make_unique<AtomicFile>(path);
  AtomicFile& f = *file;
  const bool extras = !m.colors.empty() || !m.attributes.empty() || !m.uvs.empty();
  std::string vertex_extras, edges;
  if (!m.uvs.empty()) vertex_extras += "property float s\nproperty float t\n";  // the names most readers take
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
      if (!m.uvs.empty()) r.put(m.uvs[i]);
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

constexpr std::size_t pad4(std::size_t n) {
  return n + (4 - n % 4) % 4;
}

// Appends n bytes at p to a glTF binary chunk, zero-padded to 4 bytes; returns their offset.
std::size_t append_padded(std::vector<unsigned char>& bin, const void* p, std::size_t n) {
  const std::size_t off = bin.size();
  bin.insert(bin.end(), static_cast<const unsigned char*>(p), static_cast<const unsigned char*>(p) + n);
  bin.resize(pad4(bin.size()), 0);
  return off;
}

// The glTF document being filled: one binary buffer, its views and accessors. Counting only, it lays the
// views out without copying any data: the document is the same, the binary chunk stays empty.
struct GltfBuilder {
  tinygltf::Model model;
  tinygltf::Buffer buffer;
  bool count_only = false;
  std::size_t size = 0;  // the binary chunk's bytes

  std::size_t append(const void* p, std::size_t n) {
    const auto off = size;
    size += pad4(n);
    if (!count_only) append_padded(buffer.data, p, n);
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

// A .glb's bytes: the 12-byte header, the JSON chunk (padded with spaces) and, when there is binary data,
// the BIN chunk (padded with zeros), each chunk after an 8-byte length and type.
std::uint64_t glb_container_bytes(std::size_t json_bytes, std::size_t bin_bytes) {
  return 12 + 8 + pad4(json_bytes) + (bin_bytes > 0 ? 8 + pad4(bin_bytes) : 0);
}

std::uint64_t write_glb_container(const std::string& path, const std::string& json,
                                  const std::vector<unsigned char>& bin) {
  auto file = std::make_unique<AtomicFile>(path);  // its buffer on the heap, not on a worker's stack
  AtomicFile& f = *file;
  const auto u32 = [&](std::uint64_t v) {
    const auto x = static_cast<std::uint32_t>(v);
    f.bytes(&x, 4);
  };
  const std::uint64_t total = glb_container_bytes(json.size(), bin.size());
  if (total > UINT32_MAX) throw std::runtime_error(fmt::format("{}: {} bytes exceed a .glb's 4 GiB", path, total));
  f.bytes("glTF", 4);
  u32(2);
  u32(total);
  u32(pad4(json.size()));
  f.bytes("JSON", 4);
  f.bytes(json.data(), json.size());
  f.bytes("   ", pad4(json.size()) - json.size());
  if (!bin.empty()) {
    u32(pad4(bin.size()));
    f.bytes("BIN\0", 4);
    f.bytes(bin.data(), bin.size());
    f.bytes("\0\0\0", pad4(bin.size()) - bin.size());
  }
  return f.finish();
}

// The vertex attributes every primitive shares: POSITION and NORMAL, COLOR_0 when the mesh has colours
// (clamped to [0, 1], as glTF's colours are), _BIRTH_STEP (OutputMesh::birth_steps, as floats: exact to
// 2^24 steps), and each other attribute as _NAME (application-specific attributes start with '_').
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
  if (!m.colors.empty() && b.count_only) {
    attrs["COLOR_0"] = b.vertex_floats(nullptr, nv, 3);
  } else if (!m.colors.empty()) {
    std::vector<glm::vec3> clamped(m.colors);
    for (auto& c : clamped) c = glm::clamp(c, glm::vec3(0.0f), glm::vec3(1.0f));
    attrs["COLOR_0"] = b.vertex_floats(&clamped[0].x, nv, 3);
  }
  if (!m.uvs.empty()) {  // glTF's v runs down the image, OBJ's up
    std::vector<glm::vec2> flipped(b.count_only ? 0 : nv);
    for (std::size_t i = 0; i < flipped.size(); ++i) flipped[i] = {m.uvs[i].x, 1.0f - m.uvs[i].y};
    attrs["TEXCOORD_0"] = b.vertex_floats(b.count_only ? nullptr : &flipped[0].x, nv, 2);
  }
  if (m.birth_steps.size() == nv && b.count_only) {
    attrs[kBirthStep] = b.vertex_floats(nullptr, nv, 1);
  } else if (m.birth_steps.size() == nv) {
    const std::vector<float> steps(m.birth_steps.begin(), m.birth_steps.end());
    attrs[kBirthStep] = b.vertex_floats(steps.data(), nv, 1);
  }
  for (const auto& a : m.attributes) {
    const auto taken = [&](const auto& match) {
      return std::any_of(attrs.begin(), attrs.end(), [&](const auto& kv) { return match(kv.first); });
    };
    attrs[free_attribute_name(a.name, taken)] = b.vertex_floats(a.values.data(), nv, a.components);
  }
  return attrs;
}

// Long because tinygltf's model is filled field by field: buffers, views, accessors, materials, then the
// meshes and nodes. Without plant groups there is one mesh "plant" (a primitive and material per part) on
// one node; with them, the ungrouped parts stay there and each plant group is a mesh and a child node of
// its own, named as the group.
void build_plain_glb(GltfBuilder& b, const OutputMesh& m) {
  tinygltf::Model& model = b.model;
  model.asset.version = "2.0";
  model.asset.generator = "growbench";
  if (m.positions.empty()) {  // nothing to draw: a root node alone, as glTF has no empty accessor or buffer
    tinygltf::Node root;
    root.name = "plant";
    model.nodes.push_back(root);
    tinygltf::Scene scene;
    scene.nodes = {0};
    model.scenes.push_back(scene);
    model.defaultScene = 0;
    return;
  }
  // One allocation for the whole binary chunk (positions, normals, indices, each padded to 4 bytes).
  std::size_t vertex_floats = (m.colors.empty() ? 6 : 9) + (m.birth_steps.empty() ? 0 : 1) + (m.uvs.empty() ? 0 : 2);
  for (const auto& a : m.attributes) vertex_floats += static_cast<std::size_t>(a.components);
  if (!b.count_only)
    b.buffer.data.reserve(vertex_floats * m.positions.size() * sizeof(float) + m.triangles.size() * sizeof(glm::uvec3) +
                          m.lines.size() * sizeof(glm::uvec2) + 4 * (2 * m.groups.size() + 3 + m.attributes.size()));
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
}

// The plain layout's JSON: tinygltf's, with the buffer (which tinygltf would copy whole to write it) added
// here. Both serialise through nlohmann::json, so the text is what tinygltf alone would write.
std::string plain_glb_json(GltfBuilder& b) {
  const std::size_t size = b.size;
  b.model.buffers.clear();
  std::ostringstream text;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&b.model, text, false, false))
    throw std::runtime_error("glTF serialisation failed");
  nlohmann::json doc = nlohmann::json::parse(text.str());
  if (size > 0) doc["buffers"] = nlohmann::json::array({{{"byteLength", size}}});
  return doc.dump();
}

}  // namespace

std::uint64_t write_glb(const std::string& path, const OutputMesh& m) {
  GltfBuilder b;
  build_plain_glb(b, m);
  const std::string json = plain_glb_json(b);
  return write_glb_container(path, json, b.buffer.data);
}

namespace {

// A rotation as glTF writes it (x, y, z, w).
std::vector<double> gltf_rotation(const glm::quat& q) {
  return {q.x, q.y, q.z, q.w};
}

// The rotation that turns a glTF light's or camera's forward axis (-Z) onto `forward`, with `up` up.
glm::quat facing(const glm::vec3& forward) {
  const glm::vec3 f = glm::normalize(forward);
  const glm::vec3 up = std::abs(f.y) > 0.999f ? glm::vec3(0.0f, 0.0f, -1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
  return glm::quatLookAtRH(f, up);
}

// The scene's materials, the colours its renders give them (sRGB there, linear here as glTF's are).
int scene_material(tinygltf::Model& model, const char* name, glm::vec3 srgb) {
  tinygltf::Material mat;
  mat.name = name;
  const auto linear = [](float c) { return c <= 0.04045f ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
  mat.pbrMetallicRoughness.baseColorFactor = {linear(srgb.r), linear(srgb.g), linear(srgb.b), 1.0};
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = 0.9;
  model.materials.push_back(mat);
  return static_cast<int>(model.materials.size() - 1);
}

// One node and mesh per scene mesh, shaded smooth within its creases as the renders shade it.
void add_scene_meshes(GltfBuilder& b, const Scene& scene) {
  const int ground = scene_material(b.model, "ground", {0.59f, 0.58f, 0.55f});
  const int surface = scene_material(b.model, "surface", {0.80f, 0.78f, 0.74f});
  for (const TriangleMesh& mesh : scene.meshes) {
    if (mesh.triangles.empty() || !mesh.visible) continue;  // a collision-only object is not shown
    const geom::ShadedMesh sm = geom::crease_shaded(mesh);
    Aabb box;
    for (const auto& v : sm.vertices) box.extend(v);
    tinygltf::Primitive prim;
    const std::size_t nv = sm.vertices.size();
    prim.attributes["POSITION"] =
        b.accessor(b.view(sm.vertices.data(), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
    b.model.accessors.back().minValues = {box.min.x, box.min.y, box.min.z};
    b.model.accessors.back().maxValues = {box.max.x, box.max.y, box.max.z};
    prim.attributes["NORMAL"] =
        b.accessor(b.view(sm.normals.data(), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
    prim.indices = b.indices(sm.triangles.data(), sm.triangles.size() * 3);
    prim.material = mesh.climbable ? surface : ground;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh gm;
    gm.name = mesh.name;
    gm.primitives.push_back(prim);
    b.model.meshes.push_back(gm);
    tinygltf::Node node;
    node.name = mesh.name;
    node.mesh = static_cast<int>(b.model.meshes.size() - 1);
    node.extras = tinygltf::Value(tinygltf::Value::Object{{"climbable", tinygltf::Value(mesh.climbable)}});
    b.model.nodes.push_back(node);
  }
}

// The scene's light (KHR_lights_punctual): the sun a directional light shining along -direction, a point
// light at its place; and its camera, looking from its position at its look-at point.
void add_scene_light_and_camera(GltfBuilder& b, const Scene& scene) {
  tinygltf::Light light;
  tinygltf::Node light_node;
  light.color = {1.0, 0.98, 0.94};
  if (scene.light.kind == Light::Kind::Sun) {
    light.name = light_node.name = "sun";
    light.type = "directional";
    light.intensity = 3.0;
    light_node.rotation = gltf_rotation(facing(-scene.light.direction));
  } else {
    light.name = light_node.name = "light";
    light.type = "point";
    // Candela giving about the sun's illuminance at the scene's middle.
    light.intensity = 3.0 * std::max(1e-6, double(glm::dot(scene.light.position - scene.bounds().center(),
                                                           scene.light.position - scene.bounds().center())));
    light_node.translation = {scene.light.position.x, scene.light.position.y, scene.light.position.z};
  }
  b.model.lights.push_back(light);
  light_node.extensions["KHR_lights_punctual"] =
      tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(0)}});
  b.model.nodes.push_back(light_node);

  const Camera& c = scene.camera;
  tinygltf::Camera cam;
  cam.name = "camera";
  cam.type = "perspective";
  cam.perspective.yfov = glm::radians(double(c.fov_deg));  // growbench's fov is vertical (harness/render/camera.hpp)
  const double size = std::max(
      1.0, double(glm::length(scene.bounds().max - scene.bounds().min)) + double(glm::length(c.position - c.look_at)));
  cam.perspective.znear = 1e-3 * size;
  cam.perspective.zfar = 100.0 * size;
  b.model.cameras.push_back(cam);
  tinygltf::Node cam_node;
  cam_node.name = "camera";
  cam_node.camera = 0;
  cam_node.translation = {c.position.x, c.position.y, c.position.z};
  if (glm::length(c.look_at - c.position) > 0.0f) cam_node.rotation = gltf_rotation(facing(c.look_at - c.position));
  b.model.nodes.push_back(cam_node);
}

}  // namespace

std::uint64_t write_scene_glb(const std::string& path, const Scene& scene) {
  GltfBuilder b;
  b.model.asset.version = "2.0";
  b.model.asset.generator = "growbench";
  b.model.asset.extras = tinygltf::Value(tinygltf::Value::Object{
      {"scene", tinygltf::Value(scene.name)}, {"content_hash", tinygltf::Value(scene.content_hash())}});
  add_scene_meshes(b, scene);
  add_scene_light_and_camera(b, scene);
  tinygltf::Scene root;
  root.name = scene.name;
  for (std::size_t i = 0; i < b.model.nodes.size(); ++i) root.nodes.push_back(static_cast<int>(i));
  b.model.scenes.push_back(root);
  b.model.defaultScene = 0;
  const std::string json = plain_glb_json(b);
  return write_glb_container(path, json, b.buffer.data);
}

std::uint64_t plain_glb_bytes(const OutputMesh& m) {
  GltfBuilder b;
  b.count_only = true;
  build_plain_glb(b, m);
  return glb_container_bytes(plain_glb_json(b).size(), b.size);
}

namespace {

using Json = nlohmann::json;

constexpr int kByte = 5120, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125, kFloat = 5126;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr std::uint32_t kNoVertex = UINT32_MAX;
// uint16 indices, without 65535: glTF forbids the primitive restart value in an index buffer.
constexpr std::size_t kPieceVertices = 65535;

// A meshoptimizer filter for a compressed view (EXT_meshopt_compression's OCTAHEDRAL, QUATERNION,
// EXPONENTIAL): the view's values as floats (4 per unit vector or quaternion, stride / 4 otherwise), encoded
// with `bits` bits. The filtered bytes compress better than the plain quantized ones, and decode to the
// same accessor types.
struct ViewFilter {
  const char* name;
  int bits;
  std::vector<float> values;
};

// The document of the quantized layouts: JSON and the binary chunk. Compressed, every view's bytes are
// encoded by meshoptimizer into the binary chunk, and the view describes its decoded bytes in a second
// buffer without data of its own (EXT_meshopt_compression's fallback buffer).
class CompactGlb {
 public:
  explicit CompactGlb(bool compress) : compress_(compress) {
    doc_["asset"] = {{"version", "2.0"}, {"generator", "growbench"}};
    for (const char* k : {"accessors", "bufferViews", "materials", "meshes", "nodes"}) doc_[k] = Json::array();
  }
  [[nodiscard]] bool compressed() const { return compress_; }
  // `count` records of `stride` bytes (a multiple of 4) at p; `vertex` for vertex attributes. Compressed,
  // with a filter, the filter's encoding of its values replaces the bytes at p.
  int attribute_view(const void* p, std::size_t count, std::size_t stride, bool vertex,
                     const ViewFilter* filter = nullptr) {
    Json v = {{"byteLength", count * stride}};
    if (vertex) {
      v["byteStride"] = stride;
      v["target"] = kArrayBuffer;
    }
    if (!compress_) return plain_view(std::move(v), p, count * stride);
    std::vector<unsigned char> filtered;
    if (filter) {
      filtered.resize(count * stride);
      const std::string_view name = filter->name;
      if (name == "OCTAHEDRAL")
        meshopt_encodeFilterOct(filtered.data(), count, stride, filter->bits, filter->values.data());
      if (name == "QUATERNION")
        meshopt_encodeFilterQuat(filtered.data(), count, stride, filter->bits, filter->values.data());
      if (name == "EXPONENTIAL")
        meshopt_encodeFilterExp(filtered.data(), count, stride, filter->bits, filter->values.data());
      p = filtered.data();
    }
    std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), p, count, stride));
    const int view = compressed_view(std::move(v), out, stride, count, "ATTRIBUTES");
    if (filter) at("bufferViews", view)["extensions"]["EXT_meshopt_compression"]["filter"] = filter->name;
    return view;
  }
  // `count` indices (a multiple of 3 for triangles) written as uint16 when `narrow`, else uint32.
  int index_view(const std::uint32_t* p, std::size_t count, bool narrow, bool triangles) {
    const std::size_t size = narrow ? 2 : 4;
    Json v = {{"byteLength", count * size}, {"target", kElementArrayBuffer}};
    if (compress_) {
      std::vector<unsigned char> out(triangles ? meshopt_encodeIndexBufferBound(count, count)
                                               : meshopt_encodeIndexSequenceBound(count, count));
      out.resize(triangles ? meshopt_encodeIndexBuffer(out.data(), out.size(), p, count)
                           : meshopt_encodeIndexSequence(out.data(), out.size(), p, count));
      return compressed_view(std::move(v), out, size, count, triangles ? "TRIANGLES" : "INDICES");
    }
    if (!narrow) return plain_view(std::move(v), p, count * 4);
    std::vector<std::uint16_t> shorts(p, p + count);
    return plain_view(std::move(v), shorts.data(), count * 2);
  }
  int accessor(int view, int component, std::size_t count, const char* type, bool normalized = false) {
    Json a = {{"bufferView", view}, {"componentType", component}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    return add("accessors", std::move(a));
  }
  int add(const char* array, Json item) {
    doc_[array].push_back(std::move(item));
    return static_cast<int>(doc_[array].size() - 1);
  }
  Json& at(const char* array, int i) { return doc_[array][static_cast<std::size_t>(i)]; }
  void use(const char* extension, bool required) {
    auto listed = [&](const char* list) {
      Json& l = doc_[list];
      if (std::find(l.begin(), l.end(), extension) == l.end()) l.push_back(extension);
    };
    listed("extensionsUsed");
    if (required) listed("extensionsRequired");
  }
  std::uint64_t write(const std::string& path, int root) {
    doc_["scenes"] = Json::array({{{"nodes", {root}}}});
    doc_["scene"] = 0;
    for (const char* k : {"accessors", "bufferViews", "materials", "meshes"})
      if (doc_[k].empty()) doc_.erase(k);  // glTF's arrays hold at least one item when present
    doc_["buffers"] = Json::array({{{"byteLength", bin_.size()}}});
    if (compress_) {
      use("EXT_meshopt_compression", true);
      doc_["buffers"].push_back(
          {{"byteLength", fallback_}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    }
    return write_glb_container(path, doc_.dump(), bin_);
  }

 private:
  int plain_view(Json v, const void* p, std::size_t n) {
    v["buffer"] = 0;
    v["byteOffset"] = append_padded(bin_, p, n);
    return add("bufferViews", std::move(v));
  }
  int compressed_view(Json v, const std::vector<unsigned char>& data, std::size_t stride, std::size_t count,
                      const char* mode) {
    v["buffer"] = 1;
    v["byteOffset"] = fallback_;
    fallback_ += pad4(v["byteLength"].get<std::size_t>());
    v["extensions"]["EXT_meshopt_compression"] = {{"buffer", 0},
                                                  {"byteOffset", append_padded(bin_, data.data(), data.size())},
                                                  {"byteLength", data.size()},
                                                  {"byteStride", stride},
                                                  {"count", count},
                                                  {"mode", mode}};
    return add("bufferViews", std::move(v));
  }
  bool compress_;
  Json doc_;
  std::vector<unsigned char> bin_;
  std::size_t fallback_ = 0;
};

// Primitives of `arity` indices cut, in order, into pieces of at most kPieceVertices distinct vertices:
// each piece's vertices (mesh indices, in order of first use) and its indices into them. `local` holds
// kNoVertex for every mesh vertex, and does again on return.
struct Piece {
  std::vector<std::uint32_t> vertices, indices;
};
std::vector<Piece> cut_pieces(const std::uint32_t* idx, std::size_t primitives, std::size_t arity,
                              std::vector<std::uint32_t>& local) {
  std::vector<Piece> pieces(1);
  for (std::size_t t = 0; t < primitives; ++t) {
    const std::uint32_t* prim = idx + t * arity;
    std::size_t fresh = 0;
    for (std::size_t k = 0; k < arity; ++k) fresh += local[prim[k]] == kNoVertex ? 1 : 0;
    if (pieces.back().vertices.size() + fresh > kPieceVertices) {
      for (const auto v : pieces.back().vertices) local[v] = kNoVertex;
      pieces.emplace_back();
    }
    Piece& p = pieces.back();
    for (std::size_t k = 0; k < arity; ++k) {
      std::uint32_t& l = local[prim[k]];
      if (l == kNoVertex) {
        l = static_cast<std::uint32_t>(p.vertices.size());
        p.vertices.push_back(prim[k]);
      }
      p.indices.push_back(l);
    }
  }
  for (const auto v : pieces.back().vertices) local[v] = kNoVertex;
  if (pieces.back().indices.empty()) pieces.pop_back();
  return pieces;
}

template <class T, std::size_t N>
int vertex_accessor(CompactGlb& g, const std::vector<std::array<T, N>>& values, int component, const char* type,
                    bool normalized) {
  const int view = g.attribute_view(values.data(), values.size(), sizeof(T) * N, true);
  return g.accessor(view, component, values.size(), type, normalized);
}

// Growth steps as a SCALAR accessor: per vertex, unsigned 16-bit in 4-byte records (meshopt wants records
// of a multiple of 4 bytes, and a vertex view says its stride) when every step fits; else, and per
// instance (whose views are tightly packed), float, exact to 2^24 steps.
int birth_step_accessor(CompactGlb& g, const std::vector<std::uint32_t>& steps, bool vertex) {
  const std::uint32_t last = steps.empty() ? 0 : *std::max_element(steps.begin(), steps.end());
  if (vertex && last <= UINT16_MAX) {
    std::vector<std::array<std::uint16_t, 2>> narrow(steps.size(), {0, 0});
    for (std::size_t i = 0; i < steps.size(); ++i) narrow[i][0] = static_cast<std::uint16_t>(steps[i]);
    return g.accessor(g.attribute_view(narrow.data(), narrow.size(), 4, vertex), kUnsignedShort, narrow.size(),
                      "SCALAR");
  }
  const std::vector<float> wide(steps.begin(), steps.end());
  return g.accessor(g.attribute_view(wide.data(), wide.size(), 4, vertex), kFloat, wide.size(), "SCALAR");
}

// The vertex attributes of a piece, quantized; `box_min` and `step` dequantize its positions.
Json piece_attributes(CompactGlb& g, const OutputMesh& m, const Piece& p, const glm::vec3& box_min, float step) {
  const std::size_t n = p.vertices.size();
  std::vector<std::array<std::uint16_t, 4>> pos(n, {0, 0, 0, 0});
  std::vector<std::array<std::int8_t, 4>> nrm(n, {0, 0, 0, 0});
  std::array<long, 3> lo{65535, 65535, 65535}, hi{0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 q = glm::round((m.positions[p.vertices[i]] - box_min) / step);
    const glm::vec3 nv = glm::round(glm::clamp(m.normals[p.vertices[i]], -1.0f, 1.0f) * 127.0f);
    for (int k = 0; k < 3; ++k) {
      const long c = std::clamp(std::lround(q[k]), 0L, 65535L);
      pos[i][static_cast<std::size_t>(k)] = static_cast<std::uint16_t>(c);
      lo[static_cast<std::size_t>(k)] = std::min(lo[static_cast<std::size_t>(k)], c);
      hi[static_cast<std::size_t>(k)] = std::max(hi[static_cast<std::size_t>(k)], c);
      nrm[i][static_cast<std::size_t>(k)] = static_cast<std::int8_t>(nv[k]);
    }
  }
  Json attrs;
  attrs["POSITION"] = vertex_accessor(g, pos, kUnsignedShort, "VEC3", false);
  g.at("accessors", attrs["POSITION"])["min"] = lo;
  g.at("accessors", attrs["POSITION"])["max"] = hi;
  ViewFilter oct{"OCTAHEDRAL", 8, {}};
  if (g.compressed()) {
    oct.values.reserve(4 * n);
    for (const auto v : p.vertices) {
      const glm::vec3 d = m.normals[v];
      const glm::vec3 u = glm::length(d) > 0.0f ? glm::normalize(d) : glm::vec3(0.0f, 0.0f, 1.0f);
      oct.values.insert(oct.values.end(), {u.x, u.y, u.z, 0.0f});
    }
  }
  attrs["NORMAL"] =
      g.accessor(g.attribute_view(nrm.data(), n, 4, true, g.compressed() ? &oct : nullptr), kByte, n, "VEC3", true);
  if (!m.colors.empty()) {
    std::vector<std::array<std::uint16_t, 4>> col(n, {0, 0, 0, 0});
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        col[i][static_cast<std::size_t>(k)] =
            static_cast<std::uint16_t>(std::lround(std::clamp(m.colors[p.vertices[i]][k], 0.0f, 1.0f) * 65535.0f));
    attrs["COLOR_0"] = vertex_accessor(g, col, kUnsignedShort, "VEC3", true);
  }
  if (!m.uvs.empty()) {  // float: v grows along the branches without bound, so it does not normalize
    std::vector<std::array<float, 2>> uv(n);
    for (std::size_t i = 0; i < n; ++i) uv[i] = {m.uvs[p.vertices[i]].x, 1.0f - m.uvs[p.vertices[i]].y};
    attrs["TEXCOORD_0"] = vertex_accessor(g, uv, kFloat, "VEC2", false);
  }
  if (m.birth_steps.size() == m.positions.size()) {
    std::vector<std::uint32_t> steps(n);
    for (std::size_t i = 0; i < n; ++i) steps[i] = m.birth_steps[p.vertices[i]];
    attrs[kBirthStep] = birth_step_accessor(g, steps, true);
  }
  for (const auto& a : m.attributes) {
    static constexpr const char* kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
    const auto c = static_cast<std::size_t>(std::clamp(a.components, 1, 4));
    std::vector<float> values(n * c);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < c; ++k)
        values[i * c + k] = a.values[p.vertices[i] * static_cast<std::size_t>(a.components) + k];
    const auto taken = [&](const auto& match) {
      for (auto it = attrs.begin(); it != attrs.end(); ++it)
        if (match(it.key())) return true;
      return false;
    };
    attrs[free_attribute_name(a.name, taken)] =
        g.accessor(g.attribute_view(values.data(), n, 4 * c, true), kFloat, n, kTypes[c - 1]);
  }
  return attrs;
}

// A piece as a mesh of one primitive on a node whose translation and uniform scale dequantize its
// positions (uniform, so the normals stay as they are); returns the node.
int write_piece(CompactGlb& g, const OutputMesh& m, const Piece& p, std::size_t arity, int material,
                const std::string& name) {
  Aabb box;
  for (const auto v : p.vertices) box.extend(m.positions[v]);
  const glm::vec3 extent = box.max - box.min;
  float step = std::max({extent.x, extent.y, extent.z}) / 65535.0f;
  if (!(step > 0.0f)) step = 1.0f;  // a single point
  Json prim = {{"attributes", piece_attributes(g, m, p, box.min, step)}, {"material", material}};
  prim["indices"] = g.accessor(g.index_view(p.indices.data(), p.indices.size(), true, arity == 3), kUnsignedShort,
                               p.indices.size(), "SCALAR");
  prim["mode"] = arity == 3 ? 4 : 1;
  const int mesh = g.add("meshes", {{"name", name}, {"primitives", Json::array({prim})}});
  return g.add("nodes", {{"name", name},
                         {"mesh", mesh},
                         {"translation", {box.min.x, box.min.y, box.min.z}},
                         {"scale", {step, step, step}}});
}

// The organs mesh_plant put in its organ groups: "leaves" holds leaves and young leaves, "flowers"
// flowers and buds.
bool in_organ_group(const std::string& group, OrganKind kind) {
  if (group == "leaves") return kind == OrganKind::Leaf || kind == OrganKind::YoungLeaf;
  if (group == "flowers") return kind == OrganKind::Flower || kind == OrganKind::Bud;
  return false;
}

// One organ shape as a mesh (float positions and normals: a few vertices) drawn at every organ of it by
// EXT_mesh_gpu_instancing; returns the node.
int write_instances(CompactGlb& g, const OrganShape& shape, const std::vector<const Organ*>& organs,
                    const std::vector<std::uint32_t>& steps, int material, const std::string& name) {
  const std::size_t nv = shape.mesh.vertices.size();
  Json attrs;
  attrs["POSITION"] = g.accessor(g.attribute_view(shape.mesh.vertices.data(), nv, 12, true), kFloat, nv, "VEC3");
  Aabb box;
  for (const auto& v : shape.mesh.vertices) box.extend(v);
  g.at("accessors", attrs["POSITION"])["min"] = {box.min.x, box.min.y, box.min.z};
  g.at("accessors", attrs["POSITION"])["max"] = {box.max.x, box.max.y, box.max.z};
  attrs["NORMAL"] = g.accessor(g.attribute_view(shape.normals.data(), nv, 12, true), kFloat, nv, "VEC3");
  const std::size_t ni = 3 * shape.mesh.triangles.size();
  const bool narrow = nv <= kPieceVertices;
  const int indices = g.accessor(g.index_view(&shape.mesh.triangles[0].x, ni, narrow, true),
                                 narrow ? kUnsignedShort : kUnsignedInt, ni, "SCALAR");
  Json prim = {{"attributes", attrs}, {"indices", indices}, {"material", material}};
  const int mesh = g.add("meshes", {{"name", name}, {"primitives", Json::array({prim})}});
  // Per organ: where it is, how it is turned (a unit quaternion as normalized int16 x, y, z, w) and its
  // size: the transform add_organ applies to the shape.
  const std::size_t n = organs.size();
  std::vector<glm::vec3> translation(n), scale(n);
  std::vector<std::array<std::int16_t, 4>> rotation(n);
  // Compressed: translations to 16 bits of mantissa under an exponent shared by x, y and z (the branches'
  // quantization step, for a plant a few metres across), rotations to 14 bits per component, sizes to 14.
  ViewFilter t{"EXPONENTIAL", 16, {}}, r{"QUATERNION", 14, {}}, s{"EXPONENTIAL", 14, {}};
  const bool f = g.compressed();
  for (std::size_t i = 0; i < n; ++i) {
    translation[i] = organs[i]->position;
    scale[i] = glm::vec3(organs[i]->size);
    const glm::quat q = glm::normalize(organs[i]->orientation);
    const std::array<float, 4> xyzw{q.x, q.y, q.z, q.w};
    for (std::size_t k = 0; k < 4; ++k) rotation[i][k] = static_cast<std::int16_t>(std::lround(xyzw[k] * 32767.0f));
    if (f) {
      t.values.insert(t.values.end(), {translation[i].x, translation[i].y, translation[i].z});
      r.values.insert(r.values.end(), xyzw.begin(), xyzw.end());
      s.values.insert(s.values.end(), {scale[i].x, scale[i].y, scale[i].z});
    }
  }
  Json inst;
  inst["TRANSLATION"] =
      g.accessor(g.attribute_view(translation.data(), n, 12, false, f ? &t : nullptr), kFloat, n, "VEC3");
  inst["ROTATION"] =
      g.accessor(g.attribute_view(rotation.data(), n, 8, false, f ? &r : nullptr), kShort, n, "VEC4", true);
  inst["SCALE"] = g.accessor(g.attribute_view(scale.data(), n, 12, false, f ? &s : nullptr), kFloat, n, "VEC3");
  if (!steps.empty()) inst[kBirthStep] = birth_step_accessor(g, steps, false);
  g.use("EXT_mesh_gpu_instancing", false);
  return g.add("nodes",
               {{"name", name}, {"mesh", mesh}, {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", inst}}}}}});
}

// An organ group's organs by shape (OrganShapes' index), when they are what the group holds: the group's
// triangles are exactly theirs. Empty otherwise, and the group is written as pieces.
std::vector<std::vector<const Organ*>> organs_by_shape(const MeshGroup& group, const Plant& plant,
                                                       const OrganShapes& shapes) {
  std::vector<std::vector<const Organ*>> by_shape(shapes.size());
  std::size_t triangles = 0;
  for (const auto& o : plant.organs) {
    if (!in_organ_group(group.name, o.kind)) continue;
    by_shape[shapes.index_of(o)].push_back(&o);
    triangles += shapes.of(o).mesh.triangles.size();
  }
  if (triangles != group.triangle_count || group.line_count > 0 || !group.plant_group.empty()) return {};
  return by_shape;
}

int glb_material(CompactGlb& g, const MeshGroup& group) {
  Json mat = {{"name", group.material},
              {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
              {"doubleSided", group.material != "bark"}};
  for (const auto& c : material_colors())
    if (group.material == c.material) mat["pbrMetallicRoughness"]["baseColorFactor"] = {c.r, c.g, c.b, 1.0};
  return g.add("materials", std::move(mat));
}

}  // namespace

std::uint64_t write_glb(const std::string& path, const OutputMesh& m, GlbLayout layout, const Plant& plant,
                        const OrganShapes& shapes) {
  // Nothing to instance or compress, and glTF wants every buffer at least one byte long: a plant with no
  // geometry is written as the plain layout's empty scene, which every reader takes.
  if (layout == GlbLayout::Plain || (m.triangles.empty() && m.lines.empty())) return write_glb(path, m);
  CompactGlb g(layout == GlbLayout::Compact);
  const bool instancing = m.colors.empty() && m.attributes.empty();
  const std::uint32_t last_step = last_birth_step(plant);
  std::vector<std::uint32_t> local(m.positions.size(), kNoVertex);
  std::vector<int> children;                            // of the root
  std::map<std::string, std::vector<int>> group_nodes;  // plant group -> its nodes
  for (const auto& group : m.groups) {
    const int material = glb_material(g, group);
    std::vector<int>& into = group.plant_group.empty() ? children : group_nodes[group.plant_group];
    std::vector<std::vector<const Organ*>> by_shape;
    if (instancing) by_shape = organs_by_shape(group, plant, shapes);
    if (!by_shape.empty()) {
      for (std::size_t s = 0; s < by_shape.size(); ++s) {
        if (by_shape[s].empty()) continue;
        std::vector<std::uint32_t> steps;
        if (!m.birth_steps.empty())
          for (const Organ* o : by_shape[s]) steps.push_back(organ_birth_step(plant, *o, last_step));
        into.push_back(write_instances(g, shapes.at(s), by_shape[s], steps, material, group.name));
      }
      continue;
    }
    const auto pieces = [&](const std::uint32_t* idx, std::size_t count, std::size_t arity) {
      for (const Piece& p : cut_pieces(idx, count, arity, local))
        into.push_back(write_piece(g, m, p, arity, material, group.name));
    };
    if (group.triangle_count > 0) pieces(&m.triangles[group.first_triangle].x, group.triangle_count, 3);
    if (group.line_count > 0) pieces(&m.lines[group.first_line].x, group.line_count, 2);
    g.use("KHR_mesh_quantization", true);
  }
  for (const auto& [name, nodes] : group_nodes)
    children.push_back(g.add("nodes", {{"name", name}, {"children", nodes}}));
  Json root = {{"name", "plant"}};
  if (!children.empty()) root["children"] = children;
  return g.write(path, g.add("nodes", std::move(root)));
}

std::uint64_t write_skeleton_obj(const std::string& path, const Plant& plant) {
  TextFile out(path);
  out.print("# growbench skeleton: {} nodes; vertex i+1 is node i; '#r' gives the radius of the next vertex\n",
            plant.nodes.size());
  using Buf = fmt::memory_buffer;
  out.records(plant.nodes.size(), [&](std::size_t i, Buf& b) {
    const PlantNode& n = plant.nodes[i];
    fmt::format_to(fmt::appender(b), FMT_COMPILE("#r {:.6g}\nv {:.6g} {:.6g} {:.6g}\n"), n.radius, n.position.x,
                   n.position.y, n.position.z);
  });
  const auto chains = plant_chains(plant);
  out.records(chains.size(), [&](std::size_t c, Buf& b) {
    b.push_back('l');
    for (const auto i : chains[c]) fmt::format_to(fmt::appender(b), FMT_COMPILE(" {}"), i + 1);
    b.push_back('\n');
  });
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
constexpr char kTubeStyleTag[4] = {'T', 'S', 'T', 'Y'};   // f32 tension, f32 branch blend, u8 uvs, f32 v increment
constexpr char kOrganStyleTag[4] = {'O', 'R', 'G', 'N'};  // u64 n, per shape name: u64 length, name;
                                                          // per organ u16 shape, 3 f32 tint

bool has_sections(const Plant& p) {
  return !p.node_groups.empty() || !p.node_attributes.empty() || !p.node_tubes.empty() ||
         p.branch_geometry != BranchGeometry::Tube || p.tube_style != TubeStyle{} || p.organs_styled();
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
  if (plant.tube_style != TubeStyle{}) {
    put_tag(b, kTubeStyleTag, 4 + 4 + 1 + 4);
    put(b, plant.tube_style.tension);
    put(b, plant.tube_style.branch_blend);
    put(b, static_cast<std::uint8_t>(plant.tube_style.uvs));
    put(b, plant.tube_style.v_increment);
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
    } else if (is(kTubeStyleTag)) {
      plant.tube_style.tension = r.get<float>();
      plant.tube_style.branch_blend = r.get<float>();
      plant.tube_style.uvs = r.get<std::uint8_t>() != 0;
      plant.tube_style.v_increment = r.get<float>();
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
