#include "scenes/sdf.hpp"

#include <mutex>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

namespace growbench {

struct SdfGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

SdfGrid::SdfGrid(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
                 float band_voxels)
    : impl_(std::make_unique<Impl>()) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
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
        solid[i] ? openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, tris, band_voxels)
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

float SdfGrid::sample(const glm::vec3& p) const {
  // An unregistered accessor: cheap to make, so one per call keeps concurrent queries safe.
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(impl_->grid->constTree());
  const openvdb::Vec3d ijk = impl_->grid->transform().worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
  return openvdb::tools::BoxSampler::sample(acc, ijk);
}

std::size_t SdfGrid::active_voxels() const { return impl_->grid->activeVoxelCount(); }

}  // namespace growbench
