// The separable fit the effects share: linear coefficients per channel by normal equations (whole
// or streamed), the search objective on strided rows, curvature σ, and channel and JSON helpers.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::diag::fx {

/// printf-style formatting into a std::string (up to 511 characters).
std::string Fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
/// A Series' column c as doubles (for the numerics that take double arrays).
inline Vec ColD(const Series& s, int c) { return s.col(c).cast<double>(); }

inline double Ln(double x) { return std::log(std::max(x, 1.0)); }

/// BIC-like penalty per parameter for hyper-parameter choices on training data.
inline double Penalty(const Context& cx) { return Ln(static_cast<double>(cx.n_train) * cx.nc); }

struct ChannelFit {
  Mat beta;              // p × N
  std::vector<Mat> cov;  // per channel, unit
  Vec sse;               // per channel, unweighted
  double sse_w = 0.0;
};

/// Column c of a fit's prediction: pred(i, c) = Σ_j f.beta(j, c) · feat(i, c)_j on every row
/// (x: p doubles of work space).
template <class F>
void PredictChannel(const Context& cx, const ChannelFit& f, int p, int c, F& feat, double* x,
                    Series* pred) {
  for (int i = 0; i < cx.n; ++i) {
    feat(i, c, x);
    double v = 0.0;
    for (int j = 0; j < p; ++j) v += f.beta(j, c) * x[j];
    (*pred)(i, c) = static_cast<float>(v);
  }
}

/// Per-channel least squares target_c ≈ Σ_j beta_jc · feat(i, c)_j on training rows; fills pred.
template <class F>
ChannelFit FitChannels(const Context& cx, const Series& target, int p, F feat, Series* pred,
                       const std::vector<int>* only = nullptr, int stride = 1) {
  ChannelFit out;
  out.beta = Mat::Zero(p, cx.nc);
  out.cov.assign(static_cast<std::size_t>(cx.nc), Mat::Zero(p, p));
  out.sse = Vec::Zero(cx.nc);
  std::vector<double> x(static_cast<std::size_t>(p));
  if (pred != nullptr) pred->setZero(cx.n, cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    const bool active = only == nullptr || std::find(only->begin(), only->end(), c) != only->end();
    if (!active) {
      if (stride > 1) continue;  // searches only compare the active channels
      double s = 0.0;
      for (int i = 0; i < cx.n; ++i) {
        if (cx.train[static_cast<std::size_t>(i)])
          s += static_cast<double>(target(i, c)) * target(i, c);
      }
      out.sse(c) = s;
      out.sse_w += s * cx.weight(c);
      continue;
    }
    NormalEq ne(p);
    for (int i = 0; i < cx.n; i += stride) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      feat(i, c, x.data());
      ne.Add(x.data(), target(i, c));
    }
    const auto r = ne.Solve();
    out.beta.col(c) = r.beta;
    out.cov[static_cast<std::size_t>(c)] = r.cov_unit;
    out.sse(c) = r.sse;
    out.sse_w += r.sse * cx.weight(c);
    if (pred != nullptr) PredictChannel(cx, out, p, c, feat, x.data(), pred);
  }
  return out;
}

/// The prediction of a fit FitChannels solved without one (kept only after a choice between
/// variants): pred(i, c) = Σ_j f.beta(j, c) · feat(i, c)_j on every row, FitChannels' sums.
template <class F>
void PredictChannels(const Context& cx, const ChannelFit& f, int p, F feat, Series* pred) {
  std::vector<double> x(static_cast<std::size_t>(p));
  pred->setZero(cx.n, cx.nc);
  for (int c = 0; c < cx.nc; ++c) PredictChannel(cx, f, p, c, feat, x.data(), pred);
}

/// The prediction of a fit whose features are streamed (ForLaggedLoad, ForRinging), made only once
/// the fit is kept: rows(visit) runs the streams, calling visit(i, c, v) for every row and
/// channel; feat(i, c, v, x) fills the p features; pred(i, c) = Σ_j f.beta(j, c) · x_j, the sums
/// FitChannels forms, in its order (memory: no n × N feature buffer).
template <class Rows, class F>
void PredictStreamed(const Context& cx, const ChannelFit& f, int p, Rows rows, F feat,
                     Series* pred) {
  std::vector<double> x(static_cast<std::size_t>(p));
  pred->resize(cx.n, cx.nc);
  rows([&](int i, int c, const double* v) {
    feat(i, c, v, x.data());
    double s = 0.0;
    for (int j = 0; j < p; ++j) s += f.beta(j, c) * x[static_cast<std::size_t>(j)];
    (*pred)(i, c) = static_cast<float>(s);
  });
}

/// σ of parameter j of channel c from its unit covariance and the channel's residual variance.
double ParamSigma(const Context& cx, const ChannelFit& f, int c, int j);
/// ParamSigma of linear coefficient j on every channel: the σ the engine reports for it.
Vec CoefSigmas(const Context& cx, const ChannelFit& f, int j);
nlohmann::json JsonNum(double v);
nlohmann::json VecJson(const Vec& v);
/// Puts coefficient j of every channel and its σ into e.params[key] / e.sigma[key]; returns it.
Vec PutChannelCoef(const Context& cx, const ChannelFit& f, int j, const char* key, EffectFit* e);
/// A search that starts near an earlier fit of the same effect when given one (RefitFn's
/// contract), else searches in full; `uncertainty` as RefitFn's.
using NearSearchFn = std::optional<EffectFit> (*)(const Context& cx, const Series& target,
                                                  const EffectFit* near, bool uncertainty);
/// The FitFn of an effect whose fit is one NearSearchFn: the full search, with uncertainties.
template <NearSearchFn Search>
std::optional<EffectFit> FitBy(const Context& cx, const Series& target) {
  return Search(cx, target, nullptr, true);
}
/// Its RefitFn: the search near an earlier fit.
template <NearSearchFn Search>
std::optional<EffectFit> RefitBy(const Context& cx, const Series& target, const EffectFit& near,
                                 bool uncertainty) {
  return Search(cx, target, &near, uncertainty);
}
/// Restart flags of the context's segments for the filters (nullptr for one recording).
const std::uint8_t* Restarts(const Context& cx);
/// Whitened training SSE of a one-coefficient-per-channel fit of `feature`, on every
/// search_stride-th row and scaled back to the full count: the objective of parameter searches.
/// `feature` is n × N, or compact (`compact`: its row r is row r·search_stride, StrideRows).
double SearchSse(const Context& cx, const Series& target, const Mat& feature, bool compact = false);
/// Rows 0, row_step, 2·row_step, … below cx.n for row_step = cx.search_stride: the rows a search
/// reads, and the rows of a compact search buffer (row i is at i / row_step).
std::vector<int> StrideRows(const Context& cx);
/// out(r, c) = LP_τ[load_c] at row rows[r] (rows increasing): the first-order lag of the load,
/// restarting per segment, kept only at `rows` (memory: rows × N instead of n × N; the same values
/// as the whole filter). Kept in the context's lag memo (lag_cache.hpp) and taken from it.
void LowPassLoadRows(const Context& cx, double tau, const std::vector<int>& rows, Mat* out);

/// Visits equally long streams over the context's rows (one column per channel) row by row:
/// visit(i, c, v) with v[q] stream q's value at row i, channel c; per channel the rows come in
/// increasing order (memory: windows of rows, not n × N).
template <class F>
void ForStreams(const Context& cx, const std::vector<std::unique_ptr<LowPassWindows>>& s, F visit) {
  std::vector<double> v(s.size());
  for (;;) {
    bool more = true;
    for (const auto& q : s) more = q->Next() && more;  // every stream has the same windows
    if (!more) return;
    const std::size_t b = s.front()->begin();
    for (int c = 0; c < cx.nc; ++c) {
      for (std::size_t j = 0; j < s.front()->size(); ++j) {
        for (std::size_t q = 0; q < s.size(); ++q) v[q] = s[q]->col(static_cast<std::size_t>(c))[j];
        visit(static_cast<int>(b + j), c, v.data());
      }
    }
  }
}

/// The load's columns (the filters' inputs).
inline std::vector<const double*> LoadColumns(const Context& cx) {
  std::vector<const double*> in;
  for (int c = 0; c < cx.nc; ++c) in.push_back(cx.load.col(c).data());
  return in;
}

/// Streams the first-order lags of the load LP_τ[load] (restarting per segment) for the k time
/// constants taus[0..k) over every row: visit(i, c, lag) with lag[q] the lag of τ_q (ForStreams).
template <class F>
void ForLaggedLoad(const Context& cx, const double* taus, int k, F visit) {
  const std::vector<const double*> in = LoadColumns(cx);
  std::vector<std::unique_ptr<LowPassWindows>> s;
  for (int q = 0; q < k; ++q) {
    s.push_back(std::make_unique<FirstOrderLowPassStream>(cx.data->t_s.data(),
                                                          static_cast<std::size_t>(cx.n), taus[q],
                                                          in.data(), in.size(), Restarts(cx)));
  }
  ForStreams(cx, s, visit);
}

/// Streams the ringing H_{f,ζ}[load] − load of every channel for the k modes (f_hz[q], zeta[q])
/// over every row (restarting at rest per segment): visit(i, c, h) with h[q] mode q's ringing.
template <class F>
void ForRinging(const Context& cx, const double* f_hz, const double* zeta, int k, F visit) {
  const std::vector<const double*> in = LoadColumns(cx);
  std::vector<std::unique_ptr<LowPassWindows>> s;
  for (int q = 0; q < k; ++q) {
    s.push_back(std::make_unique<SecondOrderLowPassStream>(
        cx.data->t_s.data(), static_cast<std::size_t>(cx.n), f_hz[q], zeta[q], in.data(), in.size(),
        Restarts(cx)));
  }
  std::vector<double> h(static_cast<std::size_t>(k));
  ForStreams(cx, s, [&](int i, int c, const double* v) {
    for (int q = 0; q < k; ++q) h[static_cast<std::size_t>(q)] = v[q] - cx.load(i, c);
    visit(i, c, h.data());
  });
}

/// The ringing of the channels `chans` over rows [i0, i0 + m) (at rest at row i0, restarting per
/// segment), kept at rows i0, i0 + step, …: out(r, k) is row i0 + r·step of channel chans[k]
/// (memory: (m / step) × chans, not n × N; the values ForRinging gives when i0 = 0).
void RingingAt(const Context& cx, double f_hz, double zeta, const std::vector<int>& chans, int i0,
               int m, int step, Mat* out);

/// FitChannels' normal equations for features that arrive row window by row window (streamed
/// filters, FirstOrderLowPassStream): Add rows of one channel in increasing order, then Solve. The
/// same sums in the same order per channel as FitChannels over every row, so the same fit.
class ChannelSums {
 public:
  ChannelSums(const Context& cx, int p) : eq_(static_cast<std::size_t>(cx.nc), NormalEq(p)) {}
  void Add(int c, const double* x, double y) { eq_[static_cast<std::size_t>(c)].Add(x, y); }
  /// The fit of every channel (FitChannels with all channels active), without a prediction.
  [[nodiscard]] ChannelFit Solve(const Context& cx) const;
  /// The sums of the first k features alone (NormalEq::Leading): a nested model's fit from the
  /// same pass.
  [[nodiscard]] ChannelSums Leading(int k) const {
    ChannelSums s;
    for (const NormalEq& e : eq_) s.eq_.push_back(e.Leading(k));
    return s;
  }

 private:
  ChannelSums() = default;
  std::vector<NormalEq> eq_;
};
/// 0, 1, …, cx.nc − 1.
inline std::vector<int> AllChannels(const Context& cx) {
  std::vector<int> all(static_cast<std::size_t>(cx.nc));
  for (int c = 0; c < cx.nc; ++c) all[static_cast<std::size_t>(c)] = c;
  return all;
}
/// The two channels carrying the most whitened energy of r (where ringing searches look).
std::vector<int> StrongestTwo(const Context& cx, const Series& r);
/// Channel whose prediction carries the largest whitened energy.
int DominantChannel(const Context& cx, const Series& pred);
/// Channels carrying at least `share` of the prediction's whitened energy.
std::vector<int> ActiveChannels(const Context& cx, const Series& pred, double share = 0.02);
/// Channels on which the prediction's whitened mean square exceeds `share` (of the noise's, 1),
/// or the dominant channel alone when none does.
std::vector<int> ChannelsAboveNoise(const Context& cx, const Series& pred, double share = 0.01);
/// Channels whose single coefficient is significant (|β|/σ > 5) and carries ≥ 5 % of the energy
/// explained across channels.
std::vector<int> SignificantChannels(const Context& cx, const ChannelFit& f, const Series& pred,
                                     int j);
std::string ChannelList(const std::vector<int>& ch);
nlohmann::json IntList(const std::vector<int>& ch);
double RowCorr(const Context& cx, const Series& target, const Series& pred, int c);

// Hat (linear B-spline) basis in time with k intervals: row i → (index, fraction).
struct HatBasis {
  double t0 = 0.0;
  double h = 1.0;
  int k = 1;
  void At(double t, int* idx, double* frac) const {
    double u = (t - t0) / h;
    int j = static_cast<int>(std::floor(u));
    if (j < 0) j = 0;
    if (j >= k) j = k - 1;
    *idx = j;
    *frac = std::clamp(u - j, 0.0, 1.0);
  }
};

HatBasis MakeHat(const Context& cx, int k);

/// The residual's spectral lines, two ways. Both read r twice where rows are excluded
/// (cx.excluded: glitches, lagging load transitions), as is and with those rows bridged by
/// straight lines, and merge the lines: a ringing that dies within a transition shows only in the
/// first, one that lasts through the holds under the steps' broadband misfit only in the second.
///  - SpectralLines: lines of r's Welch spectra, whitened and summed over channels: local maxima
///    (from the 4th bin) over 4 × the median level, strongest first, as (level / median level,
///    frequency in Hz); `threads` > 1 reads the two ways side by side.
///  - LocalLines: lines of r's median-periodogram spectra (WelchMedian: load steps in a few
///    segments do not lift it), whitened and summed over channels, that stand out of their
///    neighbourhood (over `min_ratio` × the median of the 16 bins each side, so a red spectrum's
///    slope does not hide them), most prominent first, as (level / local median, frequency in Hz
///    interpolated between bins).
std::vector<std::pair<double, double>> SpectralLines(const Context& cx, const Series& r,
                                                     int threads = 1);
std::vector<std::pair<double, double>> LocalLines(const Context& cx, const Series& r,
                                                  double min_ratio = 8.0);

}  // namespace ftstack::diag::fx
