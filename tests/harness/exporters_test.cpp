#include "harness/output/exporters.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include "core/json_util.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

Plant y_plant() {
  Plant p;
  p.nodes = {{{0, 0, 0}, 0.05f, kNoParent, 0, 0, 0},
             {{0, 1, 0}, 0.04f, 0, 0, 0, 1},
             {{0, 2, 0}, 0.02f, 1, 0, 0, 2},
             {{1, 2, 0}, 0.02f, 1, 1, 1, 2}};
  p.organs = {{{0, 2, 0}, {1, 0, 0, 0}, 0.1f, OrganKind::Leaf, 2}, {{1, 2, 0}, {1, 0, 0, 0}, 0.1f, OrganKind::Leaf, 3}};
  return p;
}

TEST(Mesher, ChainsAndTriangleCounts) {
  const Plant p = y_plant();
  const auto chains = plant_chains(p);
  ASSERT_EQ(chains.size(), 2u);
  EXPECT_EQ(chains[0], (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(chains[1], (std::vector<std::int32_t>{1, 3}));
  MesherOptions o;
  o.sides = 6;
  const OutputMesh m = mesh_plant(p, o);
  // Main chain: 2 segments x 6 sides x 2 + 2 caps x 6; branch: 1 x 6 x 2 + 2 x 6; two leaves x 2.
  EXPECT_EQ(m.triangles.size(), (24u + 12u) + (12u + 12u) + 4u);
  ASSERT_EQ(m.groups.size(), 2u);
  EXPECT_EQ(m.groups[0].name, "branches");
  EXPECT_EQ(m.groups[1].triangle_count, 4u);
  // Ring vertices sit at the node radius from the axis.
  EXPECT_NEAR(glm::length(glm::vec2(m.positions[0].x, m.positions[0].z)), 0.05f, 1e-6f);
  // The lateral branch starts with its own (thinner) radius at the parent node.
  const std::size_t branch_first_ring = 3 * 6 + 2;  // after the main chain's rings and two cap centres
  EXPECT_NEAR(glm::length(m.positions[branch_first_ring] - glm::vec3(0, 1, 0)), 0.02f, 1e-6f);
}

TEST(Mesher, CustomLeafFromObj) {
  const auto dir = test::temp_dir("leaf_obj");
  // A three-triangle leaf authored 2 units long from z = 0.5: normalised to z in [0, 1].
  const std::string leaf = test::write_text(dir / "leaf.obj",
                                            "v 0 0 0.5\nv 0.2 0 1.5\nv 0 0 2.5\nv -0.2 0 1.5\nv 0 0.1 1.5\n"
                                            "f 1 2 3\nf 1 3 4\nf 1 5 3\n");
  const TriangleMesh m = load_organ_obj(leaf).mesh;
  ASSERT_EQ(m.triangles.size(), 3u);
  EXPECT_FLOAT_EQ(m.vertices[0].z, 0.0f);
  EXPECT_FLOAT_EQ(m.vertices[2].z, 1.0f);
  EXPECT_FLOAT_EQ(m.vertices[1].x, 0.1f);  // scaled by 1/2 like z
  // Every leaf of the plant is that shape: 3 triangles each instead of the default's 2.
  MesherOptions o;
  o.leaf_obj = leaf;
  const OutputMesh mesh = mesh_plant(y_plant(), with_leaf_mesh(o));
  ASSERT_EQ(mesh.groups.size(), 2u);
  EXPECT_EQ(mesh.groups[1].triangle_count, 6u);
  EXPECT_EQ(with_leaf_mesh(o).leaf->mesh.triangles.size(), 3u);
  // A leaf of size 0.1 at (0, 2, 0) with the identity frame spans z 0..0.1 there.
  float zmax = -1.0f;
  for (std::uint32_t t = mesh.groups[1].first_triangle; t < mesh.groups[1].first_triangle + 3; ++t)
    for (int k = 0; k < 3; ++k) zmax = std::max(zmax, mesh.positions[mesh.triangles[t][k]].z);
  EXPECT_NEAR(zmax, 0.1f, 1e-6f);
  // Bad leaves are errors that name the file and what was expected.
  auto message = [](const std::string& path) {
    try {
      (void)load_organ_obj(path);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message((dir / "none.obj").string()).find("none.obj: no such file"), std::string::npos);
  const std::string flat = test::write_text(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(message(flat).find("no length along z"), std::string::npos) << message(flat);
  const std::string empty = test::write_text(dir / "empty.obj", "v 0 0 0\n");
  EXPECT_NE(message(empty).find("empty.obj: the OBJ file has no faces"), std::string::npos) << message(empty);
}

// Large enough for the parallel formatting (chunks of 8192 records): the file must be exactly what a
// serial loop writes, on one thread and on all of them.
TEST(Exporters, LargeObjIsTheSerialTextOnAnyThreadCount) {
  OutputMesh m;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    m.positions.emplace_back(0.001f * static_cast<float>(i), std::sin(static_cast<float>(i)),
                             -1e-7f * static_cast<float>(i));
    m.normals.push_back(glm::normalize(glm::vec3(1.0f, std::cos(static_cast<float>(i)), 0.5f)));
  }
  for (std::uint32_t t = 0; t < 30001; ++t)
    m.triangles.emplace_back(t % 20000, (7 * t + 1) % 20000, (13 * t + 2) % 20000);
  m.groups = {{"branches", "bark", 0, 17000}, {"leaves", "leaf", 17000, 13001}};
  std::string expected = "# growbench plant: 20000 vertices, 30001 triangles\nmtllib plant.mtl\n";
  for (const auto& v : m.positions) expected += fmt::format("v {:.6g} {:.6g} {:.6g}\n", v.x, v.y, v.z);
  for (const auto& n : m.normals) expected += fmt::format("vn {:.4f} {:.4f} {:.4f}\n", n.x, n.y, n.z);
  for (const auto& g : m.groups) {
    expected += fmt::format("g {}\nusemtl {}\n", g.name, g.material);
    for (std::uint32_t t = g.first_triangle; t < g.first_triangle + g.triangle_count; ++t) {
      const glm::uvec3 f = m.triangles[t] + glm::uvec3(1);
      expected += fmt::format("f {0}//{0} {1}//{1} {2}//{2}\n", f.x, f.y, f.z);
    }
  }
  const auto dir = test::temp_dir("large_obj");
  auto read = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  for (const int threads : {1, 2, 4}) {
    const auto path = dir / fmt::format("t{}", threads) / "plant.obj";
    std::filesystem::create_directories(path.parent_path());
    tbb::task_arena(threads).execute([&] { write_obj(path.string(), m); });
    const std::string text = read(path);
    EXPECT_EQ(text.size(), expected.size()) << threads << " threads";
    EXPECT_TRUE(text == expected) << threads << " threads";
    EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  }
}

TEST(Exporters, ObjReadsBackWithGroupsAndMaterials) {
  const auto dir = test::temp_dir("obj");
  const OutputMesh m = mesh_plant(y_plant());
  const auto bytes = write_obj((dir / "plant.obj").string(), m);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "plant.obj") + std::filesystem::file_size(dir / "plant.mtl"));
  tinyobj::ObjReader r;
  ASSERT_TRUE(r.ParseFromFile((dir / "plant.obj").string())) << r.Error();
  EXPECT_EQ(r.GetAttrib().vertices.size(), 3 * m.positions.size());
  ASSERT_EQ(r.GetShapes().size(), 2u);
  EXPECT_EQ(r.GetShapes()[0].name, "branches");
  EXPECT_EQ(r.GetShapes()[1].name, "leaves");
  std::size_t faces = 0;
  for (const auto& s : r.GetShapes()) faces += s.mesh.num_face_vertices.size();
  EXPECT_EQ(faces, m.triangles.size());
  ASSERT_EQ(r.GetMaterials().size(), 3u);
  EXPECT_EQ(r.GetMaterials()[0].name, "bark");
}

TEST(Exporters, BinaryPlyLayout) {
  const auto dir = test::temp_dir("ply");
  const OutputMesh m = mesh_plant(y_plant());
  const auto bytes = write_ply((dir / "p.ply").string(), m);
  std::ifstream in(dir / "p.ply", std::ios::binary);
  std::string header, line;
  while (std::getline(in, line)) {
    header += line + "\n";
    if (line == "end_header") break;
  }
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex " + std::to_string(m.positions.size())), std::string::npos);
  EXPECT_NE(header.find("element face " + std::to_string(m.triangles.size())), std::string::npos);
  EXPECT_EQ(bytes, header.size() + m.positions.size() * 24 + m.triangles.size() * 13);
  float first[3];
  in.read(reinterpret_cast<char*>(first), sizeof(first));
  EXPECT_EQ(glm::vec3(first[0], first[1], first[2]), m.positions[0]);
}

TEST(Exporters, GlbReadsBackWithTinyGltf) {
  const auto dir = test::temp_dir("glb");
  const OutputMesh m = mesh_plant(y_plant());
  const auto bytes = write_glb((dir / "p.glb").string(), m);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "p.glb"));
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir / "p.glb").string())) << err;
  ASSERT_EQ(model.meshes.size(), 1u);
  ASSERT_EQ(model.meshes[0].primitives.size(), m.groups.size());
  const auto& pos = model.accessors[static_cast<std::size_t>(model.meshes[0].primitives[0].attributes.at("POSITION"))];
  EXPECT_EQ(pos.count, m.positions.size());
  std::size_t indices = 0;
  for (const auto& p : model.meshes[0].primitives)
    indices += model.accessors[static_cast<std::size_t>(p.indices)].count;
  EXPECT_EQ(indices, 3 * m.triangles.size());
  EXPECT_EQ(model.materials[0].name, "bark");
  // The first vertex survives the round trip bit for bit.
  const auto& view = model.bufferViews[static_cast<std::size_t>(pos.bufferView)];
  glm::vec3 first;
  std::memcpy(&first, model.buffers[0].data.data() + view.byteOffset, sizeof(first));
  EXPECT_EQ(first, m.positions[0]);
}

TEST(Exporters, SkeletonHasNodesAndPolylines) {
  const auto dir = test::temp_dir("skel");
  write_skeleton_obj((dir / "s.obj").string(), y_plant());
  std::ifstream in(dir / "s.obj");
  std::vector<std::string> v, l, r;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) v.push_back(line);
    if (line.rfind("l ", 0) == 0) l.push_back(line);
    if (line.rfind("#r ", 0) == 0) r.push_back(line);
  }
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[3], "v 1 2 0");
  EXPECT_EQ(r[0], "#r 0.05");
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0], "l 1 2 3");
  EXPECT_EQ(l[1], "l 2 4");
}

// Large enough for parallel chunks of nodes and of chains: the file is what a serial loop writes.
TEST(Exporters, LargeSkeletonIsTheSerialTextOnAnyThreadCount) {
  Plant p;
  p.nodes.push_back({{0, 0, 0}, 0.05f, kNoParent, 0, 0, 0});
  for (std::int32_t i = 1; i < 30000; ++i) {  // a spine (even nodes) with a one-node twig on each (odd)
    const std::int32_t parent = i % 2 == 1 ? i - 1 : i - 2;
    const float t = static_cast<float>(i);
    p.nodes.push_back({{std::sin(t), 0.001f * t, -1e-7f * t}, 0.05f / (1.0f + t), parent, 0, 0, 0});
  }
  std::string expected =
      "# growbench skeleton: 30000 nodes; vertex i+1 is node i; '#r' gives the radius of the next vertex\n";
  for (const auto& n : p.nodes)
    expected += fmt::format("#r {:.6g}\nv {:.6g} {:.6g} {:.6g}\n", n.radius, n.position.x, n.position.y, n.position.z);
  const auto chains = plant_chains(p);
  ASSERT_GT(chains.size(), 10000u);
  for (const auto& chain : chains) {
    expected += "l";
    for (const auto i : chain) expected += fmt::format(" {}", i + 1);
    expected += "\n";
  }
  const auto dir = test::temp_dir("large_skeleton");
  for (const int threads : {1, 2, 4}) {
    const auto path = dir / fmt::format("s{}.obj", threads);
    tbb::task_arena(threads).execute([&] { write_skeleton_obj(path.string(), p); });
    const std::string text = read_text_file(path.string());
    EXPECT_EQ(text.size(), expected.size()) << threads << " threads";
    EXPECT_TRUE(text == expected) << threads << " threads";
  }
}

// y_plant with two decals: one on scene mesh 2's texture coordinates, one planar with axes that are
// neither unit nor axis-aligned (so a field read into the wrong place shows).
Plant decal_plant() {
  Plant p = y_plant();
  SurfaceDecal uv;
  uv.image = "texture.png";
  uv.mesh = 2;
  SurfaceDecal planar;
  planar.image = "wall-vines.png";
  planar.mesh = kPlanarDecal;
  planar.origin = {-1.5f, 0.25f, 2.0f};
  planar.u_axis = {3.0f, 0.0f, 0.5f};
  planar.v_axis = {0.0f, 2.5f, -0.125f};
  p.decals = {uv, planar};
  return p;
}

std::string file_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

template <class T>
void append(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

TEST(PlantSnapshot, DecalsRoundTripWithTheImagePrefix) {
  const auto dir = test::temp_dir("snapshot_decals");
  const Plant p = decal_plant();
  const auto bytes = write_plant_snapshot((dir / "p.gbplant").string(), p);
  Plant without = p;
  without.decals.clear();
  const auto base = write_plant_snapshot((dir / "base.gbplant").string(), without);
  // The section after the polygons: a count, then per decal its name's length and bytes, mesh, origin
  // and the two axes.
  EXPECT_EQ(bytes, base + 8 + (8 + 11 + 4 + 36) + (8 + 14 + 4 + 36));
  const Plant q = read_plant_snapshot((dir / "p.gbplant").string());
  EXPECT_EQ(q.geometry_hash(), p.geometry_hash());
  ASSERT_EQ(q.decals.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(q.decals[i].image, p.decals[i].image);
    EXPECT_EQ(q.decals[i].mesh, p.decals[i].mesh);
    EXPECT_EQ(q.decals[i].origin, p.decals[i].origin);
    EXPECT_EQ(q.decals[i].u_axis, p.decals[i].u_axis);
    EXPECT_EQ(q.decals[i].v_axis, p.decals[i].v_axis);
  }
  // A frame's snapshot names the images written beside it with the frame's prefix; nothing else changes.
  write_plant_snapshot((dir / "step_000010.gbplant").string(), p, "step_000010.");
  const Plant f = read_plant_snapshot((dir / "step_000010.gbplant").string());
  ASSERT_EQ(f.decals.size(), 2u);
  EXPECT_EQ(f.decals[0].image, "step_000010.texture.png");
  EXPECT_EQ(f.decals[1].image, "step_000010.wall-vines.png");
  EXPECT_EQ(f.decals[1].u_axis, p.decals[1].u_axis);
  EXPECT_EQ(f.geometry_hash(), p.geometry_hash());
  // A prefix that would make the stored names other than plain file names is refused before writing.
  EXPECT_THROW(write_plant_snapshot((dir / "bad.gbplant").string(), p, "frames/"), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.gbplant"));
}

TEST(PlantSnapshot, SnapshotsWrittenBeforeDecalsStillRead) {
  // The layout before decals, byte by byte: the magic, one node, no organs, one triangle.
  std::string old = "GBPLANT1";
  append<std::uint64_t>(old, 1);
  append(old, glm::vec3(0.5f, 1.0f, -2.0f));
  append(old, 0.25f);
  append<std::int32_t>(old, kNoParent);
  append<std::uint16_t>(old, 0);
  append<std::uint32_t>(old, 7);
  append<std::uint32_t>(old, 3);
  append<std::uint64_t>(old, 0);
  append<std::uint64_t>(old, 1);
  append<std::uint64_t>(old, 3);
  for (const glm::vec3 v : {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)}) append(old, v);
  const auto dir = test::temp_dir("snapshot_old");
  test::write_text(dir / "old.gbplant", old);
  const Plant p = read_plant_snapshot((dir / "old.gbplant").string());
  ASSERT_EQ(p.nodes.size(), 1u);
  EXPECT_EQ(p.nodes[0].position, glm::vec3(0.5f, 1.0f, -2.0f));
  EXPECT_EQ(p.nodes[0].shoot, 7u);
  EXPECT_EQ(p.nodes[0].birth_step, 3u);
  ASSERT_EQ(p.polygons.size(), 1u);
  EXPECT_EQ(p.polygons[0].vertices[2], glm::vec3(0, 1, 0));
  EXPECT_TRUE(p.decals.empty());
  // And a plant without decals is written in that layout, so older builds read it too.
  write_plant_snapshot((dir / "new.gbplant").string(), p);
  EXPECT_EQ(file_text(dir / "new.gbplant"), old);
}

TEST(PlantSnapshot, CorruptDecalsAreErrorsNamingTheFile) {
  const auto dir = test::temp_dir("snapshot_decals_bad");
  Plant without = decal_plant();
  without.decals.clear();
  const std::size_t at = write_plant_snapshot((dir / "base.gbplant").string(), without);  // the decal section
  write_plant_snapshot((dir / "p.gbplant").string(), decal_plant());
  const std::string good = file_text(dir / "p.gbplant");
  auto error_with = [&](const std::string& name, const std::string& data) {
    test::write_text(dir / name, data);
    return test::error_of([&] { read_plant_snapshot((dir / name).string()); });
  };
  // A count, or a name's length, larger than the rest of the file: refused before anything is allocated.
  std::string data = good;
  const std::uint64_t huge = std::uint64_t{1} << 60;
  std::memcpy(data.data() + at, &huge, 8);
  std::string e = error_with("count.gbplant", data);
  EXPECT_NE(e.find("count.gbplant: plant snapshot count"), std::string::npos) << e;
  EXPECT_NE(e.find("exceeds the file"), std::string::npos) << e;
  data = good;
  std::memcpy(data.data() + at + 8, &huge, 8);
  e = error_with("length.gbplant", data);
  EXPECT_NE(e.find("length.gbplant: plant snapshot count"), std::string::npos) << e;
  // Cut inside the second decal.
  e = error_with("cut.gbplant", good.substr(0, good.size() - 20));
  EXPECT_NE(e.find("cut.gbplant: plant snapshot cut short"), std::string::npos) << e;
  // A name that is not a plain file name: the plant's own check, through the reader.
  data = good;
  data[at + 8 + 8 + 4] = '/';  // "text/re.png"
  e = error_with("name.gbplant", data);
  EXPECT_NE(e.find("name.gbplant: plant snapshot holds an invalid plant: decal 0 has image name"), std::string::npos)
      << e;
  // Bytes after the decals.
  e = error_with("trailing.gbplant", good + "x");
  EXPECT_NE(e.find("trailing.gbplant: plant snapshot has trailing bytes"), std::string::npos) << e;
}

TEST(Exporters, UnwritableDirectoryIsAClearError) {
  try {
    write_ply("/nonexistent-dir/x.ply", mesh_plant(y_plant()));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.ply"), std::string::npos);
  }
}

}  // namespace
}  // namespace growbench
