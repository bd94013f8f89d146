// Content hashes of files: what identifies a binary or a plugin in a record, whatever its name or date.
#pragma once

#include <string>

namespace growbench {

// XXH3 (64 bits) of the file's bytes as 16 hex digits; "unknown" when it cannot be read.
std::string file_hash(const std::string& path);

}  // namespace growbench
