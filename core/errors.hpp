#pragma once

#include <new>
#include <stdexcept>
#include <string>

#include "core/utf8.hpp"

namespace growbench {

// An error in user input (scene file, mesh, parameter, grammar, suite). The message names the source
// (file, JSON path, line/column or key) and what was expected; the CLI prints it and exits with status 2.
// The message is kept valid UTF-8 (escape_utf8), since it may quote input and is written to journals.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(escape_utf8(what)) {}
  explicit InputError(const char* what) : InputError(std::string(what)) {}
};

// A plugin algorithm failed on its own account: it returned an error, or handed over a plant the host
// refuses (a parent out of order, a coordinate that is not finite, an organ turned by a non-unit
// quaternion). Not growbench's bug and not the scene's fault: the CLI names the plugin and exits with 2,
// a suite records `plugin_error`.
class PluginError : public std::runtime_error {
 public:
  explicit PluginError(const std::string& what) : std::runtime_error(escape_utf8(what)) {}
};

// Memory ran out, or would: an allocation failed in a library, or a size estimated before building
// exceeds what the process may use. A std::bad_alloc, so every handler of allocation failure counts it
// as out_of_memory, but with a message saying what needed the memory.
class OutOfMemoryError : public std::bad_alloc {
 public:
  explicit OutOfMemoryError(const std::string& what) : what_(escape_utf8(what)) {}
  [[nodiscard]] const char* what() const noexcept override { return what_.what(); }

 private:
  std::runtime_error what_;  // its copy cannot throw, as an exception's must not
};

}  // namespace growbench
