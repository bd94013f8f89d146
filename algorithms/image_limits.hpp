// The largest image an algorithm reads as input (a vines mask, an L-system's pic() image), on each side.
// An image's file can be tiny and its pixels vast (a 27 KB PNG of 15000 x 15000 decoded to gigabytes), so
// the size is checked from the header, before decoding. No lookup an algorithm makes needs more.
#pragma once

namespace growbench {

inline constexpr int kMaxImageSide = 16384;

}  // namespace growbench
