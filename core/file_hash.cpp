#include "core/file_hash.hpp"

#include <fstream>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <xxhash.h>

namespace growbench {

std::string file_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "unknown";
  const std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> st(XXH3_createState(), &XXH3_freeState);
  XXH3_64bits_reset(st.get());
  std::vector<char> buf(1 << 16);
  while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0)
    XXH3_64bits_update(st.get(), buf.data(), static_cast<std::size_t>(in.gcount()));
  return in.bad() ? std::string("unknown") : fmt::format("{:016x}", XXH3_64bits_digest(st.get()));
}

}  // namespace growbench
