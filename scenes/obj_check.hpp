// Checks the numbers of an OBJ file before tinyobjloader reads it. tinyobjloader (2.0.0rc10, Debian's)
// reads a coordinate it cannot parse, or one that is missing, as 0 and an index with atoi, and reports
// neither; this pass over the same lines (split as tinyobjloader splits them) refuses what it would
// misread, naming FILE:LINE.
#pragma once

#include <string>
#include <string_view>

namespace growbench {

// InputError "PATH:LINE: ..." for the first `v`, `vt`, `vn` or `f` line tinyobjloader would misread:
// a coordinate that is not a finite number (nan, inf, 1e400, junk), a vertex with fewer than three, a
// face with fewer than three corners, or an index that is not an integer, is 0, or names a vertex,
// texture coordinate or normal not defined before the line.
void check_obj_text(const std::string& path, std::string_view text);

}  // namespace growbench
