#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "algorithms/algorithm.hpp"

namespace growbench::spacecol {

enum class Points { Auto, Envelope, Surface, File };
enum class Surface { Free, Avoid, Cling };
enum class Leaves { None, Tips, Interval, Both };
enum class NoiseField { Position, Random };

// The parameters as the growth reads them. Every value comes from the parameter table (make_config):
// no member has a default of its own. points_file, a path, is read where the points are loaded.
struct Config {
  bool closed;  // venation=closed
  Points points;
  std::size_t point_count;
  float center_density;
  float surface_offset;
  float influence, kill, step;
  glm::vec3 tropism;
  float noise;
  NoiseField noise_field;
  float noise_scale;
  Surface surface;
  float cling_distance;
  float split;
  bool seek;
  float tip_radius, pipe_exponent;
  Leaves leaves;
  int leaf_interval;
  float leaf_size;
};
Config make_config(const Params& params);

}  // namespace growbench::spacecol
