#include "harness/output/exporters.hpp"

#include <array>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <stdexcept>
#include <type_traits>

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

}  // namespace

std::uint64_t write_obj(const std::string& path, const OutputMesh& m) {
  const std::filesystem::path p(path);
  const std::string mtl_name = p.stem().string() + ".mtl";
  TextFile mtl((p.parent_path() / mtl_name).string());
  mtl.print(
      "# growbench materials\n"
      "newmtl bark\nKd 0.36 0.25 0.17\nKa 0 0 0\nKs 0.05 0.05 0.05\nNs 10\n\n"
      "newmtl leaf\nKd 0.22 0.50 0.16\nKa 0 0 0\nKs 0.1 0.1 0.1\nNs 20\n\n"
      "newmtl flower\nKd 0.92 0.85 0.95\nKa 0 0 0\nKs 0.1 0.1 0.1\nNs 20\n");
  std::uint64_t bytes = mtl.finish();

  TextFile out(path);
  out.print("# growbench plant: {} vertices, {} triangles\nmtllib {}\n", m.positions.size(), m.triangles.size(),
            mtl_name);
  using Buf = fmt::memory_buffer;
  out.records(m.positions.size(), [&](std::size_t i, Buf& b) {
    const glm::vec3& v = m.positions[i];
    fmt::format_to(std::back_inserter(b), "v {:.6g} {:.6g} {:.6g}\n", v.x, v.y, v.z);
  });
  out.records(m.normals.size(), [&](std::size_t i, Buf& b) {
    const glm::vec3& n = m.normals[i];
    fmt::format_to(std::back_inserter(b), "vn {:.4f} {:.4f} {:.4f}\n", n.x, n.y, n.z);
  });
  for (const auto& g : m.groups) {
    out.print("g {}\nusemtl {}\n", g.name, g.material);
    out.records(g.triangle_count, [&](std::size_t i, Buf& b) {
      const glm::uvec3 f = m.triangles[g.first_triangle + i] + glm::uvec3(1);
      fmt::format_to(std::back_inserter(b), "f {0}//{0} {1}//{1} {2}//{2}\n", f.x, f.y, f.z);
    });
  }
  return bytes + out.finish();
}

std::uint64_t write_ply(const std::string& path, const OutputMesh& m) {
  auto file = std::make_unique<AtomicFile>(path);
  AtomicFile& f = *file;
  const std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment growbench plant\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      m.positions.size(), m.triangles.size());
  f.bytes(header.data(), header.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    f.bytes(&m.positions[i], sizeof(glm::vec3));
    f.bytes(&m.normals[i], sizeof(glm::vec3));
  }
  for (const auto& t : m.triangles) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {static_cast<std::int32_t>(t.x), static_cast<std::int32_t>(t.y),
                                 static_cast<std::int32_t>(t.z)};
    f.bytes(&three, 1);
    f.bytes(idx, sizeof(idx));
  }
  return f.finish();
}

// Long because tinygltf's model is filled field by field: buffers, views, accessors, materials, then the scene.
std::uint64_t write_glb(const std::string& path, const OutputMesh& m) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "growbench";
  tinygltf::Buffer buffer;
  // One allocation for the whole binary chunk (positions, normals, indices, each padded to 4 bytes).
  buffer.data.reserve(2 * m.positions.size() * sizeof(glm::vec3) + m.triangles.size() * sizeof(glm::uvec3) +
                      4 * (m.groups.size() + 2));
  auto append = [&](const void* p, std::size_t n) {
    const auto off = buffer.data.size();
    buffer.data.insert(buffer.data.end(), static_cast<const unsigned char*>(p),
                       static_cast<const unsigned char*>(p) + n);
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
  const int pos_view =
      view(append(m.positions.data(), nv * sizeof(glm::vec3)), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
  const int nrm_view =
      view(append(m.normals.data(), nv * sizeof(glm::vec3)), nv * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
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
    const int idx_view =
        view(append(&m.triangles[g.first_triangle], bytes), bytes, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
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

 private:
  std::string path_, data_;
  std::size_t pos_ = 0;
};

// The smallest record of a decal: an empty name's length, mesh, origin and both axes.
constexpr std::size_t kDecalMinBytes = 8 + 4 + 3 * 12;
constexpr char kOrganStyleTag[8] = {'O', 'R', 'G', 'A', 'N', 'S', '1', '\0'};

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
  const bool styled = !plant.organ_shapes.empty() ||
                      std::any_of(plant.organs.begin(), plant.organs.end(),
                                  [](const Organ& o) { return o.shape != kKindShape || o.tint != glm::vec3(1.0f); });
  if (!plant.decals.empty() || styled) {
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
  if (styled) {  // a tag, the organ shapes' names, then each organ's shape and tint
    b.bytes(kOrganStyleTag, sizeof(kOrganStyleTag));
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
  // Snapshots of plants without organ shapes or tints end here.
  if (!r.at_end() && r.tag(kOrganStyleTag)) {
    plant.organ_shapes.resize(r.count(9));
    for (auto& name : plant.organ_shapes) name = r.text(r.count(1));
    for (auto& o : plant.organs) {
      o.shape = r.get<std::uint16_t>();
      o.tint = r.vec3();
    }
  }
  if (!r.at_end()) throw InputError(fmt::format("{}: plant snapshot has trailing bytes", path));
  if (const std::string bad = plant.validate(); !bad.empty())
    throw InputError(fmt::format("{}: plant snapshot holds an invalid plant: {}", path, bad));
  return plant;
}

}  // namespace growbench
