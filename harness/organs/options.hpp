// The organ pass every algorithm's plant goes through after growth: variation (scale, rotation about
// the stem and about the normal, colour jitter, alternating blooms) and placement (free, or avoiding
// intersections with fallbacks). Its settings are a parameter table like an algorithm's, given as
// `--organ key=value` or a suite entry's "organs" object.
#pragma once

#include <string>
#include <vector>

#include "core/params.hpp"

namespace growbench {

// The table `growbench list` prints under "organs" and --organ validates.
const std::vector<ParamSpec>& organ_param_specs();

// The settings, read from the table once (no defaults of their own: the table holds them).
struct OrganOptions {
  std::string placement;        // free | avoid
  std::string fallback_flower;  // the shape a flower that does not fit tries next ("none": dropped)
  std::string fallback_bud;
  double fallback_leaf;  // a leaf that does not fit tries this fraction of its size (0: dropped)
  double turn_deg;       // before its fallback, an organ tries itself turned by +- this (0: not)
  double shrink;         // and then itself at this fraction of its size (1: not)
  double scale_min, scale_max;
  double roll_deg, tilt_deg;  // random rotation about the stem (+Z) and about the normal (+Y), +-
  double color_jitter;
  bool alternate_bloom;
  // True when the pass changes anything: without it the plant is measured and exported as grown.
  [[nodiscard]] bool active() const;
};

// Reads `key=value` assignments (InputError naming the key, as --set does). `params_out`, when given,
// receives the validated table (what a record stores).
OrganOptions read_organ_options(const std::vector<std::string>& assignments, Params* params_out = nullptr);

}  // namespace growbench
