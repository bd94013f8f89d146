// Where a plugin algorithm came from, as the loader (algorithms/plugins/loader.hpp) found it and a run's
// record names it: a result says exactly what ran.
#pragma once

#include <cstdint>
#include <string>

namespace growbench {

struct PluginOrigin {
  std::string name;  // the algorithm's
  std::string path;  // absolute
  std::string hash;  // XXH3 (64 bits) of the file, 16 hex digits
  std::uint32_t abi_version = 0;
  std::string version;  // the plugin's own
};

}  // namespace growbench
