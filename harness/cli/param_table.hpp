// A parameter table as `growbench list` and `growbench scenes` print it, and as Markdown for the
// algorithms' READMEs (`growbench list --markdown NAME`, filled in by scripts/readme-params).
#pragma once

#include <string>
#include <vector>

#include "core/params.hpp"

namespace growbench::cli {

void print_param_table(const std::vector<ParamSpec>& specs);

// One row per parameter: name, type, default, allowed range or choices, unit, doc.
std::string param_table_markdown(const std::vector<ParamSpec>& specs);

// `text` as inline code, whatever backticks it holds, safe in a table cell.
std::string markdown_code(const std::string& text);
// Text as literal Markdown (what could start code, emphasis, a link or HTML escaped), on one line.
std::string markdown_text(const std::string& text);

}  // namespace growbench::cli
