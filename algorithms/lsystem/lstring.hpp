// The derived string: one 16-bit word per module (ASCII symbol, parameter count, "new in the last
// generation" flag) and the parameters of all modules, in order, in a separate float array. A plain
// symbol costs 2 bytes; while rewriting, input and output together cost 4 bytes per plain symbol.
// A module's parameters start where the previous module's end, so walking left or right from a
// module whose parameter offset is known keeps the offset without any index.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace growbench::lsys {

constexpr std::uint16_t kSymbolMask = 0x7f;
constexpr int kCountShift = 7;
constexpr std::uint16_t kNewFlag = 1u << 10;

constexpr std::uint16_t encode(char symbol, int count) {
  return static_cast<std::uint16_t>((static_cast<unsigned>(symbol) & kSymbolMask) |
                                    (static_cast<unsigned>(count) << kCountShift));
}
constexpr char symbol_of(std::uint16_t w) {
  return static_cast<char>(w & kSymbolMask);
}
constexpr int count_of(std::uint16_t w) {
  return (w >> kCountShift) & 7;
}
constexpr bool is_new(std::uint16_t w) {
  return (w & kNewFlag) != 0;
}

namespace detail {
// Memory for a Buffer. A generation writes its whole output into fresh memory, so the first touch of
// every page (a page fault, and the kernel zeroing the page) is a large share of a plain rewrite.
// Blocks of a huge page or more are aligned to it and marked for transparent huge pages, which take
// one fault per huge page instead of one per base page.
void* allocate_buffer(std::size_t bytes);
struct FreeBuffer {
  void operator()(void* p) const;
};
}  // namespace detail

// A growable array of trivially copyable values that does not zero what it allocates (the writers
// fill every element), so a generation's output costs one pass of writes, not two.
template <class T>
class Buffer {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] std::size_t capacity() const { return capacity_; }
  [[nodiscard]] T* data() { return data_.get(); }
  [[nodiscard]] const T* data() const { return data_.get(); }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  // Resizes without preserving or initialising contents.
  void resize_discard(std::size_t n) {
    if (n > capacity_) {
      data_.reset();
      data_.reset(static_cast<T*>(detail::allocate_buffer(n * sizeof(T))));
      capacity_ = n;
    }
    size_ = n;
  }
  void assign(const std::vector<T>& v) {
    resize_discard(v.size());
    if (!v.empty()) std::memcpy(data_.get(), v.data(), v.size() * sizeof(T));
  }
  void release() {
    data_.reset();
    size_ = capacity_ = 0;
  }
  [[nodiscard]] std::size_t bytes() const { return capacity_ * sizeof(T); }

 private:
  std::unique_ptr<T[], detail::FreeBuffer> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

struct LString {
  Buffer<std::uint16_t> symbols;
  Buffer<float> params;
  Buffer<std::uint16_t> ages;  // generations since each module was produced (only when a rule reads g)

  [[nodiscard]] std::size_t size() const { return symbols.size(); }
  [[nodiscard]] std::size_t bytes() const { return symbols.bytes() + params.bytes() + ages.bytes(); }
};

// The string as text, e.g. "F(1,0.5)[+A]"; `limit` caps the modules printed (0: all).
std::string to_text(const LString& s, const std::vector<std::string>& strings, std::size_t limit = 0);

}  // namespace growbench::lsys
