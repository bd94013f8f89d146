#pragma once

#include <stdexcept>

namespace growbench {

// An error in user input (scene file, mesh, parameter, grammar, suite). The message names the source
// (file, JSON path, line/column or key) and what was expected; the CLI prints it and exits with status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace growbench
