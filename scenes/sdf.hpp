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
  SdfGrid(const std::vector<const TriangleMesh*>& meshes, const std::vector<bool>& solid, float voxel_size,
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
  struct Impl;
  std::unique_ptr<Impl> impl_;
  float background_ = 0.0f;
};

}  // namespace growbench
