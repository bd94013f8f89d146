// What an L-system's groups, attributes and tube arguments become in the exported files, read back with
// real readers: tinygltf for glTF, tinyobjloader for OBJ, and for PLY a small reader here (Debian packages
// no C++ PLY library) that parses any binary little-endian header and body, so it checks what the
// header declares rather than what the writer meant to write.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include "algorithms/grow_util.hpp"
#include "core/errors.hpp"
#include "harness/output/exporters.hpp"
#include "harness/output/mesher.hpp"
#include "harness/render/render.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

// ---------- a PLY reader: binary little-endian, scalar and list properties ----------

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<std::string> properties;                            // in order
  std::map<std::string, std::vector<double>> columns;             // scalar properties
  std::map<std::string, std::vector<std::vector<double>>> lists;  // list properties
};

struct Ply {
  std::vector<std::string> comments;
  std::vector<PlyElement> elements;
  const PlyElement& element(const std::string& name) const {
    for (const auto& e : elements)
      if (e.name == name) return e;
    throw std::runtime_error("no element " + name);
  }
  bool has(const std::string& name) const {
    return std::any_of(elements.begin(), elements.end(), [&](const PlyElement& e) { return e.name == name; });
  }
};

std::size_t ply_size(const std::string& type) {
  static const std::map<std::string, std::size_t> sizes = {{"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},
                                                           {"short", 2}, {"ushort", 2},  {"int16", 2},  {"uint16", 2},
                                                           {"int", 4},   {"uint", 4},    {"int32", 4},  {"uint32", 4},
                                                           {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(type);
  if (it == sizes.end()) throw std::runtime_error("unknown PLY type " + type);
  return it->second;
}

double ply_value(const std::string& type, const char* p) {
  auto get = [&](auto v) {
    std::memcpy(&v, p, sizeof(v));
    return static_cast<double>(v);
  };
  if (type == "char" || type == "int8") return get(std::int8_t{});
  if (type == "uchar" || type == "uint8") return get(std::uint8_t{});
  if (type == "short" || type == "int16") return get(std::int16_t{});
  if (type == "ushort" || type == "uint16") return get(std::uint16_t{});
  if (type == "int" || type == "int32") return get(std::int32_t{});
  if (type == "uint" || type == "uint32") return get(std::uint32_t{});
  if (type == "float" || type == "float32") return get(float{});
  return get(double{});
}

Ply read_ply(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t header_end = data.find("end_header\n");
  if (data.rfind("ply\n", 0) != 0 || header_end == std::string::npos) throw std::runtime_error("not a PLY");
  std::istringstream header(data.substr(0, header_end));
  struct Property {
    std::string name, type, count_type;  // count_type set for a list
  };
  std::vector<std::vector<Property>> props;
  Ply ply;
  for (std::string line; std::getline(header, line);) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string format;
      ls >> format;
      if (format != "binary_little_endian") throw std::runtime_error("format " + format);
    } else if (word == "comment") {
      ply.comments.push_back(line.substr(8));
    } else if (word == "element") {
      PlyElement e;
      ls >> e.name >> e.count;
      ply.elements.push_back(e);
      props.emplace_back();
    } else if (word == "property") {
      Property p;
      ls >> p.type;
      if (p.type == "list") ls >> p.count_type >> p.type;
      ls >> p.name;
      props.back().push_back(p);
      ply.elements.back().properties.push_back(p.name);
    }
  }
  std::size_t pos = header_end + std::strlen("end_header\n");
  for (std::size_t k = 0; k < ply.elements.size(); ++k) {
    PlyElement& e = ply.elements[k];
    for (std::size_t i = 0; i < e.count; ++i)
      for (const Property& p : props[k]) {
        auto read = [&](const std::string& type) {
          if (pos + ply_size(type) > data.size()) throw std::runtime_error("PLY body cut short");
          const double v = ply_value(type, data.data() + pos);
          pos += ply_size(type);
          return v;
        };
        if (p.count_type.empty()) {
          e.columns[p.name].push_back(read(p.type));
        } else {
          const auto n = static_cast<std::size_t>(read(p.count_type));
          std::vector<double> items;
          for (std::size_t j = 0; j < n; ++j) items.push_back(read(p.type));
          e.lists[p.name].push_back(items);
        }
      }
  }
  if (pos != data.size()) throw std::runtime_error("PLY has bytes after its elements");
  return ply;
}

// ---------- helpers ----------

// The L-system grown from `premise` (no rules) at the origin, one unit per F, width 0.1.
class PlantAttributes : public test::OnEnvelope {
 protected:
  static Plant grow(const std::string& premise, std::vector<std::string> extra = {}) {
    std::vector<std::string> sets = {"premise=" + premise, "rules=",      "generations=0",
                                     "start=origin",       "step_size=1", "thickness=0.1"};
    sets.insert(sets.end(), extra.begin(), extra.end());
    return test::grow("lsystem", *scene_, *query_, sets);
  }
};

std::string text_of(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) out.push_back(line);
  return out;
}

tinygltf::Model load_glb(const std::filesystem::path& p) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, p.string())) << err;
  return model;
}

// An accessor's float values (tightly packed, as the writer makes them).
std::vector<float> floats_of(const tinygltf::Model& model, int accessor) {
  const auto& a = model.accessors[static_cast<std::size_t>(accessor)];
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const auto& v = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const std::size_t n = a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(a.type));
  std::vector<float> out(n);
  std::memcpy(out.data(), model.buffers[0].data.data() + v.byteOffset + a.byteOffset, n * sizeof(float));
  return out;
}

std::size_t index_count(const tinygltf::Model& model, const tinygltf::Mesh& mesh) {
  std::size_t n = 0;
  for (const auto& p : mesh.primitives) n += model.accessors[static_cast<std::size_t>(p.indices)].count;
  return n;
}

// ---------- groups ----------

TEST_F(PlantAttributes, GroupsBecomeObjGroupsAndGltfNodes) {
  // The reference's example: gF [ gFF ] F puts the first and last F into group 0, the branch into group 1.
  const Plant p = grow("gF[gFF]F");
  ASSERT_EQ(p.node_groups, (std::vector<std::int32_t>{0, 0, 1, 1, 0}));
  const OutputMesh m = mesh_plant(p);
  ASSERT_EQ(m.groups.size(), 2u);
  EXPECT_EQ(m.groups[0].plant_group, "lsys0");
  EXPECT_EQ(m.groups[1].plant_group, "lsys1");
  // each chain: 2 segments x 6 sides x 2 triangles + 2 caps x 6
  EXPECT_EQ(m.groups[0].triangle_count, 36u);
  EXPECT_EQ(m.groups[1].triangle_count, 36u);

  const auto dir = test::temp_dir("attr_groups");
  write_obj((dir / "p.obj").string(), m);
  const std::string obj = text_of(dir / "p.obj");
  EXPECT_EQ(lines_starting(obj, "g "), (std::vector<std::string>{"g branches lsys0", "g branches lsys1"}));
  EXPECT_NE(obj.find("g branches lsys0\nusemtl bark\nf "), std::string::npos);
  tinyobj::ObjReader r;
  ASSERT_TRUE(r.ParseFromFile((dir / "p.obj").string())) << r.Error();
  ASSERT_EQ(r.GetShapes().size(), 2u);
  EXPECT_EQ(r.GetShapes()[0].name, "branches lsys0");
  EXPECT_EQ(r.GetShapes()[0].mesh.num_face_vertices.size(), 36u);
  EXPECT_EQ(r.GetShapes()[1].name, "branches lsys1");

  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  ASSERT_EQ(model.nodes.size(), 3u);
  EXPECT_EQ(model.nodes[0].name, "plant");
  EXPECT_EQ(model.nodes[0].mesh, -1);  // everything is in a group
  EXPECT_EQ(model.nodes[0].children, (std::vector<int>{1, 2}));
  EXPECT_EQ(model.nodes[1].name, "lsys0");
  EXPECT_EQ(model.nodes[2].name, "lsys1");
  for (int k : {1, 2}) {
    const auto& mesh = model.meshes[static_cast<std::size_t>(model.nodes[static_cast<std::size_t>(k)].mesh)];
    EXPECT_EQ(mesh.name, model.nodes[static_cast<std::size_t>(k)].name);
    EXPECT_EQ(index_count(model, mesh), 3u * 36u);
  }
}

TEST_F(PlantAttributes, UngroupedPartsStayAsTheyWereAndThePrefixNamesGroups) {
  // g only in the branch; the main axis (3 segments here) stays "branches"; polygons are no group's
  const Plant p = grow("FF[g(4)F]F{.+(90)f.+(90)f.}", {"group_prefix=twig"});
  const OutputMesh m = mesh_plant(p);
  const auto dir = test::temp_dir("attr_prefix");
  write_obj((dir / "p.obj").string(), m);
  EXPECT_EQ(lines_starting(text_of(dir / "p.obj"), "g "),
            (std::vector<std::string>{"g branches", "g branches twig4", "g polygons"}));
  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  ASSERT_EQ(model.nodes.size(), 2u);
  EXPECT_EQ(model.nodes[1].name, "twig4");
  const auto& plant_mesh = model.meshes[static_cast<std::size_t>(model.nodes[0].mesh)];
  EXPECT_EQ(plant_mesh.name, "plant");
  ASSERT_EQ(plant_mesh.primitives.size(), 2u);  // the ungrouped branches and the polygon
  EXPECT_EQ(index_count(model, plant_mesh), 3u * (3u * 12u + 12u + 1u));
  EXPECT_EQ(index_count(model, model.meshes[static_cast<std::size_t>(model.nodes[1].mesh)]), 3u * 24u);
  // a prefix that would not stay one word is refused
  EXPECT_THROW(grow("gF", {"group_prefix=a b"}), InputError);
}

// ---------- colours and attributes ----------

TEST_F(PlantAttributes, CdBecomesVertexColoursInGltfPlyAndObj) {
  const Plant p = grow("a(\"Cd\",1,0.5,0.25)FF[a(\"Cd\",0,0.2,1)F]F{.+(90)f.+(90)f.}");
  const OutputMesh m = mesh_plant(p);
  ASSERT_EQ(m.colors.size(), m.positions.size());
  const glm::vec3 trunk(1.0f, 0.5f, 0.25f), branch(0.0f, 0.2f, 1.0f);
  const glm::vec3 leaf = material_color("leaf");
  // trunk: 4 rings of 6 and 2 caps; branch: 2 rings and 2 caps; the polygon's 3 vertices have no colour of
  // their own and take their material's
  std::map<std::tuple<float, float, float>, int> seen;
  for (const auto& c : m.colors) ++seen[{c.x, c.y, c.z}];
  EXPECT_EQ(seen.size(), 3u);
  EXPECT_EQ((seen[{trunk.x, trunk.y, trunk.z}]), 26);
  EXPECT_EQ((seen[{branch.x, branch.y, branch.z}]), 14);
  EXPECT_EQ((seen[{leaf.x, leaf.y, leaf.z}]), 3);

  const auto dir = test::temp_dir("attr_cd");
  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  const auto& prim = model.meshes[0].primitives[0];
  ASSERT_TRUE(prim.attributes.count("COLOR_0"));
  const auto& acc = model.accessors[static_cast<std::size_t>(prim.attributes.at("COLOR_0"))];
  EXPECT_EQ(acc.type, TINYGLTF_TYPE_VEC3);
  const std::vector<float> colors = floats_of(model, prim.attributes.at("COLOR_0"));
  ASSERT_EQ(colors.size(), 3 * m.positions.size());
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    ASSERT_EQ(glm::vec3(colors[3 * v], colors[3 * v + 1], colors[3 * v + 2]), m.colors[v]) << v;
  EXPECT_EQ(glm::vec3(colors[0], colors[1], colors[2]), trunk);  // the root's ring

  write_ply((dir / "p.ply").string(), m);
  const Ply ply = read_ply(dir / "p.ply");
  const PlyElement& vertex = ply.element("vertex");
  EXPECT_EQ(vertex.properties, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"}));
  ASSERT_EQ(vertex.count, m.positions.size());
  // sRGB bytes: 1 -> 255, 0.5 -> 188, 0.25 -> 137, 0.2 -> 124, 0 -> 0
  EXPECT_EQ(vertex.columns.at("red")[0], 255.0);
  EXPECT_EQ(vertex.columns.at("green")[0], 188.0);
  EXPECT_EQ(vertex.columns.at("blue")[0], 137.0);
  std::set<std::tuple<double, double, double>> bytes;
  for (std::size_t v = 0; v < vertex.count; ++v)
    bytes.insert({vertex.columns.at("red")[v], vertex.columns.at("green")[v], vertex.columns.at("blue")[v]});
  EXPECT_TRUE(bytes.count({0.0, 124.0, 255.0}));
  EXPECT_EQ(vertex.columns.at("y")[6], static_cast<double>(m.positions[6].y));
  EXPECT_EQ(ply.element("face").count, m.triangles.size());

  write_obj((dir / "p.obj").string(), m);
  tinyobj::ObjReader r;
  ASSERT_TRUE(r.ParseFromFile((dir / "p.obj").string())) << r.Error();
  const auto& rgb = r.GetAttrib().colors;
  ASSERT_EQ(rgb.size(), 3 * m.positions.size());
  EXPECT_NEAR(rgb[0], 1.0, 1e-4);
  EXPECT_NEAR(rgb[1], 0.7354, 1e-4);  // sRGB-encoded 0.5
  EXPECT_NEAR(rgb[2], 0.5371, 1e-4);
}

// An organ's own colour (its shape's, times its tint) reaches glTF as linear COLOR_0 and PLY as sRGB bytes;
// the branch vertices then carry the bark material's colour.
TEST_F(PlantAttributes, OrganColoursBecomeVertexColoursInGltfAndPly) {
  Plant p = grow("FK");
  ASSERT_EQ(p.organs.size(), 1u);
  p.organs[0].tint = glm::vec3(1.0f, 0.5f, 0.25f);
  const OrganShapes shapes = organ_shapes(p);
  const glm::vec3 petal = shapes.linear_color(p.organs[0]), bark = material_color("bark");
  const std::size_t petal_vertices = shapes.of(p.organs[0]).mesh.vertices.size();
  const OutputMesh m = mesh_plant(p);
  ASSERT_EQ(m.colors.size(), m.positions.size());
  EXPECT_EQ(std::count(m.colors.begin(), m.colors.end(), petal), static_cast<std::ptrdiff_t>(petal_vertices));
  EXPECT_EQ(std::count(m.colors.begin(), m.colors.end(), bark),
            static_cast<std::ptrdiff_t>(m.positions.size() - petal_vertices));

  const auto dir = test::temp_dir("attr_organ_colour");
  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  std::size_t petal_in_gltf = 0;
  for (const auto& prim : model.meshes[0].primitives) {
    ASSERT_TRUE(prim.attributes.count("COLOR_0"));
    const std::vector<float> colors = floats_of(model, prim.attributes.at("COLOR_0"));
    ASSERT_EQ(colors.size(), 3 * m.positions.size());
    for (std::size_t v = 0; v < m.positions.size(); ++v)
      ASSERT_EQ(glm::vec3(colors[3 * v], colors[3 * v + 1], colors[3 * v + 2]), m.colors[v]) << v;
    petal_in_gltf = static_cast<std::size_t>(std::count(m.colors.begin(), m.colors.end(), petal));
  }
  EXPECT_EQ(petal_in_gltf, petal_vertices);

  write_ply((dir / "p.ply").string(), m);
  const Ply ply = read_ply(dir / "p.ply");  // kept: the element below refers into it
  const PlyElement& vertex = ply.element("vertex");
  auto srgb_byte = [](float linear) {
    const double s = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
    return std::round(255.0 * s);
  };
  std::size_t petal_in_ply = 0;
  for (std::size_t v = 0; v < vertex.count; ++v)
    if (std::abs(vertex.columns.at("red")[v] - srgb_byte(petal.r)) <= 1.0 &&
        std::abs(vertex.columns.at("green")[v] - srgb_byte(petal.g)) <= 1.0 &&
        std::abs(vertex.columns.at("blue")[v] - srgb_byte(petal.b)) <= 1.0)
      ++petal_in_ply;
  EXPECT_EQ(petal_in_ply, petal_vertices);
}

TEST_F(PlantAttributes, OtherAttributesBecomePlyPropertiesAndGltfUnderscoreAttributes) {
  const Plant p = grow("a(\"wet\",0.5)a(\"uv2\",1,2)F[a(\"wet\",0.75)F]F");
  const OutputMesh m = mesh_plant(p);
  EXPECT_TRUE(m.colors.empty());  // no Cd
  ASSERT_EQ(m.attributes.size(), 2u);
  const auto dir = test::temp_dir("attr_other");
  write_ply((dir / "p.ply").string(), m);
  const Ply ply = read_ply(dir / "p.ply");
  const PlyElement& vertex = ply.element("vertex");
  EXPECT_EQ(vertex.properties, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "wet", "uv2_0", "uv2_1"}));
  std::set<double> wet(vertex.columns.at("wet").begin(), vertex.columns.at("wet").end());
  EXPECT_EQ(wet, (std::set<double>{0.5, 0.75}));
  EXPECT_EQ(vertex.columns.at("uv2_1")[0], 2.0);

  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  const auto& prim = model.meshes[0].primitives[0];
  ASSERT_TRUE(prim.attributes.count("_wet"));
  ASSERT_TRUE(prim.attributes.count("_uv2"));
  EXPECT_EQ(model.accessors[static_cast<std::size_t>(prim.attributes.at("_wet"))].type, TINYGLTF_TYPE_SCALAR);
  EXPECT_EQ(model.accessors[static_cast<std::size_t>(prim.attributes.at("_uv2"))].type, TINYGLTF_TYPE_VEC2);
  const auto wet_values = floats_of(model, prim.attributes.at("_wet"));
  ASSERT_EQ(wet_values.size(), m.positions.size());
  EXPECT_EQ(wet_values, m.attributes[0].values);
  EXPECT_EQ(std::count(wet_values.begin(), wet_values.end(), 0.75f), 14);  // the branch's rings and caps
}

TEST_F(PlantAttributes, RendersColourConesByCdAndLeaveOthersAsTheyWere) {
  const Plant p = grow("a(\"Cd\",1,0,0)F[a(\"Cd\",0,0,1)F]");
  const auto dir = test::temp_dir("attr_render");
  RenderOptions o;
  write_pov((dir / "c.pov").string(), *scene_, p, o);
  const std::string pov = text_of(dir / "c.pov");
  EXPECT_NE(pov.find("coloured by Cd"), std::string::npos);
  EXPECT_NE(pov.find(" texture { GB_Bark pigment { rgb <0,0,1> } } }"), std::string::npos) << pov;
  EXPECT_NE(pov.find(" texture { GB_Bark pigment { rgb <1,0,0> } } }"), std::string::npos);
  Plant plain = p;
  plain.node_attributes.clear();
  write_pov((dir / "plain.pov").string(), *scene_, plain, o);
  EXPECT_EQ(text_of(dir / "plain.pov").find("pigment { rgb"), std::string::npos);
}

// ---------- F(l, w, s, d) and the geometry type ----------

TEST_F(PlantAttributes, TubeSectionsAndDivisionsFollowF) {
  // 3 sections of 4 divisions, then 1 of 8: 2 x (3 x 4 + 8) triangles, caps of 4 and 8
  const Plant p = grow("F(1,0.1,3,4)F(1,0.1,1,8)");
  ASSERT_EQ(p.node_tubes.size(), 3u);
  EXPECT_EQ(p.node_tubes[1].sections, 3);
  EXPECT_EQ(p.node_tubes[1].divisions, 4);
  EXPECT_EQ(p.node_tubes[2].divisions, 8);
  EXPECT_EQ(p.validate(), "");
  const OutputMesh m = mesh_plant(p);
  EXPECT_EQ(m.triangles.size(), 2u * (3u * 4u + 8u) + 4u + 8u);
  // rings: 4 of 4 (the joint closes the first run), 2 of 8 (the joint again, and the tip), 2 cap centres
  EXPECT_EQ(m.positions.size(), 4u * 4u + 2u * 8u + 2u);
  // the section rings lie at thirds of the first segment
  EXPECT_NEAR(m.positions[4].y, 1.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(m.positions[8].y, 2.0f / 3.0f, 1e-6f);
  // s alone: 2 sections of the mesher's sides (6); and sides from the options where d is not given
  EXPECT_EQ(mesh_plant(grow("F(1,0.1,2)")).triangles.size(), 2u * 6u * 2u + 12u);
  MesherOptions eight;
  eight.sides = 8;
  EXPECT_EQ(mesh_plant(grow("F(1,0.1,2)"), eight).triangles.size(), 2u * 8u * 2u + 16u);
  // values are rounded and clamped; 0 leaves both to the mesher, and then the plant has no tube data
  const Plant big = grow("F(1,0.1,1000,2.4)");
  EXPECT_EQ(big.node_tubes[1].sections, kMaxTubeSections);
  EXPECT_EQ(big.node_tubes[1].divisions, kMinTubeDivisions);
  const Plant zero = grow("F(1,0.1,0,0)F");
  EXPECT_TRUE(zero.node_tubes.empty());
  EXPECT_EQ(zero.geometry_hash(), grow("F(1,0.1)F").geometry_hash());
  EXPECT_NE(p.geometry_hash(), grow("F(1,0.1)F(1,0.1)").geometry_hash());
}

// The centre of the ring of `n` vertices from `first`.
glm::vec3 ring_centre(const OutputMesh& m, std::size_t first, std::size_t n) {
  glm::vec3 c(0.0f);
  for (std::size_t k = first; k < first + n; ++k) c += m.positions[k];
  return c / static_cast<float>(n);
}

// Tension 0 puts a segment's middle ring on the cardinal spline through the nodes: for nodes P0, P1, P2
// the Hermite midpoint of P1..P2 with tangents (P2 - P0) / 2 and P2 - P1 is (P1 + P2) / 2 + (up - d) / 16
// for P1 - P0 = up and P2 - P1 = d. Tension 1 keeps it on the segment; so does a plain F (one section).
TEST_F(PlantAttributes, TensionSweepsTheSectionsAlongACurveThroughTheNodes) {
  const std::string premise = "F(1,0.1,2,4)+(90)F(1,0.1,2,4)";
  const Plant straight = grow(premise);
  const Plant swept = grow(premise, {"tension=0"});
  ASSERT_EQ(swept.nodes.size(), 3u);
  const glm::vec3 p0 = swept.nodes[0].position, p1 = swept.nodes[1].position, p2 = swept.nodes[2].position;
  const glm::vec3 up = p1 - p0, d = p2 - p1;
  ASSERT_NEAR(glm::dot(up, d), 0.0f, 1e-6f);
  const OutputMesh ms = mesh_plant(straight), mc = mesh_plant(swept);
  ASSERT_EQ(mc.positions.size(), ms.positions.size());  // rings: P0, middle, P1, middle, P2 (one strip of 4)
  auto near = [](const glm::vec3& a, const glm::vec3& b) { return glm::length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(ring_centre(ms, 4, 4), p0 + 0.5f * up));
  EXPECT_TRUE(near(ring_centre(ms, 12, 4), p1 + 0.5f * d));
  EXPECT_TRUE(near(ring_centre(mc, 4, 4), p0 + 0.5f * up + (up - d) / 16.0f));
  EXPECT_TRUE(near(ring_centre(mc, 12, 4), p1 + 0.5f * d + (up - d) / 16.0f));
  EXPECT_TRUE(near(ring_centre(mc, 8, 4), p1));  // the nodes stay where they are
  EXPECT_EQ(swept.tube_style.tension, 0.0f);
  EXPECT_NE(swept.geometry_hash(), straight.geometry_hash());
  EXPECT_EQ(grow(premise, {"tension=1"}).geometry_hash(), straight.geometry_hash());
  EXPECT_EQ(mesh_plant(grow("F+(90)F", {"tension=0"})).positions, mesh_plant(grow("F+(90)F")).positions);
}

// Branch blend 1 starts a side branch along its parent's heading: its middle ring is at
// P1 + d / 2 + up / 8 (the Hermite midpoint with tangents up, of the branch's length, and 0 at tension 1).
TEST_F(PlantAttributes, BranchBlendStartsABranchAlongItsParentsHeading) {
  const std::string premise = "F(1,0.1)[+(90)F(1,0.1,2,4)]F";
  const Plant plain = grow(premise), blended = grow(premise, {"branch_blend=1"});
  ASSERT_EQ(blended.nodes.size(), 4u);
  const glm::vec3 p0 = blended.nodes[0].position, p1 = blended.nodes[1].position, p2 = blended.nodes[2].position;
  ASSERT_EQ(blended.nodes[2].parent, 1);
  const glm::vec3 up = p1 - p0, d = p2 - p1;
  // the trunk (3 rings of 6 and two cap centres), then the branch: rings of 4 at P1, its middle, P2
  const OutputMesh mp = mesh_plant(plain), mb = mesh_plant(blended);
  const std::size_t branch = 3 * 6 + 2;
  auto near = [](const glm::vec3& a, const glm::vec3& b) { return glm::length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(ring_centre(mp, branch + 4, 4), p1 + 0.5f * d));
  EXPECT_TRUE(near(ring_centre(mb, branch + 4, 4), p1 + 0.5f * d + up / 8.0f));
  EXPECT_TRUE(near(ring_centre(mb, branch, 4), p1));
  EXPECT_TRUE(near(ring_centre(mb, 6, 6), p1));  // the trunk is as it was
}

// tube_uvs: u runs 0..1 around each ring (a seam vertex repeats the first), v grows by vertical_increment
// per segment from the root, and OBJ (vt), PLY (s, t) and glTF (TEXCOORD_0, v down) carry them.
TEST_F(PlantAttributes, TubeUvsRunAroundTheRingsAndAlongTheSegments) {
  const Plant p = grow("F(1,0.1,2,4)F", {"tube_uvs=true", "vertical_increment=0.5"});
  const OutputMesh m = mesh_plant(p);
  // a strip of 3 rings of 4 + 1, then (the divisions change to 6) a strip of 2 rings of 6 + 1, 2 cap centres
  ASSERT_EQ(m.positions.size(), 3u * 5u + 2u * 7u + 2u);
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  const std::vector<float> v = {0.0f, 0.25f, 0.5f};
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t s = 0; s < 5; ++s) {
      EXPECT_FLOAT_EQ(m.uvs[r * 5 + s].x, static_cast<float>(s) / 4.0f) << r << " " << s;
      EXPECT_FLOAT_EQ(m.uvs[r * 5 + s].y, v[r]) << r << " " << s;
    }
  EXPECT_EQ(m.positions[4], m.positions[0]);  // the seam
  EXPECT_FLOAT_EQ(m.uvs[15].y, 0.5f);
  EXPECT_FLOAT_EQ(m.uvs[22].y, 1.0f);
  EXPECT_FLOAT_EQ(m.uvs[28].x, 1.0f);
  // every triangle is a real one: no index reaches past its strip
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ASSERT_LT(t[k], m.positions.size());

  const auto dir = test::temp_dir("attr_uvs");
  write_obj((dir / "p.obj").string(), m);
  tinyobj::ObjReader r;
  ASSERT_TRUE(r.ParseFromFile((dir / "p.obj").string())) << r.Error();
  ASSERT_EQ(r.GetAttrib().texcoords.size(), 2 * m.positions.size());
  EXPECT_FLOAT_EQ(r.GetAttrib().texcoords[2 * 22 + 1], 1.0f);
  const auto& first = r.GetShapes()[0].mesh.indices[0];
  EXPECT_EQ(first.texcoord_index, first.vertex_index);
  write_ply((dir / "p.ply").string(), m);
  const Ply ply = read_ply(dir / "p.ply");
  EXPECT_EQ(ply.element("vertex").columns.at("t")[22], 1.0);
  EXPECT_EQ(ply.element("vertex").columns.at("s")[3], 0.75);
  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  const auto& prim = model.meshes[0].primitives[0];
  ASSERT_TRUE(prim.attributes.count("TEXCOORD_0"));
  const std::vector<float> uv = floats_of(model, prim.attributes.at("TEXCOORD_0"));
  EXPECT_FLOAT_EQ(uv[2 * 22 + 1], 0.0f);  // glTF's v is 1 - OBJ's
  EXPECT_FLOAT_EQ(uv[2 * 5 + 1], 0.75f);

  // without tube_uvs nothing changes: no texture coordinates, the same hash as before the option existed
  EXPECT_TRUE(mesh_plant(grow("F(1,0.1,2,4)F")).uvs.empty());
  EXPECT_EQ(grow("F", {"vertical_increment=0.5"}).geometry_hash(), grow("F").geometry_hash());
  EXPECT_NE(p.geometry_hash(), grow("F(1,0.1,2,4)F").geometry_hash());
  write_plant_snapshot((dir / "p.gbplant").string(), p);
  EXPECT_EQ(read_plant_snapshot((dir / "p.gbplant").string()).tube_style, p.tube_style);
}

TEST_F(PlantAttributes, SkeletonGeometryIsLinesInEveryFormat) {
  const Plant p = grow("g(2)F[+F]F", {"geometry=skeleton"});
  EXPECT_EQ(p.branch_geometry, BranchGeometry::Skeleton);
  const OutputMesh m = mesh_plant(p);
  ASSERT_EQ(m.lines.size(), 3u);
  ASSERT_EQ(m.groups.size(), 1u);  // the branches' lines, in group 2
  EXPECT_EQ(m.groups[0].triangle_count, 0u);
  EXPECT_EQ(m.groups[0].line_count, 3u);
  EXPECT_EQ(m.groups[0].plant_group, "lsys2");
  EXPECT_TRUE(m.triangles.empty());
  EXPECT_EQ(m.positions.size(), 4u);  // one vertex per node

  const auto dir = test::temp_dir("attr_skeleton");
  write_obj((dir / "p.obj").string(), m);
  const std::string obj = text_of(dir / "p.obj");
  EXPECT_EQ(lines_starting(obj, "l "), (std::vector<std::string>{"l 1 2", "l 2 3", "l 2 4"}));
  tinyobj::ObjReader r;
  ASSERT_TRUE(r.ParseFromFile((dir / "p.obj").string())) << r.Error();
  EXPECT_EQ(r.GetShapes()[0].lines.indices.size(), 6u);

  write_ply((dir / "p.ply").string(), m);
  const Ply ply = read_ply(dir / "p.ply");
  ASSERT_TRUE(ply.has("edge"));
  EXPECT_EQ(ply.element("edge").columns.at("vertex1"), (std::vector<double>{0, 1, 1}));
  EXPECT_EQ(ply.element("edge").columns.at("vertex2"), (std::vector<double>{1, 2, 3}));

  write_glb((dir / "p.glb").string(), m);
  const tinygltf::Model model = load_glb(dir / "p.glb");
  ASSERT_EQ(model.nodes.size(), 2u);
  EXPECT_EQ(model.nodes[1].name, "lsys2");
  const auto& lines = model.meshes[static_cast<std::size_t>(model.nodes[1].mesh)];
  ASSERT_EQ(lines.primitives.size(), 1u);
  EXPECT_EQ(lines.primitives[0].mode, TINYGLTF_MODE_LINE);
  EXPECT_EQ(index_count(model, lines), 6u);
  // and tubes are the default
  EXPECT_EQ(grow("F").branch_geometry, BranchGeometry::Tube);
}

// ---------- the skeleton PLY ----------

TEST(SkeletonPly, NodesWithWidthGenerationArcAgeAndEdges) {
  Plant p;
  p.nodes = {{{0, 0, 0}, 0.05f, kNoParent, 0, 0, 0},
             {{0, 1, 0}, 0.04f, 0, 0, 0, 1},
             {{0, 3, 0}, 0.02f, 1, 0, 0, 2},
             {{4, 4, 0}, 0.02f, 1, 1, 1, 5}};
  const auto dir = test::temp_dir("skeleton_ply");
  const auto bytes = write_skeleton_ply((dir / "s.ply").string(), p);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "s.ply"));
  const Ply ply = read_ply(dir / "s.ply");
  const PlyElement& v = ply.element("vertex");
  EXPECT_EQ(v.properties, (std::vector<std::string>{"x", "y", "z", "width", "generation", "arc", "age"}));
  EXPECT_EQ(v.columns.at("y"), (std::vector<double>{0, 1, 3, 4}));
  EXPECT_EQ(v.columns.at("width")[0], static_cast<double>(2.0f * 0.05f));
  EXPECT_EQ(v.columns.at("generation"), (std::vector<double>{0, 0, 0, 1}));
  EXPECT_EQ(v.columns.at("arc"), (std::vector<double>{0, 1, 3, 6}));  // 1 + |(4, 3, 0)|
  EXPECT_EQ(v.columns.at("age"), (std::vector<double>{5, 4, 3, 0}));
  EXPECT_EQ(ply.element("edge").columns.at("vertex1"), (std::vector<double>{0, 1, 1}));
  EXPECT_EQ(ply.element("edge").columns.at("vertex2"), (std::vector<double>{1, 2, 3}));
}

TEST_F(PlantAttributes, SkeletonPlyCarriesGroupsTubesAndAttributes) {
  const Plant p = grow("a(\"Cd\",0,0.5,1)a(\"wet\",3)gF(1,0.1,2,5)[g(-1)F]");
  const auto dir = test::temp_dir("skeleton_ply_attr");
  write_skeleton_ply((dir / "s.ply").string(), p);
  const Ply ply = read_ply(dir / "s.ply");
  const PlyElement& v = ply.element("vertex");
  EXPECT_EQ(v.properties, (std::vector<std::string>{"x", "y", "z", "width", "generation", "arc", "age", "group",
                                                    "sections", "divisions", "red", "green", "blue", "wet"}));
  EXPECT_EQ(v.columns.at("group"), (std::vector<double>{0, 0, -1}));
  EXPECT_EQ(v.columns.at("sections"), (std::vector<double>{0, 2, 0}));
  EXPECT_EQ(v.columns.at("divisions"), (std::vector<double>{0, 5, 0}));
  EXPECT_EQ(v.columns.at("green"), (std::vector<double>{188, 188, 188}));
  EXPECT_EQ(v.columns.at("wet"), (std::vector<double>{3, 3, 3}));
  EXPECT_EQ(v.columns.at("generation"), (std::vector<double>{0, 0, 1}));
}

// ---------- snapshots ----------

TEST_F(PlantAttributes, SnapshotsKeepGroupsAttributesTubesAndGeometry) {
  const Plant p = grow("a(\"Cd\",1,0,1)gF(1,0.1,2,5)[g(3)F]", {"geometry=skeleton", "group_prefix=x"});
  const auto dir = test::temp_dir("snapshot_attr");
  write_plant_snapshot((dir / "p.gbplant").string(), p);
  const Plant q = read_plant_snapshot((dir / "p.gbplant").string());
  EXPECT_EQ(q.geometry_hash(), p.geometry_hash());
  EXPECT_EQ(q.node_groups, p.node_groups);
  EXPECT_EQ(q.group_prefix, "x");
  ASSERT_EQ(q.node_attributes.size(), 1u);
  EXPECT_EQ(q.node_attributes[0].name, "Cd");
  EXPECT_EQ(q.node_attributes[0].values, p.node_attributes[0].values);
  ASSERT_EQ(q.node_tubes.size(), p.node_tubes.size());
  EXPECT_EQ(q.node_tubes[1].divisions, 5);
  EXPECT_EQ(q.branch_geometry, BranchGeometry::Skeleton);
  // A section of a later build is skipped; one whose length disagrees with its content is an error.
  std::string data = text_of(dir / "p.gbplant");
  std::string later = data + "NEW!";
  const std::uint64_t three = 3;
  later.append(reinterpret_cast<const char*>(&three), 8);
  later += "abc";
  test::write_text(dir / "later.gbplant", later);
  EXPECT_EQ(read_plant_snapshot((dir / "later.gbplant").string()).geometry_hash(), p.geometry_hash());
  const std::size_t geom = data.rfind("GEOM");
  ASSERT_NE(geom, std::string::npos);
  data[geom + 4] = 2;  // GEOM's length 1 -> 2
  data += "x";
  test::write_text(dir / "bad.gbplant", data);
  const std::string e = test::error_of([&] { read_plant_snapshot((dir / "bad.gbplant").string()); });
  EXPECT_NE(e.find("bad.gbplant: plant snapshot has a section whose length does not match"), std::string::npos) << e;
}

}  // namespace
}  // namespace growbench
