#include "core/random.hpp"

#include <gtest/gtest.h>

namespace growbench {
namespace {

TEST(Random, PureFunctionOfSeedStreamIndex) {
  Rng a(7, 3), b(7, 3), c(7, 4), d(8, 3);
  for (int i = 0; i < 100; ++i) {
    const auto x = a.next_u64();
    EXPECT_EQ(x, b.next_u64());
    EXPECT_NE(x, c.next_u64());
    EXPECT_NE(x, d.next_u64());
  }
  Rng skip(7, 3, 50), ref(7, 3);
  for (int i = 0; i < 50; ++i) ref.next_u64();
  EXPECT_EQ(skip.next_u64(), ref.next_u64());
}

TEST(Random, UniformAndUnitVectorStatistics) {
  Rng r(1, 1);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  glm::dvec3 mean(0.0);
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
    const glm::vec3 v = r.unit_vector();
    ASSERT_NEAR(glm::length(v), 1.0f, 1e-5f);
    mean += glm::dvec3(v);
  }
  // Mean 1/2 and variance 1/12: 6 standard errors.
  EXPECT_NEAR(sum / n, 0.5, 6 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 2e-3);
  EXPECT_LT(glm::length(mean / double(n)), 6 * std::sqrt(1.0 / 3.0 / n) * 1.8);
}

}  // namespace
}  // namespace growbench
