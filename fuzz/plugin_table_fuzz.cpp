// A plugin's table as load_plugin checks it (algorithms/plugins/loader): ABI version and size, name,
// function pointers, every parameter row (type, default, range, choices) and the test parameters.
//
// The table comes from a text input, one setting per line; text after the keyword is the rest of the line,
// and "~" stands for NULL:
//   abi N | size N | name T | summary T | version T | functions MASK (create, start, step, finish, plant,
//   counts, stats, destroy: bit 0 up) | params_null N | tests_null N | test T
//   param T (starts a row; then, for it:) type N | int N | real X | bool N | text T | vec3 X Y Z | min X |
//   max X | unit T | doc T | choice T (appends one) | choices_null N
// The table is handed to a stub plugin (plugin_table_stub.c) whose entry point returns it, and the stub
// is loaded through a hard link: a table that loads is registered under its path, and the next table
// needs a path the loader has not seen.
#include <dlfcn.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/plugins/loader.hpp"
#include "fuzz/fuzz_util.hpp"
#include "growbench/plugin.h"

namespace {

namespace fs = std::filesystem;

// Everything one input's table points to, kept until the next input.
struct Table {
  growbench_plugin plugin{};
  std::deque<std::string> strings;  // a deque: adding one never moves the others
  std::vector<growbench_param> rows;
  std::vector<std::vector<const char*>> choices;
  std::vector<bool> choices_null;
  std::vector<const char*> tests;
  bool params_null = false, tests_null = false;
  std::uint32_t params_null_count = 0, tests_null_count = 0;

  const char* text(const std::string& s) { return s == "~" ? nullptr : strings.emplace_back(s).c_str(); }
};

// Stand-ins for the plugin's functions: the loader only checks that they are set.
growbench_instance* create(const growbench_host*) {
  return nullptr;
}
int32_t start(growbench_instance*, const growbench_scene*, const growbench_value*, uint64_t) {
  return 0;
}
int32_t step(growbench_instance*) {
  return 0;
}
int32_t finish(growbench_instance*) {
  return 0;
}
int32_t plant(growbench_instance*, growbench_plant_view*) {
  return 0;
}
void counts(growbench_instance*, uint64_t*, uint64_t*) {}
uint32_t stats(growbench_instance*, const growbench_stat**) {
  return 0;
}
void destroy(growbench_instance*) {}

double real(std::istringstream& in) {
  std::string s;
  in >> s;
  return std::strtod(s.c_str(), nullptr);  // "nan", "inf", "-1e400" and hex floats too
}
std::int64_t integer(std::istringstream& in) {
  std::string s;
  in >> s;
  return std::strtoll(s.c_str(), nullptr, 0);
}
std::string rest(std::istringstream& in) {
  std::string s;
  std::getline(in >> std::ws, s);
  return s;
}

void set_functions(growbench_plugin& p, std::int64_t mask) {
  p.create = mask & 1 ? create : nullptr;
  p.start = mask & 2 ? start : nullptr;
  p.step = mask & 4 ? step : nullptr;
  p.finish = mask & 8 ? finish : nullptr;
  p.plant = mask & 16 ? plant : nullptr;
  p.counts = mask & 32 ? counts : nullptr;
  p.stats = mask & 64 ? stats : nullptr;
  p.destroy = mask & 128 ? destroy : nullptr;
}

// One line of a parameter row; false when the keyword is not a row's.
bool row_line(Table& t, const std::string& key, std::istringstream& in) {
  if (t.rows.empty()) return false;
  growbench_param& r = t.rows.back();
  if (key == "type")
    r.type = static_cast<std::int32_t>(integer(in));
  else if (key == "int")
    r.default_value.integer = integer(in);
  else if (key == "real")
    r.default_value.real = real(in);
  else if (key == "bool")
    r.default_value.boolean = static_cast<std::int32_t>(integer(in));
  else if (key == "text")
    r.default_value.text = t.text(rest(in));
  else if (key == "vec3")
    for (double& v : r.default_value.vec3) v = real(in);
  else if (key == "min")
    r.min = real(in);
  else if (key == "max")
    r.max = real(in);
  else if (key == "unit")
    r.unit = t.text(rest(in));
  else if (key == "doc")
    r.doc = t.text(rest(in));
  else if (key == "choice")
    t.choices.back().push_back(t.text(rest(in)));
  else if (key == "choices_null") {
    t.choices_null.back() = true;
    r.choice_count = static_cast<std::uint32_t>(integer(in));
  } else
    return false;
  return true;
}

void read_line(Table& t, const std::string& line) {
  std::istringstream in(line);
  std::string key;
  in >> key;
  growbench_plugin& p = t.plugin;
  if (key == "abi")
    p.abi_version = static_cast<std::uint32_t>(integer(in));
  else if (key == "size")
    p.struct_size = static_cast<std::uint32_t>(integer(in));
  else if (key == "name")
    p.name = t.text(rest(in));
  else if (key == "summary")
    p.summary = t.text(rest(in));
  else if (key == "version")
    p.version = t.text(rest(in));
  else if (key == "functions")
    set_functions(p, integer(in));
  else if (key == "test")
    t.tests.push_back(t.text(rest(in)));
  else if (key == "params_null") {
    t.params_null = true;
    t.params_null_count = static_cast<std::uint32_t>(integer(in));
  } else if (key == "tests_null") {
    t.tests_null = true;
    t.tests_null_count = static_cast<std::uint32_t>(integer(in));
  } else if (key == "param") {
    growbench_param r{};
    r.name = t.text(rest(in));
    r.min = -HUGE_VAL;
    r.max = HUGE_VAL;
    t.rows.push_back(r);
    t.choices.emplace_back();
    t.choices_null.push_back(false);
  } else {
    row_line(t, key, in);
  }
}

// The table an input describes; a complete, valid-looking header unless the input says otherwise.
void build(Table& t, const std::uint8_t* data, std::size_t size) {
  t.plugin.abi_version = GROWBENCH_PLUGIN_ABI_VERSION;
  t.plugin.struct_size = sizeof(growbench_plugin);
  set_functions(t.plugin, 255);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  for (std::string line; std::getline(in, line);) read_line(t, line);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (t.choices_null[i]) {
      t.rows[i].choices = nullptr;
    } else {
      t.rows[i].choices = t.choices[i].data();
      t.rows[i].choice_count = static_cast<std::uint32_t>(t.choices[i].size());
    }
  }
  t.plugin.params = t.params_null ? nullptr : t.rows.data();
  t.plugin.param_count = t.params_null ? t.params_null_count : static_cast<std::uint32_t>(t.rows.size());
  t.plugin.test_params = t.tests_null ? nullptr : t.tests.data();
  t.plugin.test_param_count = t.tests_null ? t.tests_null_count : static_cast<std::uint32_t>(t.tests.size());
}

// The stub's path for the next load: a new hard link once a table has loaded under the current one.
class StubLinks {
 public:
  StubLinks() {
    std::string pattern = (fs::path(GROWBENCH_FUZZ_PLUGIN_STUB).parent_path() / "links.XXXXXX").string();
    if (!mkdtemp(pattern.data())) fail("mkdtemp");
    dir_ = pattern;
    next();
    void* handle = dlopen(path_.c_str(), RTLD_NOW | RTLD_LOCAL);  // the loader's dlopen finds this one
    if (!handle) fail(dlerror());
    set_table_ = reinterpret_cast<void (*)(const growbench_plugin*)>(dlsym(handle, "growbench_fuzz_set_table"));
    if (!set_table_) fail("no growbench_fuzz_set_table in the stub");
  }
  ~StubLinks() { fs::remove_all(dir_); }
  [[nodiscard]] const std::string& path() const { return path_; }
  void set_table(const growbench_plugin* t) const { set_table_(t); }
  void next() {
    if (!path_.empty()) fs::remove(path_);
    path_ = (dir_ / ("plugin" + std::to_string(count_++) + ".so")).string();
    if (link(GROWBENCH_FUZZ_PLUGIN_STUB, path_.c_str()) != 0) fail("link");
  }

 private:
  [[noreturn]] static void fail(const char* what) {
    std::fprintf(stderr, "plugin_table_fuzz: %s\n", what);
    std::abort();
  }
  fs::path dir_;
  std::string path_;
  std::uint64_t count_ = 0;
  void (*set_table_)(const growbench_plugin*) = nullptr;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static StubLinks links;
  static std::vector<std::unique_ptr<Table>> loaded;  // a registered plugin's entry keeps its table
  auto table = std::make_unique<Table>();
  build(*table, data, size);
  links.set_table(&table->plugin);
  growbench::fuzz::expect_input_errors([&] {
    (void)growbench::load_plugin(links.path());
    loaded.push_back(std::move(table));
    links.next();
  });
  return 0;
}
