#include "diagnosis/engine/locate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "diagnosis/engine/signal.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::diag {
namespace {

/// z of a χ² statistic with ν degrees of freedom (Wilson–Hilferty).
double ChiSquareZ(double x, double nu) {
  if (nu <= 0) return 0.0;
  const double a = 2.0 / (9.0 * nu);
  return (std::cbrt(x / nu) - (1.0 - a)) / std::sqrt(a);
}

/// Channels: slow (window means of m rows) and fast (mean square) χ² tests.
void LocateChannels(Report& r, int m, int blocks) {
  const Context& cx = r.cx;
  for (int c = 0; c < cx.nc; ++c) {
    double xlow = 0.0;
    double xfull = 0.0;
    for (int b = 0; b < blocks; ++b) {
      double s = 0.0;
      const int i0 = b * m;
      const int i1 = b + 1 == blocks ? cx.n : i0 + m;
      for (int i = i0; i < i1; ++i) s += cx.resid(i, c);
      const double mean = s / (i1 - i0);
      xlow += mean * mean * (i1 - i0) * cx.weight(c);
    }
    for (int i = 0; i < cx.n; ++i)
      xfull += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c);
    const double zlow = ChiSquareZ(xlow, blocks);
    const double zfull = ChiSquareZ(xfull, cx.n);
    if (zlow > 6.0 || (zfull > 6.0 && xfull / cx.n > 1.05)) r.mismatch_channels.push_back(c);
  }
}

/// Time windows: blocks of m rows flagged on the mismatching channels, merged.
void LocateWindows(Report& r, int m, int blocks) {
  const Context& cx = r.cx;
  const auto& d = *cx.data;
  const auto nf = static_cast<double>(r.mismatch_channels.size());
  std::vector<bool> flag(static_cast<std::size_t>(blocks), false);
  for (int b = 0; b < blocks; ++b) {
    const int i0 = b * m;
    const int i1 = b + 1 == blocks ? cx.n : i0 + m;
    double xm = 0.0;
    double xs = 0.0;
    for (int c : r.mismatch_channels) {
      double s = 0.0;
      for (int i = i0; i < i1; ++i) {
        s += cx.resid(i, c);
        xs += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c);
      }
      xm += s * s / (i1 - i0) * cx.weight(c);
    }
    flag[static_cast<std::size_t>(b)] =
        ChiSquareZ(xm, nf) > 4.5 || ChiSquareZ(xs, nf * (i1 - i0)) > 4.5;
  }
  // Merge flagged blocks separated by at most one quiet block.
  std::vector<std::pair<int, int>> runs;
  for (int b = 0; b < blocks; ++b) {
    if (!flag[static_cast<std::size_t>(b)]) continue;
    if (!runs.empty() && b - runs.back().second <= 2) {
      runs.back().second = b;
    } else {
      runs.emplace_back(b, b);
    }
  }
  while (runs.size() > 40) {
    std::size_t gi = 1;
    int gap = std::numeric_limits<int>::max();
    for (std::size_t j = 1; j < runs.size(); ++j) {
      if (runs[j].first - runs[j - 1].second < gap) {
        gap = runs[j].first - runs[j - 1].second;
        gi = j;
      }
    }
    runs[gi - 1].second = runs[gi].second;
    runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(gi));
  }
  for (const auto& [b0, b1] : runs) {
    const int i0 = b0 * m;
    const int i1 = std::min(cx.n - 1, b1 + 1 == blocks ? cx.n - 1 : (b1 + 1) * m - 1);
    r.windows.emplace_back(d.t_s[static_cast<std::size_t>(i0)],
                           d.t_s[static_cast<std::size_t>(i1)]);
  }
}

/// Load region: where in the load space the excess over noise lives.
void LocateLoadRegion(Report& r) {
  const Context& cx = r.cx;
  const auto& d = *cx.data;
  const auto nf = static_cast<double>(r.mismatch_channels.size());
  if (!d.has_wrench()) return;
  std::vector<double> excess(static_cast<std::size_t>(cx.n));
  double mean_ex = 0.0;
  for (int i = 0; i < cx.n; ++i) {
    double e = 0.0;
    for (int c : r.mismatch_channels)
      e += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c) - 1.0;
    excess[static_cast<std::size_t>(i)] = e / nf;
    mean_ex += e / nf;
  }
  mean_ex /= cx.n;
  double best_eta = 0.0;
  int best_k = -1;
  int best_bin = 0;
  double best_bin_mean = 0.0;
  double best_lo = 0.0;
  double best_hi = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double peak = d.wrench.col(k).cwiseAbs().maxCoeff();
    if (peak <= 0) continue;
    double sum[6] = {};
    double cnt[6] = {};
    for (int i = 0; i < cx.n; ++i) {
      const double u = d.wrench(i, k) / peak;
      const int mag = std::min(2, static_cast<int>(std::fabs(u) * 3.0));
      const int bin = (u >= 0 ? 3 : 0) + mag;
      sum[bin] += excess[static_cast<std::size_t>(i)];
      cnt[bin] += 1.0;
    }
    double between = 0.0;
    double total = 0.0;
    for (int i = 0; i < cx.n; ++i)
      total += (excess[static_cast<std::size_t>(i)] - mean_ex) *
               (excess[static_cast<std::size_t>(i)] - mean_ex);
    int top = -1;
    double top_mean = -std::numeric_limits<double>::infinity();
    for (int b = 0; b < 6; ++b) {
      if (cnt[b] < 20) continue;
      const double mb = sum[b] / cnt[b];
      between += cnt[b] * (mb - mean_ex) * (mb - mean_ex);
      if (mb > top_mean) {
        top_mean = mb;
        top = b;
      }
    }
    const double eta = total > 0 ? between / total : 0.0;
    if (top >= 0 && eta > best_eta) {
      best_eta = eta;
      best_k = k;
      best_bin = top;
      best_bin_mean = top_mean;
      const int mag = top % 3;
      const double a = peak * mag / 3.0;
      const double b = peak * (mag + 1) / 3.0;
      best_lo = top >= 3 ? a : -b;
      best_hi = top >= 3 ? b : -a;
    }
  }
  if (best_k >= 0 && best_eta > 0.01) {
    r.load_region = {{"component", kWrenchAxisNames[best_k]}, {"sign", best_bin >= 3 ? "+" : "-"},
                     {"range", {best_lo, best_hi}},           {"excess_ratio", 1.0 + best_bin_mean},
                     {"mean_excess_ratio", 1.0 + mean_ex},    {"eta_squared", best_eta}};
  } else {
    r.load_region = {{"component", nullptr}, {"note", "the excess does not depend on the load"}};
  }
}

/// Rows per location block (block_s of rows) and the number of blocks.
std::pair<int, int> LocateBlocks(const Context& cx) {
  const auto m = static_cast<int>(std::llround(cx.block_s * cx.rate_hz));
  return {m, std::max(1, cx.n / std::max(1, m))};
}

/// One-sided normal quantile: z with P(Z > z) = p (bisection on erfc; 0 < p < 0.5).
double UpperZ(double p) {
  double lo = 0.0;
  double hi = 40.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

/// Model-informed location, after a claim: a channel the model-free tests missed joins the
/// mismatch channels when the claimed model removes a significant held-out χ² there, by the
/// claim's own statistic on that channel alone. The claim has established the effect; which
/// channels carry it is then N one-channel tests, held at a family-wise error of 0.1 %
/// (Bonferroni: z above the upper 0.001/N quantile, 3.7 for 8 channels). A matched filter sees
/// a weak structured effect (ringing after load steps) that block means and variances cannot.
/// Windows and the load region are then located again on the grown set.
void LocateByModel(Report& r) {
  const Context& cx = r.cx;
  const double z_channel = UpperZ(1e-3 / std::max(1, cx.nc));
  bool grew = false;
  for (int c = 0; c < cx.nc; ++c) {
    if (std::find(r.mismatch_channels.begin(), r.mismatch_channels.end(), c) !=
        r.mismatch_channels.end()) {
      continue;
    }
    double delta = 0.0;
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double e = cx.resid(i, c);
      const double m = r.model(i, c);
      delta += (e * e - (e - m) * (e - m)) * cx.weight(c);
      pp += m * m * cx.weight(c);
    }
    if (pp > 0 && delta / (2.0 * std::sqrt(pp)) > z_channel) {
      r.mismatch_channels.push_back(c);
      grew = true;
    }
  }
  if (!grew) return;
  std::sort(r.mismatch_channels.begin(), r.mismatch_channels.end());
  const auto [m, blocks] = LocateBlocks(cx);
  r.windows.clear();
  r.load_region = nlohmann::json();
  LocateWindows(r, m, blocks);
  LocateLoadRegion(r);
}

void Locate(Report& r) {
  const auto [m, blocks] = LocateBlocks(r.cx);
  LocateChannels(r, m, blocks);
  if (r.mismatch_channels.empty()) return;
  LocateWindows(r, m, blocks);
  LocateLoadRegion(r);
}

/// The residual spectrum for the report, whitened and averaged over channels.
void ReportSpectrum(Report& r) {
  const Context& cx = r.cx;
  const auto rows = static_cast<std::size_t>(cx.n);
  const std::size_t seg = WelchSegment(rows);
  if (rows >= seg && seg >= 32) {
    for (int c = 0; c < cx.nc; ++c) {
      const Eigen::VectorXd col = cx.resid.col(c).cast<double>();
      const Spectrum s = Welch(col.data(), rows, cx.rate_hz, seg);
      if (r.spectrum_power.empty()) {
        r.spectrum_hz = s.freq_hz;
        r.spectrum_power.assign(s.power.size(), 0.0);
      }
      for (std::size_t k = 0; k < s.power.size(); ++k)
        r.spectrum_power[k] += s.power[k] * cx.weight(c) / cx.nc;
    }
  }
}

}  // namespace ftstack::diag
