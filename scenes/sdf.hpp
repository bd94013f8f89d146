// The OpenVDB signed distance grid behind SceneQuery. Only sdf.cpp includes OpenVDB (a slow header).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/scene.hpp"

namespace growbench {

class SdfGrid {
 public:
  // solid[i]: mesh i becomes a signed level set (it must be closed); otherwise an unsigned distance field.
  // OutOfMemoryError when memory runs out inside OpenVDB; InputError when OpenVDB refuses the voxel size.
  SdfGrid(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
          float band_voxels);
  // The smallest voxel size OpenVDB's transform accepts (it refuses a scale whose cube is nearly 0).
  static double min_voxel_size();
  // The most voxels from the origin along an axis that OpenVDB's 32-bit coordinates address with room.
  static double max_voxel_reach();
  // About how many bytes building the field takes at its peak: the narrow band's voxels (the meshes'
  // area over voxel_size^2, times the band's thickness) at what OpenVDB's trees hold for each while
  // meshToLevelSet works, measured on the standard scenes and bundled meshes.
  static double estimate_peak_bytes(const std::vector<const TriangleMesh*>& meshes, float voxel_size,
                                    float band_voxels);
  ~SdfGrid();
  // Trilinear sample in world space; returns +/- band width outside the narrow band (sign kept).
  [[nodiscard]] float sample(const glm::vec3& p) const;
  // The same trilinear value and its exact gradient (the derivative of the trilinear interpolant, not
  // normalised), from one read of the cell's eight voxels.
  [[nodiscard]] float sample_gradient(const glm::vec3& p, glm::vec3& gradient) const;
  [[nodiscard]] float background() const { return background_; }
  [[nodiscard]] std::size_t active_voxels() const;

 private:
  void build(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
             float band_voxels);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  float background_ = 0.0f;
};

}  // namespace growbench
