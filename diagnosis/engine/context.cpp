// The diagnosis context (residual, noise, hold-out blocks, sim zero and sensitivity, spectral
// lines) and the whitened train/hold-out sums.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "diagnosis/engine/debug.hpp"
#include "diagnosis/engine/parallel.hpp"
#include "diagnosis/engine/separable_fit.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

namespace {

/// Spectral lines of the whitened residual, summed over channels: the five strongest peaks over
/// four times the median level (cx.peak_hz, cx.peak_ratio).
void FindSpectralLines(Context& cx) {
  const auto lines = SpectralLines(cx, cx.resid, cx.threads);
  for (std::size_t j = 0; j < std::min<std::size_t>(lines.size(), 5); ++j) {
    cx.peak_ratio.push_back(lines[j].first);
    cx.peak_hz.push_back(lines[j].second);
  }
}

}  // namespace

namespace {

/// Whether the clock is uniform to 1e-6 relative at the median rate.
bool UniformClock(const DiagData& d, double dt) {
  for (std::size_t i = 1; i < d.t_s.size(); ++i) {
    if (std::fabs(d.t_s[i] - d.t_s[i - 1] - dt) > 1e-6 * dt + 1e-9) return false;
  }
  return true;
}

/// The whole-record floor over the quiet-hold noise beyond which the floor is not noise.
constexpr double kQuietNoiseRatio = 5.0;
/// The lag memo's budget: about sixty lags of a search's 12 000 rows × 8 channels.
constexpr std::size_t kLagCacheBytes = std::size_t{48} << 20;

/// The robust noise per channel (or the given one) and its weights.
void EstimateNoise(Context& cx, const Eigen::VectorXd* sigma) {
  cx.sigma.resize(cx.nc);
  cx.weight.resize(cx.nc);
  ParallelFor(static_cast<std::size_t>(cx.nc), cx.threads, [&](std::size_t ch) {
    const int c = static_cast<int>(ch);
    // The quiet holds' noise (typical_sigma_mvv) where the conditioning measured one and the
    // whole-record floor is over kQuietNoiseRatio × it: load changes and ringing lift that floor,
    // which would make real structure look like noise. Within that ratio the floor is kept (a
    // coloured noise's first differences understate it).
    const auto cu = static_cast<std::size_t>(c);
    const double quiet =
        cu < cx.conditioning.noise.size() ? cx.conditioning.noise[cu].typical_sigma_mvv : 0.0;
    double s = RobustNoise(ColD(cx.resid, c).data(), static_cast<std::size_t>(cx.n), cx.rate_hz);
    if (quiet > 0.0 && s > kQuietNoiseRatio * quiet) s = quiet;
    // Floor: a tiny fraction of the channel's signal scale, so identical files do not divide by 0.
    const double peak = std::max(std::fabs(cx.load.col(c).maxCoeff() + cx.zero(c)),
                                 std::fabs(cx.load.col(c).minCoeff() + cx.zero(c)));
    const double scale = std::max(1e-9, peak * 1e-9);
    s = std::max(s, scale);
    if (sigma != nullptr) s = (*sigma)(c);
    cx.sigma(c) = s;
    cx.weight(c) = 1.0 / (s * s);
  });
}

/// Segment restarts and the hold-out split: interleaved blocks of about block_s (≥ 20 rows, ≥ 30
/// blocks), every third held out; blocks restart at every segment boundary.
void SplitHoldOut(Context& cx, const DiagData& d, double block_s) {
  auto rows_per_block = static_cast<std::size_t>(std::max(20.0, std::round(block_s * cx.rate_hz)));
  rows_per_block = std::min(rows_per_block, std::max<std::size_t>(4, d.rows() / 30));
  cx.block_s = static_cast<double>(rows_per_block) * cx.dt;
  cx.search_stride = std::max(1, static_cast<int>(std::lround(cx.n / 12000.0)));
  cx.train.resize(d.rows());
  if (!d.segment.empty()) {
    cx.restart.assign(d.rows(), 0);
    for (std::size_t i = 1; i < d.rows(); ++i) {
      if (d.segment[i] != d.segment[i - 1]) {
        cx.restart[i] = 1;
        ++cx.segments;
      }
    }
  }
  std::size_t block = 0;
  std::size_t in_block = 0;
  for (std::size_t i = 0; i < d.rows(); ++i) {
    if (i > 0 && (in_block == rows_per_block || (!cx.restart.empty() && cx.restart[i] != 0))) {
      ++block;
      in_block = 0;
    }
    ++in_block;
    cx.train[i] = (block % 3) == 1 ? 0 : 1;
    if (cx.train[i]) {
      ++cx.n_train;
    } else {
      ++cx.n_hold;
    }
  }
}

/// Zero and sensitivity of the sim by regression on the wrench; the load (sim − zero) and its
/// range.
void SplitSim(Context& cx, const DiagData& d, Mat sim) {
  cx.zero = Vec::Zero(cx.nc);
  cx.sens = Mat::Zero(cx.nc, 6);
  if (d.has_wrench()) {
    ParallelFor(static_cast<std::size_t>(cx.nc), cx.threads, [&](std::size_t ch) {
      const int c = static_cast<int>(ch);
      NormalEq ne(7);
      double x[7];
      for (int i = 0; i < cx.n; ++i) {
        x[0] = 1.0;
        for (int k = 0; k < 6; ++k) x[k + 1] = d.wrench(i, k);
        ne.Add(x, sim(i, c));
      }
      const auto r = ne.Solve();
      cx.zero(c) = r.beta(0);
      for (int k = 0; k < 6; ++k) cx.sens(c, k) = r.beta(k + 1);
    });
  }
  sim.rowwise() -= cx.zero.transpose();
  cx.load = std::move(sim);
  cx.lag_cache = std::make_shared<LagCache>(kLagCacheBytes);
  cx.load_range.resize(cx.nc);
  for (int c = 0; c < cx.nc; ++c)
    cx.load_range(c) = cx.load.col(c).maxCoeff() - cx.load.col(c).minCoeff();
}

/// temp − 20 °C per row where the temperature changes at all (else empty).
void SetTemperature(Context& cx, const DiagData& d) {
  if (!d.has_temp()) return;
  double lo = d.temp_c.front();
  double hi = lo;
  for (double v : d.temp_c) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (hi - lo > 1e-6) {
    cx.dtemp.resize(d.rows());
    for (std::size_t i = 0; i < d.rows(); ++i) cx.dtemp[i] = d.temp_c[i] - 20.0;
  }
}

/// The context from the residual and the sim's outputs (n × N each, mV/V): `sim` becomes the load.
Context Build(const DiagData& d, Series resid, Mat sim, double block_s,
              const Eigen::VectorXd* sigma, Quantisation quantisation, int threads) {
  Context cx;
  cx.threads = ResolveThreads(threads);
  cx.quantisation = std::move(quantisation);
  cx.data = &d;
  cx.n = static_cast<int>(d.rows());
  cx.nc = d.channels();
  cx.resid = std::move(resid);
  cx.rate_hz = d.rate_hz();
  cx.dt = 1.0 / cx.rate_hz;
  cx.uniform = UniformClock(d, cx.dt);
  auto t0 = std::chrono::steady_clock::now();
  SplitHoldOut(cx, d, block_s);
  SplitSim(cx, d, std::move(sim));
  DebugTime("context", "hold-out split and sim zero", t0);
  t0 = std::chrono::steady_clock::now();
  ConditionData(&cx);
  DebugTime("context", "conditioning", t0);
  t0 = std::chrono::steady_clock::now();
  EstimateNoise(cx, sigma);
  SetTemperature(cx, d);
  DebugTime("context", "noise", t0);
  t0 = std::chrono::steady_clock::now();
  FindSpectralLines(cx);
  DebugTime("context", "spectral lines", t0);
  return cx;
}

}  // namespace

Context MakeContext(const DiagData& d, double block_s, const Eigen::VectorXd* sigma, int threads) {
  return Build(d, (d.real_mvv - d.sim_mvv).cast<float>(), d.sim_mvv, block_s, sigma,
               FindQuantisation(d), threads);
}

Context MakeContext(DiagData* d, double block_s, const Eigen::VectorXd* sigma, int threads) {
  d->released_channels = d->channels();
  // Real − sim in double, rounded once; the real bridges are released as soon as it is formed.
  Series resid = (d->real_mvv - d->sim_mvv).cast<float>();
  Quantisation quantisation = FindQuantisation(*d);
  d->real_mvv = Mat();
  Mat sim = std::move(d->sim_mvv);  // both matrices are left empty
  return Build(*d, std::move(resid), std::move(sim), block_s, sigma, std::move(quantisation),
               threads);
}

Context RefitCopy(Context* cx) {
  Series resid = std::move(cx->resid);
  Context copy = *cx;
  cx->resid = std::move(resid);
  return copy;
}

void SetNoise(Context* cx, const Eigen::VectorXd& sigma) {
  cx->sigma = sigma;
  cx->weight = sigma.array().square().inverse().matrix();
  cx->peak_hz.clear();
  cx->peak_ratio.clear();
  FindSpectralLines(*cx);
}

namespace {

/// The whitened sums with prediction pred(i, c).
template <class P>
Sums ScoreWith(const Context& cx, const Series& target, P pred) {
  Sums s;
  for (int c = 0; c < cx.nc; ++c) {
    double tr = 0.0;
    double ho = 0.0;
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      const double p = pred(i, c);
      const double e = static_cast<double>(target(i, c)) - p;
      if (cx.train[static_cast<std::size_t>(i)]) {
        tr += e * e;
      } else if (cx.held_out(static_cast<std::size_t>(i))) {
        ho += e * e;
        pp += p * p;
      }
    }
    s.train_sse += tr * cx.weight(c);
    s.hold_sse += ho * cx.weight(c);
    s.hold_pp += pp * cx.weight(c);
  }
  return s;
}

}  // namespace

Sums Score(const Context& cx, const Series& target, const Series* pred) {
  if (pred == nullptr) return ScoreWith(cx, target, [](int, int) { return 0.0; });
  return ScoreWith(cx, target, [pred](int i, int c) { return static_cast<double>((*pred)(i, c)); });
}

Sums ScoreSum(const Context& cx, const Series& target, const Series& a, const Series& b) {
  return ScoreWith(cx, target, [&](int i, int c) {
    return static_cast<double>(a(i, c)) + static_cast<double>(b(i, c));
  });
}

}  // namespace ftstack::diag
