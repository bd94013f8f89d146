// Loading algorithm plugins (include/growbench/plugin.h): shared libraries that register one algorithm
// each beside the built-ins. A loaded plugin stays loaded until the process exits: its tables and any
// thread-local or TBB state it made must outlive every algorithm it created, and forked trials inherit
// it. Loading is for the command line to do before any work starts; it is not thread-safe.
#pragma once

#include <string>
#include <vector>

#include "algorithms/algorithm.hpp"
#include "growbench/plugin.h"

namespace growbench {

// Loads the plugin at `path` and registers its algorithm; loading the same file again returns the
// entry already registered. InputError naming the file when it is missing, is not a shared library,
// has no growbench_plugin_entry, speaks another ABI version, takes a name already taken, or has a
// malformed table.
// The plugin is first loaded in a child: one whose loading crashes, exits or hangs is an InputError
// here, not the end of the command.
const AlgorithmEntry& load_plugin(const std::string& path);
// The checks load_plugin makes of a plugin's table, on their own (for tests and fuzzing): its name,
// functions, parameter rows (names, types, ranges, finite defaults in range, choices, UTF-8 text, no
// duplicates) and test parameters. InputError "PATH: malformed plugin table: ..." naming the row.
AlgorithmInfo read_plugin_table(const std::string& path, const growbench_plugin& table);
// Loads `paths` in order, then every *.so in the directories GROWBENCH_PLUGIN_PATH names (separated
// by ':', each directory's files in name order). A file there that does not load, or an entry that is not a
// directory, is a warning on stderr naming it and why, and is skipped.
void load_plugins(const std::vector<std::string>& paths);
// The plugins' algorithms, in loading order.
std::vector<const AlgorithmEntry*> plugin_algorithms();
// Where the plugin at `path` comes from (its name, file hash, ABI and own version), read as load_plugin reads
// it but without registering it: for a plugin another process runs (ab's side B). Same errors.
PluginOrigin describe_plugin(const std::string& path);
// Where each loaded plugin came from, in loading order (what a run's context records).
std::vector<PluginOrigin> loaded_plugins();

}  // namespace growbench
