#include "harness/organs/options.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "algorithms/organ_shapes.hpp"

namespace growbench {

const std::vector<ParamSpec>& organ_param_specs() {
  static const std::vector<ParamSpec> specs = {
      param::choice("placement", "free", {"free", "avoid"})
          .doc("free: every organ where the algorithm put it; avoid: in the plant's order, an organ that would "
               "intersect an organ already placed or a branch other than its own stem tries itself turned, then "
               "smaller, then its fallback, else is dropped"),
      param::text("fallback_flower", "bud").doc("the shape a flower falls back to under avoid ('none': dropped)"),
      param::text("fallback_bud", "none").doc("the shape a bud falls back to under avoid ('none': dropped)"),
      param::real("fallback_leaf", 0.6)
          .range(0, 1)
          .doc("a leaf falls back to itself at this fraction of its size under avoid (0: dropped)"),
      param::real("turn_deg", 30.0)
          .range(0, 90)
          .unit("deg")
          .doc("under avoid, an organ that does not fit first tries itself turned by +-turn_deg about its two cross "
               "axes at its attachment point, then pointed along its stem and so turned (0: none of these)"),
      param::real("shrink", 0.7)
          .range(0.1, 1)
          .doc("under avoid, it then tries itself at this fraction of its size, before its fallback (1: no shrink)"),
      param::real("scale_min", 1.0)
          .range(0.01, 100)
          .doc("each organ's size is scaled by a draw in [scale_min, "
               "scale_max]"),
      param::real("scale_max", 1.0).range(0.01, 100).doc("see scale_min"),
      param::real("roll_deg", 0.0).range(0, 180).unit("deg").doc("random rotation about the stem, in +-roll_deg"),
      param::real("tilt_deg", 0.0)
          .range(0, 180)
          .unit("deg")
          .doc("random rotation about the organ's normal, in "
               "+-tilt_deg"),
      param::real("color_jitter", 0.0)
          .range(0, 0.9)
          .doc("each organ's colour channels are scaled by 1 + a draw in +-color_jitter"),
      param::boolean("alternate_bloom", false)
          .doc("every second flower drawn as a blossom becomes a half_bloom, in the plant's order"),
  };
  return specs;
}

bool OrganOptions::active() const {
  return placement != "free" || scale_min != 1.0 || scale_max != 1.0 || roll_deg != 0.0 || tilt_deg != 0.0 ||
         color_jitter != 0.0 || alternate_bloom;
}

OrganOptions read_organ_options(const std::vector<std::string>& assignments, Params* params_out) {
  Params p("organ options", organ_param_specs());
  for (const auto& a : assignments) p.set_assignment(a);
  if (p.real("scale_min") > p.real("scale_max"))
    throw InputError(
        fmt::format("organ options: scale_min {} is above scale_max {}", p.real("scale_min"), p.real("scale_max")));
  for (const char* key : {"fallback_flower", "fallback_bud"})
    if (p.text(key) != "none") (void)organ_shape_named(p.text(key), fmt::format("organ option {}", key));
  OrganOptions o{p.text("placement"), p.text("fallback_flower"), p.text("fallback_bud"), p.real("fallback_leaf"),
                 p.real("turn_deg"),  p.real("shrink"),          p.real("scale_min"),    p.real("scale_max"),
                 p.real("roll_deg"),  p.real("tilt_deg"),        p.real("color_jitter"), p.boolean("alternate_bloom")};
  if (params_out) *params_out = std::move(p);
  return o;
}

}  // namespace growbench
