// The seed's acceleration grid (after Worley's cellular texturing): space cut into cubes at least the
// reach of a query wide, so a query looks at its own cell and the neighbouring ones only. Cells are
// found through an open-addressing hash table, since the vines occupy a thin surface of the space the
// grid spans (a dense array would be mostly empty).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace growbench::vines {

class CellTable {
 public:
  static constexpr std::int32_t kEmpty = -1;

  explicit CellTable(float cell) : inv_cell_(1.0f / cell) { rehash(1024); }

  [[nodiscard]] glm::ivec3 cell_of(const glm::vec3& p) const { return glm::ivec3(glm::floor(p * inv_cell_)); }
  // Cell coordinates in 21 bits each (offset to be non-negative), with the top bit set so that no key
  // is zero, the empty slot's mark.
  static std::uint64_t key(const glm::ivec3& c) {
    constexpr std::int64_t kOffset = 1 << 20;
    auto part = [](int v) { return static_cast<std::uint64_t>(static_cast<std::int64_t>(v) + kOffset) & 0x1FFFFFu; };
    return (1ull << 63) | (part(c.x) << 42) | (part(c.y) << 21) | part(c.z);
  }
  [[nodiscard]] std::int32_t find(std::uint64_t k) const {
    for (std::size_t i = slot(k);; i = (i + 1) & mask_) {
      if (keys_[i] == k) return values_[i];
      if (keys_[i] == 0) return kEmpty;
    }
  }
  // The value of cell k, inserted as kEmpty when new.
  std::int32_t& at(std::uint64_t k) {
    if (2 * (size_ + 1) > keys_.size()) rehash(2 * keys_.size());
    std::size_t i = slot(k);
    for (; keys_[i] != 0; i = (i + 1) & mask_)
      if (keys_[i] == k) return values_[i];
    keys_[i] = k;
    ++size_;
    return values_[i] = kEmpty;
  }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  [[nodiscard]] std::size_t slot(std::uint64_t k) const {
    k ^= k >> 33;
    k *= 0xFF51AFD7ED558CCDull;
    k ^= k >> 33;
    return static_cast<std::size_t>(k) & mask_;
  }
  void rehash(std::size_t capacity) {
    std::vector<std::uint64_t> keys(capacity, 0);
    std::vector<std::int32_t> values(capacity, kEmpty);
    keys.swap(keys_);
    values.swap(values_);
    mask_ = capacity - 1;
    size_ = 0;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (keys[i] != 0) at(keys[i]) = values[i];
  }

  float inv_cell_;
  std::vector<std::uint64_t> keys_;
  std::vector<std::int32_t> values_;
  std::size_t mask_ = 0, size_ = 0;
};

}  // namespace growbench::vines
