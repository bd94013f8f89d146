#include "scenes/scene_query.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include "core/kdtree.hpp"
#include "core/memory.hpp"
#include "core/random.hpp"
#include "scenes/geometry.hpp"
#include "scenes/host_queries.hpp"
#include "scenes/sdf.hpp"

namespace growbench {

namespace {

// Embree asserts (and aborts the process) on a ray whose origin or direction has a component beyond
// FLT_LARGE (about 1.8e18) or NaN, or whose interval is NaN. Such a ray is answered here, without
// Embree, as one that hits nothing: no input, a plugin's or a grammar's, can end the process.
bool embree_takes(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) {
  constexpr float large = 1.8e18f;
  const glm::vec3 big = glm::max(glm::abs(o), glm::abs(d));
  return big.x <= large && big.y <= large && big.z <= large && !std::isnan(tmin) && !std::isnan(tmax);
}

bool finite_point(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

RTCRay make_ray(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) {
  RTCRay ray{};
  ray.org_x = o.x;
  ray.org_y = o.y;
  ray.org_z = o.z;
  ray.dir_x = d.x;
  ray.dir_y = d.y;
  ray.dir_z = d.z;
  ray.tnear = tmin;
  ray.tfar = tmax;
  ray.mask = 0xFFFFFFFFu;
  return ray;
}
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

glm::vec3 face_normal(const TriangleMesh& m, std::uint32_t tri) {
  const auto& t = m.triangles[tri];
  const glm::vec3 n = glm::cross(m.vertices[t.y] - m.vertices[t.x], m.vertices[t.z] - m.vertices[t.x]);
  const float len = glm::length(n);
  return len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
}

// Embree calls this from C code, so it must not throw: it prints, and callers check rtcGetDeviceError.
void embree_error(void*, RTCError code, const char* str) {
  fmt::print(stderr, "Embree error {}: {}\n", static_cast<int>(code), str ? str : "");
}

// Embree's error `e` (rtcGetDeviceError) as an exception: out of memory is OutOfMemoryError, as every
// library's is; anything else is a bug here.
[[noreturn]] void throw_embree(RTCError e, const char* what) {
  if (e == RTC_ERROR_OUT_OF_MEMORY) throw OutOfMemoryError(fmt::format("Embree: out of memory {}", what));
  throw std::runtime_error(fmt::format("Embree: {} failed (error {})", what, static_cast<int>(e)));
}
// `what` is a C string: this runs in phases whose allocations are counted.
void check_embree(RTCDevice device, const char* what) {
  if (const RTCError e = rtcGetDeviceError(device); e != RTC_ERROR_NONE) throw_embree(e, what);
}
// A new buffer of `g`. Embree returns null when it cannot make one; `g` is then released.
template <class T>
T* new_buffer(RTCDevice device, RTCGeometry g, RTCBufferType type, RTCFormat format, std::size_t stride,
              std::size_t count) {
  void* p = rtcSetNewGeometryBuffer(g, type, 0, format, stride, count);
  if (!p) {
    rtcReleaseGeometry(g);
    const RTCError e = rtcGetDeviceError(device);
    throw_embree(e == RTC_ERROR_NONE ? RTC_ERROR_UNKNOWN : e, "allocating a geometry buffer");
  }
  return static_cast<T*>(p);
}

// One Embree scene over a list of meshes (geometry ID = index in the list).
struct BvhScene {
  RTCScene scene = nullptr;
  std::vector<const TriangleMesh*> meshes;

  BvhScene(RTCDevice device, std::vector<const TriangleMesh*> ms) : meshes(std::move(ms)) {
    scene = rtcNewScene(device);
    if (!scene) throw_embree(rtcGetDeviceError(device), "making a scene");
    try {
      build(device);
    } catch (...) {
      rtcReleaseScene(scene);
      throw;
    }
  }
  void build(RTCDevice device) {
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      const TriangleMesh& m = *meshes[i];
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb =
          new_buffer<float>(device, g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.vertices.size());
      std::copy_n(&m.vertices[0].x, 3 * m.vertices.size(), vb);
      auto* ib = new_buffer<unsigned>(device, g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                      m.triangles.size());
      std::copy_n(&m.triangles[0].x, 3 * m.triangles.size(), ib);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(scene, g, static_cast<unsigned>(i));
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene);
    check_embree(device, "building the BVH");
  }
  ~BvhScene() {
    if (scene) rtcReleaseScene(scene);
  }
  BvhScene(const BvhScene&) = delete;
  BvhScene& operator=(const BvhScene&) = delete;

  RayHit ray(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) const {
    if (!embree_takes(o, d, tmin, tmax)) return {};
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray = make_ray(o, d, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    RayHit r;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return r;
    r.hit = true;
    r.t = rh.ray.tfar;
    r.point = o + r.t * d;
    r.mesh = rh.hit.geomID;
    r.triangle = rh.hit.primID;
    r.normal = face_normal(*meshes[r.mesh], r.triangle);
    return r;
  }

  bool occluded(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) const {
    if (!embree_takes(o, d, tmin, tmax)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = make_ray(o, d, tmin, tmax);
    rtcOccluded1(scene, &ctx, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
  }

  // Ray parity along a fixed, irrational-ish direction (avoids grazing axis-aligned edges).
  bool inside_by_parity(const glm::vec3& p) const {
    const glm::vec3 d = glm::normalize(glm::vec3(0.5773f, 0.6170f, 0.5348f));
    int crossings = 0;
    float t = 0.0f;
    for (int guard = 0; guard < 10000; ++guard) {
      const RayHit h = ray(p, d, t, std::numeric_limits<float>::infinity());
      if (!h.hit) break;
      ++crossings;
      t = h.t + 1e-5f * std::max(1.0f, h.t);
    }
    return (crossings & 1) != 0;
  }
};

struct PointQueryState {
  const std::vector<const TriangleMesh*>* meshes;
  ClosestHit best;
  const std::vector<bool>* skip = nullptr;  // skip[mesh]: not a candidate
};

bool point_query_callback(RTCPointQueryFunctionArguments* args) {
  auto* st = static_cast<PointQueryState*>(args->userPtr);
  if (st->skip && (*st->skip)[args->geomID]) return false;
  const TriangleMesh& m = *(*st->meshes)[args->geomID];
  const auto& t = m.triangles[args->primID];
  // In double precision: in float, the closest point on a long sliver (a column's 3 m side) is off by
  // up to half a millimetre, more than a climbing plant's distance from its wall.
  const glm::dvec3 p(args->query->x, args->query->y, args->query->z);
  const auto c = geom::closest_feature_on_triangle(p, glm::dvec3(m.vertices[t.x]), glm::dvec3(m.vertices[t.y]),
                                                   glm::dvec3(m.vertices[t.z]));
  const glm::vec3 q(c.point);
  const auto d = static_cast<float>(glm::length(c.point - p));
  // Ties go to the lower (mesh, triangle): the answer does not depend on BVH traversal order.
  if (d < args->query->radius ||
      (d == st->best.distance && std::pair(args->geomID, args->primID) < std::pair(st->best.mesh, st->best.triangle))) {
    st->best.found = true;
    st->best.point = q;
    st->best.distance = d;
    st->best.mesh = args->geomID;
    st->best.triangle = args->primID;
    args->query->radius = d;
    return true;
  }
  return false;
}

}  // namespace

namespace {
// The distance from p to the nearest of the tree's vertices, a little enlarged so that rounding never
// excludes the true closest point: a radius that bounds a closest-point search on their surface.
float nearest_vertex_bound(const Vec3Tree& tree, const glm::vec3& p) {
  std::uint32_t idx = 0;
  float d2 = 0.0f;
  nanoflann::KNNResultSet<float, std::uint32_t> rs(1);
  rs.init(&idx, &d2);
  tree.findNeighbors(rs, &p.x, nanoflann::SearchParams());
  return std::sqrt(d2) * (1.0f + 1e-5f) + 1e-7f;
}
}  // namespace

// Every vertex used by a triangle lies on the surface, so the nearest one bounds the closest-point
// distance from above: an unbounded Embree point query starts from that radius instead of infinity,
// so a point far from the mesh visits a small part of the BVH rather than most of it.
struct SceneQuery::VertexIndex {
  std::vector<glm::vec3> pts;
  Vec3Cloud cloud{&pts};
  std::unique_ptr<Vec3Tree> tree;
  explicit VertexIndex(const Scene& s) {
    for (const auto& m : s.meshes) {
      std::vector<bool> used(m.vertices.size(), false);
      for (const auto& t : m.triangles) used[t.x] = used[t.y] = used[t.z] = true;
      for (std::size_t i = 0; i < m.vertices.size(); ++i)
        if (used[i]) pts.push_back(m.vertices[i]);
    }
    tree = std::make_unique<Vec3Tree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  }
  float upper_bound(const glm::vec3& p) const { return nearest_vertex_bound(*tree, p); }
};

// A solid's pseudonormals (Baerentzen & Aanaes 2005): per face its unit normal, per edge the sum of its
// two faces' normals, per vertex the sum of its faces' normals weighted by their angles there. For the
// closest point q on a closed mesh to p, p lies inside exactly when (p - q) points against the
// pseudonormal of the feature q lies on, whichever triangle reported it.
struct SceneQuery::Solid {
  std::uint32_t mesh = 0;
  Aabb bounds;
  std::vector<glm::vec3> face, vertex, edge;  // edge: three per triangle (ab, bc, ca)
  std::vector<glm::vec3> pts;                 // vertices, to bound the closest-point search
  Vec3Cloud cloud{&pts};
  std::unique_ptr<Vec3Tree> tree;

  Solid(const TriangleMesh& m, std::uint32_t id) : mesh(id), bounds(m.bounds()) {
    face.resize(m.triangles.size());
    vertex.assign(m.vertices.size(), glm::vec3(0.0f));
    std::unordered_map<std::uint64_t, glm::vec3> edges;
    edges.reserve(m.triangles.size() * 2);
    auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b); };
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto& tri = m.triangles[t];
      const glm::vec3 n = glm::cross(m.vertices[tri.y] - m.vertices[tri.x], m.vertices[tri.z] - m.vertices[tri.x]);
      const float len = glm::length(n);
      face[t] = len > 0.0f ? n / len : glm::vec3(0.0f);  // a degenerate face has no side to give
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 e1 = m.vertices[tri[(k + 1) % 3]] - m.vertices[tri[k]];
        const glm::vec3 e2 = m.vertices[tri[(k + 2) % 3]] - m.vertices[tri[k]];
        const float l1 = glm::length(e1), l2 = glm::length(e2);
        if (l1 > 0.0f && l2 > 0.0f)
          vertex[tri[k]] += std::acos(std::clamp(glm::dot(e1, e2) / (l1 * l2), -1.0f, 1.0f)) * face[t];
        edges[key(tri[k], tri[(k + 1) % 3])] += face[t];
      }
    }
    edge.resize(3 * m.triangles.size());
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        edge[3 * t + static_cast<std::size_t>(k)] = edges.at(key(m.triangles[t][k], m.triangles[t][(k + 1) % 3]));
    pts = m.vertices;
    tree = std::make_unique<Vec3Tree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  }
  float search_radius(const glm::vec3& p) const { return nearest_vertex_bound(*tree, p); }
  glm::vec3 pseudonormal(const TriangleMesh& m, std::uint32_t t, geom::TriangleFeature f) const {
    using F = geom::TriangleFeature;
    const auto& tri = m.triangles[t];
    switch (f) {
      case F::VertexA:
        return vertex[tri.x];
      case F::VertexB:
        return vertex[tri.y];
      case F::VertexC:
        return vertex[tri.z];
      case F::EdgeAB:
        return edge[3 * t];
      case F::EdgeBC:
        return edge[3 * t + 1];
      case F::EdgeCA:
        return edge[3 * t + 2];
      case F::Face:
        break;
    }
    return face[t];
  }
};

namespace {
struct SideState {
  const TriangleMesh* mesh;
  std::uint32_t id;
  bool found = false;
  double distance = std::numeric_limits<double>::infinity();
  std::uint32_t triangle = 0;
  geom::TriangleFeaturePoint closest{};
};
bool side_callback(RTCPointQueryFunctionArguments* args) {
  auto* st = static_cast<SideState*>(args->userPtr);
  if (args->geomID != st->id) return false;
  const auto& t = st->mesh->triangles[args->primID];
  const glm::dvec3 p(args->query->x, args->query->y, args->query->z);
  const auto& v = st->mesh->vertices;
  const auto c = geom::closest_feature_on_triangle(p, glm::dvec3(v[t.x]), glm::dvec3(v[t.y]), glm::dvec3(v[t.z]));
  const double d = glm::length(c.point - p);
  if (d < st->distance || (st->found && d == st->distance && args->primID < st->triangle)) {
    st->found = true;
    st->distance = d;
    st->triangle = args->primID;
    st->closest = c;
    // Embree prunes in float: a little slack keeps a triangle as near as this one in the running.
    args->query->radius = static_cast<float>(d) * (1.0f + 1e-6f) + 1e-7f;
    return true;
  }
  return false;
}
}  // namespace

struct SceneQuery::Embree {
  RTCDevice device = nullptr;
  std::unique_ptr<BvhScene> main;
  std::vector<std::pair<const Shape*, std::unique_ptr<BvhScene>>> shapes;  // mesh envelopes/zones
  Embree() {
    device = rtcNewDevice("threads=0");
    if (!device) throw_embree(rtcGetDeviceError(nullptr), "creating a device");
    rtcSetDeviceErrorFunction(device, embree_error, nullptr);
  }
  ~Embree() {
    shapes.clear();
    main.reset();
    rtcReleaseDevice(device);
  }
  Embree(const Embree&) = delete;
  Embree& operator=(const Embree&) = delete;
};

SceneQuery::SceneQuery(const Scene& scene, SceneQueryOptions options)
    : scene_(scene), options_(options), embree_(std::make_unique<Embree>()) {
  host_queries_ = std::make_unique<DirectQueries>(*this);
  if (scene.meshes.empty()) throw InputError(fmt::format("scene '{}' has no meshes", scene.name));
  for (const auto& m : scene.meshes)
    if (m.triangles.empty())
      throw InputError(fmt::format("scene '{}': mesh '{}' has no triangles", scene.name, m.name));

  auto t0 = std::chrono::steady_clock::now();
  std::vector<const TriangleMesh*> ptrs;
  for (const auto& m : scene.meshes) ptrs.push_back(&m);
  embree_->main = std::make_unique<BvhScene>(embree_->device, ptrs);
  vertices_ = std::make_unique<VertexIndex>(scene);
  auto add_shape = [&](const Shape& s) {
    if (s.kind == Shape::Kind::Mesh)
      embree_->shapes.emplace_back(&s, std::make_unique<BvhScene>(embree_->device, std::vector{&s.mesh}));
  };
  if (scene.envelope) add_shape(*scene.envelope);
  for (const auto& z : scene.zones) add_shape(z.shape);
  bvh_seconds_ = seconds_since(t0);

  // Area CDF for surface sampling.
  bool any_climbable = false;
  for (const auto& m : scene.meshes) any_climbable = any_climbable || m.climbable;
  if (any_climbable)
    for (const auto& m : scene.meshes) not_climbable_.push_back(!m.climbable);
  double acc = 0.0;
  for (std::uint32_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const auto& m = scene.meshes[mi];
    if (any_climbable && !m.climbable) continue;
    for (std::uint32_t ti = 0; ti < m.triangles.size(); ++ti) {
      const auto& t = m.triangles[ti];
      acc += 0.5 * glm::length(glm::cross(m.vertices[t.y] - m.vertices[t.x], m.vertices[t.z] - m.vertices[t.x]));
      cdf_.push_back(acc);
      cdf_tri_.emplace_back(mi, ti);
    }
  }
  total_area_ = acc;

  // Solids: the closed meshes, for the exact inside test and the distance field alike.
  std::vector<const TriangleMesh*> sdf_meshes;
  for (std::uint32_t i = 0; i < scene.meshes.size(); ++i) {
    const auto& m = scene.meshes[i];
    solid_.push_back(m.is_closed());
    solids_.push_back(solid_.back() ? std::make_unique<Solid>(m, i) : nullptr);
    sdf_meshes.push_back(&m);
  }
  Aabb b;
  for (const auto& m : scene.meshes) b.extend(m.bounds());
  voxel_size_ = options.voxel_size > 0.0f ? options.voxel_size : glm::length(b.size()) / 256.0f;
  if (!(voxel_size_ > 0.0f) || !std::isfinite(voxel_size_))
    throw InputError(fmt::format("scene '{}': cannot size the distance field (degenerate bounds)", scene.name));
  if (options.build_sdf) {
    check_sdf_size(sdf_meshes, b, options.voxel_size > 0.0f);
    t0 = std::chrono::steady_clock::now();
    sdf_ = std::make_unique<SdfGrid>(sdf_meshes, solid_, voxel_size_, options.band_voxels);
    sdf_seconds_ = seconds_since(t0);
  }
}

void SceneQuery::check_sdf_size(const std::vector<const TriangleMesh*>& meshes, const Aabb& bounds, bool given) const {
  const std::string what =
      given ? fmt::format("--voxel-size {}", voxel_size_)
            : fmt::format("the automatic voxel size {} m (the meshes' bounding-box diagonal / 256)", voxel_size_);
  if (voxel_size_ < SdfGrid::min_voxel_size())
    throw InputError(fmt::format("scene '{}': {} is below {:.3g} m, the smallest voxel OpenVDB represents{}",
                                 scene_.name, what, SdfGrid::min_voxel_size(),
                                 given ? "" : "; the scene is too small: scale it up, or give --voxel-size"));
  const glm::vec3 far = glm::max(glm::abs(bounds.min), glm::abs(bounds.max));
  const float reach = std::max({far.x, far.y, far.z});
  if (reach / voxel_size_ > SdfGrid::max_voxel_reach())
    throw InputError(
        fmt::format("scene '{}': {}: the meshes reach {} m from the origin, more voxels than OpenVDB's "
                    "coordinates address; expected a larger voxel size",
                    scene_.name, what, reach));
  const double need = SdfGrid::estimate_peak_bytes(meshes, voxel_size_, options_.band_voxels);
  if (const auto headroom = memory_headroom(); headroom && need > static_cast<double>(*headroom))
    throw OutOfMemoryError(
        fmt::format("scene '{}': the distance field at {} would need about {}, more than the {} "
                    "this process may still take; a larger --voxel-size needs less (a quarter "
                    "for twice the size)",
                    scene_.name, what, format_bytes(need), format_bytes(static_cast<double>(*headroom))));
}

SceneQuery::~SceneQuery() = default;

namespace {
void point_query(RTCScene scene, const glm::vec3& p, float radius, RTCPointQueryFunction f, void* user) {
  RTCPointQuery q{};
  q.x = p.x;
  q.y = p.y;
  q.z = p.z;
  q.time = 0.0f;
  q.radius = radius;
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(scene, &q, &ctx, f, user);
}
struct VisitState {
  SceneQuery::TriangleVisitor visit;
  void* user;
};
bool visit_callback(RTCPointQueryFunctionArguments* args) {
  const auto* st = static_cast<const VisitState*>(args->userPtr);
  const float before = args->query->radius;
  st->visit(st->user, args->geomID, args->primID, &args->query->radius);
  return args->query->radius != before;
}
}  // namespace

struct BoxIndex::Impl {
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }
};

namespace {
void box_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& boxes = *static_cast<const std::vector<Aabb>*>(args->geometryUserPtr);
  const Aabb& b = boxes[args->primID];
  *args->bounds_o = RTCBounds{b.min.x, b.min.y, b.min.z, 0.0f, b.max.x, b.max.y, b.max.z, 0.0f};
}
// The visitor rides behind the intersect context, which Embree hands to every callback.
struct BoxRayContext {
  RTCIntersectContext context;
  BoxIndex::Visitor visit;
  void* user;
};
void box_occluded(const RTCOccludedFunctionNArguments* args) {
  if (args->valid[0] == 0) return;
  const auto* c = reinterpret_cast<const BoxRayContext*>(args->context);
  if (c->visit(c->user, args->primID)) RTCRayN_tfar(args->ray, args->N, 0) = -std::numeric_limits<float>::infinity();
}
void box_intersect(const RTCIntersectFunctionNArguments*) {}  // only occlusion queries are made
}  // namespace

BoxIndex::BoxIndex(void* device, std::vector<Aabb> boxes) : boxes_(std::move(boxes)), impl_(std::make_unique<Impl>()) {
  auto* dev = static_cast<RTCDevice>(device);
  // Empty boxes stay out of the BVH (Embree skips primitives with invalid bounds), so ids keep their
  // meaning without ever being visited.
  impl_->scene = rtcNewScene(dev);
  if (!impl_->scene) throw_embree(rtcGetDeviceError(dev), "making a scene");
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(boxes_.size()));
  rtcSetGeometryUserData(g, &boxes_);
  rtcSetGeometryBoundsFunction(g, box_bounds, &boxes_);
  rtcSetGeometryIntersectFunction(g, box_intersect);
  rtcSetGeometryOccludedFunction(g, box_occluded);
  rtcCommitGeometry(g);
  rtcAttachGeometryByID(impl_->scene, g, 0);
  rtcReleaseGeometry(g);
  rtcCommitScene(impl_->scene);
  check_embree(dev, "building a box index");
}

BoxIndex::~BoxIndex() = default;

void BoxIndex::visit_segment(const glm::vec3& o, const glm::vec3& d, Visitor visit, void* user) const {
  BoxRayContext c{{}, visit, user};
  rtcInitIntersectContext(&c.context);
  // A point is a ray of length zero. Its direction (1, 1, 1) has reciprocal 1, so the slab tests
  // subtract exactly and a box holding p is never missed.
  const bool point = d == glm::vec3(0.0f);
  if (!embree_takes(o, d, 0.0f, 1.0f)) return;
  RTCRay ray = make_ray(o, point ? glm::vec3(1.0f) : d, 0.0f, point ? 0.0f : 1.0f);
  rtcOccluded1(impl_->scene, &c.context, &ray);
}

std::unique_ptr<BoxIndex> SceneQuery::box_index(std::vector<Aabb> boxes) const {
  return std::unique_ptr<BoxIndex>(new BoxIndex(embree_->device, std::move(boxes)));
}

struct Occluder::Impl {
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }
};

namespace {
// The ray's ignored owner rides behind the intersect context, which Embree hands to the filter.
struct OccluderContext {
  RTCIntersectContext context;
  std::uint32_t ignore;
  const std::vector<std::uint32_t>* owners;
};
void owner_filter(const RTCFilterFunctionNArguments* args) {
  const auto* c = reinterpret_cast<const OccluderContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i)
    if (args->valid[i] != 0 && (*c->owners)[RTCHitN_primID(args->hit, args->N, i)] == c->ignore) args->valid[i] = 0;
}
}  // namespace

Occluder::Occluder(void* device, std::vector<Capsule> capsules, std::vector<Triangle> triangles)
    : impl_(std::make_unique<Impl>()) {
  auto* dev = static_cast<RTCDevice>(device);
  impl_->scene = rtcNewScene(dev);
  if (!impl_->scene) throw_embree(rtcGetDeviceError(dev), "making a scene");
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (!capsules.empty()) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* vb =
        new_buffer<float>(dev, g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * capsules.size());
    auto* ib = new_buffer<unsigned>(dev, g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT, sizeof(unsigned), capsules.size());
    for (std::size_t i = 0; i < capsules.size(); ++i) {
      const Capsule& c = capsules[i];
      const float v[8] = {c.a.x, c.a.y, c.a.z, c.ra, c.b.x, c.b.y, c.b.z, c.rb};
      std::copy_n(v, 8, vb + 8 * i);
      ib[i] = static_cast<unsigned>(2 * i);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->scene, g, 0);
    rtcReleaseGeometry(g);
  }
  if (!triangles.empty()) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb =
        new_buffer<float>(dev, g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * triangles.size());
    auto* ib =
        new_buffer<unsigned>(dev, g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size());
    owners_.reserve(triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        std::copy_n(&triangles[i].v[k].x, 3, vb + 9 * i + 3 * static_cast<std::size_t>(k));
        ib[3 * i + static_cast<std::size_t>(k)] = static_cast<unsigned>(3 * i + static_cast<std::size_t>(k));
      }
      owners_.push_back(triangles[i].owner);
    }
    rtcSetGeometryOccludedFilterFunction(g, owner_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->scene, g, 1);
    rtcReleaseGeometry(g);
  }
  // Built on one thread: a parallel build's own allocations vary run to run, and the phase that asks
  // (the metrics) must allocate the same way every time.
  tbb::task_arena one(1);
  one.execute([&] { rtcCommitScene(impl_->scene); });
  check_embree(dev, "building the plant's occluder");
}

Occluder::~Occluder() = default;

bool Occluder::occluded(const glm::vec3& o, const glm::vec3& d, float tmax, std::uint32_t ignore, float tmin) const {
  if (!embree_takes(o, d, tmin, tmax)) return false;
  OccluderContext c{{}, ignore, &owners_};
  rtcInitIntersectContext(&c.context);
  RTCRay ray = make_ray(o, d, tmin, tmax);
  rtcOccluded1(impl_->scene, &c.context, &ray);
  return ray.tfar < 0.0f;
}

std::unique_ptr<Occluder> SceneQuery::occluder(std::vector<Occluder::Capsule> capsules,
                                               std::vector<Occluder::Triangle> triangles) const {
  return std::unique_ptr<Occluder>(new Occluder(embree_->device, std::move(capsules), std::move(triangles)));
}

float SceneQuery::inside_screen() const {
  // Beyond the band the field holds +/- the band width, and the sign there is the band's.
  return sdf_ ? std::min(2.0f * voxel_size_, 0.999f * sdf_->background()) : std::numeric_limits<float>::infinity();
}

bool SceneQuery::inside(const glm::vec3& p) const {
  if (sdf_) {
    const float v = sdf_->sample(p), screen = inside_screen();
    if (v >= screen) return false;
    if (v <= -screen) return true;
  }
  return inside_exact(p);
}

bool SceneQuery::inside_exact(const glm::vec3& p) const {
  for (std::uint32_t i = 0; i < solids_.size(); ++i)
    if (inside_mesh(i, p)) return true;  // it skips meshes that are not solid or whose bounds miss p
  return false;
}

bool SceneQuery::inside_mesh(std::uint32_t mesh, const glm::vec3& p) const {
  if (mesh >= solids_.size() || !solids_[mesh]) return false;
  const Solid& solid = *solids_[mesh];
  if (!solid.bounds.contains(p)) return false;
  SideState st{&scene_.meshes[mesh], mesh};
  point_query(embree_->main->scene, p, solid.search_radius(p), side_callback, &st);
  // Within a float's rounding of the surface (a micrometre at metre scale) a point is on it: outside.
  const glm::vec3 a = glm::abs(p);
  if (!st.found || st.distance <= 1e-6 * std::max({1.0f, a.x, a.y, a.z})) return false;
  return glm::dot(glm::dvec3(p) - st.closest.point,
                  glm::dvec3(solid.pseudonormal(scene_.meshes[mesh], st.triangle, st.closest.feature))) < 0.0;
}

ClosestHit SceneQuery::closest_point(const glm::vec3& p, float max_distance, bool climbable_only) const {
  if (!finite_point(p)) return {};  // no surface is nearest to a point that is not one
  PointQueryState st{&embree_->main->meshes, {}, climbable_only && !not_climbable_.empty() ? &not_climbable_ : nullptr};
  // The vertex bound counts every mesh, so it only bounds an unfiltered query.
  const float radius = std::isfinite(max_distance) ? max_distance
                       : st.skip                   ? std::numeric_limits<float>::infinity()
                                                   : vertices_->upper_bound(p);
  point_query(embree_->main->scene, p, radius, point_query_callback, &st);
  if (st.best.found) st.best.normal = face_normal(scene_.meshes[st.best.mesh], st.best.triangle);
  return st.best;
}

void SceneQuery::visit_near(const glm::vec3& p, float radius, TriangleVisitor visit, void* user) const {
  VisitState st{visit, user};
  point_query(embree_->main->scene, p, radius, visit_callback, &st);
}

RayHit SceneQuery::ray(const glm::vec3& origin, const glm::vec3& dir, float tmax, float tmin) const {
  return embree_->main->ray(origin, dir, tmin, tmax);
}

bool SceneQuery::occluded(const glm::vec3& origin, const glm::vec3& dir, float tmax, float tmin) const {
  return embree_->main->occluded(origin, dir, tmin, tmax);
}

bool SceneQuery::light_visible(const glm::vec3& p, float bias) const {
  const glm::vec3 d = scene_.light.towards(p);
  // A point Embree cannot take (not finite, or far beyond any scene) is in no light.
  if (!embree_takes(p, d, bias, scene_.light.distance(p))) return false;
  return !occluded(p, d, scene_.light.distance(p), bias);
}

float SceneQuery::signed_distance(const glm::vec3& p) const {
  if (!sdf_) throw std::logic_error("SceneQuery: the distance field was not built");
  if (!finite_point(p)) return std::numeric_limits<float>::quiet_NaN();
  const float v = sdf_->sample(p);
  const float band = sdf_->background();
  if (std::abs(v) < 0.999f * band) return v;
  // Beyond the band: exact distance from Embree, sign from the level set.
  const float d = closest_point(p).distance;
  return v < 0.0f ? -d : d;
}

SceneQuery::BandSample SceneQuery::band_sample(const glm::vec3& p) const {
  if (!sdf_) throw std::logic_error("SceneQuery: the distance field was not built");
  BandSample s;
  glm::vec3 g;
  s.distance = sdf_->sample_gradient(p, g);
  const float band = sdf_->background();
  const float len = glm::length(g);
  // A cell with any corner at the background value is not resolved: treat it as outside the band.
  s.in_band = std::abs(s.distance) < 0.999f * band - voxel_size_ && len > 1e-12f;
  if (s.in_band)
    s.gradient = g / len;
  else
    s.distance = s.distance < 0.0f ? -band : band;
  return s;
}

glm::vec3 SceneQuery::gradient(const glm::vec3& p) const {
  if (!sdf_) throw std::logic_error("SceneQuery: the distance field was not built");
  const float h = 0.5f * voxel_size_;
  const float v = sdf_->sample(p);
  if (std::abs(v) < 0.999f * sdf_->background() - h) {
    const glm::vec3 g((sdf_->sample(p + glm::vec3(h, 0, 0)) - sdf_->sample(p - glm::vec3(h, 0, 0))),
                      (sdf_->sample(p + glm::vec3(0, h, 0)) - sdf_->sample(p - glm::vec3(0, h, 0))),
                      (sdf_->sample(p + glm::vec3(0, 0, h)) - sdf_->sample(p - glm::vec3(0, 0, h))));
    const float len = glm::length(g);
    if (len > 1e-12f) return g / len;
  }
  // Beyond the band (or a flat spot): the direction from the closest surface point.
  const ClosestHit c = closest_point(p);
  const glm::vec3 d = p - c.point;
  const float len = glm::length(d);
  if (len > 1e-12f) return (v < 0.0f ? -d : d) / len;
  return c.normal;
}

bool SceneQuery::inside_shape(const Shape& shape, const glm::vec3& p) const {
  if (shape.kind != Shape::Kind::Mesh) return shape.contains_analytic(p);
  for (const auto& [s, bvh] : embree_->shapes)
    if (s == &shape) return bvh->inside_by_parity(p);
  throw std::logic_error("SceneQuery::inside_shape: mesh shape is not part of this scene");
}

SurfaceSample SceneQuery::sample_surface(std::uint64_t seed, std::uint64_t index) const {
  Rng rng(seed, 0x5A3F1Eull, 3 * index);
  const double u = rng.uniform() * total_area_;
  auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  if (it == cdf_.end()) --it;
  const auto [mi, ti] = cdf_tri_[static_cast<std::size_t>(it - cdf_.begin())];
  const auto& m = scene_.meshes[mi];
  const auto& t = m.triangles[ti];
  const double r1 = std::sqrt(rng.uniform()), r2 = rng.uniform();
  const auto a = static_cast<float>(1.0 - r1), b = static_cast<float>(r1 * (1.0 - r2)), c = static_cast<float>(r1 * r2);
  return {a * m.vertices[t.x] + b * m.vertices[t.y] + c * m.vertices[t.z], face_normal(m, ti), mi, ti};
}

std::size_t SceneQuery::sdf_active_voxels() const {
  return sdf_ ? sdf_->active_voxels() : 0;
}

}  // namespace growbench
