// The statistics behind the statistical gate, against values worked out by hand.
#include "harness/stats/stats.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/random.hpp"

namespace growbench {
namespace {

TEST(Stats, MannWhitneyExactTails) {
  // Completely separated samples: only 1 of the C(n+m, n) arrangements is this extreme on each side.
  const MannWhitney three = mann_whitney({1, 2, 3}, {4, 5, 6});
  EXPECT_TRUE(three.exact);
  EXPECT_EQ(three.u, 0.0);
  EXPECT_NEAR(three.p, 2.0 / 20.0, 1e-12);
  EXPECT_NEAR(mann_whitney({6, 7, 8, 9, 10}, {1, 2, 3, 4, 5}).p, 2.0 / 252.0, 1e-12);
  EXPECT_EQ(mann_whitney({6, 7, 8, 9, 10}, {1, 2, 3, 4, 5}).u, 25.0);
  std::vector<double> a, b;
  for (int i = 0; i < 10; ++i) a.push_back(i), b.push_back(100 + i);
  EXPECT_NEAR(mann_whitney(a, b).p, 2.0 / 184756.0, 1e-15);
  // One swap: U = 1; P(U <= 1) = 2 / C(10, 5) (U = 0 and U = 1 each have one arrangement).
  EXPECT_NEAR(mann_whitney({1, 2, 3, 4, 6}, {5, 7, 8, 9, 10}).p, 4.0 / 252.0, 1e-12);
  // Interleaved: U = 6 of 16; the counts of U = 0..6 among the 70 arrangements are 1 1 2 3 5 5 7.
  EXPECT_NEAR(mann_whitney({1, 3, 5, 7}, {2, 4, 6, 8}).p, 2.0 * 24.0 / 70.0, 1e-12);
}

TEST(Stats, MannWhitneyWithTiesUsesTheCorrectedNormal) {
  const MannWhitney t = mann_whitney({1, 2, 2, 3, 3, 3}, {3, 4, 4, 5, 5, 6});
  EXPECT_FALSE(t.exact);
  // U of the first: nothing beats a 3 or more, and its three 3s tie the other's one 3: 1.5. Mean
  // 36 / 2 = 18. Tied groups of 2 (value 2), 4 (value 3), 2 (value 4) and 2 (value 5) give
  // sum t^3 - t = 78, so the variance is 36 / 12 (13 - 78 / 132); z is continuity-corrected.
  EXPECT_NEAR(t.u, 1.5, 1e-12);
  const double z = (18.0 - 1.5 - 0.5) / std::sqrt(3.0 * (13.0 - 78.0 / 132.0));
  EXPECT_NEAR(t.p, std::erfc(z / std::sqrt(2.0)), 1e-12);
  EXPECT_NEAR(mann_whitney({2, 2, 2}, {2, 2, 2}).p, 1.0, 1e-12);
}

TEST(Stats, SignedRankExactTails) {
  // All five positive: W+ = 15, reached by 1 of the 2^5 sign patterns.
  EXPECT_NEAR(wilcoxon_signed_rank({1, 2, 3, 4, 5}).p, 2.0 / 32.0, 1e-12);
  EXPECT_EQ(wilcoxon_signed_rank({1, 2, 3, 4, 5}).w_plus, 15.0);
  EXPECT_NEAR(wilcoxon_signed_rank({0.0, 1, 2, 3, 4, 5}).p, 2.0 / 32.0, 1e-12) << "zeros are dropped";
  EXPECT_NEAR(wilcoxon_signed_rank({1, 2, 3, 4, 5, 6, 7, 8}).p, 2.0 / 256.0, 1e-12);
  // The smallest negative: W+ = 14; W+ >= 14 for 2 of 32 patterns.
  EXPECT_NEAR(wilcoxon_signed_rank({-1, 2, 3, 4, 5}).p, 4.0 / 32.0, 1e-12);
  EXPECT_NEAR(wilcoxon_signed_rank({-5, -4, -3, -2, -1}).p, 2.0 / 32.0, 1e-12);
  EXPECT_TRUE(wilcoxon_signed_rank({-5, -4, -3, -2, -1}).exact);
  EXPECT_FALSE(wilcoxon_signed_rank({1, 1, 2, 3}).exact);
}

TEST(Stats, PairsSeeThroughDrift) {
  // The machine slows by half over twelve rounds; B is 5% slower than A in every round.
  Rng rng(5, 3);
  std::vector<double> a, b, a2;
  for (int i = 0; i < 12; ++i) {
    const double drift = 1.0 + 0.5 * i / 11.0;
    a.push_back(drift * (1.0 + 0.005 * rng.uniform(-1.0, 1.0)));
    b.push_back(1.05 * drift * (1.0 + 0.005 * rng.uniform(-1.0, 1.0)));
    a2.push_back(drift * (1.0 + 0.005 * rng.uniform(-1.0, 1.0)));
  }
  const TimingVerdict unpaired = judge_timings(a, b, 1.03, 0.01, false);
  EXPECT_EQ(unpaired.verdict, "inconclusive") << "the drift swamps the unpaired comparison";
  const TimingVerdict paired = judge_timings(a, b, 1.03, 0.01, true);
  EXPECT_EQ(paired.verdict, "slower");
  EXPECT_NEAR(paired.paired_interval.ratio, 1.05, 0.01);
  EXPECT_NEAR(paired.paired_test.p, 2.0 / 4096.0, 1e-12);  // all twelve pairs slower
  EXPECT_EQ(judge_timings(a, a2, 1.03, 0.01, true).verdict, "no change");
}

TEST(Stats, NormalQuantileAndRepetitions) {
  EXPECT_NEAR(normal_upper_quantile(0.005), 2.5758293, 1e-6);
  EXPECT_NEAR(normal_upper_quantile(0.2), 0.8416212, 1e-6);
  // 2 (2.5758 + 0.8416)^2 0.02^2 / ln(1.03)^2 / 0.955 = 11.19 -> 12 per side.
  EXPECT_EQ(repetitions_needed(0.02, 1.03, 0.01, 0.8), 12);
  // Four times the noise, sixteen times the repetitions (to rounding).
  EXPECT_NEAR(repetitions_needed(0.08, 1.03, 0.01, 0.8), 179, 1);
  EXPECT_EQ(repetitions_needed(0.0, 1.03), 3);
}

TEST(Stats, MedianRatioIntervalCoversTheTrueRatio) {
  Rng rng(7, 1);
  std::vector<double> a, b;
  for (int i = 0; i < 25; ++i) {
    a.push_back(100.0 * (1.0 + 0.01 * rng.uniform(-1.0, 1.0)));
    b.push_back(110.0 * (1.0 + 0.01 * rng.uniform(-1.0, 1.0)));
  }
  const RatioInterval r = median_ratio_interval(a, b);
  EXPECT_NEAR(r.ratio, 1.10, 0.01);
  EXPECT_LT(r.lo, r.ratio);
  EXPECT_GT(r.hi, r.ratio);
  EXPECT_GT(r.lo, 1.07);
  EXPECT_LT(r.hi, 1.13);
  // The same samples give the same interval: a reviewer can recompute a verdict.
  const RatioInterval again = median_ratio_interval(a, b);
  EXPECT_EQ(r.lo, again.lo);
  EXPECT_EQ(r.hi, again.hi);
  EXPECT_DOUBLE_EQ(median_of({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median_of({4, 1, 3, 2}), 2.5);
  // Median 3, absolute deviations 2 1 0 1 97: MAD 1, whatever the outlier.
  EXPECT_NEAR(robust_cv({1, 2, 3, 4, 100}), 1.4826 / 3.0, 1e-12);
}

// The interval that results.json carries for every cell, and reports/report.py shows.
TEST(Stats, MedianIntervalFromOrderStatistics) {
  bool exact = false;
  // n = 10: (x_(2), x_(9)) covers 1 - 2 * 11/1024 = 97.9%; (x_(3), x_(8)) only 89%.
  EXPECT_EQ(median_interval({10, 9, 8, 7, 6, 5, 4, 3, 2, 1}, exact), std::make_pair(2.0, 9.0));
  EXPECT_TRUE(exact);
  // n = 6 is the smallest with a 95% pair: (x_(1), x_(6)) covers 1 - 2/64 = 96.9%.
  EXPECT_EQ(median_interval({5, 1, 4, 2, 6, 3}, exact), std::make_pair(1.0, 6.0));
  EXPECT_TRUE(exact);
  // n = 5: no pair reaches 95%, the full range, marked inexact.
  EXPECT_EQ(median_interval({5, 1, 4, 2, 3}, exact), std::make_pair(1.0, 5.0));
  EXPECT_FALSE(exact);
}

TEST(Stats, VerdictsSlowerNoChangeAndInconclusive) {
  Rng rng(11, 2);
  auto sample = [&](double centre, double noise, int n) {
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(centre * (1.0 + noise * rng.uniform(-1.0, 1.0)));
    return v;
  };
  const std::vector<double> base = sample(1.0, 0.01, 15);
  EXPECT_EQ(judge_timings(base, sample(1.05, 0.01, 15)).verdict, "slower");
  EXPECT_EQ(judge_timings(base, sample(0.95, 0.01, 15)).verdict, "faster");
  EXPECT_EQ(judge_timings(base, sample(1.0, 0.01, 15)).verdict, "no change");
  // 30% noise cannot show a 3% effect in 6 repetitions, nor rule it out.
  const TimingVerdict noisy = judge_timings(sample(1.0, 0.3, 6), sample(1.0, 0.3, 6));
  EXPECT_EQ(noisy.verdict, "inconclusive");
  EXPECT_GT(noisy.needed, 30);
  // Significant but below the effect asked for: not flagged.
  const TimingVerdict small = judge_timings(sample(1.0, 0.001, 20), sample(1.01, 0.001, 20));
  EXPECT_LT(small.test.p, 0.01);
  EXPECT_NE(small.verdict, "slower");
}

}  // namespace
}  // namespace growbench
