#include "scenes/sdf.hpp"

#include <cmath>
#include <limits>
#include <mutex>

#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

namespace growbench {

struct SdfGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

namespace {
// Peak bytes per narrow-band voxel while meshToLevelSet builds, and active voxels per voxel-sized square
// of surface per voxel of band half-width, both measured (see estimate_peak_bytes).
constexpr double kPeakBytesPerVoxel = 26.0;
constexpr double kVoxelsPerFace = 1.7;
}  // namespace

double SdfGrid::min_voxel_size() {
  // ScaleMap refuses |sx * sy * sz| < 3 * Tolerance<double>; a little above its cube root, to be safe.
  return 1.01 * std::cbrt(3.0 * openvdb::math::Tolerance<double>::value());
}

double SdfGrid::max_voxel_reach() {
  return 0.25 * static_cast<double>(std::numeric_limits<openvdb::Int32>::max());
}

double SdfGrid::estimate_peak_bytes(const std::vector<const TriangleMesh*>& meshes, float voxel_size,
                                    float band_voxels) {
  double area = 0.0;
  for (const auto* m : meshes) area += m->area();
  const double faces = area / (static_cast<double>(voxel_size) * voxel_size);
  return kPeakBytesPerVoxel * kVoxelsPerFace * faces * band_voxels;
}

SdfGrid::SdfGrid(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
                 float band_voxels)
    : impl_(std::make_unique<Impl>()) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  try {
    build(meshes, solid, voxel_size, band_voxels);
  } catch (const OutOfMemoryError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutOfMemoryError(
        fmt::format("out of memory building the distance field at voxel size {} m (OpenVDB); a "
                    "larger --voxel-size needs less",
                    voxel_size));
  } catch (const openvdb::Exception& e) {
    throw InputError(fmt::format("voxel size {} m: OpenVDB cannot build the distance field: {}", voxel_size, e.what()));
  }
}

void SdfGrid::build(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
                    float band_voxels) {
  const auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
  background_ = voxel_size * band_voxels;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const auto& m = *meshes[i];
    std::vector<openvdb::Vec3s> points;
    points.reserve(m.vertices.size());
    for (const auto& v : m.vertices) points.emplace_back(v.x, v.y, v.z);
    std::vector<openvdb::Vec3I> tris;
    tris.reserve(m.triangles.size());
    for (const auto& t : m.triangles) tris.emplace_back(t.x, t.y, t.z);
    const std::vector<openvdb::Vec4I> quads;
    openvdb::FloatGrid::Ptr g =
        solid[i]
            ? openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, tris, band_voxels)
            : openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xform, points, tris, quads, band_voxels);
    if (!impl_->grid) {
      impl_->grid = g;
    } else {
      openvdb::tools::csgUnion(*impl_->grid, *g);
    }
  }
  if (!impl_->grid) impl_->grid = openvdb::FloatGrid::create(background_);
  impl_->grid->setTransform(xform);
}

SdfGrid::~SdfGrid() = default;

namespace {

// A point OpenVDB's 32-bit coordinates cannot address (NaN among them, whose floor is undefined) lies beyond
// the narrow band, where the field holds its background.
bool addressable(const openvdb::Vec3d& index) {
  const double reach = SdfGrid::max_voxel_reach();
  return std::abs(index.x()) <= reach && std::abs(index.y()) <= reach && std::abs(index.z()) <= reach;
}

}  // namespace

float SdfGrid::sample(const glm::vec3& p) const {
  // An unregistered accessor: cheap to make, so one per call keeps concurrent queries safe.
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(impl_->grid->constTree());
  const openvdb::Vec3d ijk = impl_->grid->transform().worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
  if (!addressable(ijk)) return background_;
  return openvdb::tools::BoxSampler::sample(acc, ijk);
}

float SdfGrid::sample_gradient(const glm::vec3& p, glm::vec3& gradient) const {
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(impl_->grid->constTree());
  const openvdb::Vec3d xyz = impl_->grid->transform().worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
  if (!addressable(xyz)) {
    gradient = glm::vec3(0.0f);
    return background_;
  }
  const openvdb::Coord ijk = openvdb::Coord::floor(xyz);
  float v[2][2][2];
  openvdb::tools::BoxSampler::getValues(v, acc, ijk);
  const auto x = static_cast<float>(xyz.x() - ijk.x()), y = static_cast<float>(xyz.y() - ijk.y()),
             z = static_cast<float>(xyz.z() - ijk.z());
  // Bilinear faces of the cell along each axis, then their difference for the derivative.
  auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
  const float x0 = lerp(lerp(v[0][0][0], v[0][0][1], z), lerp(v[0][1][0], v[0][1][1], z), y);
  const float x1 = lerp(lerp(v[1][0][0], v[1][0][1], z), lerp(v[1][1][0], v[1][1][1], z), y);
  const float y0 = lerp(lerp(v[0][0][0], v[0][0][1], z), lerp(v[1][0][0], v[1][0][1], z), x);
  const float y1 = lerp(lerp(v[0][1][0], v[0][1][1], z), lerp(v[1][1][0], v[1][1][1], z), x);
  const float z0 = lerp(lerp(v[0][0][0], v[0][1][0], y), lerp(v[1][0][0], v[1][1][0], y), x);
  const float z1 = lerp(lerp(v[0][0][1], v[0][1][1], y), lerp(v[1][0][1], v[1][1][1], y), x);
  const auto inv = static_cast<float>(1.0 / impl_->grid->voxelSize().x());
  gradient = glm::vec3(x1 - x0, y1 - y0, z1 - z0) * inv;
  return lerp(x0, x1, x);
}

std::size_t SdfGrid::active_voxels() const {
  return impl_->grid->activeVoxelCount();
}

}  // namespace growbench
