#include "algorithms/plugins/loader.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "algorithms/plugins/plugin_algorithm.hpp"
#include "core/data_path.hpp"
#include "core/errors.hpp"
#include "core/file_hash.hpp"
#include "core/utf8.hpp"
#include "growbench/plugin.h"

namespace growbench {
namespace {

namespace fs = std::filesystem;

struct Loaded {
  std::string path;
  AlgorithmInfo info;
  AlgorithmEntry entry;
};

std::deque<Loaded>& loaded() {
  static std::deque<Loaded> list;  // a deque: registering more never moves an entry handed out
  return list;
}

// Why `s` cannot be a name ([a-z0-9_]+), or "" when it can.
std::string name_problem(const char* s) {
  if (!s) return "its name is NULL";
  if (!*s) return "its name is empty";
  for (const char* c = s; *c; ++c)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_'))
      return fmt::format("its name '{}' has '{}'; expected a-z, 0-9 and _ only", escape_utf8(s),
                         utf8_char_at(s, static_cast<std::size_t>(c - s)));
  return {};
}

std::string text_or_empty(const char* s) {
  return s ? s : "";
}

// `s` (which may be NULL), when it is UTF-8; std::invalid_argument naming `what` otherwise. What a table
// says is printed and written to records, which are JSON.
std::string utf8_text(const char* s, const std::string& what) {
  std::string t = text_or_empty(s);
  if (!is_valid_utf8(t)) throw std::invalid_argument(fmt::format("{} '{}' is not valid UTF-8", what, escape_utf8(t)));
  return t;
}

// One row of the plugin's table as a ParamSpec; throws std::invalid_argument saying what is wrong.
ParamSpec read_row(const growbench_param& r) {
  if (const std::string why = name_problem(r.name); !why.empty()) throw std::invalid_argument(why);
  ParamSpec s;
  s.name = r.name;
  s.unit = utf8_text(r.unit, "its unit");
  s.doc = utf8_text(r.doc, "its doc");
  const bool ranged = r.type == GROWBENCH_PARAM_INT || r.type == GROWBENCH_PARAM_REAL || r.type == GROWBENCH_PARAM_VEC3;
  if (ranged) {
    if (std::isnan(r.min) || std::isnan(r.max) || r.min > r.max)
      throw std::invalid_argument(fmt::format("its range [{}, {}] is empty or not a number", r.min, r.max));
    s.min = r.min;
    s.max = r.max;
  }
  auto in_range = [&](double v) {
    if (!std::isfinite(v) || v < r.min || v > r.max)
      throw std::invalid_argument(fmt::format("its default {} is not a finite value in [{}, {}]", v, r.min, r.max));
  };
  switch (r.type) {
    case GROWBENCH_PARAM_INT:
      s.type = ParamType::Int;
      in_range(static_cast<double>(r.default_value.integer));
      s.default_value = r.default_value.integer;
      break;
    case GROWBENCH_PARAM_REAL:
      s.type = ParamType::Real;
      in_range(r.default_value.real);
      s.default_value = r.default_value.real;
      break;
    case GROWBENCH_PARAM_BOOL:
      s.type = ParamType::Bool;
      if (r.default_value.boolean != 0 && r.default_value.boolean != 1)
        throw std::invalid_argument(fmt::format("its default {} is not 0 or 1", r.default_value.boolean));
      s.default_value = r.default_value.boolean == 1;
      break;
    case GROWBENCH_PARAM_STRING:
      s.type = ParamType::String;
      s.default_value = utf8_text(r.default_value.text, "its default");
      break;
    case GROWBENCH_PARAM_VEC3:
      s.type = ParamType::Vec3;
      for (double v : r.default_value.vec3) in_range(v);
      s.default_value = glm::dvec3(r.default_value.vec3[0], r.default_value.vec3[1], r.default_value.vec3[2]);
      break;
    case GROWBENCH_PARAM_CHOICE: {
      s.type = ParamType::Choice;
      if (r.choice_count == 0 || !r.choices) throw std::invalid_argument("a choice without choices");
      std::set<std::string> seen;
      for (std::uint32_t k = 0; k < r.choice_count; ++k) {
        if (!r.choices[k]) throw std::invalid_argument(fmt::format("choice {} is NULL", k));
        if (!*r.choices[k]) throw std::invalid_argument(fmt::format("choice {} is empty", k));
        (void)utf8_text(r.choices[k], fmt::format("choice {}", k));
        if (!seen.insert(r.choices[k]).second)
          throw std::invalid_argument(fmt::format("choice '{}' is listed twice", r.choices[k]));
        s.choices.emplace_back(r.choices[k]);
      }
      if (!r.default_value.text) throw std::invalid_argument("its default is NULL; expected one of its choices");
      const std::string d = r.default_value.text;
      if (!seen.count(d))
        throw std::invalid_argument(fmt::format("its default '{}' is not one of its choices", escape_utf8(d)));
      s.default_value = d;
      break;
    }
    default:
      throw std::invalid_argument(fmt::format("type {} is not a growbench_param_type", r.type));
  }
  return s;
}

// The table as ABI 1 first defined it, through `destroy`: members added later come after it, so a plugin
// built before them still loads (and the host reads no member beyond its struct_size).
constexpr std::size_t kTableSizeV1 = offsetof(growbench_plugin, destroy) + sizeof(growbench_plugin::destroy);

}  // namespace

AlgorithmInfo read_plugin_table(const std::string& path, const growbench_plugin& t) {
  auto bad = [&](const std::string& what) {
    return InputError(fmt::format("{}: malformed plugin table: {}", path, what));
  };
  if (t.struct_size < kTableSizeV1)
    throw bad(fmt::format("struct_size {} is smaller than ABI {}'s {}", t.struct_size, t.abi_version, kTableSizeV1));
  if (const std::string why = name_problem(t.name); !why.empty()) throw bad(why);
  if (!t.create || !t.start || !t.step || !t.finish || !t.plant || !t.destroy)
    throw bad("create, start, step, finish, plant and destroy must all be set");
  if (t.param_count > 0 && !t.params) throw bad(fmt::format("param_count is {} but params is NULL", t.param_count));
  if (t.test_param_count > 0 && !t.test_params)
    throw bad(fmt::format("test_param_count is {} but test_params is NULL", t.test_param_count));
  AlgorithmInfo info;
  info.name = t.name;
  try {
    info.summary = utf8_text(t.summary, "its summary");
    (void)utf8_text(t.version, "its version");
  } catch (const std::invalid_argument& e) {
    throw bad(e.what());
  }
  std::set<std::string> names;
  for (std::uint32_t i = 0; i < t.param_count; ++i) {
    const growbench_param& r = t.params[i];
    try {
      info.params.push_back(read_row(r));
    } catch (const std::invalid_argument& e) {
      throw bad(fmt::format("parameter {} ('{}'): {}", i, escape_utf8(text_or_empty(r.name)), e.what()));
    }
    if (!names.insert(info.params.back().name).second)
      throw bad(fmt::format("parameter {} ('{}') is declared twice", i, info.params.back().name));
  }
  Params check(fmt::format("plugin '{}'", info.name), info.params);
  for (std::uint32_t i = 0; i < t.test_param_count; ++i) {
    if (!t.test_params[i]) throw bad(fmt::format("test_params[{}] is NULL; expected key=value", i));
    const std::string a = t.test_params[i];
    try {
      check.set_assignment(a);
    } catch (const InputError& e) {
      throw bad(fmt::format("test_params[{}] '{}': {}", i, a, e.what()));
    }
    info.test_params.push_back(a);
  }
  return info;
}

namespace {

// An algorithm written in Python: the bridge module makes its table (algorithms/plugins/python/bridge.cpp).
// RTLD_GLOBAL: numpy's extension modules take the interpreter's symbols from the process.
const growbench_plugin* open_python(const std::string& path) {
  const std::string bridge = module_path("python_bridge.so");
  void* handle = dlopen(bridge.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (!handle) {
    const char* why = dlerror();
    throw InputError(fmt::format("{}: algorithms in Python need {}, which did not load ({})", path, bridge,
                                 why ? why : "dlopen failed"));
  }
  using Make = const growbench_plugin* (*)(const char*, char*, std::size_t);
  const auto make = reinterpret_cast<Make>(dlsym(handle, "growbench_python_plugin"));
  if (!make) throw InputError(fmt::format("{}: {} has no growbench_python_plugin()", path, bridge));
  std::array<char, 8192> why{};
  const growbench_plugin* t = make(path.c_str(), why.data(), why.size());
  if (!t) throw InputError(fmt::format("{}: {}", path, why.data()));
  return t;
}

bool is_python(const std::string& path) {
  return fs::path(path).extension() == ".py";
}

const growbench_plugin* open_plugin(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(fmt::format("{}: no such plugin file", path));
  if (fs::is_directory(path, ec)) throw InputError(fmt::format("{}: is a directory, not a plugin file", path));
  // dlopen would wait forever on a FIFO and read a device: a plugin is a file.
  if (!fs::is_regular_file(path, ec))
    throw InputError(
        fmt::format("{}: not a regular file (a FIFO, a device or a socket); expected a plugin's "
                    "shared library file",
                    path));
  if (is_python(path)) return open_python(path);
  // RTLD_LOCAL: one plugin's symbols never satisfy another's. Never closed (see loader.hpp).
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw InputError(fmt::format("{}: not a loadable shared library ({})", path, why ? why : "dlopen failed"));
  }
  dlerror();
  void* sym = dlsym(handle, GROWBENCH_PLUGIN_ENTRY_SYMBOL);
  if (!sym)
    throw InputError(fmt::format("{}: no {}() entry point; is it a growbench plugin? (see docs/plugins.md)", path,
                                 GROWBENCH_PLUGIN_ENTRY_SYMBOL));
  const auto entry = reinterpret_cast<growbench_plugin_entry_fn>(sym);
  const growbench_plugin* t = entry();
  if (!t) throw InputError(fmt::format("{}: {}() returned NULL", path, GROWBENCH_PLUGIN_ENTRY_SYMBOL));
  if (t->abi_version < GROWBENCH_PLUGIN_ABI_OLDEST || t->abi_version > GROWBENCH_PLUGIN_ABI_VERSION)
    throw InputError(
        fmt::format("{}: built for plugin ABI version {}, but this growbench speaks versions {} to {}; rebuild "
                    "it against this growbench's SDK",
                    path, t->abi_version, GROWBENCH_PLUGIN_ABI_OLDEST, GROWBENCH_PLUGIN_ABI_VERSION));
  return t;
}

// Loading runs the library's constructors and its entry(), code the host cannot vet: one that crashed,
// aborted or called exit() ended `list` (and `suite`, with exit 0 and no results). It is loaded first in a
// child, which reports what loading said; a child that ends any other way, or takes longer than
// kProbeSeconds, is an InputError naming the plugin. Then it is loaded here, as before.
constexpr int kProbeSeconds = 30;
void probe_in_child(const std::string& path) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return;  // cannot probe: the load below still checks the rest
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return;
  }
  if (pid == 0) {
    close(fds[0]);
    // A plugin's exit() here would run the exit handlers of libraries whose threads the fork did not
    // copy (and wait for them forever): handlers run in reverse order, so this one, registered after the
    // host's libraries' and before the plugin's, ends the child with the plugin's status before theirs.
    on_exit([](int status, void*) { _exit(status); }, nullptr);
    std::string said = "ok";
    try {
      (void)read_plugin_table(path, *open_plugin(path));
    } catch (const std::exception& e) {
      said = e.what();
    }
    const char* p = said.data();
    for (std::size_t left = said.size(); left > 0;) {
      const ssize_t w = write(fds[1], p, left);
      if (w <= 0) break;
      p += w;
      left -= static_cast<std::size_t>(w);
    }
    _exit(0);
  }
  close(fds[1]);
  std::string said;
  bool late = false;
  for (const auto t0 = std::chrono::steady_clock::now();;) {
    const auto left = std::chrono::seconds(kProbeSeconds) - (std::chrono::steady_clock::now() - t0);
    pollfd pfd{fds[0], POLLIN, 0};
    const int rc = poll(
        &pfd, 1,
        static_cast<int>(std::max<long long>(0, std::chrono::duration_cast<std::chrono::milliseconds>(left).count())));
    if (rc < 0 && errno == EINTR) continue;
    if (rc == 0) {
      late = true;
      kill(pid, SIGKILL);
      break;
    }
    char buf[4096];
    const ssize_t n = rc > 0 ? read(fds[0], buf, sizeof buf) : -1;
    if (n <= 0) break;  // EOF: the child has ended or closed its end
    said.append(buf, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  // A child that closed its end without ending (a constructor that closes every descriptor and then waits)
  // is given kProbeSeconds more to end, then killed.
  int status = 0;
  for (const auto t0 = std::chrono::steady_clock::now();;) {
    const pid_t w = waitpid(pid, &status, late ? 0 : WNOHANG);
    if (w == pid || (w < 0 && errno != EINTR)) break;
    if (w == 0 && std::chrono::steady_clock::now() - t0 > std::chrono::seconds(kProbeSeconds)) {
      late = true;
      kill(pid, SIGKILL);
    } else if (w == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  if (said == "ok") return;
  if (!late && WIFEXITED(status) && WEXITSTATUS(status) == 0 && !said.empty()) throw InputError(said);
  const std::string how =
      late ? fmt::format("did not return within {} s", kProbeSeconds)
      : WIFSIGNALED(status)
          ? fmt::format("ended the process with signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)))
          : fmt::format("ended the process with exit status {}", WEXITSTATUS(status));
  throw InputError(fmt::format("{}: loading it {} (in its constructors or {}()); a plugin must load and return", path,
                               how, GROWBENCH_PLUGIN_ENTRY_SYMBOL));
}

void check_name_free(const std::string& path, const std::string& name) {
  for (const auto& e : algorithm_registry())
    if (e.info().name == name)
      throw InputError(fmt::format("{}: plugin algorithm '{}' has the name of a built-in algorithm", path, name));
  for (const auto& l : loaded())
    if (l.info.name == name)
      throw InputError(
          fmt::format("{}: plugin algorithm '{}' has the name of the plugin loaded from {}", path, name, l.path));
}

}  // namespace

namespace {

std::string canonical_path(const std::string& given) {
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(given, ec), ec);
  return abs.empty() ? given : abs.string();
}

// Where the algorithm `info` read from table `t` came from, as records name it: load_plugin and
// describe_plugin must say the same of one file.
PluginOrigin origin_of(const std::string& path, const AlgorithmInfo& info, const growbench_plugin& t) {
  return PluginOrigin{info.name, path, file_hash(path), t.abi_version, text_or_empty(t.version)};
}

}  // namespace

const AlgorithmEntry& load_plugin(const std::string& given) {
  const std::string path = canonical_path(given);
  for (const auto& l : loaded())
    if (l.path == path) return l.entry;
  probe_in_child(path);
  const growbench_plugin* t = open_plugin(path);
  AlgorithmInfo info = read_plugin_table(path, *t);
  check_name_free(path, info.name);
  auto origin = std::make_shared<PluginOrigin>(origin_of(path, info, *t));
  Loaded& l = loaded().emplace_back(Loaded{path, std::move(info), {}});
  const AlgorithmInfo* ip = &l.info;
  l.entry = AlgorithmEntry{[ip]() -> const AlgorithmInfo& { return *ip; },
                           [t, ip, path]() { return make_plugin_algorithm(t, *ip, path); },
                           {},
                           std::move(origin)};
  return l.entry;
}

// The directories in GROWBENCH_PLUGIN_PATH hold whatever was put there; one bad file must not stop a command
// that never asked for it, so it is skipped, said on stderr. A plugin a command names (--plugin, a suite's
// "plugins") is an error instead.
namespace {
void warn_skipped(const std::string& why) {
  fmt::print(stderr, "growbench: warning: GROWBENCH_PLUGIN_PATH: skipped: {}\n", why);
}
}  // namespace

void load_plugins(const std::vector<std::string>& paths) {
  for (const auto& p : paths) load_plugin(p);
  const char* env = std::getenv("GROWBENCH_PLUGIN_PATH");
  if (!env) return;
  std::string list = env;
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t end = std::min(list.find(':', start), list.size());
    const std::string dir = list.substr(start, end - start);
    start = end + 1;
    if (dir.empty()) continue;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      warn_skipped(fmt::format("'{}' is not a directory", dir));
      continue;
    }
    std::vector<std::string> files;
    for (const auto& f : fs::directory_iterator(dir, ec))
      if (f.path().extension() == ".so") files.push_back(f.path().string());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) try {
        load_plugin(f);
      } catch (const InputError& e) {
        warn_skipped(e.what());
      }
  }
}

std::vector<const AlgorithmEntry*> plugin_algorithms() {
  std::vector<const AlgorithmEntry*> v;
  for (const auto& l : loaded()) v.push_back(&l.entry);
  return v;
}

PluginOrigin describe_plugin(const std::string& given) {
  const std::string path = canonical_path(given);
  for (const auto& l : loaded())
    if (l.path == path) return *l.entry.plugin;
  probe_in_child(path);
  const growbench_plugin* t = open_plugin(path);
  const AlgorithmInfo info = read_plugin_table(path, *t);
  return origin_of(path, info, *t);
}

std::vector<PluginOrigin> loaded_plugins() {
  std::vector<PluginOrigin> v;
  for (const auto& l : loaded()) v.push_back(*l.entry.plugin);
  return v;
}

}  // namespace growbench
