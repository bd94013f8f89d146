// The space-colonization peer of `make peers`: Runions et al. 2007 as a user would write it with
// nanoflann, single-threaded, open venation. It is the yardstick growbench's spacecol is measured
// against, so it stays the textbook loop: every step, every live point finds its nearest node (a
// dynamic kd-tree over the nodes), dies within the kill distance, pulls that node within the
// influence radius; each pulled node grows one child a step along its mean pull. Growth ends when no
// point is left or a step grows nothing.
//
//   spacecol_reference POINTS_FILE --root X,Y,Z --step D --kill K --influence I   (all required)
//
// POINTS_FILE holds one "x y z" per line (what growbench's points_file reads). Reading it is not
// timed; the growth loop is. Prints one JSON line: seconds, nodes, steps, points left.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nanoflann.hpp>

namespace {

using Vec3 = std::array<float, 3>;

struct Cloud {
  std::vector<Vec3> pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using NodeTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3>;

// Every option is required: the case's values live in bench/peers/cases.json alone.
struct Options {
  std::string points_file;
  Vec3 root{NAN, NAN, NAN};
  float step = NAN, kill = NAN, influence = NAN;
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "spacecol_reference: %s\nusage: spacecol_reference POINTS_FILE --root X,Y,Z "
               "--step D --kill K --influence I\n",
               why);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) {
      o.points_file = a;
      continue;
    }
    if (i + 1 >= argc) usage("an option lacks its value");
    const char* v = argv[++i];
    if (a == "--root") {
      if (std::sscanf(v, "%f,%f,%f", &o.root[0], &o.root[1], &o.root[2]) != 3) usage("--root wants X,Y,Z");
    } else if (a == "--step") {
      o.step = std::strtof(v, nullptr);
    } else if (a == "--kill") {
      o.kill = std::strtof(v, nullptr);
    } else if (a == "--influence") {
      o.influence = std::strtof(v, nullptr);
    } else {
      usage("unknown option");
    }
  }
  if (o.points_file.empty()) usage("no points file");
  if (std::isnan(o.root[0]) || !(o.step > 0) || !(o.kill > 0) || !(o.influence > 0))
    usage("--root, --step, --kill and --influence are required (positive lengths)");
  return o;
}

std::vector<Vec3> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) usage("cannot open the points file");
  std::vector<Vec3> pts;
  Vec3 p;
  while (in >> p[0] >> p[1] >> p[2]) pts.push_back(p);
  return pts;
}

float dist2(const Vec3& a, const Vec3& b) {
  const float x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

// A child that lands on one of its parent's earlier children is the same pull again (the node sits
// between points that keep pulling it the same way); without this check such a node grows forever.
bool repeats_a_child(const std::vector<std::vector<std::uint32_t>>& children, const std::vector<Vec3>& nodes,
                     std::uint32_t parent, const Vec3& pos, float step) {
  const float lim = 0.05f * step;
  for (const std::uint32_t c : children[parent])
    if (dist2(nodes[c], pos) < lim * lim) return true;
  return false;
}

struct Result {
  std::size_t nodes = 0, steps = 0, alive = 0;
};

Result grow(const Options& o, const std::vector<Vec3>& points) {
  Cloud nodes;
  nodes.pts.push_back(o.root);
  NodeTree tree(3, nodes, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  std::vector<std::vector<std::uint32_t>> children(1);
  std::vector<char> alive(points.size(), 1);
  std::size_t alive_count = points.size(), steps = 0;
  const float kill2 = o.kill * o.kill, infl2 = o.influence * o.influence;
  std::vector<Vec3> pull;
  std::vector<std::uint32_t> pulled;
  while (alive_count > 0) {
    pull.assign(nodes.pts.size(), Vec3{0, 0, 0});
    pulled.clear();
    for (std::size_t s = 0; s < points.size(); ++s) {
      if (!alive[s]) continue;
      std::uint32_t nearest = 0;
      float d2 = 0;
      nanoflann::KNNResultSet<float, std::uint32_t> result(1);
      result.init(&nearest, &d2);
      tree.findNeighbors(result, points[s].data(), nanoflann::SearchParams());
      if (d2 < kill2) {
        alive[s] = 0;
        --alive_count;
      } else if (d2 < infl2) {
        const float inv = 1.0f / std::sqrt(d2);
        Vec3& p = pull[nearest];
        if (p[0] == 0 && p[1] == 0 && p[2] == 0) pulled.push_back(nearest);
        for (int k = 0; k < 3; ++k) p[k] += (points[s][k] - nodes.pts[nearest][k]) * inv;
      }
    }
    const std::size_t before = nodes.pts.size();
    for (const std::uint32_t v : pulled) {
      const Vec3& p = pull[v];
      const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      if (len == 0) continue;
      Vec3 c;
      for (int k = 0; k < 3; ++k) c[k] = nodes.pts[v][k] + o.step * p[k] / len;
      if (repeats_a_child(children, nodes.pts, v, c, o.step)) continue;
      children[v].push_back(static_cast<std::uint32_t>(nodes.pts.size()));
      nodes.pts.push_back(c);
      children.emplace_back();
    }
    ++steps;
    if (nodes.pts.size() == before) break;
    tree.addPoints(static_cast<std::uint32_t>(before), static_cast<std::uint32_t>(nodes.pts.size() - 1));
  }
  return {nodes.pts.size(), steps, alive_count};
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const std::vector<Vec3> points = read_points(o.points_file);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();  // CPU time beside the wall time: a shared machine's load shows in the gap
  const Result r = grow(o, points);
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "{\"peer\": \"spacecol_reference\", \"nanoflann\": \"%d.%d.%d\", \"seconds\": %.6f, \"cpu_seconds\": %.6f, "
      "\"nodes\": %zu, "
      "\"steps\": %zu, \"points\": %zu, \"points_left\": %zu}\n",
      NANOFLANN_VERSION >> 8, (NANOFLANN_VERSION >> 4) & 0xf, NANOFLANN_VERSION & 0xf, secs, cpu, r.nodes, r.steps,
      points.size(), r.alive);
  return 0;
}
