// The .glb layouts (harness/output/exporters.hpp): the plain layout's size computed without writing it, and
// the instanced and compact layouts decoded back here (meshoptimizer's own decoder for the compressed views)
// and compared with the plain mesh: pieces within half a quantization step, organs where add_organ puts them.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "harness/output/exporters.hpp"
#include "harness/record/record.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using Json = nlohmann::json;

// A climbing stem of `n` nodes (a helix, so no two pieces share a box) with a lateral twig every tenth
// node, a leaf on every node turned a different way each (every seventh a young leaf), and with `flowers` a
// flower on every fiftieth.
Plant helix_plant(int n, bool flowers) {
  Plant p;
  for (int i = 0; i < n; ++i) {
    const float a = 0.05f * static_cast<float>(i);
    const glm::vec3 pos(0.3f * std::cos(a), 0.002f * static_cast<float>(i), 0.3f * std::sin(a));
    const float r = 0.004f - 0.003f * static_cast<float>(i) / static_cast<float>(n);
    p.nodes.push_back({pos, r, i == 0 ? kNoParent : i - 1, 0, 0, static_cast<std::uint32_t>(i)});
    const glm::quat q =
        glm::angleAxis(0.7f * static_cast<float>(i), glm::normalize(glm::vec3(std::sin(a), 1.0f, 0.3f)));
    p.organs.push_back({pos, q, 0.02f + 0.01f * std::sin(a), i % 7 == 0 ? OrganKind::YoungLeaf : OrganKind::Leaf, i});
    if (flowers && i % 50 == 25) p.organs.push_back({pos, q, 0.03f, OrganKind::Flower, i});
  }
  for (int i = 10; i < n; i += 10) {
    const auto parent = static_cast<std::size_t>(i);
    const glm::vec3 tip = p.nodes[parent].position + glm::vec3(0.05f, 0.01f, 0.0f);
    p.nodes.push_back({tip, 0.001f, i, 1, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
  }
  return p;
}

struct Glb {
  Json doc;
  std::string bin;
};

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Glb read_glb(const std::filesystem::path& path) {
  const std::string data = file_bytes(path);
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, data.data() + at, 4);
    return v;
  };
  EXPECT_EQ(data.substr(0, 4), "glTF");
  EXPECT_EQ(u32(8), data.size());
  const std::uint32_t json_bytes = u32(12);
  EXPECT_EQ(data.substr(16, 4), "JSON");
  Glb g{Json::parse(data.substr(20, json_bytes)), ""};
  if (20 + json_bytes < data.size()) {
    EXPECT_EQ(data.substr(20 + json_bytes + 4, 4), std::string("BIN\0", 4));
    g.bin = data.substr(20 + json_bytes + 8, u32(20 + json_bytes));
  }
  return g;
}

// A view's bytes as a reader sees them: decoded by meshoptimizer when the view is compressed.
std::string view_bytes(const Glb& g, int view) {
  const Json& v = g.doc["bufferViews"][static_cast<std::size_t>(view)];
  if (!v.contains("extensions")) {
    EXPECT_EQ(v["buffer"], 0);
    return g.bin.substr(v.value("byteOffset", std::size_t{0}),
                        v["byteLength"].get<std::size_t>());  // glTF's default offset is 0
  }
  const Json& e = v["extensions"]["EXT_meshopt_compression"];
  const auto count = e["count"].get<std::size_t>(), stride = e["byteStride"].get<std::size_t>();
  const auto* src = reinterpret_cast<const unsigned char*>(g.bin.data()) + e["byteOffset"].get<std::size_t>();
  const auto n = e["byteLength"].get<std::size_t>();
  std::string out(count * stride, '\0');
  const std::string mode = e["mode"];
  int rc = -1;
  if (mode == "ATTRIBUTES") rc = meshopt_decodeVertexBuffer(out.data(), count, stride, src, n);
  if (mode == "TRIANGLES") rc = meshopt_decodeIndexBuffer(out.data(), count, stride, src, n);
  if (mode == "INDICES") rc = meshopt_decodeIndexSequence(out.data(), count, stride, src, n);
  EXPECT_EQ(rc, 0) << "view " << view << " (" << mode << ")";
  const std::string filter = e.value("filter", "NONE");
  if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
  if (filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
  if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
  EXPECT_EQ(out.size(), v["byteLength"].get<std::size_t>());
  return out;
}

// An accessor's components as floats, normalized types mapped as glTF maps them.
std::vector<float> accessor_values(const Glb& g, int accessor) {
  const Json& a = g.doc["accessors"][static_cast<std::size_t>(accessor)];
  const std::string type = a["type"];
  const std::size_t comps = type == "SCALAR" ? 1 : static_cast<std::size_t>(type[3] - '0');
  const int ct = a["componentType"];
  const std::size_t size = ct == 5126 || ct == 5125 ? 4 : ct == 5122 || ct == 5123 ? 2 : 1;
  const int view = a["bufferView"];
  const std::string bytes = view_bytes(g, view);
  const Json& v = g.doc["bufferViews"][static_cast<std::size_t>(view)];
  const std::size_t stride = v.contains("byteStride") ? v["byteStride"].get<std::size_t>() : comps * size;
  const bool normalized = a.value("normalized", false);
  std::vector<float> out;
  for (std::size_t i = 0; i < a["count"].get<std::size_t>(); ++i) {
    for (std::size_t c = 0; c < comps; ++c) {
      const char* p = bytes.data() + i * stride + c * size;
      float x = 0.0f;
      if (ct == 5126) std::memcpy(&x, p, 4);
      if (ct == 5125) x = static_cast<float>(*reinterpret_cast<const std::uint32_t*>(p));
      if (ct == 5123) x = *reinterpret_cast<const std::uint16_t*>(p) / (normalized ? 65535.0f : 1.0f);
      if (ct == 5122) x = std::max(*reinterpret_cast<const std::int16_t*>(p) / (normalized ? 32767.0f : 1.0f), -1.0f);
      if (ct == 5120) x = std::max(*reinterpret_cast<const std::int8_t*>(p) / (normalized ? 127.0f : 1.0f), -1.0f);
      out.push_back(x);
    }
  }
  return out;
}

glm::vec3 vec3_at(const std::vector<float>& v, std::size_t i) {
  return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

// What a quantized file holds, decoded: every piece's triangle corners (position and normal, in order) and
// every instanced organ's vertices, both in world space.
struct Decoded {
  std::vector<glm::vec3> corners, corner_normals, organ_vertices;
  std::vector<float> corner_tolerance;           // half the piece's quantization step
  std::vector<float> corner_steps, organ_steps;  // _BIRTH_STEP, when the file has it
  std::size_t pieces = 0;
};

Decoded decode(const Glb& g) {
  Decoded d;
  for (const Json& node : g.doc["nodes"]) {
    if (!node.contains("mesh")) continue;
    const Json& prim = g.doc["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0];
    const auto pos = accessor_values(g, prim["attributes"]["POSITION"]);
    const auto nrm = accessor_values(g, prim["attributes"]["NORMAL"]);
    const auto idx = accessor_values(g, prim["indices"]);
    if (node.contains("extensions")) {
      const Json& inst = node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"];
      const auto t = accessor_values(g, inst["TRANSLATION"]), r = accessor_values(g, inst["ROTATION"]),
                 s = accessor_values(g, inst["SCALE"]);
      const auto steps = inst.contains("_BIRTH_STEP") ? accessor_values(g, inst["_BIRTH_STEP"]) : std::vector<float>{};
      for (std::size_t i = 0; i < t.size() / 3; ++i) {
        const glm::mat3 rot =
            glm::mat3_cast(glm::normalize(glm::quat(r[4 * i + 3], r[4 * i], r[4 * i + 1], r[4 * i + 2])));
        for (std::size_t k = 0; k < pos.size() / 3; ++k) {
          d.organ_vertices.push_back(vec3_at(t, i) + rot * (vec3_at(pos, k) * vec3_at(s, i)));
          if (!steps.empty()) d.organ_steps.push_back(steps[i]);
        }
      }
      continue;
    }
    ++d.pieces;
    const glm::vec3 origin(node["translation"][0], node["translation"][1], node["translation"][2]);
    const float step = node["scale"][0];
    EXPECT_EQ(node["scale"][1], node["scale"][0]);  // uniform: normals need no correction
    EXPECT_EQ(g.doc["accessors"][prim["indices"].get<std::size_t>()]["componentType"], 5123);  // uint16
    const auto steps = prim["attributes"].contains("_BIRTH_STEP")
                           ? accessor_values(g, prim["attributes"]["_BIRTH_STEP"])
                           : std::vector<float>{};
    for (const float i : idx) {
      if (!steps.empty()) d.corner_steps.push_back(steps[static_cast<std::size_t>(i)]);
      EXPECT_LT(i, 65535.0f);  // the primitive restart value is not an index
      const auto k = static_cast<std::size_t>(i);
      d.corners.push_back(origin + step * vec3_at(pos, k));
      d.corner_normals.push_back(vec3_at(nrm, k));
      d.corner_tolerance.push_back(0.5f * step);
    }
  }
  return d;
}

// Checks a quantized file against the plain mesh it was made from. The compact layout's filters keep
// fewer bits: 16 of mantissa for the organs' positions (relative to their largest coordinate), 14 for
// rotations and sizes, 8 for octahedral normals (a half step of 1/255 on the octahedron, stretched up to
// twice on the sphere, then rounded to int8: within 0.03, where int8 alone is within 0.01).
void expect_same_plant(const Glb& g, const OutputMesh& m, const Plant& plant, bool compact) {
  const Decoded d = decode(g);
  std::vector<glm::vec3> corners, normals, organ_vertices;
  std::vector<float> organ_tolerance, corner_steps, organ_steps;
  for (const auto& group : m.groups) {
    const bool organs = group.name == "leaves" || group.name == "flowers";
    for (std::uint32_t t = group.first_triangle; t < group.first_triangle + group.triangle_count; ++t)
      for (int k = 0; k < 3; ++k) {
        if (organs) continue;
        corners.push_back(m.positions[m.triangles[t][k]]);
        normals.push_back(m.normals[m.triangles[t][k]]);
        corner_steps.push_back(static_cast<float>(m.birth_steps[m.triangles[t][k]]));
      }
  }
  // Instances come shape by shape within each organ group; here every organ of a group has one shape.
  for (const char* group : {"leaves", "flowers"}) {
    const OrganShapes shapes(plant);
    for (const auto& o : plant.organs) {
      const bool in = std::string(group) == "leaves" ? o.kind == OrganKind::Leaf || o.kind == OrganKind::YoungLeaf
                                                     : o.kind == OrganKind::Flower || o.kind == OrganKind::Bud;
      if (!in) continue;
      const glm::vec3 a = glm::abs(o.position);
      for (const auto& v : shapes.of(o).mesh.vertices) {
        organ_vertices.push_back(organ_point(o, v));
        organ_steps.push_back(static_cast<float>(plant.nodes[static_cast<std::size_t>(o.node)].birth_step));
        organ_tolerance.push_back(compact ? 5e-6f + 6e-5f * std::max({a.x, a.y, a.z}) + 1e-3f * o.size : 5e-6f);
      }
    }
  }
  // meshoptimizer's index codec may start a triangle at another corner (the same triangle, the same
  // winding), so each triangle must match in one of its three rotations.
  ASSERT_EQ(d.corners.size(), corners.size());
  // Each vertex and organ carries the step at which it appeared, exactly.
  ASSERT_EQ(d.corner_steps.size(), corners.size());
  ASSERT_EQ(d.organ_steps, organ_steps);
  auto corner_matches = [&](std::size_t decoded, std::size_t expected) {
    const glm::vec3 e = glm::abs(d.corners[decoded] - corners[expected]);
    return std::max({e.x, e.y, e.z}) <= d.corner_tolerance[decoded] * 1.01f + 1e-6f &&
           glm::length(d.corner_normals[decoded] - normals[expected]) <= (compact ? 0.03f : 0.01f) &&
           d.corner_steps[decoded] == corner_steps[expected];
  };
  for (std::size_t t = 0; t < corners.size(); t += 3) {
    int rotation = -1;
    for (std::size_t r = 0; r < 3 && rotation < 0; ++r)
      if (corner_matches(t, t + r) && corner_matches(t + 1, t + (r + 1) % 3) && corner_matches(t + 2, t + (r + 2) % 3))
        rotation = static_cast<int>(r);
    ASSERT_GE(rotation, 0) << "triangle " << t / 3;
    if (!compact) {
      ASSERT_EQ(rotation, 0) << "triangle " << t / 3;  // uncompressed indices are as written
    }
  }
  ASSERT_EQ(d.organ_vertices.size(), organ_vertices.size());
  for (std::size_t i = 0; i < organ_vertices.size(); ++i)
    ASSERT_LE(glm::length(d.organ_vertices[i] - organ_vertices[i]), organ_tolerance[i]) << "organ vertex " << i;
}

TEST(Glb, PlainBytesAreTheFileSizeWithoutWritingIt) {
  const auto dir = test::temp_dir("glb_plain_bytes");
  OutputMesh m = mesh_plant(helix_plant(300, true));
  const auto plain = write_glb((dir / "a.glb").string(), m);
  EXPECT_EQ(plain, std::filesystem::file_size(dir / "a.glb"));
  EXPECT_EQ(plain_glb_bytes(m), plain);
  // Colours, an attribute of three floats, and lines: every part of the document that has a size.
  m.colors.assign(m.positions.size(), glm::vec3(0.25f, 2.0f, -1.0f));
  m.attributes.push_back({"w x", 3, std::vector<float>(3 * m.positions.size(), 0.5f)});
  m.lines = {{0, 1}, {1, 2}, {2, 3}};
  m.groups.push_back({"skeleton", "bark", 0, 0});
  m.groups.back().first_line = 0;
  m.groups.back().line_count = 3;
  m.groups.back().plant_group = "g1";
  EXPECT_EQ(plain_glb_bytes(m), write_glb((dir / "b.glb").string(), m));
  EXPECT_EQ(plain_glb_bytes(OutputMesh{}), write_glb((dir / "empty.glb").string(), OutputMesh{}));
}

// A viewer plays a plant back from its file: each vertex carries the step at which its part appeared. A
// tube's rings appear with the segment they end (a chain's first ring with its first segment), so at step k
// exactly the segments whose end node existed are whole; an organ appears with its node.
TEST(Glb, EachVertexCarriesTheStepItsPartAppeared) {
  Plant p;
  p.nodes = {{{0, 0, 0}, 0.01f, kNoParent, 0, 0, 0}, {{0, 1, 0}, 0.01f, 0, 0, 0, 3}, {{0, 2, 0}, 0.01f, 1, 0, 0, 7}};
  p.organs.push_back({{0, 2, 0}, glm::quat(1, 0, 0, 0), 0.1f, OrganKind::Leaf, 2});
  p.polygons.push_back({{{1, 0, 0}, {1, 1, 0}, {2, 1, 0}}});
  MesherOptions o;
  o.sides = 4;
  const OutputMesh m = mesh_plant(p, o);
  ASSERT_EQ(m.birth_steps.size(), m.positions.size());
  const std::size_t leaf = OrganShapes(p).of(p.organs[0]).mesh.vertices.size();
  std::vector<std::uint32_t> expect = {3, 3, 3, 3, 3, 3, 3, 3, 7, 7, 7, 7, 3, 7};  // three rings, two caps
  expect.insert(expect.end(), leaf, 7);
  expect.insert(expect.end(), {7, 7, 7});  // a polygon stands for no node: it appears with the plant
  EXPECT_EQ(m.birth_steps, expect);
  // Every layout writes them; the plain file as floats.
  const auto dir = test::temp_dir("glb_steps");
  write_glb((dir / "plain.glb").string(), m);
  const Glb plain = read_glb(dir / "plain.glb");
  const auto steps = accessor_values(plain, plain.doc["meshes"][0]["primitives"][0]["attributes"]["_BIRTH_STEP"]);
  EXPECT_EQ(steps, std::vector<float>(expect.begin(), expect.end()));
  EXPECT_EQ(plain_glb_bytes(m), std::filesystem::file_size(dir / "plain.glb"));
  // A user attribute of that name, in any case, keeps its own: viewers read names lower-cased.
  OutputMesh named = m;
  named.attributes.push_back({"Birth_Step", 1, std::vector<float>(m.positions.size(), 5.0f)});
  write_glb((dir / "named.glb").string(), named);
  write_glb((dir / "named_compact.glb").string(), named, GlbLayout::Compact, p, OrganShapes(p));
  for (const char* file : {"named.glb", "named_compact.glb"}) {
    const Glb g = read_glb(dir / file);
    const Json& attrs = g.doc["meshes"][0]["primitives"][0]["attributes"];
    EXPECT_TRUE(attrs.contains("_BIRTH_STEP")) << file << attrs.dump();
    EXPECT_TRUE(attrs.contains("_Birth_Step_")) << file << attrs.dump();
    for (const float v : accessor_values(g, attrs["_Birth_Step_"])) EXPECT_EQ(v, 5.0f) << file;
    const std::vector<float> kept = accessor_values(g, attrs["_BIRTH_STEP"]);
    EXPECT_NE(std::find(kept.begin(), kept.end(), 3.0f), kept.end()) << file;
  }
}

// glTF wants buffers of at least one byte; a plant with no geometry has no buffer data in any layout.
TEST(Glb, APlantWithNoGeometryIsThePlainEmptySceneInEveryLayout) {
  const auto dir = test::temp_dir("glb_empty");
  const Plant plant;
  const auto read = [](const std::filesystem::path& p) { return read_text_file(p.string()); };
  const auto plain = write_glb((dir / "plain.glb").string(), OutputMesh{});
  for (const GlbLayout layout : {GlbLayout::Instanced, GlbLayout::Compact}) {
    const auto path = dir / fmt::format("{}.glb", glb_layout_name(layout));
    EXPECT_EQ(write_glb(path.string(), OutputMesh{}, layout, plant, OrganShapes(plant)), plain);
    EXPECT_EQ(read(path), read(dir / "plain.glb")) << glb_layout_name(layout);
  }
  EXPECT_EQ(read(dir / "plain.glb").find("buffers"), std::string::npos);
}

TEST(Glb, InstancedAndCompactDecodeToThePlainPlant) {
  const auto dir = test::temp_dir("glb_layouts");
  // More than 65535 branch vertices: the branches are cut into pieces.
  // Without flowers: a built-in blossom has a colour of its own, which makes the plant coloured.
  const Plant plant = helix_plant(12000, false);
  const OutputMesh m = mesh_plant(plant);
  ASSERT_GT(m.positions.size(), 65535u + 4 * plant.organs.size());
  const auto plain = write_glb((dir / "plain.glb").string(), m);
  for (const GlbLayout layout : {GlbLayout::Instanced, GlbLayout::Compact}) {
    SCOPED_TRACE(std::string(glb_layout_name(layout)));
    const auto path = dir / fmt::format("{}.glb", glb_layout_name(layout));
    const auto bytes = write_glb(path.string(), m, layout, plant, OrganShapes(plant));
    EXPECT_EQ(bytes, std::filesystem::file_size(path));
    const Glb g = read_glb(path);
    const bool compact = layout == GlbLayout::Compact;
    EXPECT_EQ(g.doc["extensionsUsed"],
              compact ? Json({"KHR_mesh_quantization", "EXT_mesh_gpu_instancing", "EXT_meshopt_compression"})
                      : Json({"KHR_mesh_quantization", "EXT_mesh_gpu_instancing"}));
    EXPECT_EQ(g.doc["extensionsRequired"],
              compact ? Json({"KHR_mesh_quantization", "EXT_meshopt_compression"}) : Json({"KHR_mesh_quantization"}));
    expect_same_plant(g, m, plant, compact);
    EXPECT_GE(decode(g).pieces, 2u);
    // A leaf per node, as on the wall ivy: compact a fifth of the plain file or less, instanced (quantized,
    // not compressed) half.
    EXPECT_LE((compact ? 5 : 2) * bytes, plain) << bytes << " of " << plain;
  }
}

TEST(Glb, ColouredOrgansAreQuantizedNotInstanced) {
  const auto dir = test::temp_dir("glb_coloured");
  // The built-in blossom's own colour is not its kind's: flowers colour the plant, and its organs are
  // then quantized with the branches. Other colours are given here to check the colour accessor.
  const Plant plant = helix_plant(200, true);
  OutputMesh m = mesh_plant(plant);
  ASSERT_FALSE(m.colors.empty());
  m.colors.assign(m.positions.size(), glm::vec3(0.5f, 0.25f, 1.0f));
  write_glb((dir / "c.glb").string(), m, GlbLayout::Compact, plant, OrganShapes(plant));
  const Glb g = read_glb(dir / "c.glb");
  EXPECT_EQ(g.doc["extensionsUsed"], Json({"KHR_mesh_quantization", "EXT_meshopt_compression"}));
  const Decoded d = decode(g);
  EXPECT_TRUE(d.organ_vertices.empty());
  EXPECT_EQ(d.corners.size(), 3 * m.triangles.size());
  const auto colour = accessor_values(g, g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"]);
  EXPECT_NEAR(colour[0], 0.5f, 0.5f / 65535.0f);
  EXPECT_EQ(colour[2], 1.0f);
}

// `growbench run --glb` end to end: the record's sizes are the files', the plain size the same whichever
// layout was written, one instance per leaf, the same bytes on one and two threads, and a bad layout refused.
TEST(Glb, RunWritesTheChosenLayout) {
  const auto dir = test::temp_dir("glb_run");
  const std::string plant = "run -q -a ivy -s wall --set max_root_length=0.75 ";
  auto run = [&](const std::string& args, const std::string& out) {
    const auto r = test::run_growbench(plant + args + " -o " + (dir / out).string());
    EXPECT_EQ(r.status, 0) << r.out;
    std::ifstream in(dir / out / "record.json");
    return Json::parse(in);
  };
  const Json plain = run("--glb plain --threads 1", "plain");
  const Json one = run("--threads 1", "one");
  const Json two = run("--threads 2", "two");
  EXPECT_EQ(plain["output_bytes"]["glb"].get<std::uintmax_t>(), std::filesystem::file_size(dir / "plain/plant.glb"));
  EXPECT_EQ(plain["output_bytes"]["glb_plain"], plain["output_bytes"]["glb"]);
  EXPECT_EQ(one["output_bytes"]["glb"].get<std::uintmax_t>(), std::filesystem::file_size(dir / "one/plant.glb"));
  EXPECT_EQ(one["output_bytes"]["glb_plain"], plain["output_bytes"]["glb"]);
  EXPECT_EQ(file_bytes(dir / "one/plant.glb"), file_bytes(dir / "two/plant.glb"));
  // The default layout is compact: the ivy's leaves are instances of one leaf, one per leaf.
  const Glb g = read_glb(dir / "one/plant.glb");
  EXPECT_EQ(g.doc["extensionsRequired"], Json({"KHR_mesh_quantization", "EXT_meshopt_compression"}));
  std::size_t instances = 0;
  for (const Json& node : g.doc["nodes"])
    if (node.contains("extensions"))
      instances +=
          g.doc["accessors"]
               [node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"].get<std::size_t>()]["count"]
                   .get<std::size_t>();
  EXPECT_GT(one["counts"]["leaves"].get<std::size_t>(), 100u);
  EXPECT_EQ(instances, one["counts"]["leaves"].get<std::size_t>());
  const auto r = test::run_growbench(plant + "--glb draco -o " + (dir / "bad").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--glb: draco not in {plain,instanced,compact}"), std::string::npos) << r.out;
}

// scene.glb: every scene mesh a node of its name with its vertices where the scene has them, the sun shining
// along -direction, the camera at its position looking at its look-at point, with the vertical fov.
TEST(Glb, SceneFileHoldsTheMeshesTheSunAndTheCamera) {
  const auto dir = test::temp_dir("glb_scene");
  Scene scene = load_scene("wall");
  scene.light.direction = {1.0f, 2.0f, -0.5f};
  scene.camera = {{0.5f, 1.2f, 4.0f}, {0.1f, 0.9f, 0.0f}, 38.0f};
  const auto bytes = write_scene_glb((dir / "scene.glb").string(), scene);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "scene.glb"));
  const Glb g = read_glb(dir / "scene.glb");
  EXPECT_EQ(g.doc["asset"]["extras"]["content_hash"], scene.content_hash());
  EXPECT_EQ(g.doc["asset"]["extras"]["scene"], scene.name);
  const auto quat = [](const Json& r) {
    return glm::quat(r[3].get<float>(), r[0].get<float>(), r[1].get<float>(), r[2].get<float>());
  };
  std::size_t meshes = 0;
  for (const Json& node : g.doc["nodes"]) {
    if (node.contains("mesh")) {
      const TriangleMesh& m = scene.meshes.at(meshes++);
      EXPECT_EQ(node["name"], m.name);
      EXPECT_EQ(node["extras"]["climbable"], m.climbable);
      const Json& prim = g.doc["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0];
      const std::string material = g.doc["materials"][prim["material"].get<std::size_t>()]["name"];
      EXPECT_EQ(material, m.climbable ? "surface" : "ground");
      const std::vector<float> pos = accessor_values(g, prim["attributes"]["POSITION"]);
      const std::vector<float> idx = accessor_values(g, prim["indices"]);
      ASSERT_EQ(idx.size(), 3 * m.triangles.size());
      for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
          EXPECT_EQ(vec3_at(pos, static_cast<std::size_t>(idx[3 * t + static_cast<std::size_t>(k)])),
                    m.vertices[m.triangles[t][k]]);
    } else if (node.contains("camera")) {
      EXPECT_EQ(node["name"], "camera");
      EXPECT_EQ(glm::vec3(node["translation"][0].get<float>(), node["translation"][1].get<float>(),
                          node["translation"][2].get<float>()),
                scene.camera.position);
      const glm::vec3 forward = quat(node["rotation"]) * glm::vec3(0.0f, 0.0f, -1.0f);
      EXPECT_LT(glm::length(forward - glm::normalize(scene.camera.look_at - scene.camera.position)), 1e-5f);
      const Json& cam = g.doc["cameras"][node["camera"].get<std::size_t>()];
      EXPECT_NEAR(cam["perspective"]["yfov"].get<double>(), 38.0 * M_PI / 180.0, 1e-6);
    } else {
      EXPECT_EQ(node["name"], "sun");
      const Json& light = g.doc["extensions"]["KHR_lights_punctual"]["lights"]
                               [node["extensions"]["KHR_lights_punctual"]["light"].get<std::size_t>()];
      EXPECT_EQ(light["type"], "directional");
      const glm::vec3 shines = quat(node["rotation"]) * glm::vec3(0.0f, 0.0f, -1.0f);
      EXPECT_LT(glm::length(shines + glm::normalize(scene.light.direction)), 1e-5f);
    }
  }
  EXPECT_EQ(meshes, scene.meshes.size());
  EXPECT_EQ(g.doc["nodes"].size(), scene.meshes.size() + 2);
}

TEST(Glb, LayoutNames) {
  // A spec names its layout; reading it back gives the same layout, and an unknown name is refused at its path.
  for (const GlbLayout l : {GlbLayout::Plain, GlbLayout::Instanced, GlbLayout::Compact}) {
    TrialSpec spec;
    spec.glb = l;
    const nlohmann::json j = to_json(spec);
    EXPECT_EQ(j["glb"], std::string(glb_layout_name(l)));
    EXPECT_EQ(from_json<TrialSpec>(j, "spec.json").glb, l);
  }
  EXPECT_EQ(glb_layout_name(kDefaultGlbLayout), "compact");
  nlohmann::json j = to_json(TrialSpec{});
  j["glb"] = "draco";
  try {
    (void)from_json<TrialSpec>(j, "spec.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "spec.json: at glb: expected one of plain, instanced, compact, got \"draco\"");
  }
}

}  // namespace
}  // namespace growbench
