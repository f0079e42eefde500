// The exact second-order low pass on the actual timestamps (signal.hpp): the step coefficients of a
// chunk of rows are computed together in vectorized loops, then the recursion runs over the chunk.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "diagnosis/filters/lowpass.hpp"
#include "diagnosis/filters/lowpass_kernels.hpp"

namespace ftstack::diag {
namespace {

using lowpass::kChunk;

/// The highest degree of the power series of Φ(δ) (SeriesSteps).
constexpr int kMaxDegree = 19;

/// ÿ + 2ζω ẏ + ω² y = ω² u, homogeneous state [y, ẏ]: ẋ = A·x with A = [[0, 1], [−ω², −2σ]].
struct SecondOrderShape {
  double w;      ///< ω, rad/s
  double zeta;   ///< ζ
  double sigma;  ///< ζω
  double d2;     ///< 1 − ζ²
  double wd;     ///< ω·√|1 − ζ²|
  double lam;    ///< the largest |eigenvalue| of A: ω, or |σ| + ω_d when overdamped
  /// The steps the exp/sin/cos loops take: dt in [dt_series, dt_max] (exp arguments within ±700,
  /// angles within kMaxAngle; none when ω_d vanishes); below dt_series (overdamped: ω_d·dt <
  /// 1e-4) ScalarCS's series, unless a whole chunk is on it.
  double dt_series;
  double dt_max;
  /// e^{Aδ} = α·I + β·A with α = Σ alpha[k]·v^k and ω·β = Σ beta[k]·v^k in v = ω·δ.
  std::array<double, kMaxDegree + 1> alpha;
  std::array<double, kMaxDegree + 1> beta;
};

SecondOrderShape MakeShape(double w, double zeta) {
  SecondOrderShape sh{};
  sh.w = w;
  sh.zeta = zeta;
  sh.sigma = zeta * w;
  sh.d2 = 1.0 - zeta * zeta;
  sh.wd = w * std::sqrt(std::fabs(sh.d2));
  sh.lam = sh.d2 >= 0 ? w : std::fabs(sh.sigma) + sh.wd;
  if (sh.d2 > 0) {
    sh.dt_series = 0.0;
    sh.dt_max =
        sh.wd >= 1e-100 ? std::min(lowpass::kMaxAngle / sh.wd, 700.0 / std::fabs(sh.sigma)) : -1.0;
  } else {
    sh.dt_series = 1e-4 / sh.wd;
    sh.dt_max = 700.0 / (std::fabs(sh.sigma) + sh.wd);
  }
  // A^k = a_k·I + b_k·A (A² = −2σ·A − ω²·I): a_{k+1} = −ω²·b_k, b_{k+1} = a_k − 2σ·b_k. Scaled,
  // â_k = a_k/ω^k and b̂_k = b_k/ω^(k−1): â_{k+1} = −b̂_k, b̂_{k+1} = â_k − 2ζ·b̂_k.
  double a = 1.0;
  double b = 0.0;
  double factorial = 1.0;
  for (int k = 0; k <= kMaxDegree; ++k) {
    sh.alpha[static_cast<std::size_t>(k)] = a / factorial;
    sh.beta[static_cast<std::size_t>(k)] = b / factorial;
    const double next_a = -b;
    b = a - 2.0 * zeta * b;
    a = next_a;
    factorial *= static_cast<double>(k + 1);
  }
  return sh;
}

/// c = e^{−σ dt}·cos(ω_d dt), s = e^{−σ dt}·sin(ω_d dt)/ω_d (cosh and sinh when overdamped), so
/// that Φ(dt) = [[c + σs, s], [−ω²s, c − σs]]: the scalar closed form.
void ScalarCS(const SecondOrderShape& sh, double dt, double* c, double* s) {
  const double x = sh.wd * dt;
  const double decay = std::exp(-sh.sigma * dt);
  if (x < 1e-4) {  // near critical damping: series of cos and sin(x)/x (or cosh, sinh)
    const double sign = sh.d2 >= 0 ? -1.0 : 1.0;
    *c = decay * (1.0 + sign * 0.5 * x * x);
    *s = decay * dt * (1.0 + sign * x * x / 6.0);
  } else if (sh.d2 > 0) {
    *c = decay * std::cos(x);
    *s = decay * std::sin(x) / sh.wd;
  } else {  // overdamped: two real decays, both ≤ 1, no overflow
    const double e1 = std::exp((-sh.sigma + sh.wd) * dt);
    const double e2 = std::exp((-sh.sigma - sh.wd) * dt);
    *c = 0.5 * (e1 + e2);
    *s = 0.5 * (e1 - e2) / sh.wd;
  }
}

/// Exact one-step coefficients of each row of a chunk for an input linear over the step: Φ(dt)
/// and 1/dt (for the input's slope). The arrays hold one dt's throughout while `uniform`.
struct SecondOrderChunk {
  alignas(64) double p00[kChunk];
  alignas(64) double p01[kChunk];
  alignas(64) double p10[kChunk];
  alignas(64) double p11[kChunk];
  alignas(64) double inv_dt[kChunk];
  bool uniform = false;
  double uniform_dt = 0.0;
};

/// Φ and 1/dt from ScalarCS's c and s into row j of the chunk.
inline void StoreStep(const SecondOrderShape& sh, double dt, double c, double s, std::size_t j,
                      SecondOrderChunk* k) {
  k->p00[j] = c + sh.sigma * s;
  k->p01[j] = s;
  k->p10[j] = -(sh.w * sh.w) * s;
  k->p11[j] = c - sh.sigma * s;
  k->inv_dt[j] = 1.0 / dt;
}

/// The steps of a chunk from dt = dt_ref + δ: Φ(dt) = Φ(dt_ref)·Φ(δ) with Φ(dt_ref) from ScalarCS
/// and Φ(δ) = α·I + β·A from the power series to degree K (SeriesDegree).
template <int K>
void SeriesSteps(const SecondOrderShape& sh, const double* dt, std::size_t len, double dt_ref,
                 SecondOrderChunk* k) {
  // Local copies: the compiler need not reload them after each store through k.
  std::array<double, K + 1> alpha;
  std::array<double, K + 1> beta;
  std::copy_n(sh.alpha.begin(), K + 1, alpha.begin());
  std::copy_n(sh.beta.begin(), K + 1, beta.begin());
  double c = 0.0;
  double s = 0.0;
  ScalarCS(sh, dt_ref, &c, &s);
  const double alpha_ref = c + sh.sigma * s;  // Φ(dt_ref) = α·I + β·A, B = ω·β
  const double b_ref = sh.w * s;
  const double b_ref_2z = 2.0 * sh.zeta * b_ref;
  const double inv_w = 1.0 / sh.w;
  for (std::size_t j = 0; j < len; ++j) {
    const double v = sh.w * (dt[j] - dt_ref);
    const double a_d = lowpass::Horner<K>(alpha, v);
    const double b_d = lowpass::Horner<K>(beta, v);
    // (α_r·I + β_r·A)(α_d·I + β_d·A) with A² = −2σ·A − ω²·I, in B = ω·β.
    const double a_t = alpha_ref * a_d - b_ref * b_d;
    const double b_t = (alpha_ref - b_ref_2z) * b_d + b_ref * a_d;
    k->p00[j] = a_t;
    k->p01[j] = b_t * inv_w;
    k->p10[j] = -sh.w * b_t;
    k->p11[j] = a_t - 2.0 * sh.zeta * b_t;
    k->inv_dt[j] = 1.0 / dt[j];
  }
}

/// The steps when underdamped (ζ² < 1) from ExpKernel and SinCosKernel; returns a non-zero flag
/// when rows lie outside [0, dt_max]. Below x = ω_d·dt = 1e-4, where ScalarCS switches to its
/// series, sin(x)/ω_d agrees with dt·(1 − x²/6) to a few ulps.
std::uint64_t UnderdampedSteps(const SecondOrderShape& sh, const double* dt, std::size_t len,
                               SecondOrderChunk* k) {
  const double inv_wd = 1.0 / sh.wd;
  std::uint64_t outside = 0;
  for (std::size_t j = 0; j < len; ++j) {
    const double decay = lowpass::ExpKernel(-sh.sigma * dt[j]);
    double co = 0.0;
    double si = 0.0;
    lowpass::SinCosKernel(sh.wd * dt[j], &co, &si);
    StoreStep(sh, dt[j], decay * co, decay * si * inv_wd, j, k);
    outside |= lowpass::Outside(dt[j], 0.0, sh.dt_max);
  }
  return outside;
}

/// The same when critically or overdamped (ζ² ≥ 1): e^{−σ dt} and ScalarCS's series when every
/// row of the chunk is on it, else the two real decays (flagging the rows on the series).
std::uint64_t OverdampedSteps(const SecondOrderShape& sh, const double* dt, std::size_t len,
                              SecondOrderChunk* k) {
  std::uint64_t not_series = 0;
  for (std::size_t j = 0; j < len; ++j) not_series |= lowpass::Outside(dt[j], 0.0, sh.dt_series);
  std::uint64_t outside = 0;
  if (not_series == 0) {
    const double sign = sh.d2 >= 0 ? -1.0 : 1.0;
    for (std::size_t j = 0; j < len; ++j) {
      const double decay = lowpass::ExpKernel(-sh.sigma * dt[j]);
      const double x = sh.wd * dt[j];
      const double c = decay * (1.0 + sign * 0.5 * x * x);
      StoreStep(sh, dt[j], c, decay * dt[j] * (1.0 + sign * x * x / 6.0), j, k);
      outside |= lowpass::Outside(dt[j], 0.0, sh.dt_max);
    }
    return outside;
  }
  const double half_inv_wd = 0.5 / sh.wd;
  for (std::size_t j = 0; j < len; ++j) {
    const double e1 = lowpass::ExpKernel((-sh.sigma + sh.wd) * dt[j]);
    const double e2 = lowpass::ExpKernel((-sh.sigma - sh.wd) * dt[j]);
    StoreStep(sh, dt[j], 0.5 * (e1 + e2), (e1 - e2) * half_inv_wd, j, k);
    outside |= lowpass::Outside(dt[j], sh.dt_series, sh.dt_max);
  }
  return outside;
}

/// The degree SeriesSteps needs for ρ = λ·max|δ| (λ the largest |eigenvalue| of A), or
/// kMaxDegree + 1 beyond ρ ≈ 1: as |â_k| ≤ (k − 1)·(λ/ω)^k and |b̂_k| ≤ k·(λ/ω)^(k−1), the
/// truncation is about ρ^(K+1)/K!, kept below 1e-17 (K = 11 for ρ = 1/8, 19 for ρ = 1).
int SeriesDegree(double rho) {
  int degree = 0;
  double term = rho;
  while (!(term <= 1e-17) && degree <= kMaxDegree) {
    ++degree;
    term *= rho / degree;
  }
  return degree;
}

void SecondOrderCoefficients(const SecondOrderShape& sh, const double* t_s, std::size_t i0,
                             std::size_t len, SecondOrderChunk* k) {
  alignas(64) double dt[kChunk];
  const bool same = lowpass::ChunkSteps(t_s, i0, len, dt);
  if (same && k->uniform && dt[0] == k->uniform_dt) return;
  double c = 0.0;
  double s = 0.0;
  if (same) {  // one dt: the closed form once, kept across chunks
    ScalarCS(sh, dt[0], &c, &s);
    StoreStep(sh, dt[0], c, s, 0, k);
    for (double* a : {k->p00, k->p01, k->p10, k->p11, k->inv_dt}) {
      std::fill(a + 1, a + kChunk, a[0]);
    }
    k->uniform = true;
    k->uniform_dt = dt[0];
    return;
  }
  k->uniform = false;
  double lo = 0.0;
  double hi = 0.0;
  lowpass::StepRange(dt, len, &lo, &hi);
  const double dt_ref = 0.5 * (lo + hi);
  const int degree = SeriesDegree(sh.lam * 0.5 * (hi - lo));  // λ·|δ| ≤ λ·(hi − lo)/2
  if (lo > 0.0 && degree <= kMaxDegree && sh.w >= 1e-100) {   // the usual case: a jittered clock
    if (degree <= 7) {
      SeriesSteps<7>(sh, dt, len, dt_ref, k);
    } else if (degree <= 9) {
      SeriesSteps<9>(sh, dt, len, dt_ref, k);
    } else if (degree <= 11) {
      SeriesSteps<11>(sh, dt, len, dt_ref, k);
    } else if (degree <= 13) {
      SeriesSteps<13>(sh, dt, len, dt_ref, k);
    } else if (degree <= 16) {
      SeriesSteps<16>(sh, dt, len, dt_ref, k);
    } else {
      SeriesSteps<kMaxDegree>(sh, dt, len, dt_ref, k);
    }
    return;
  }
  // Wider spreads (gaps, high frequencies), dt ≤ 0, NaN: exp, sin and cos per row.
  const std::uint64_t outside =
      sh.d2 > 0 ? UnderdampedSteps(sh, dt, len, k) : OverdampedSteps(sh, dt, len, k);
  if (outside == 0) return;
  // The rows the vector loops may have got wrong (a superset: the series rows of an overdamped
  // chunk are redone even when the chunk was all series), by ScalarCS.
  for (std::size_t j = 0; j < len; ++j) {
    if (dt[j] >= sh.dt_series && dt[j] <= sh.dt_max) continue;
    ScalarCS(sh, dt[j], &c, &s);
    StoreStep(sh, dt[j], c, s, j, k);
  }
}

/// The recursion over the rows of a chunk for B columns at once (their states in registers); row
/// i of column b is y[b][i − y_off].
template <int B>
void SecondOrderBlock(const SecondOrderChunk& k, double lag, std::size_t i0, std::size_t len,
                      const double* const* x, double* const* y, std::ptrdiff_t y_off,
                      double* pos_io, double* vel_io, const std::uint8_t* restart) {
  const auto at = [&](std::size_t i) { return static_cast<std::ptrdiff_t>(i) - y_off; };
  double pos[B];
  double vel[B];
  double xp[B];
  for (int b = 0; b < B; ++b) {
    pos[b] = pos_io[b];
    vel[b] = vel_io[b];
    xp[b] = x[b][i0 - 1];
  }
  for (std::size_t j = 0; j < len; ++j) {
    const std::size_t i = i0 + j;
    if (restart != nullptr && restart[i] != 0) {  // a new recording: at rest at its first input
      for (int b = 0; b < B; ++b) {
        y[b][at(i)] = pos[b] = xp[b] = x[b][i];
        vel[b] = 0.0;
      }
      continue;
    }
    const double p00 = k.p00[j];
    const double p01 = k.p01[j];
    const double p10 = k.p10[j];
    const double p11 = k.p11[j];
    const double inv_dt = k.inv_dt[j];
    for (int b = 0; b < B; ++b) {
      // y = y_p + e with the particular solution y_p(τ) = u(τ) − lag·slope for u linear in τ.
      const double xi = x[b][i];
      const double slope = (xi - xp[b]) * inv_dt;
      const double e0 = pos[b] - (xp[b] - lag * slope);
      const double e1 = vel[b] - slope;
      pos[b] = xi - lag * slope + p00 * e0 + p01 * e1;
      vel[b] = slope + p10 * e0 + p11 * e1;
      xp[b] = xi;
      y[b][at(i)] = pos[b];
    }
  }
  for (int b = 0; b < B; ++b) {
    pos_io[b] = pos[b];
    vel_io[b] = vel[b];
  }
}

/// SecondOrderBlock<4> without restarts, the four columns' states in four-wide vectors: the same
/// products and sums in the same order per column (vector lanes round like scalars, and no FMA:
/// lowpass_kernels.hpp), so the same bits.
void SecondOrderBlock4(const SecondOrderChunk& k, double lag, std::size_t i0, std::size_t len,
                       const double* const* x, double* const* y, std::ptrdiff_t y_off,
                       double* pos_io, double* vel_io) {
  using V4 = double __attribute__((vector_size(32)));
  const auto at = [&](std::size_t i) { return static_cast<std::ptrdiff_t>(i) - y_off; };
  V4 pos = {pos_io[0], pos_io[1], pos_io[2], pos_io[3]};
  V4 vel = {vel_io[0], vel_io[1], vel_io[2], vel_io[3]};
  V4 xp = {x[0][i0 - 1], x[1][i0 - 1], x[2][i0 - 1], x[3][i0 - 1]};
  const V4 lag4 = {lag, lag, lag, lag};
  for (std::size_t j = 0; j < len; ++j) {
    const std::size_t i = i0 + j;
    const V4 p00 = {k.p00[j], k.p00[j], k.p00[j], k.p00[j]};
    const V4 p01 = {k.p01[j], k.p01[j], k.p01[j], k.p01[j]};
    const V4 p10 = {k.p10[j], k.p10[j], k.p10[j], k.p10[j]};
    const V4 p11 = {k.p11[j], k.p11[j], k.p11[j], k.p11[j]};
    const V4 inv_dt = {k.inv_dt[j], k.inv_dt[j], k.inv_dt[j], k.inv_dt[j]};
    const V4 xi = {x[0][i], x[1][i], x[2][i], x[3][i]};
    const V4 slope = (xi - xp) * inv_dt;
    const V4 e0 = pos - (xp - lag4 * slope);
    const V4 e1 = vel - slope;
    pos = xi - lag4 * slope + p00 * e0 + p01 * e1;
    vel = slope + p10 * e0 + p11 * e1;
    xp = xi;
    const std::ptrdiff_t o = at(i);
    for (int b = 0; b < 4; ++b) y[b][o] = pos[b];
  }
  for (int b = 0; b < 4; ++b) {
    pos_io[b] = pos[b];
    vel_io[b] = vel[b];
  }
}

/// Rows [i_begin, i_end) (i_begin − 1 a multiple of kChunk) of m columns from the states pos, vel
/// (row i_begin − 1), row i of column c at y[c][i − y_off].
// Flattened: every helper inlined, which the compiler does not do on its own here and which is
// measurably faster (the loops are then compiled with what the caller knows).
FTSTACK_LOWPASS_TARGETS [[gnu::flatten]] void SecondOrderRows(
    const SecondOrderShape& sh, double lag, const double* t_s, std::size_t i_begin,
    std::size_t i_end, const double* const* x, double* const* y, std::ptrdiff_t y_off,
    std::size_t m, const std::uint8_t* restart, double* pos, double* vel, SecondOrderChunk* k) {
  for (std::size_t i0 = i_begin; i0 < i_end; i0 += kChunk) {
    const std::size_t len = std::min(kChunk, i_end - i0);
    SecondOrderCoefficients(sh, t_s, i0, len, k);
    // Four columns at a time (their states in registers), then the rest together.
    std::size_t c = 0;
    for (; c + 4 <= m; c += 4) {
      if (restart == nullptr) {
        SecondOrderBlock4(*k, lag, i0, len, x + c, y + c, y_off, pos + c, vel + c);
      } else {
        SecondOrderBlock<4>(*k, lag, i0, len, x + c, y + c, y_off, pos + c, vel + c, restart);
      }
    }
    const std::size_t r = m - c;
    if (r == 3)
      SecondOrderBlock<3>(*k, lag, i0, len, x + c, y + c, y_off, pos + c, vel + c, restart);
    if (r == 2)
      SecondOrderBlock<2>(*k, lag, i0, len, x + c, y + c, y_off, pos + c, vel + c, restart);
    if (r == 1)
      SecondOrderBlock<1>(*k, lag, i0, len, x + c, y + c, y_off, pos + c, vel + c, restart);
  }
}

}  // namespace

void SecondOrderLowPass(const double* t_s, const double* x, std::size_t n, double freq_hz,
                        double damping_ratio, double* y) {
  SecondOrderLowPassColumns(t_s, n, freq_hz, damping_ratio, &x, &y, 1);
}

void SecondOrderLowPassColumns(const double* t_s, std::size_t n, double freq_hz,
                               double damping_ratio, const double* const* x, double* const* y,
                               std::size_t m, const std::uint8_t* restart) {
  if (n == 0 || m == 0) return;
  const SecondOrderShape sh = MakeShape(2.0 * M_PI * freq_hz, damping_ratio);
  const double lag = 2.0 * damping_ratio / sh.w;  // the steady lag of y behind a ramp, s
  std::vector<double> pos(m);
  std::vector<double> vel(m, 0.0);
  for (std::size_t c = 0; c < m; ++c) y[c][0] = pos[c] = x[c][0];
  SecondOrderChunk k;
  SecondOrderRows(sh, lag, t_s, 1, n, x, y, 0, m, restart, pos.data(), vel.data(), &k);
}

struct SecondOrderLowPassStream::State {
  SecondOrderShape sh;
  double lag;
  std::vector<double> pos;
  std::vector<double> vel;
  SecondOrderChunk k;
};

SecondOrderLowPassStream::SecondOrderLowPassStream(const double* t_s, std::size_t n, double freq_hz,
                                                   double damping_ratio, const double* const* x,
                                                   std::size_t m, const std::uint8_t* restart)
    : LowPassWindows(t_s, n, x, m, restart), st_(std::make_unique<State>()) {
  st_->sh = MakeShape(2.0 * M_PI * freq_hz, damping_ratio);
  st_->lag = 2.0 * damping_ratio / st_->sh.w;
  st_->pos.assign(m, 0.0);
  st_->vel.assign(m, 0.0);
}

SecondOrderLowPassStream::~SecondOrderLowPassStream() = default;

void SecondOrderLowPassStream::Start() {
  for (std::size_t c = 0; c < x_.size(); ++c) {
    st_->pos[c] = x_[c][0];
    st_->vel[c] = 0.0;
  }
}

void SecondOrderLowPassStream::FilterRows(std::size_t i_begin, std::size_t i_end,
                                          std::ptrdiff_t y_off) {
  SecondOrderRows(st_->sh, st_->lag, t_s_, i_begin, i_end, x_.data(), y_.data(), y_off, x_.size(),
                  restart_, st_->pos.data(), st_->vel.data(), &st_->k);
}

}  // namespace ftstack::diag
