#include "harness/stats/stats.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/random.hpp"

namespace growbench {

std::pair<double, double> median_interval(std::vector<double> v, bool& exact) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  exact = false;
  if (n == 0) return {NAN, NAN};
  // P(l <= B(n, 1/2) <= n - l) for l = 1, 2, ...
  auto coverage = [&](std::size_t l) {
    double p = 0.0;
    for (std::size_t k = l; k + l <= n; ++k)
      p += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) - n * std::log(2.0));
    return p;
  };
  std::size_t best = 0;
  for (std::size_t l = 1; 2 * l <= n; ++l)
    if (coverage(l) >= 0.95) best = l;
  if (best == 0) return {v.front(), v.back()};
  exact = true;
  return {v[best - 1], v[n - best]};
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  const double hi = v[m];
  if (v.size() % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m)));
}

std::string format_seconds(double s) {
  if (!std::isfinite(s)) return "-";
  const double a = std::abs(s);
  return a >= 1.0    ? fmt::format("{:.3f} s", s)
         : a >= 1e-3 ? fmt::format("{:.2f} ms", s * 1e3)
                     : fmt::format("{:.1f} us", s * 1e6);
}

double robust_cv(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = median_of(v);
  std::vector<double> dev;
  for (const double x : v) dev.push_back(std::abs(x - m));
  return m != 0.0 ? 1.4826 * median_of(dev) / std::abs(m) : 0.0;
}

namespace {

double normal_upper_tail(double z) {
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// P(U <= u) under the null for sizes n and m without ties: the number of arrangements with a given U
// satisfies c(n, m, u) = c(n - 1, m, u - m) + c(n, m - 1, u); kept as probabilities, built row by row.
std::vector<double> exact_u_distribution(int n, int m) {
  // p[i][j] is the distribution of U for sizes (i, j), a vector over u = 0..i*j.
  std::vector<std::vector<std::vector<double>>> p(static_cast<std::size_t>(n + 1),
                                                  std::vector<std::vector<double>>(static_cast<std::size_t>(m + 1)));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j) {
      auto& d = p[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      d.assign(static_cast<std::size_t>(i * j + 1), 0.0);
      if (i == 0 || j == 0) {
        d[0] = 1.0;
        continue;
      }
      // The largest of all i + j values is from the first sample with probability i / (i + j): it then
      // beats all j of the second sample.
      const double wa = static_cast<double>(i) / (i + j), wb = static_cast<double>(j) / (i + j);
      const auto& da = p[static_cast<std::size_t>(i - 1)][static_cast<std::size_t>(j)];
      const auto& db = p[static_cast<std::size_t>(i)][static_cast<std::size_t>(j - 1)];
      for (std::size_t u = 0; u < da.size(); ++u) d[u + static_cast<std::size_t>(j)] += wa * da[u];
      for (std::size_t u = 0; u < db.size(); ++u) d[u] += wb * db[u];
    }
  return p[static_cast<std::size_t>(n)][static_cast<std::size_t>(m)];
}

// The central `level` interval of bootstrap replicates (linear interpolation between order statistics).
void percentile_interval(std::vector<double>& replicates, double level, RatioInterval& r) {
  std::sort(replicates.begin(), replicates.end());
  auto at = [&](double q) {
    const double pos = q * static_cast<double>(replicates.size() - 1);
    const auto i = static_cast<std::size_t>(pos);
    const double f = pos - static_cast<double>(i);
    return i + 1 < replicates.size() ? replicates[i] * (1.0 - f) + replicates[i + 1] * f : replicates[i];
  };
  const double tail = (1.0 - level) / 2.0;
  r.lo = at(tail);
  r.hi = at(1.0 - tail);
}

}  // namespace

double normal_upper_quantile(double q) {
  double lo = -40.0, hi = 40.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (normal_upper_tail(mid) > q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

MannWhitney mann_whitney(const std::vector<double>& a, const std::vector<double>& b) {
  MannWhitney r;
  const std::size_t n = a.size(), m = b.size();
  if (n == 0 || m == 0) return r;
  // Ranks of the pooled sample, ties sharing their mean rank.
  std::vector<std::pair<double, int>> all;
  for (const double x : a) all.push_back({x, 0});
  for (const double x : b) all.push_back({x, 1});
  std::sort(all.begin(), all.end());
  double rank_sum_a = 0.0, tie_term = 0.0;
  bool ties = false;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i;
    while (j < all.size() && all[j].first == all[i].first) ++j;
    const double t = static_cast<double>(j - i), mean_rank = 0.5 * static_cast<double>(i + 1 + j);
    if (t > 1) {
      ties = true;
      tie_term += t * t * t - t;
    }
    for (std::size_t k = i; k < j; ++k)
      if (all[k].second == 0) rank_sum_a += mean_rank;
    i = j;
  }
  const double dn = static_cast<double>(n), dm = static_cast<double>(m);
  r.u = rank_sum_a - dn * (dn + 1.0) / 2.0;
  if (!ties && n <= 40 && m <= 40) {
    r.exact = true;
    const std::vector<double> dist = exact_u_distribution(static_cast<int>(n), static_cast<int>(m));
    const auto u = static_cast<std::size_t>(std::llround(r.u));
    double below = 0.0, above = 0.0;
    for (std::size_t k = 0; k <= u; ++k) below += dist[k];
    for (std::size_t k = u; k < dist.size(); ++k) above += dist[k];
    r.p = std::min(1.0, 2.0 * std::min(below, above));
    return r;
  }
  r.exact = false;
  const double mean = dn * dm / 2.0, big_n = dn + dm;
  const double var = dn * dm / 12.0 * ((big_n + 1.0) - tie_term / (big_n * (big_n - 1.0)));
  if (var <= 0.0) {
    r.p = 1.0;
    return r;
  }
  const double z = std::max(0.0, std::abs(r.u - mean) - 0.5) / std::sqrt(var);  // continuity-corrected
  r.p = std::min(1.0, 2.0 * normal_upper_tail(z));
  return r;
}

SignedRank wilcoxon_signed_rank(const std::vector<double>& d_in) {
  SignedRank r;
  std::vector<double> d;
  for (const double x : d_in)
    if (x != 0.0) d.push_back(x);
  const std::size_t n = d.size();
  if (n == 0) return r;
  std::vector<std::pair<double, bool>> mag;  // |d|, positive
  for (const double x : d) mag.push_back({std::abs(x), x > 0.0});
  std::sort(mag.begin(), mag.end());
  double tie_term = 0.0;
  bool ties = false;
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j < n && mag[j].first == mag[i].first) ++j;
    const double t = static_cast<double>(j - i), rank = 0.5 * static_cast<double>(i + 1 + j);
    if (t > 1) {
      ties = true;
      tie_term += t * t * t - t;
    }
    for (std::size_t k = i; k < j; ++k)
      if (mag[k].second) r.w_plus += rank;
    i = j;
  }
  const double dn = static_cast<double>(n);
  if (!ties && n <= 40) {
    // Under the null each rank's sign is a fair coin: W+ is the sum of a random subset of 1..n.
    const std::size_t max_w = n * (n + 1) / 2;
    std::vector<double> exact(max_w + 1, 0.0);
    exact[0] = 1.0;
    for (std::size_t k = 1; k <= n; ++k) {
      std::vector<double> next(max_w + 1, 0.0);
      for (std::size_t w = 0; w + k <= max_w; ++w) {
        next[w] += 0.5 * exact[w];
        next[w + k] += 0.5 * exact[w];
      }
      exact.swap(next);
    }
    const auto w = static_cast<std::size_t>(std::llround(r.w_plus));
    double below = 0.0, above = 0.0;
    for (std::size_t k = 0; k <= w; ++k) below += exact[k];
    for (std::size_t k = w; k <= max_w; ++k) above += exact[k];
    r.p = std::min(1.0, 2.0 * std::min(below, above));
    return r;
  }
  r.exact = false;
  const double mean = dn * (dn + 1.0) / 4.0;
  const double var = dn * (dn + 1.0) * (2.0 * dn + 1.0) / 24.0 - tie_term / 48.0;
  if (var <= 0.0) return r;
  const double z = std::max(0.0, std::abs(r.w_plus - mean) - 0.5) / std::sqrt(var);
  r.p = std::min(1.0, 2.0 * normal_upper_tail(z));
  return r;
}

RatioInterval median_ratio_interval(const std::vector<double>& a, const std::vector<double>& b, double level,
                                    int resamples, std::uint64_t seed) {
  RatioInterval r;
  if (a.empty() || b.empty()) return r;
  const double ma = median_of(a);
  r.ratio = ma != 0.0 ? median_of(b) / ma : 1.0;
  Rng rng(seed, 0xAB);
  std::vector<double> ra(a.size()), rb(b.size()), ratios;
  ratios.reserve(static_cast<std::size_t>(resamples));
  for (int k = 0; k < resamples; ++k) {
    for (auto& x : ra) x = a[rng.next_u64() % a.size()];
    for (auto& x : rb) x = b[rng.next_u64() % b.size()];
    const double m = median_of(ra);
    if (m != 0.0) ratios.push_back(median_of(rb) / m);
  }
  if (ratios.empty()) return r;
  percentile_interval(ratios, level, r);
  return r;
}

RatioInterval paired_ratio_interval(const std::vector<double>& a, const std::vector<double>& b, double level,
                                    int resamples, std::uint64_t seed) {
  RatioInterval r;
  std::vector<double> q;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (a[i] != 0.0) q.push_back(b[i] / a[i]);
  if (q.empty()) return r;
  r.ratio = median_of(q);
  Rng rng(seed, 0xBA);
  std::vector<double> rq(q.size()), meds;
  meds.reserve(static_cast<std::size_t>(resamples));
  for (int k = 0; k < resamples; ++k) {
    for (auto& x : rq) x = q[rng.next_u64() % q.size()];
    meds.push_back(median_of(rq));
  }
  percentile_interval(meds, level, r);
  return r;
}

int repetitions_needed(double cv, double effect, double alpha, double power) {
  const double delta = std::log(effect);
  if (delta <= 0.0) return 1 << 30;
  const double z = normal_upper_quantile(alpha / 2.0) + normal_upper_quantile(1.0 - power);
  const double n = 2.0 * z * z * cv * cv / (delta * delta) / 0.955;
  return std::max(3, static_cast<int>(std::ceil(n)));
}

TimingVerdict judge_timings(const std::vector<double>& a, const std::vector<double>& b, double effect, double alpha,
                            bool paired) {
  TimingVerdict v;
  v.n_a = static_cast<int>(a.size());
  v.n_b = static_cast<int>(b.size());
  v.median_a = median_of(a);
  v.median_b = median_of(b);
  v.cv = std::max(robust_cv(a), robust_cv(b));
  v.needed = repetitions_needed(v.cv, effect, alpha);
  v.test = mann_whitney(b, a);  // U of the new side: large when it is slower
  v.interval = median_ratio_interval(a, b);
  auto slower = [&](double p, const RatioInterval& i) { return p < alpha && i.ratio >= effect && i.lo > 1.0; };
  auto faster = [&](double p, const RatioInterval& i) { return p < alpha && i.ratio <= 1.0 / effect && i.hi < 1.0; };
  auto within = [&](const RatioInterval& i) { return i.lo > 1.0 / effect && i.hi < effect; };
  bool is_slower = slower(v.test.p, v.interval), is_faster = faster(v.test.p, v.interval);
  bool is_same = within(v.interval);
  v.paired = paired && a.size() == b.size() && a.size() >= 3;
  if (v.paired) {
    std::vector<double> logs;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i] > 0.0 && b[i] > 0.0) logs.push_back(std::log(b[i] / a[i]));
    v.paired_test = wilcoxon_signed_rank(logs);
    v.paired_interval = paired_ratio_interval(a, b);
    // The spread of one pair's log ratio is sqrt(2) times one side's: as a per-side CV for the count.
    std::vector<double> q;
    for (const double l : logs) q.push_back(std::exp(l));
    v.paired_cv = robust_cv(q) / std::sqrt(2.0);
    v.needed = std::min(v.needed, repetitions_needed(v.paired_cv, effect, alpha));
    is_slower = is_slower || slower(v.paired_test.p, v.paired_interval);
    is_faster = is_faster || faster(v.paired_test.p, v.paired_interval);
    is_same = is_same || within(v.paired_interval);
  }
  if (is_slower && !is_faster)
    v.verdict = "slower";
  else if (is_faster && !is_slower)
    v.verdict = "faster";
  else if (is_same && !is_slower && !is_faster)
    v.verdict = "no change";
  else
    v.verdict = "inconclusive";
  return v;
}

}  // namespace growbench
