// The L-system expression compiler, on one expression as a rule's condition, argument or probability
// holds it, with the formals and user variables a rule might have; an expression that compiles is then
// evaluated. A compile error must point into the text (its offset becomes the message's column).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/lsystem/expr.hpp"
#include "fuzz/fuzz_util.hpp"

namespace {

// The host calls as plain functions of their arguments (the real host asks the scene and an image).
class Host : public growbench::lsys::ExprHost {
 public:
  double in(double x, double y, double z) const override { return x + y + z > 0.0 ? 1.0 : 0.0; }
  double pic(double u, double v, double plane) const override { return u * v + plane; }
  double rand(double seed) const override { return seed * 0.5; }
  double chan(double index) const override { return index; }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace growbench::lsys;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  static const std::vector<std::string> formals = {"n", "len", "w2"};
  static const std::vector<std::string> users = {"k", "q"};
  Expr expr;
  ExprError error;
  growbench::fuzz::expect_input_errors([&] {
    if (!ExprCompiler::compile(text, ExprScope{&formals, &users}, expr, error)) {
      if (error.offset > text.size()) {
        std::fprintf(stderr, "expr_fuzz: error offset %zu past the text's %zu bytes: %s\n", error.offset, text.size(),
                     error.message.c_str());
        std::abort();
      }
      return;
    }
    std::array<double, kMaxSlots> env{};
    for (std::size_t i = 0; i < env.size(); ++i) env[i] = 0.25 * static_cast<double>(i) - 3.0;
    (void)expr.eval(env.data(), Host());
  });
  return 0;
}
