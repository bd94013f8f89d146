// Where the binary finds the data it reads (bundled meshes, example grammars, the report script): in
// the checkout it was built from while that is still there, otherwise in the share/growbench/ an
// installed binary has beside it (cmake/install.cmake keeps the checkout's layout there).
#pragma once

#include <string>
#include <string_view>

namespace growbench {

// `relative` is a path in the checkout, e.g. "scenes/meshes".
std::string data_path(std::string_view relative);

// A module the binary loads at run time (plugins/python_bridge.so): in the build tree's plugins/ while
// running from it, otherwise in the lib/growbench/ beside the installed binary.
std::string module_path(std::string_view name);

// Whether this binary runs from the build tree it was built in (not an installed copy).
bool running_from_build_tree();

}  // namespace growbench
