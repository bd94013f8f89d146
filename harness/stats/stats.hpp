// Statistics for comparing timings: the Mann-Whitney U test, a bootstrap interval for the ratio of
// medians, and how many repetitions a given noise level needs. Used by `growbench ab` (which runs both
// sides) and `growbench compare` (which reads two results files). Everything here is deterministic: the
// bootstrap draws from a fixed counter-based stream, so a reviewer gets the same verdict from the same
// samples.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace growbench {

double median_of(std::vector<double> v);

// A distribution-free 95% confidence interval for the median: the order statistics (x_(l), x_(n+1-l)) of
// the largest l whose binomial coverage is at least 95%. Below 6 samples no pair reaches it: the interval
// is then the full range and `exact` is false. NANs for an empty sample.
std::pair<double, double> median_interval(std::vector<double> v, bool& exact);

// A duration for a table: "645.8 us", "12.34 ms", "1.234 s" ("-" when not finite).
std::string format_seconds(double s);

// A coefficient of variation robust to the odd outlier (a trial that shared its core with a cron job):
// 1.4826 x the median absolute deviation over the median (the SD over the mean for normal data).
double robust_cv(const std::vector<double>& v);

struct MannWhitney {
  double u = 0.0;     // U of the first sample: pairs (a, b) with a > b, ties counted 1/2
  double p = 1.0;     // two-sided
  bool exact = true;  // exact null distribution (no ties, both sizes <= 40); else normal, tie-corrected
};
MannWhitney mann_whitney(const std::vector<double>& a, const std::vector<double>& b);

// The Wilcoxon signed-rank test of paired differences d (zeros dropped): two-sided p of a median 0.
struct SignedRank {
  double w_plus = 0.0;  // the sum of the ranks of |d| over the positive d
  double p = 1.0;
  bool exact = true;  // exact (no ties among |d|, n <= 40); else normal, tie-corrected
};
SignedRank wilcoxon_signed_rank(const std::vector<double>& d);

struct RatioInterval {
  double ratio = 1.0;         // median(b) / median(a)
  double lo = 1.0, hi = 1.0;  // percentile bootstrap interval
};
// Resamples a and b independently `resamples` times; level 0.95 gives the 2.5% and 97.5% percentiles.
RatioInterval median_ratio_interval(const std::vector<double>& a, const std::vector<double>& b, double level = 0.95,
                                    int resamples = 4000, std::uint64_t seed = 20170601);

// The same for paired samples: the median of b[i] / a[i], resampling the pairs.
RatioInterval paired_ratio_interval(const std::vector<double>& a, const std::vector<double>& b, double level = 0.95,
                                    int resamples = 4000, std::uint64_t seed = 20170601);

// Repetitions per side for a two-sided Mann-Whitney test at `alpha` to detect a ratio of `effect`
// between medians with probability `power`, when each side's (robust) coefficient of variation is `cv`
// (normal approximation on the log scale, divided by the test's 0.955 relative efficiency).
int repetitions_needed(double cv, double effect, double alpha = 0.01, double power = 0.8);

// The upper quantile z with P(Z > z) = q of the standard normal.
double normal_upper_quantile(double q);

struct TimingVerdict {
  // "slower" | "faster": p < alpha, the median ratio at least `effect` (or at most 1/effect), and its
  // interval excluding 1 -- by the Mann-Whitney test of the two samples, or (paired samples) by the
  // signed-rank test of the pairs' ratios. "no change": an interval inside (1/effect, effect).
  // "inconclusive": neither; `needed` says how many repetitions per side the observed noise calls for.
  std::string verdict;
  int n_a = 0, n_b = 0;
  double median_a = 0.0, median_b = 0.0, cv = 0.0;
  MannWhitney test;
  RatioInterval interval;
  bool paired = false;  // below: the pairs' log ratios, when a[i] and b[i] ran side by side
  SignedRank paired_test;
  RatioInterval paired_interval;
  double paired_cv = 0.0;  // robust spread of the pairs' ratios
  int needed = 0;
};
// `paired`: a[i] and b[i] were measured next to each other (growbench ab's alternating pairs), so drift
// of the machine that moves both cancels in their ratio; the unpaired test counts it as noise.
TimingVerdict judge_timings(const std::vector<double>& a, const std::vector<double>& b, double effect = 1.03,
                            double alpha = 0.01, bool paired = false);

}  // namespace growbench
