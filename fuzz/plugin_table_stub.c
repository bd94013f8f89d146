/* The plugin the plugin-table fuzz target loads: its entry point returns whatever table the target gave
 * it last, so that each input reaches the loader through dlopen and growbench_plugin_entry, as a real
 * plugin's table does. */
#include "growbench/plugin.h"

static const growbench_plugin* table;

GROWBENCH_PLUGIN_EXPORT void growbench_fuzz_set_table(const growbench_plugin* t) {
  table = t;
}

GROWBENCH_PLUGIN_EXPORT const growbench_plugin* growbench_plugin_entry(void) {
  return table;
}
