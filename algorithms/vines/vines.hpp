#pragma once

#include <glm/glm.hpp>

#include "algorithms/algorithm.hpp"
#include "algorithms/vines/texture.hpp"

namespace growbench::vines {

enum class Space { Auto, Uv, Canvas };
enum class Metric { Surface, Uv };
enum class Leaves { None, Ends, Interval };

// The parameters as the growth reads them. Every value comes from the parameter table (make_config): no
// member has a default of its own. The paths (roots, mask, leaf_texture) are read where they are used.
struct Config {
  Space space;
  int resolution;
  float density;
  bool grid_nodes;
  Metric metric;
  bool cross_seams;
  float influence, kill, step;  // cells
  int stall_iterations;
  int root_count;
  bool mask_include;
  int tags;
  float tag_mix;
  float wiggle, wiggle_period;
  int kill_limit, kill_limit_offset, kill_limit_jitter;
  float tip_width, max_width, pipe_exponent;
  Leaves leaves;
  int leaf_interval;
  float leaf_size, leaf_gravity, leaf_angle_jitter;
  float leaf_scale_min, leaf_scale_max, leaf_brightness_min, leaf_brightness_max, leaf_stem_offset;
  int texture_size;
  Style style;
  glm::vec3 vine_color, leaf_color;
};
Config make_config(const Params& params);

}  // namespace growbench::vines
