// The interface every growth algorithm implements. The harness drives the steps, so budgets, time
// limits, growth curves and animation frames work the same way for all of them.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "algorithms/plant.hpp"
#include "core/params.hpp"
#include "core/plugin_origin.hpp"
#include "scenes/scene.hpp"
#include "scenes/host_queries.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {

struct AlgorithmInfo {
  std::string name;
  std::string summary;
  // The table `growbench list` prints and `--set` validates: the only place a parameter's default,
  // range, unit and doc live. The algorithm reads typed values from Params.
  std::vector<ParamSpec> params;
  std::vector<ParamPreset> presets{};  // defaults selected by the `preset` parameter (may be empty)
  // Assignments under which the algorithm promises that no node enters a solid, at a size that keeps
  // the every-algorithm-every-scene test quick.
  std::vector<std::string> test_params;
};

// A file an algorithm writes beside the plant's meshes (GrowthAlgorithm::write_outputs).
struct OutputFile {
  std::string name;  // as written into the directory asked for
  std::uint64_t bytes = 0;
};

// Where and what GrowthAlgorithm::write_outputs writes.
struct OutputRequest {
  std::string dir;     // exists
  std::string prefix;  // put before every file name: "" for a run's files, "step_000010." for a frame's
  bool frame = false;  // a growth frame: only the images plant().decals name (what renders of it need)
};

// The algorithm's own word on the plant it grew, after finish(): why the scene is one it cannot grow on
// (not_applicable: an L-system wrap with nothing climbable to wrap onto), and the checks of its own that
// the plant failed (space colonization: no attraction point reached). The harness adds its general
// checks (harness/output/validity.hpp) and records the verdict.
struct OwnVerdict {
  std::string not_applicable;           // empty: a scene it can grow on
  std::vector<std::string> degenerate;  // each own check the plant failed
};

class GrowthAlgorithm {
 public:
  virtual ~GrowthAlgorithm() = default;
  // The trial's time limit, set before start(): a step that can run long may check cancelled().
  void set_deadline(std::chrono::steady_clock::time_point t) { deadline_ = t; }
  [[nodiscard]] bool cancelled() const { return deadline_ && std::chrono::steady_clock::now() > *deadline_; }
  [[nodiscard]] virtual const AlgorithmInfo& describe() const = 0;
  // Reads the input files `params` name (spacecol's points file), once, before start(). The harness
  // calls it in the scene_load phase: reading input is not growth. An algorithm that skips it (a
  // plugin) reads them in start(). Throws InputError for a file that cannot be read.
  virtual void load_inputs(const Params& /*params*/) {}
  // Prepares a run. `params` were validated against describe().params. The scene and query outlive
  // the algorithm. Throws InputError for combinations of parameters and scene that cannot work.
  virtual void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) = 0;
  // Advances one growth step; returns false when growth has ended by itself.
  virtual bool step() = 0;
  [[nodiscard]] virtual const Plant& plant() const = 0;
  // What the harness checks after every step (budgets, the growth curve), without asking for the
  // whole plant: an algorithm that assembles its Plant on demand (hadrich) answers from its own state.
  // Must equal plant().nodes.size() and plant().organs.size().
  [[nodiscard]] virtual std::size_t node_count() const { return plant().nodes.size(); }
  [[nodiscard]] virtual std::size_t organ_count() const { return plant().organs.size(); }
  // Called once after the last step, before meshing (e.g. to assign pipe-model radii or place leaves).
  virtual void finish() {}
  // The parameters it grows with, when files it reads set some (an L-system's grammar file sets its premise
  // and angle): what the record keeps as its effective parameters. Empty: those it was given. After start().
  [[nodiscard]] virtual std::optional<Params> effective_params() const { return std::nullopt; }
  // The files its parameters named and it read, as (parameter, path): the record keeps their content hashes.
  [[nodiscard]] virtual std::vector<std::pair<std::string, std::string>> input_files() const { return {}; }
  // What in its input parses but is likely not what was meant (a grammar's '/30'), each naming where: the
  // record keeps them and `run` prints them. After start().
  [[nodiscard]] virtual std::vector<std::string> warnings() const { return {}; }
  // Algorithm-specific figures for the trial record (e.g. attraction points left).
  [[nodiscard]] virtual std::vector<std::pair<std::string, double>> stats() const { return {}; }
  // Its word on the plant as grown (OwnVerdict above); called after finish().
  [[nodiscard]] virtual OwnVerdict own_verdict() const { return {}; }
  // Files only this algorithm makes, for the plant as it is now (the vines' texture, its normal map and
  // its skeleton as SVG). The image of each of plant().decals must be among them, named prefix + image.
  // Called in the outputs phase (timed there, apart from the mesh exports) and, for each growth frame,
  // with frame set.
  [[nodiscard]] virtual std::vector<OutputFile> write_outputs(const OutputRequest& /*request*/) const { return {}; }

 private:
  std::optional<std::chrono::steady_clock::time_point> deadline_;
};

// An algorithm that asks the scene only what the plugin ABI's host table offers (HostQueries). The same
// source builds into the binary, where its queries are the SceneQuery's own, and as a plugin
// (growbench_builtin_plugin in algorithms/plugins/), where they cross the C ABI: which is how the
// boundary is shown to lose nothing.
class PortableGrowthAlgorithm : public GrowthAlgorithm {
 public:
  virtual void start_with(const Scene& scene, const HostQueries& queries, const Params& params, std::uint64_t seed) = 0;
  void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) final {
    start_with(scene, query.host_queries(), params, seed);
  }
};

// A struct an algorithm reads its parameters into, as its registration names it.
struct ParamStruct {
  std::string type;  // as written in GROWBENCH_REGISTER_ALGORITHM
  // False when the struct keeps defaults of its own beside the table: any default member initializer
  // (or a member that constructs itself, such as a container) makes it non-trivial.
  bool trivially_default_constructible;
};

// What `growbench lsystem FILE --print` shows: a rewriting algorithm's derived string (of the first plant)
// and its symbol counts, without drawing (the turtle runs only if rules read its state).
struct DerivedString {
  std::string text;  // up to print_limit modules (0: all); empty without a print_limit
  // From the parsed grammar to the last generation's string (the premise and every rewrite, with the
  // turtle runs that rules reading its state need): the work a string-rewriting peer's own timer covers.
  // Parsing the grammar is reading input; the text and the counts are output.
  double seconds = 0.0;
  // The same span's CPU time, summed over threads: on a loaded machine the wall time also holds waiting.
  double cpu_seconds = 0.0;
  std::size_t modules = 0;
  std::size_t params = 0;
  std::size_t bytes = 0;  // memory of the string
  int generations = 0;
  std::vector<std::pair<char, std::size_t>> counts;  // by symbol, in ASCII order
  std::vector<std::string> rules;  // the rules it rewrote with, one line each, as a rules file holds them
};

// What an algorithm that rewrites a string (an L-system) offers beyond growing: the string derived alone,
// and the example inputs it ships. It says so with a static `string_rewriting()` on its class, which the
// registration picks up; the command line reaches it through the registry, never the algorithm's header.
struct StringRewriting {
  std::function<DerivedString(const Params& params, std::uint64_t seed, const Scene* scene, const SceneQuery* query,
                              std::optional<std::size_t> print_limit)>
      derive;
  std::function<std::vector<std::string>()> examples;
};

struct AlgorithmEntry {
  std::function<const AlgorithmInfo&()> info;
  std::function<std::unique_ptr<GrowthAlgorithm>()> make;
  std::vector<ParamStruct> param_structs;        // built-ins only
  std::shared_ptr<const PluginOrigin> plugin{};  // null for a built-in
  std::optional<StringRewriting> rewriting{};    // a string-rewriting algorithm's extras
};

// Every algorithm, in the order of the add_subdirectory lines in algorithms/CMakeLists.txt (the order
// `growbench list` prints). The build generates it from the algorithms' growbench_algorithm() calls, so
// adding an algorithm is its folder plus one line there.
const std::vector<AlgorithmEntry>& algorithm_registry();
// The built-ins, then the plugins loaded so far (algorithms/plugins/loader.hpp), in loading order.
std::vector<const AlgorithmEntry*> all_algorithms();
// Finds an algorithm, built-in or loaded plugin, by name; InputError listing the valid names otherwise.
const AlgorithmEntry& find_algorithm(const std::string& name);
// Default parameters of an algorithm, with `owner` set for error messages.
Params default_params(const AlgorithmEntry& entry);

// Splits "a::X, b::Y<int, 2>" into its `count` type names (commas inside <> or () do not split); the
// whole text for each when the count does not match.
std::vector<std::string> split_type_list(std::string_view list, std::size_t count);

template <class Algorithm, class... ParamStructs>
AlgorithmEntry make_algorithm_entry(const AlgorithmInfo& (*info)(), std::string_view param_struct_names) {
  static_assert(sizeof...(ParamStructs) > 0, "name the struct(s) the algorithm reads its parameters into");
  AlgorithmEntry e{info, []() -> std::unique_ptr<GrowthAlgorithm> { return std::make_unique<Algorithm>(); }, {}};
  const std::vector<std::string> names = split_type_list(param_struct_names, sizeof...(ParamStructs));
  std::size_t k = 0;
  (e.param_structs.push_back({names[k++], std::is_trivially_default_constructible_v<ParamStructs>}), ...);
  if constexpr (requires { Algorithm::string_rewriting(); }) e.rewriting = Algorithm::string_rewriting();
  return e;
}

}  // namespace growbench

// Registers an algorithm from its main file: defines growbench::algorithm_entry_NAME(), which the
// registry the build generates calls. NAME is the NAME of the folder's growbench_algorithm() call;
// CLASS the GrowthAlgorithm; INFO the AlgorithmInfo its describe() returns; then the struct(s) it reads
// its parameters into, which the registry test checks keep no defaults of their own. Use it at the
// scope of namespace growbench, outside any anonymous namespace. There is no static registration
// object: the linker would drop it from the static library.
#define GROWBENCH_REGISTER_ALGORITHM(NAME, CLASS, INFO, ...)                       \
  ::growbench::AlgorithmEntry algorithm_entry_##NAME() {                           \
    return ::growbench::make_algorithm_entry<CLASS, __VA_ARGS__>(                  \
        []() -> const ::growbench::AlgorithmInfo& { return INFO; }, #__VA_ARGS__); \
  }
