// L-systems in the Houdini L-system SOP dialect (SideFX's reference; README.md beside this file): parametric,
// stochastic, context-sensitive rules with conditions, a full 3D turtle, leaf/flower instancing, in()
// against the scene, and a surface-wrap mode (the Hyphae notes' wrapped L-systems).
//
// One growth step is one generation: every plant (one per scene seed, each with its own random stream)
// rewrites its string once (derive.cpp, parallel and deterministic), then the turtle redraws the whole
// plant (turtle.cpp). A fractional generation count adds one last rewrite whose new modules are drawn
// scaled by the fraction (continuous length, angles, width).
//
// Settings come from, in increasing precedence: this table's defaults, a `.lsys` grammar file
// (grammar=FILE or the name of an example), and --set.
#include "algorithms/image_limits.hpp"
#include "algorithms/lsystem/lsystem.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <numbers>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <stb_image.h>

#include "algorithms/lsystem/derive.hpp"
#include "algorithms/organ_shapes.hpp"
#include "algorithms/lsystem/grammar.hpp"
#include "algorithms/lsystem/turtle.hpp"
#include "core/data_path.hpp"
#include "core/errors.hpp"
#include "core/random.hpp"

namespace growbench {
namespace {

// ---- parameter table (what `growbench list` prints) ----
const AlgorithmInfo kInfo = {
    .name = "lsystem",
    .summary =
        "L-system, Houdini dialect: parametric, stochastic, context-sensitive rules, 3D turtle, J/K/M organs, "
        "in(), wrap, avoid",
    .params =
        {
            param::text("grammar").doc(
                "a .lsys grammar file (premise, rules and values) or an example name (koch-island, bush, ...)"),
            param::text("premise", "FFFA").doc("the string at generation 0"),
            param::text("rules", "A = !\"[&FFFA]////[&FFFA]////[&FFFA]")
                .doc("rules, one per line: [left<] sym [>right] [:cond] = replacement [:prob]"),
            param::text("rules_file").doc("read the rules from this file (one per line, # comments) instead"),
            param::real("generations", 5.0)
                .range(0, 200)
                .doc("rewrites; a fraction adds a partly grown last generation"),
            param::real("step_size", 0.1)
                .range(0, 1e4)
                .unit("m")
                .doc("default length of F, f, G (and of J/K/M organs)"),
            param::real("step_scale", 0.8).range(0, 1e4).doc("factor of \" (and divisor of _)"),
            param::real("angle", 28.0)
                .range(-360, 360)
                .unit("deg")
                .doc("default angle of + - & ^ \\ /; also the variable a"),
            param::real("angle_scale", 0.9).range(0, 1e4).doc("factor of ; (and divisor of @)"),
            param::real("thickness", 0.02).range(0, 1e3).unit("m").doc("initial width (node radius = width / 2)"),
            param::real("thickness_scale", 0.7).range(0, 1e4).doc("factor of ! (and divisor of ?)"),
            param::real("gravity", 0.2)
                .range(-100, 100)
                .doc("tropism of T toward -Y (per unit sin, in gravity_units); also T"),
            param::choice("gravity_units", "radians", {"radians", "degrees"})
                .doc("what T's amount bends by per unit sin: radians (ABOP's tropism) or degrees, as every other "
                     "turtle angle (a grammar written for Houdini with T(5) on short stems)"),
            param::real("random_scale", 0.0)
                .range(0, 1)
                .doc("every move length is scaled by 1 + random_scale * uniform(-1, 1)"),
            param::boolean("point_attributes", false)
                .doc("Houdini's Point Attributes: every node also gets up (the turtle's up vector), lage and gen "
                     "(the rewrite that made the module drawing it) as attributes in skeleton.ply, plant.ply and "
                     "plant.glb"),
            param::real("vertical_increment", 1.0)
                .range(0, 1e6)
                .doc("Houdini's Vertical Increment: what lage adds per drawn segment along the turtle's path"),
            param::real("u_increment", 0.1).range(-1e4, 1e4).doc("default increment of ' (colour index U)"),
            param::real("v_increment", 0.1).range(-1e4, 1e4).doc("default increment of # (colour index V)"),
            param::real("b", 0.0).range(-1e12, 1e12).doc("expression variable b"),
            param::real("c", 0.0).range(-1e12, 1e12).doc("expression variable c"),
            param::real("d", 0.0).range(-1e12, 1e12).doc("expression variable d"),
            param::text("variables").doc("user variables, single letters: 'k=0.5, q=2'"),
            param::text("channels")
                .doc("values of chan(0), chan(1), ...: '1, 0.5'; a channel may be animated over the generation being "
                     "made, as keys generation:value, linear between them: '0:0 4:1, 0.5'"),
            param::text("context_ignore")
                .doc("symbols skipped when matching contexts, e.g. '+-F'; with '[' or ']' brackets become transparent"),
            param::boolean("context_siblings", false)
                .doc("Context Includes Siblings (pre-Houdini 10): a right context that reaches the end of its "
                     "branch goes on in the next sibling branch"),
            param::choice("left_context", "parent", {"parent", "branch"})
                .doc("parent: a left context passes out of its branch into the parent, skipping sibling branches "
                     "(ABOP); branch: it stops at its branch's start, as a right context stops at its end"),
            param::choice("probability", "sequential", {"sequential", "normalized"})
                .doc("sequential: each applicable rule fires with its own chance, in order (Houdini); normalized: one "
                     "of "
                     "the applicable probabilistic rules by weight (ABOP)"),
            param::choice("probability_units", "auto", {"auto", "fraction", "percent"})
                .doc("how a rule's probability reads. auto: up to 1 a fraction, above 1 a percentage (the "
                     "reference defines 0 to 1, its topiary example writes ': 80'), and a constant between 1 and 2, "
                     "which could be either, is an error; fraction: 0 to 1; percent: 0 to 100"),
            param::choice("convention", "houdini", {"houdini", "abop"})
                .doc("houdini: + turns right; abop: + turns left (The Algorithmic Beauty of Plants)"),
            param::boolean("continuous_length", true).doc("fractional generation scales new lengths"),
            param::boolean("continuous_angles", true).doc("fractional generation scales new angles"),
            param::boolean("continuous_width", true).doc("fractional generation scales new widths"),
            param::choice("start", "seeds", {"seeds", "origin"})
                .doc("seeds: one plant per scene seed (along its direction); origin: one plant at start_position, +Y"),
            param::vec3("start_position", glm::dvec3(0.0))
                .range(-1e6, 1e6)
                .unit("m")
                .doc("where the turtle starts when start=origin"),
            param::choice("surface", "free", {"free", "wrap", "avoid"})
                .doc("free: the turtle moves in space; wrap: every move is mapped onto the nearest scene surface; "
                     "avoid: a branch ends before a step that would enter a solid"),
            param::real("wrap_offset", 0.01).range(0, 10).unit("m").doc("distance kept from the surface when wrapping"),
            param::choice("in_test", "auto", {"auto", "envelope", "solids"})
                .doc("what in(x,y,z) tests: the scene envelope, the scene's solids, or auto (envelope if any, else "
                     "solids)"),
            param::text("pic_image").doc("image read by pic(u, v, plane) (PNG, JPEG, ...)"),
            param::boolean("apply_color", false)
                .doc("colour every node (Cd) from color_image at the turtle's (u, v), which ' and # move "
                     "(Houdini's Apply Color)"),
            param::text("color_image").doc("the image apply_color reads (Houdini's Image File; PNG, JPEG, ...)"),
            param::text("organ_j").doc("J's geometry: a built-in shape (leaf, blossom, half_bloom, bud; `growbench "
                                       "list organs`) or an OBJ file; empty: its kind's shape, or --leaf-obj"),
            param::text("organ_k").doc("K's geometry, as organ_j"),
            param::text("organ_m").doc("M's geometry, as organ_j"),
            param::text("leaf_param_a")
                .doc("the setting of J/K/M's built-in shape that their stamp a sets (J(s,x,a,b,c); e.g. petals, "
                     "width): Houdini's Leaf Param A"),
            param::text("leaf_param_b").doc("the shape setting stamp b sets, as leaf_param_a"),
            param::text("leaf_param_c").doc("the shape setting stamp c sets, as leaf_param_a"),
            param::choice("kind_j", "leaf", {"leaf", "young_leaf", "flower", "bud"})
                .doc("what J places, for the metrics, mesh groups and materials"),
            param::choice("kind_k", "flower", {"leaf", "young_leaf", "flower", "bud"}).doc("what K places"),
            param::choice("kind_m", "bud", {"leaf", "young_leaf", "flower", "bud"}).doc("what M places"),
            param::choice("geometry", "tube", {"tube", "skeleton"})
                .doc("tube: tubes around the branches (F(l,w,s,d): s cross sections, d divisions); skeleton: "
                     "the branches' polylines alone (Houdini's Geometry Type)"),
            param::real("tension", 1.0)
                .range(0, 1)
                .doc("Houdini's Tension, for the sections inside an F: 1 keeps them on the straight segment, lower "
                     "sweeps them along a smooth curve through the nodes"),
            param::real("branch_blend", 0.0)
                .range(0, 1)
                .doc("Houdini's Branch Blend: how much a branch's first sections leave along its parent's heading"),
            param::boolean("tube_uvs", false)
                .doc("Houdini's Apply Tube Texture Coordinates: u around each tube, v growing by vertical_increment "
                     "per segment"),
            param::text("group_prefix", "lsys")
                .doc("names of g groups: the prefix and the group number (letters, digits and _)"),
            param::integer("max_symbols", 50'000'000)
                .range(1, 2e9)
                .doc("a generation that would exceed this many symbols stops the run with an error"),
        },
    .test_params = {"surface=wrap"},  // a free tree passes through solids
};

const std::vector<std::string>& setting_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& p : kInfo.params)
      if (p.name != "grammar") v.push_back(p.name);
    return v;
  }();
  return names;
}

// A channel chan(k) reads: keys (generation, value), linear between them and held beyond them (one key:
// a constant), as Houdini's animated channels are read at the current frame, a generation here.
struct Channel {
  std::vector<std::pair<double, double>> keys;
  [[nodiscard]] double at(double g) const {
    if (g <= keys.front().first) return keys.front().second;
    for (std::size_t k = 1; k < keys.size(); ++k)
      if (g < keys[k].first) {
        const auto& [g0, v0] = keys[k - 1];
        const auto& [g1, v1] = keys[k];
        return v0 + (v1 - v0) * (g - g0) / (g1 - g0);
      }
    return keys.back().second;
  }
};

class Host final : public lsys::ExprHost {
 public:
  double in(double x, double y, double z) const override {
    if (!query_ || mode_ == 0) return 0.0;
    const glm::vec3 p(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    if (mode_ == 1) return query_->inside_shape(*query_->scene().envelope, p) ? 1.0 : 0.0;
    return query_->inside(p) ? 1.0 : 0.0;
  }
  double pic(double u, double v, double plane) const override {
    if (image_.w == 0) throw InputError("pic() needs an image: set pic_image=FILE");
    const std::uint8_t* at = image_.at(u, v);
    const float px[3] = {at[0] / 255.0f, at[1] / 255.0f, at[2] / 255.0f};
    const int pl = static_cast<int>(plane);
    if (pl >= 1 && pl <= 3) return px[pl - 1];
    return 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
  }
  double rand(double s) const override {
    std::uint64_t bits;
    std::memcpy(&bits, &s, sizeof bits);
    // Each plant has its stream (plant 0's values are those of a one-plant scene).
    return static_cast<double>(random_bits(seed_, 0x7261'6e64 + (stream_ << 32), bits) >> 11) * 0x1.0p-53;
  }
  double chan(double index) const override {
    const auto k = static_cast<long>(std::floor(index));
    if (k < 0 || static_cast<std::size_t>(k) >= channels_.size())
      throw InputError(fmt::format("chan({}) has no value: 'channels' gives {} value(s)", k, channels_.size()));
    return channels_[static_cast<std::size_t>(k)].at(generation_);
  }

  const SceneQuery* query_ = nullptr;
  int mode_ = 0;  // 0 none, 1 envelope, 2 solids
  lsys::Image image_;
  std::uint64_t seed_ = 0;
  std::uint64_t stream_ = 0;  // the plant being rewritten: plants are rewritten one after another
  double generation_ = 0.0;   // the generation being made (0: the premise), the time chan() reads at
  std::vector<Channel> channels_;
};

// One number, strictly: the whole of `text`.
double channel_number(const std::string& text, const std::string& item) {
  char* e = nullptr;
  const double v = std::strtod(text.c_str(), &e);
  if (text.empty() || e == text.c_str() || *e != '\0' || !std::isfinite(v))
    throw InputError(fmt::format("channels: in '{}', expected a number, found '{}'", item, text));
  return v;
}

// Comma-separated channels, each a number or keys 'generation:value ...' in increasing generation.
std::vector<Channel> parse_channels(const std::string& text) {
  std::vector<Channel> out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    for (std::size_t c = item.find(':'); c != std::string::npos; c = item.find(':', c + 1))
      while (c + 1 < item.size() && (item[c + 1] == ' ' || item[c + 1] == '\t')) item.erase(c + 1, 1);
    std::istringstream words(item);
    Channel ch;
    for (std::string w; words >> w;) {
      const std::size_t colon = w.find(':');
      if (colon == std::string::npos) {
        if (!ch.keys.empty() || words >> w)
          throw InputError(fmt::format("channels: in '{}', expected one number or keys generation:value", item));
        ch.keys.push_back({0.0, channel_number(w, item)});
        break;
      }
      const double g = channel_number(w.substr(0, colon), item);
      if (!ch.keys.empty() && !(g > ch.keys.back().first))
        throw InputError(fmt::format("channels: in '{}', the generations of the keys must increase", item));
      ch.keys.push_back({g, channel_number(w.substr(colon + 1), item)});
    }
    if (ch.keys.empty())
      throw InputError(
          fmt::format("channels: channel {} is empty; expected a number or keys generation:value", out.size()));
    out.push_back(std::move(ch));
    start = end + 1;
  }
  return out;
}

// Everything derived from the parameters that both the growth algorithm and `growbench lsystem` need.
struct Setup {
  Params params;
  lsys::Grammar grammar;
  lsys::DeriveSettings derive;
  lsys::TurtleSettings turtle;
  std::unique_ptr<Host> host;
  int rewrites = 0;                       // whole generations, plus one for a fractional part
  double fraction = 0.0;                  // the fractional part (0: none); the last rewrite is drawn scaled by it
  std::vector<std::string> organ_shapes;  // Plant::organ_shapes: J/K/M's shapes by name
  std::vector<std::pair<std::string, std::string>> inputs;  // (parameter, path) of each file read
  lsys::Image color_image;                                  // apply_color's
  lsys::OrganStamps stamps;                                 // leaf_param_a/b/c and J/K/M's shapes
};

// An image a parameter names, with the parameter in every error.
lsys::Image load_image(const char* param, const std::string& file) {
  int w = 0, h = 0, ch = 0;
  if (stbi_info(file.c_str(), &w, &h, &ch) == 0)
    throw InputError(fmt::format("{} '{}': cannot read the image ({})", param, file, stbi_failure_reason()));
  if (w > kMaxImageSide || h > kMaxImageSide)
    throw InputError(fmt::format("{} '{}': the image is {} x {} pixels; expected at most {} on each side", param, file,
                                 w, h, kMaxImageSide));
  unsigned char* px = stbi_load(file.c_str(), &w, &h, &ch, 3);
  if (!px) throw InputError(fmt::format("{} '{}': cannot read the image ({})", param, file, stbi_failure_reason()));
  lsys::Image image{w, h, std::vector<std::uint8_t>(px, px + static_cast<std::size_t>(w) * h * 3)};
  stbi_image_free(px);
  return image;
}

// probability_units, checked against the grammar's constant probabilities: under auto a constant above 1
// and below 2 (':1.5') is a fraction of certainty to some readers and a percentage to others, so it is
// refused rather than read as either; under fraction, one above 1 is refused.
lsys::ProbabilityUnits probability_units(const lsys::Grammar& g, const std::string& units) {
  const auto u = units == "fraction"  ? lsys::ProbabilityUnits::Fraction
                 : units == "percent" ? lsys::ProbabilityUnits::Percent
                                      : lsys::ProbabilityUnits::Auto;
  for (const auto& r : g.rules) {
    if (r.probability.empty() || !r.probability.constant()) continue;
    const double v = r.probability.constant_value();
    if (u == lsys::ProbabilityUnits::Auto && v > 1.0 && v < 2.0)
      throw InputError(
          fmt::format("{}: probability {} is ambiguous: with probability_units=auto a probability "
                      "above 1 is a percentage ({}%), though it may be meant as a fraction (certain); "
                      "expected a fraction up to 1 or a percentage of 2 or more, or set "
                      "probability_units=fraction or percent",
                      r.where, v, v));
    if (u == lsys::ProbabilityUnits::Fraction && v > 1.0)
      throw InputError(fmt::format("{}: probability {}: expected 0 to 1 with probability_units=fraction", r.where, v));
  }
  return u;
}

// An organ OBJ named by a grammar file is found beside the file, as its author wrote it.
std::string organ_relative_to(const std::string& key, const std::string& value, const std::string& grammar) {
  namespace fs = std::filesystem;
  if (key.rfind("organ_", 0) != 0 || value.empty() || fs::path(value).is_absolute()) return value;
  const fs::path beside = fs::path(grammar).parent_path() / value;
  std::error_code ec;
  return fs::is_regular_file(beside, ec) ? beside.string() : value;
}

// J, K and M's kinds and shapes; the shapes' names are checked now, before anything grows.
void organ_setup(const Params& p, Setup& s) {
  static const char* const kSymbols[3] = {"j", "k", "m"};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string& kind = p.text(fmt::format("kind_{}", kSymbols[i]));
    s.turtle.organ_kind[i] = kind == "leaf"         ? OrganKind::Leaf
                             : kind == "young_leaf" ? OrganKind::YoungLeaf
                             : kind == "flower"     ? OrganKind::Flower
                                                    : OrganKind::Bud;
    const std::string key = fmt::format("organ_{}", kSymbols[i]);
    const std::string& name = p.text(key);
    s.stamps.params[i] = p.text(fmt::format("leaf_param_{}", "abc"[i]));
    s.stamps.base[i] = !name.empty()                                 ? name
                       : s.turtle.organ_kind[i] == OrganKind::Flower ? "blossom"
                       : s.turtle.organ_kind[i] == OrganKind::Bud    ? "bud"
                                                                     : "leaf";
    s.turtle.organ_shape[i] = kKindShape;
    if (name.empty()) continue;
    (void)organ_shape_named(name, fmt::format("parameter {}", key));
    const auto it = std::find(s.organ_shapes.begin(), s.organ_shapes.end(), name);
    s.turtle.organ_shape[i] = static_cast<std::uint16_t>(it - s.organ_shapes.begin());
    if (it == s.organ_shapes.end()) s.organ_shapes.push_back(name);
  }
}

Setup make_setup(const Params& given, std::uint64_t seed, const SceneQuery* query) {
  Setup s;
  s.params = given;
  Params& p = s.params;
  // grammar file values under the user's --set values
  std::optional<lsys::GrammarFile> file;
  if (!p.text("grammar").empty()) {
    file = lsys::read_grammar_file(resolve_grammar_path(p.text("grammar")), setting_names());
    s.inputs.emplace_back("grammar", file->path);
    for (const auto& st : file->settings) {
      if (p.was_set(st.key)) continue;
      try {
        p.set(st.key, organ_relative_to(st.key, st.value, file->path));
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}:{}: {}", file->path, st.line, e.what()));
      }
    }
  }
  // rules: rules_file, else --set rules, else the grammar file's, else the default tree's
  std::vector<lsys::GrammarText> rules;
  if (!p.text("rules_file").empty()) {
    rules.push_back(lsys::read_rules_file(p.text("rules_file")));
    s.inputs.emplace_back("rules_file", p.text("rules_file"));
  } else if (p.was_set("rules") || !file) {
    rules.push_back({"parameter 'rules'", p.text("rules"), 1});
  } else {
    rules.push_back(file->rules);
  }
  if (file && !p.was_set("premise") &&
      std::none_of(file->settings.begin(), file->settings.end(), [](const auto& st) { return st.key == "premise"; }))
    throw InputError(fmt::format("{}: no premise; expected a line 'premise: SYMBOLS'", file->path));
  const auto vars = lsys::parse_variables("parameter 'variables'", p.text("variables"));
  std::vector<std::string> user_names;
  std::vector<double> user_values;
  for (const auto& [name, value] : vars) {
    if (name == "b" || name == "c" || name == "d") continue;
    user_names.push_back(name);
    user_values.push_back(value);
  }
  if (user_names.size() > static_cast<std::size_t>(lsys::kMaxSlots - lsys::kUserVar0))
    throw InputError("variables: too many user variables");
  // A premise from the file is parsed where the file has it, so that its errors name FILE:LINE:COLUMN.
  lsys::GrammarText premise{"parameter 'premise'", p.text("premise"), 1};
  if (file && !given.was_set("premise"))
    for (const auto& st : file->settings)
      if (st.key == "premise") premise = file->setting_text(st);
  s.grammar = lsys::parse_grammar(premise, rules, user_names, p.text("context_ignore"));
  if (p.boolean("point_attributes")) {
    s.grammar.uses_age = true;  // gen is the plant's rewrites less the module's age
    for (const char* name : {"up", "lage", "gen"})
      if (std::find(s.grammar.strings.begin(), s.grammar.strings.end(), name) != s.grammar.strings.end())
        throw InputError(
            fmt::format("point_attributes: the grammar sets '{}' itself with a(\"{}\", ...); "
                        "expected one or the other",
                        name, name));
  }

  s.host = std::make_unique<Host>();
  s.host->seed_ = seed;
  s.host->query_ = query;
  s.host->channels_ = parse_channels(p.text("channels"));
  if (query) {
    const std::string& mode = p.text("in_test");
    const bool has_env = query->scene().envelope.has_value();
    if (mode == "envelope") {
      if (!has_env) throw InputError("in_test=envelope: the scene has no envelope");
      s.host->mode_ = 1;
    } else if (mode == "solids") {
      s.host->mode_ = 2;
    } else {
      s.host->mode_ = has_env ? 1 : 2;
    }
    if (s.host->mode_ == 2 && !query->has_sdf()) s.host->mode_ = 0;
  }
  if (!p.text("pic_image").empty()) {
    s.host->image_ = load_image("pic_image", p.text("pic_image"));
    s.inputs.emplace_back("pic_image", p.text("pic_image"));
  }
  if (p.boolean("apply_color")) {
    if (p.text("color_image").empty())
      throw InputError("apply_color: needs an image to read the colours from: set color_image=FILE");
    if (std::find(s.grammar.strings.begin(), s.grammar.strings.end(), "Cd") != s.grammar.strings.end())
      throw InputError(
          "apply_color: the grammar colours the branches itself with a(\"Cd\", ...); use one or the other");
    s.color_image = load_image("color_image", p.text("color_image"));
    s.inputs.emplace_back("color_image", p.text("color_image"));
  }

  // Designated initializers: a member left out is a warning (-Wmissing-field-initializers), an error in CI.
  const auto max_symbols = static_cast<std::size_t>(p.integer("max_symbols"));
  s.derive = {
      .host = s.host.get(),
      .seed = seed,
      .stream = 0,  // set for each plant before it is rewritten
      .probability =
          p.text("probability") == "normalized" ? lsys::ProbabilityMode::Normalized : lsys::ProbabilityMode::Sequential,
      .units = probability_units(s.grammar, p.text("probability_units")),
      .brackets_transparent = s.grammar.ignore.test('[') || s.grammar.ignore.test(']'),
      .siblings = p.boolean("context_siblings"),
      .left_in_branch = p.text("left_context") == "branch",
      .max_symbols = max_symbols,
      .max_params = max_symbols * 2,
      .env = {},
  };
  auto& env = s.derive.env;
  env[lsys::kVarA] = p.real("angle");
  env[lsys::kVarB] = p.real("b");
  env[lsys::kVarC] = p.real("c");
  env[lsys::kVarD] = p.real("d");
  for (const auto& [name, value] : vars) {
    if (name == "b") env[lsys::kVarB] = value;
    if (name == "c") env[lsys::kVarC] = value;
    if (name == "d") env[lsys::kVarD] = value;
  }
  env[lsys::kVarGravity] = p.real("gravity");
  env[lsys::kVarLength] = p.real("step_size");
  env[lsys::kVarWidth] = p.real("thickness");
  for (std::size_t k = 0; k < user_values.size(); ++k) env[lsys::kUserVar0 + k] = user_values[k];

  if (p.text("surface") != "free" && !query)
    throw InputError(fmt::format("surface={} needs a scene with surfaces", p.text("surface")));
  for (const char c : p.text("group_prefix"))
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_'))
      throw InputError(
          fmt::format("group_prefix '{}': expected letters, digits and '_' only (it names OBJ groups "
                      "and glTF nodes)",
                      p.text("group_prefix")));
  s.turtle = {
      .step = p.real("step_size"),
      .step_scale = p.real("step_scale"),
      .angle = p.real("angle"),
      .angle_scale = p.real("angle_scale"),
      .thickness = p.real("thickness"),
      .thickness_scale = p.real("thickness_scale"),
      .gravity = p.real("gravity"),
      .gravity_unit = p.text("gravity_units") == "degrees" ? std::numbers::pi / 180.0 : 1.0,
      .random_scale = p.real("random_scale"),
      .uv_increment = {p.real("u_increment"), p.real("v_increment")},
      .convention = p.text("convention") == "abop" ? lsys::Convention::Abop : lsys::Convention::Houdini,
      // The plant's own, set for each plant when it is drawn; these draw one plant at the origin, +Y.
      .fraction = 1.0,
      .continuous_length = p.boolean("continuous_length"),
      .continuous_angles = p.boolean("continuous_angles"),
      .continuous_width = p.boolean("continuous_width"),
      .seed = seed,
      .stream = 0,
      .origin = glm::dvec3(0.0),
      .heading = glm::dvec3(0.0, 1.0, 0.0),
      .wrap = p.text("surface") == "wrap" ? query : nullptr,
      .wrap_offset = p.real("wrap_offset"),
      .avoid = p.text("surface") == "avoid" ? query : nullptr,
      .birth_step = 0,
      .organ_kind = {},
      .organ_shape = {},
      .color_image = nullptr,
      .stamps = nullptr,
      .point_attributes = p.boolean("point_attributes"),
      .vertical_increment = p.real("vertical_increment"),
      .generation = 0,  // the plant's, set when it is drawn
  };
  organ_setup(p, s);
  const double generations = p.real("generations");
  const int full = static_cast<int>(std::floor(generations + 1e-9));
  s.fraction = generations - full < 1e-6 ? 0.0 : generations - full;
  s.rewrites = full + (s.fraction > 0.0 ? 1 : 0);
  return s;
}

struct Plantlet {
  lsys::LString cur, next;
  std::vector<lsys::TurtleVars> states;
  int generation = 0;
  int start_step = 0;
  glm::dvec3 origin{0.0}, heading{0.0, 1.0, 0.0};
  std::uint64_t stream = 0;
  bool started = false;
};

class LSystem final : public GrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }

  void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) override {
    setup_ = make_setup(params, seed, &query);
    not_applicable_.clear();
    if (params.text("surface") == "wrap" && !scene.has_climbable())
      not_applicable_ = fmt::format("surface=wrap: scene '{}' has no climbable surface to wrap onto", scene.name);
    deriver_ = std::make_unique<lsys::Deriver>(setup_.grammar, setup_.derive);
    plants_.clear();
    if (setup_.params.text("start") == "origin" || scene.seeds.empty()) {
      Plantlet pl;
      pl.origin = setup_.params.vec3("start_position");
      plants_.push_back(std::move(pl));
    } else {
      for (std::size_t k = 0; k < scene.seeds.size(); ++k) {
        Plantlet pl;
        pl.origin = glm::dvec3(scene.seeds[k].position);
        pl.heading = glm::dvec3(scene.seeds[k].direction);
        pl.start_step = std::max(0, scene.seeds[k].start_step);
        pl.stream = k;
        plants_.push_back(std::move(pl));
      }
    }
    step_ = 0;
    begin_due();
    redraw();
  }

  bool step() override {
    ++step_;
    bool more = false;
    for (auto& pl : plants_) {
      if (!pl.started || pl.generation >= setup_.rewrites) continue;
      const auto t0 = std::chrono::steady_clock::now();
      use_stream(pl.stream);
      setup_.host->generation_ = pl.generation + 1;
      deriver_->rewrite(pl.cur, pl.next, pl.generation + 1, pl.states);
      rewrite_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::swap(pl.cur, pl.next);
      ++pl.generation;
    }
    begin_due();
    redraw();
    for (const auto& pl : plants_) more |= !pl.started || pl.generation < setup_.rewrites;
    if (!more) {
      for (auto& pl : plants_) {  // the spare buffers are no longer needed
        pl.next.symbols.release();
        pl.next.params.release();
        pl.next.ages.release();
      }
    }
    return more;
  }

  const Plant& plant() const override { return plant_; }

  // The grammar file's settings under the user's: what it grew with.
  std::optional<Params> effective_params() const override { return setup_.params; }
  std::vector<std::pair<std::string, std::string>> input_files() const override { return setup_.inputs; }
  std::vector<std::string> warnings() const override { return setup_.grammar.warnings; }

  // A grammar is a program in the input, whose arithmetic can divide by zero or overflow: the invalid plant
  // it draws is bad input, not a bug.
  void finish() override {
    if (const std::string bad = plant_.validate(); !bad.empty()) {
      const std::string grammar = setup_.params.text("grammar");
      throw InputError(
          fmt::format("L-system{}: the plant its rules drew is invalid ({}): an expression divided by zero, overflowed "
                      "or drew too far",
                      grammar.empty() ? "" : fmt::format(" grammar '{}'", grammar), bad));
    }
  }

  OwnVerdict own_verdict() const override { return {not_applicable_, {}}; }

  static StringRewriting string_rewriting() { return {derive_lsystem, lsystem_examples}; }

  std::vector<std::pair<std::string, double>> stats() const override {
    std::size_t symbols = 0, bytes = 0;
    for (const auto& pl : plants_) {
      symbols += pl.cur.size();
      bytes += pl.cur.bytes() + pl.next.bytes();
    }
    return {{"symbols", static_cast<double>(symbols)},
            {"string_bytes", static_cast<double>(bytes)},
            {"rewrite_s", rewrite_s_},
            {"turtle_s", turtle_s_},
            {"max_branch_depth", static_cast<double>(max_depth_)}};
  }

 private:
  void use_stream(std::uint64_t stream) {
    deriver_->set_stream(stream);
    setup_.host->stream_ = stream;
  }

  void begin_due() {
    for (auto& pl : plants_) {
      if (pl.started || pl.start_step > step_) continue;
      use_stream(pl.stream);
      setup_.host->generation_ = 0;
      deriver_->premise(pl.cur);
      pl.started = true;
    }
  }

  void redraw() {
    const auto t0 = std::chrono::steady_clock::now();
    plant_.clear();
    plant_.organ_shapes = setup_.organ_shapes;
    plant_.group_prefix = setup_.params.text("group_prefix");
    plant_.branch_geometry =
        setup_.params.text("geometry") == "skeleton" ? BranchGeometry::Skeleton : BranchGeometry::Tube;
    plant_.tube_style = {.tension = static_cast<float>(setup_.params.real("tension")),
                         .branch_blend = static_cast<float>(setup_.params.real("branch_blend")),
                         .uvs = setup_.params.boolean("tube_uvs"),
                         .v_increment = static_cast<float>(setup_.params.real("vertical_increment"))};
    if (!plant_.tube_style.uvs) plant_.tube_style.v_increment = TubeStyle{}.v_increment;  // unused: keeps the hash
    for (auto& pl : plants_) {
      if (!pl.started) continue;
      lsys::TurtleSettings ts = setup_.turtle;
      ts.origin = pl.origin;
      ts.heading = pl.heading;
      ts.stream = pl.stream;
      ts.color_image = setup_.color_image.w > 0 ? &setup_.color_image : nullptr;
      const auto& stamp_params = setup_.stamps.params;
      ts.stamps = std::all_of(stamp_params.begin(), stamp_params.end(), [](const auto& x) { return x.empty(); })
                      ? nullptr
                      : &setup_.stamps;
      ts.birth_step = static_cast<std::uint32_t>(step_);
      ts.generation = pl.generation;
      ts.fraction = (setup_.fraction > 0.0 && pl.generation == setup_.rewrites) ? setup_.fraction : 1.0;
      const bool need_states = setup_.grammar.uses_turtle && pl.generation < setup_.rewrites;
      const auto r = lsys::interpret(pl.cur, ts, setup_.grammar.strings, plant_, need_states ? &pl.states : nullptr);
      if (!need_states) pl.states.clear();
      max_depth_ = std::max(max_depth_, r.max_depth);
    }
    turtle_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  Setup setup_;
  std::string not_applicable_;  // OwnVerdict
  std::unique_ptr<lsys::Deriver> deriver_;
  std::vector<Plantlet> plants_;
  Plant plant_;
  int step_ = 0;
  double rewrite_s_ = 0.0, turtle_s_ = 0.0;
  std::size_t max_depth_ = 0;
};

}  // namespace

GROWBENCH_REGISTER_ALGORITHM(lsystem, LSystem, kInfo, lsys::TurtleSettings, lsys::DeriveSettings)

std::vector<std::string> lsystem_examples() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(data_path("algorithms/lsystem/examples"), ec))
    if (e.path().extension() == ".lsys") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string resolve_grammar_path(const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(name, ec)) return name;
  const fs::path dir(data_path("algorithms/lsystem/examples"));
  for (const auto& candidate : {dir / name, dir / (name + ".lsys")})
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  const auto names = lsystem_examples();
  const std::string near = closest_match(name, names);
  throw InputError(fmt::format("grammar '{}': no such file, and not an example{}; examples: {}", name,
                               near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), fmt::join(names, ", ")));
}

DerivedString derive_lsystem(const Params& params, std::uint64_t seed, const Scene* scene, const SceneQuery* query,
                             std::optional<std::size_t> print_limit) {
  Setup setup = make_setup(params, seed, query);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  lsys::Deriver deriver(setup.grammar, setup.derive);
  lsys::LString cur, next;
  std::vector<lsys::TurtleVars> states;
  deriver.premise(cur);
  const int rewrites = setup.rewrites;
  lsys::TurtleSettings ts = setup.turtle;
  if (scene && !scene->seeds.empty() && setup.params.text("start") == "seeds") {
    ts.origin = glm::dvec3(scene->seeds[0].position);
    ts.heading = glm::dvec3(scene->seeds[0].direction);
  } else {
    ts.origin = setup.params.vec3("start_position");
  }
  for (int g = 1; g <= rewrites; ++g) {
    if (setup.grammar.uses_turtle) {
      Plant scratch;
      lsys::interpret(cur, ts, setup.grammar.strings, scratch, &states);
    }
    setup.host->generation_ = g;
    deriver.rewrite(cur, next, g, states);
    std::swap(cur, next);
  }
  DerivedString out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  if (print_limit) out.text = lsys::to_text(cur, setup.grammar.strings, *print_limit);
  out.modules = cur.size();
  out.params = cur.params.size();
  out.bytes = cur.bytes();
  out.generations = rewrites;
  const auto counts = lsys::symbol_counts(cur);
  for (int c = 0; c < 128; ++c)
    if (counts[static_cast<std::size_t>(c)] > 0)
      out.counts.emplace_back(static_cast<char>(c), counts[static_cast<std::size_t>(c)]);
  for (const auto& r : setup.grammar.rules) out.rules.push_back(r.text);
  return out;
}

}  // namespace growbench
