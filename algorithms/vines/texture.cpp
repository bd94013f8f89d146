// Placeholder: the drawing is being written (see texture.hpp for the contract).
#include "algorithms/vines/texture.hpp"

#include <stdexcept>

namespace growbench::vines {

Image draw_texture(const std::vector<Stroke>&, const std::vector<LeafStamp>&, const DrawOptions& o) {
  Image im;
  im.width = im.height = o.size;
  im.rgba.assign(static_cast<std::size_t>(o.size) * static_cast<std::size_t>(o.size) * 4, 0);
  return im;
}
Image normal_map(const Image& t, float) {
  return t;
}
std::uint64_t write_png(const std::string&, const Image&) {
  throw std::runtime_error("write_png: not yet written");
}
std::uint64_t write_svg(const std::string&, const std::vector<Stroke>&, const std::vector<LeafStamp>&,
                        const DrawOptions&) {
  throw std::runtime_error("write_svg: not yet written");
}

}  // namespace growbench::vines
