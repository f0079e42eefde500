// Private helpers shared by the effect models (declared in separable_fit.hpp).
#include "diagnosis/engine/separable_fit.hpp"

#include <cstdarg>
#include <cstdio>
#include <limits>
#include <memory>

#include "diagnosis/engine/parallel.hpp"

namespace ftstack::diag::fx {

std::string Fmt(const char* f, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

/// σ of parameter j of channel c from its unit covariance and the channel's residual variance.
double ParamSigma(const Context& cx, const ChannelFit& f, int c, int j) {
  const double dof =
      std::max(1.0, static_cast<double>(cx.n_train) - static_cast<double>(f.beta.rows()));
  return std::sqrt(std::max(0.0, f.cov[static_cast<std::size_t>(c)](j, j) * f.sse(c) / dof));
}

Vec CoefSigmas(const Context& cx, const ChannelFit& f, int j) {
  Vec s(cx.nc);
  for (int c = 0; c < cx.nc; ++c) s(c) = ParamSigma(cx, f, c, j);
  return s;
}

void RingingAt(const Context& cx, double f_hz, double zeta, const std::vector<int>& chans, int i0,
               int m, int step, Mat* out) {
  std::vector<const double*> in;
  for (int c : chans) in.push_back(cx.load.col(c).data() + i0);  // LP[sim] − sim = LP[load] − load
  const std::uint8_t* restart = Restarts(cx);
  out->resize((m + step - 1) / step, static_cast<Eigen::Index>(chans.size()));
  SecondOrderLowPassStream s(cx.data->t_s.data() + i0, static_cast<std::size_t>(m), f_hz, zeta,
                             in.data(), in.size(), restart != nullptr ? restart + i0 : nullptr);
  const auto row_step = static_cast<std::size_t>(step);
  while (s.Next()) {
    std::size_t j = (row_step - s.begin() % row_step) % row_step;  // the window's first kept row
    for (; j < s.size(); j += row_step) {
      const std::size_t rel = s.begin() + j;
      const auto r = static_cast<Eigen::Index>(rel / row_step);
      for (std::size_t k = 0; k < chans.size(); ++k) {
        (*out)(r, static_cast<Eigen::Index>(k)) =
            s.col(k)[j] - cx.load(i0 + static_cast<int>(rel), chans[k]);
      }
    }
  }
}

std::vector<int> StrongestTwo(const Context& cx, const Series& r) {
  std::vector<int> order(static_cast<std::size_t>(cx.nc));
  Vec e(cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    order[static_cast<std::size_t>(c)] = c;
    e(c) = r.col(c).cast<double>().squaredNorm() * cx.weight(c);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return e(a) > e(b); });
  order.resize(static_cast<std::size_t>(std::min(2, cx.nc)));
  return order;
}

nlohmann::json JsonNum(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json VecJson(const Vec& v) {
  auto a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(JsonNum(v(i)));
  return a;
}

/// Puts coefficient j of every channel and its σ into e.params[key] / e.sigma[key]; returns it.
Vec PutChannelCoef(const Context& cx, const ChannelFit& f, int j, const char* key, EffectFit* e) {
  Vec v = f.beta.row(j).transpose();
  const Vec sg = CoefSigmas(cx, f, j);
  e->params[key] = VecJson(v);
  e->sigma[key] = VecJson(sg);
  return v;
}

double SearchSse(const Context& cx, const Series& target, const Mat& feature, bool compact) {
  // FitChannels with one feature, unrolled: the sums of NormalEq::Add with unit weight and the
  // arithmetic of NormalEq::Solve for p = 1 (Jacobi scaling, 1e-12 on the scaled diagonal), so the
  // value is the same to the last bit, without a per-row call or a covariance per channel.
  const int row_step = cx.search_stride;
  const int step = compact ? 1 : row_step;  // feature rows per searched row
  double sse_w = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    const double* x = feature.col(c).data();
    const float* y = target.col(c).data();
    double sxx = 0.0;
    double sxy = 0.0;
    double syy = 0.0;
    for (int i = 0, r = 0; i < cx.n; i += row_step, r += step) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      const double yi = y[i];
      sxy += x[r] * yi;
      sxx += x[r] * x[r];
      syy += yi * yi;
    }
    const double d = sxx > 0 ? 1.0 / std::sqrt(sxx) : 1.0;
    const double scaled = d * sxx * d + 1e-12;
    const double beta_scaled = d * sxy / scaled;
    const double beta = d * beta_scaled;
    sse_w += std::max(0.0, syy - beta * sxy) * cx.weight(c);
  }
  return sse_w * row_step;
}

std::vector<int> StrideRows(const Context& cx) {
  std::vector<int> rows;
  for (int i = 0; i < cx.n; i += cx.search_stride) rows.push_back(i);
  return rows;
}

namespace {

/// LowPassLoadRows without the memo: the filter itself.
void FilterLoadRows(const Context& cx, double tau, const std::vector<int>& rows, Mat* out) {
  const std::vector<const double*> in = LoadColumns(cx);
  out->resize(static_cast<Eigen::Index>(rows.size()), cx.nc);
  FirstOrderLowPassStream s(cx.data->t_s.data(), static_cast<std::size_t>(cx.n), tau, in.data(),
                            in.size(), Restarts(cx));
  std::size_t r = 0;
  while (s.Next() && r < rows.size()) {
    const auto end = s.begin() + s.size();
    for (; r < rows.size() && static_cast<std::size_t>(rows[r]) < end; ++r) {
      const std::size_t j = static_cast<std::size_t>(rows[r]) - s.begin();
      for (int c = 0; c < cx.nc; ++c) {
        (*out)(static_cast<Eigen::Index>(r), c) = s.col(static_cast<std::size_t>(c))[j];
      }
    }
  }
}

}  // namespace

void LowPassLoadRows(const Context& cx, double tau, const std::vector<int>& rows, Mat* out) {
  if (cx.lag_cache) {
    if (const auto kept = cx.lag_cache->Find(tau, rows)) {
      *out = *kept;
      return;
    }
  }
  FilterLoadRows(cx, tau, rows, out);
  if (cx.lag_cache) cx.lag_cache->Insert(tau, rows, std::make_shared<const Mat>(*out));
}

ChannelFit ChannelSums::Solve(const Context& cx) const {
  const int p = eq_.empty() ? 0 : eq_.front().p();
  ChannelFit out;
  out.beta = Mat::Zero(p, cx.nc);
  out.cov.assign(static_cast<std::size_t>(cx.nc), Mat::Zero(p, p));
  out.sse = Vec::Zero(cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    const auto r = eq_[static_cast<std::size_t>(c)].Solve();
    out.beta.col(c) = r.beta;
    out.cov[static_cast<std::size_t>(c)] = r.cov_unit;
    out.sse(c) = r.sse;
    out.sse_w += r.sse * cx.weight(c);
  }
  return out;
}

/// Channel whose prediction carries the largest whitened energy.
int DominantChannel(const Context& cx, const Series& pred) {
  int best = 0;
  double be = -1.0;
  for (int c = 0; c < cx.nc; ++c) {
    const double e = pred.col(c).cast<double>().squaredNorm() * cx.weight(c);
    if (e > be) {
      be = e;
      best = c;
    }
  }
  return best;
}

std::vector<int> ChannelsAboveNoise(const Context& cx, const Series& pred, double share) {
  std::vector<int> out;
  for (int c = 0; c < cx.nc; ++c) {
    if (pred.col(c).cast<double>().squaredNorm() * cx.weight(c) > share * cx.n) out.push_back(c);
  }
  if (out.empty()) out.push_back(DominantChannel(cx, pred));
  return out;
}

/// Channels carrying at least `share` of the prediction's whitened energy.
std::vector<int> ActiveChannels(const Context& cx, const Series& pred, double share) {
  Vec e(cx.nc);
  for (int c = 0; c < cx.nc; ++c) e(c) = pred.col(c).cast<double>().squaredNorm() * cx.weight(c);
  std::vector<int> out;
  const double tot = e.sum();
  for (int c = 0; c < cx.nc; ++c) {
    if (tot > 0 && e(c) >= share * tot) out.push_back(c);
  }
  return out;
}

/// Channels whose single coefficient is significant (|β|/σ > 5) and carries ≥ 5 % of the energy
/// explained across channels.
std::vector<int> SignificantChannels(const Context& cx, const ChannelFit& f, const Series& pred,
                                     int j) {
  std::vector<int> out;
  Vec e(cx.nc);
  for (int c = 0; c < cx.nc; ++c) e(c) = pred.col(c).cast<double>().squaredNorm() * cx.weight(c);
  const double tot = e.sum();
  for (int c = 0; c < cx.nc; ++c) {
    const double s = ParamSigma(cx, f, c, j);
    if (s > 0 && std::fabs(f.beta(j, c)) > 5.0 * s && e(c) >= 0.05 * tot) out.push_back(c);
  }
  return out;
}

std::string ChannelList(const std::vector<int>& ch) {
  std::string s;
  for (std::size_t i = 0; i < ch.size(); ++i) {
    if (i) s += ", ";
    s += "b" + std::to_string(ch[i]);
  }
  return s;
}

nlohmann::json IntList(const std::vector<int>& ch) {
  auto a = nlohmann::json::array();
  for (int c : ch) a.push_back(c);
  return a;
}

double RowCorr(const Context& cx, const Series& target, const Series& pred, int c) {
  // Memory: the columns are read in place (a Series is column-major), not copied to double.
  return Correlation(target.col(c).data(), pred.col(c).data(), static_cast<std::size_t>(cx.n));
}

HatBasis MakeHat(const Context& cx, int k) {
  HatBasis b;
  b.t0 = cx.data->t_s.front();
  b.k = k;
  b.h = (cx.data->t_s.back() - b.t0) / k;
  return b;
}

namespace {

/// x with every run of excluded rows (cx.excluded: glitches, transitions the real load lagged)
/// replaced by the line between the kept rows either side (held flat at the record's ends).
void BridgeExcluded(const Context& cx, Vec* x) {
  if (cx.excluded.empty()) return;
  const int n = cx.n;
  int i = 0;
  while (i < n) {
    if (cx.excluded[static_cast<std::size_t>(i)] == 0) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && cx.excluded[static_cast<std::size_t>(j)] != 0) ++j;
    if (i == 0 && j == n) return;  // nothing kept to bridge from
    const double a = i > 0 ? (*x)(i - 1) : (*x)(j);
    const double b = j < n ? (*x)(j) : a;
    for (int k = i; k < j; ++k) (*x)(k) = a + (b - a) * (k - i + 1) / (j - i + 1);
    i = j;
  }
}

/// r's Welch spectra (mean or, with `median`, median periodograms) whitened and summed over
/// channels, with `bridged` its excluded rows bridged (BridgeExcluded); empty when r is too short
/// for a spectrum.
void WhitenedSpectrum(const Context& cx, const Series& r, bool bridged, std::vector<double>* freq,
                      std::vector<double>* total, bool median = false) {
  const auto rows = static_cast<std::size_t>(cx.n);
  const std::size_t seg = WelchSegment(rows);
  if (rows < seg || seg < 32) return;
  for (int c = 0; c < cx.nc; ++c) {
    Vec col = ColD(r, c);
    if (bridged) BridgeExcluded(cx, &col);
    const Spectrum s = median ? numerics::WelchMedian(col.data(), rows, cx.rate_hz, seg)
                              : Welch(col.data(), rows, cx.rate_hz, seg);
    if (total->empty()) {
      total->assign(s.power.size(), 0.0);
      *freq = s.freq_hz;
    }
    for (std::size_t k = 0; k < s.power.size(); ++k) (*total)[k] += s.power[k] * cx.weight(c);
  }
}

/// The median of v[lo, hi) without v[skip_lo, skip_hi).
double MedianOutside(const std::vector<double>& v, std::size_t lo, std::size_t hi,
                     std::size_t skip_lo, std::size_t skip_hi) {
  std::vector<double> w;
  for (std::size_t k = lo; k < hi; ++k) {
    if (k < skip_lo || k >= skip_hi) w.push_back(v[k]);
  }
  if (w.empty()) return 1e-300;
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(w.size() / 2), w.end());
  return std::max(w[w.size() / 2], 1e-300);
}

/// The lines (level / floor, Hz) of a and b (one residual as is and bridged), a line not within
/// half a Welch bin of a more prominent one, most prominent first.
std::vector<std::pair<double, double>> MergeLines(const Context& cx,
                                                  std::vector<std::pair<double, double>> a,
                                                  const std::vector<std::pair<double, double>>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.rbegin(), a.rend());
  const double half_bin_hz =
      0.5 * cx.rate_hz / static_cast<double>(WelchSegment(static_cast<std::size_t>(cx.n)));
  std::vector<std::pair<double, double>> out;
  for (const auto& line : a) {
    if (std::none_of(out.begin(), out.end(), [&](const auto& o) {
          return std::fabs(o.second - line.second) < half_bin_hz;
        }))
      out.push_back(line);
  }
  return out;
}

/// SpectralLines of r as is or bridged.
std::vector<std::pair<double, double>> MeanSpectrumLines(const Context& cx, const Series& r,
                                                         bool bridged) {
  std::vector<double> total;
  std::vector<double> freq;
  std::vector<std::pair<double, double>> peaks;
  WhitenedSpectrum(cx, r, bridged, &freq, &total);
  if (total.size() < 4) return peaks;
  const double floor = MedianOutside(total, 1, total.size(), 0, 0);
  for (std::size_t k = 3; k + 1 < total.size(); ++k) {
    if (total[k] > total[k - 1] && total[k] >= total[k + 1] && total[k] > 4.0 * floor) {
      peaks.emplace_back(total[k] / floor, freq[k]);
    }
  }
  std::sort(peaks.rbegin(), peaks.rend());
  return peaks;
}

/// LocalLines of r as is or bridged.
std::vector<std::pair<double, double>> MedianSpectrumLines(const Context& cx, const Series& r,
                                                           double min_ratio, bool bridged) {
  std::vector<double> total;
  std::vector<double> freq;
  std::vector<std::pair<double, double>> peaks;
  WhitenedSpectrum(cx, r, bridged, &freq, &total, true);
  constexpr std::size_t kSide = 16;  // bins each side of the local floor
  for (std::size_t k = 3; k + 1 < total.size(); ++k) {
    if (total[k] <= total[k - 1] || total[k] < total[k + 1]) continue;
    const double floor = MedianOutside(total, k > kSide ? k - kSide : 1,
                                       std::min(total.size(), k + kSide + 1), k - 2, k + 3);
    if (total[k] < min_ratio * floor) continue;
    // The line between bins: the vertex of the parabola through the log powers of k − 1, k, k + 1.
    const double a = std::log(total[k - 1]);
    const double b = std::log(total[k]);
    const double c = std::log(total[k + 1]);
    const double den = a - 2.0 * b + c;
    const double shift = den < 0.0 ? std::clamp(0.5 * (a - c) / den, -0.5, 0.5) : 0.0;
    peaks.emplace_back(total[k] / floor, freq[k] + shift * (freq[k + 1] - freq[k]));
  }
  std::sort(peaks.rbegin(), peaks.rend());
  return peaks;
}

}  // namespace

std::vector<std::pair<double, double>> SpectralLines(const Context& cx, const Series& r,
                                                     int threads) {
  if (cx.excluded.empty()) return MeanSpectrumLines(cx, r, false);
  std::vector<std::pair<double, double>> as_is;
  std::vector<std::pair<double, double>> bridged;
  ParallelFor(2, threads, [&](std::size_t k) {
    if (k == 0) {
      as_is = MeanSpectrumLines(cx, r, false);
    } else {
      bridged = MeanSpectrumLines(cx, r, true);
    }
  });
  return MergeLines(cx, std::move(as_is), std::move(bridged));
}

std::vector<std::pair<double, double>> LocalLines(const Context& cx, const Series& r,
                                                  double min_ratio) {
  auto lines = MedianSpectrumLines(cx, r, min_ratio, false);
  if (cx.excluded.empty()) return lines;
  return MergeLines(cx, std::move(lines), MedianSpectrumLines(cx, r, min_ratio, true));
}

/// Restart flags of the context's segments for the filters (nullptr for one recording).
const std::uint8_t* Restarts(const Context& cx) {
  return cx.restart.empty() ? nullptr : cx.restart.data();
}

}  // namespace ftstack::diag::fx
