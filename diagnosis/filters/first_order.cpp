// The exact first-order low pass on the actual timestamps (signal.hpp): the step coefficients of a
// chunk of rows are computed together in vectorized loops, then the recursion runs over the chunk.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "diagnosis/filters/lowpass.hpp"
#include "diagnosis/filters/lowpass_kernels.hpp"

namespace ftstack::diag {
namespace {

using lowpass::kChunk;

/// First-order step y_i = a·y_{i−1} + b0·x_i + b1·x_{i−1} of each row of a chunk. The arrays hold
/// one dt's coefficients throughout while `uniform` (a uniform clock fills them once).
struct FirstOrderChunk {
  alignas(64) double a[kChunk];
  alignas(64) double b0[kChunk];
  alignas(64) double b1[kChunk];
  bool uniform = false;
  double uniform_dt = 0.0;
};

/// The closed form of one step (r = dt/τ) for an input linear over it (for r ≪ 1 the series of
/// FirstOrderSeries gives g = (1 − a)/r more accurately).
void FirstOrderStep(double r, double* a, double* b0, double* b1) {
  *a = std::exp(-r);
  const double g = r > 1e-8 ? (1.0 - *a) / r : 1.0 - r / 2.0;  // (1 − a)·τ/dt
  *b0 = 1.0 - g;
  *b1 = g - *a;
}

/// 1/(k+2)! for k = 0…19 (the factorials are exact in a double up to 21!).
constexpr std::array<double, 20> kInvFactorialPlus2 = [] {
  std::array<double, 20> c{};
  double f = 1.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    f *= static_cast<double>(k + 2);
    c[k] = 1.0 / f;
  }
  return c;
}();

/// The steps from the Taylor series to degree K of h = (1 − g)/r = Σ (−r)^k/(k+2)!: g = 1 − r·h =
/// (1 − a)/r and a = 1 − r·g without exp or division, g to about an ulp (FirstOrderStep's
/// (1 − a)/r loses digits as r → 0). b0 = 1 − g and b1 = g − a are formed as in FirstOrderStep:
/// differences of nearby numbers, so that a + b0 + b1 = 1 to rounding and a constant input does
/// not drift.
template <int K>
void FirstOrderSeries(const double* r, std::size_t len, FirstOrderChunk* k) {
  for (std::size_t j = 0; j < len; ++j) {
    const double h = lowpass::Horner<K>(kInvFactorialPlus2, -r[j]);
    const double g = 1.0 - r[j] * h;
    const double a = 1.0 - r[j] * g;
    k->a[j] = a;
    k->b0[j] = 1.0 - g;
    k->b1[j] = g - a;
  }
}

/// The degree FirstOrderSeries needs for steps up to r_max ≤ 1: the truncation of g,
/// r^(K+2)/(K+3)!, below 1e-17 (K = 16 for r_max = 1, K = 5 for 1/100).
int FirstOrderDegree(double r_max) {
  int degree = 0;
  double term = r_max * r_max / 6.0;
  while (term > 1e-17 && degree < 16) {
    ++degree;
    term *= r_max / (degree + 3);
  }
  return degree;
}

/// One step as the vector loops give it: the series for 0 ≤ r ≤ 1, else the closed form.
void FirstOrderExact(double r, double* a, double* b0, double* b1) {
  if (!(r >= 0.0 && r <= 1.0)) {
    FirstOrderStep(r, a, b0, b1);
    return;
  }
  const double h = lowpass::Horner<16>(kInvFactorialPlus2, -r);
  const double g = 1.0 - r * h;
  *a = 1.0 - r * g;
  *b0 = 1.0 - g;
  *b1 = g - *a;
}

/// The steps from ExpKernel, for chunks with a step beyond r = 1; the rows outside its range
/// (r < 1, where (1 − a)/r loses digits; long gaps, dt < 0) by FirstOrderExact.
void FirstOrderExp(const double* r, std::size_t len, FirstOrderChunk* k) {
  std::uint64_t outside = 0;
  for (std::size_t j = 0; j < len; ++j) {
    const double a = lowpass::ExpKernel(-r[j]);
    const double g = (1.0 - a) / r[j];
    k->a[j] = a;
    k->b0[j] = 1.0 - g;
    k->b1[j] = g - a;
    outside |= lowpass::Outside(r[j], 1.0, 700.0);
  }
  if (outside == 0) return;
  for (std::size_t j = 0; j < len; ++j) {
    if (!(r[j] >= 1.0 && r[j] <= 700.0)) FirstOrderExact(r[j], &k->a[j], &k->b0[j], &k->b1[j]);
  }
}

void FirstOrderCoefficients(const double* t_s, std::size_t i0, std::size_t len, double tau_s,
                            FirstOrderChunk* k) {
  alignas(64) double r[kChunk];
  const double inv_tau = 1.0 / tau_s;
  if (lowpass::ChunkSteps(t_s, i0, len, r)) {  // one dt: the closed form once, kept across chunks
    if (k->uniform && r[0] == k->uniform_dt) return;
    double a = 0.0;
    double b0 = 0.0;
    double b1 = 0.0;
    FirstOrderExact(r[0] * inv_tau, &a, &b0, &b1);
    std::fill(k->a, k->a + kChunk, a);
    std::fill(k->b0, k->b0 + kChunk, b0);
    std::fill(k->b1, k->b1 + kChunk, b1);
    k->uniform = true;
    k->uniform_dt = r[0];
    return;
  }
  k->uniform = false;
  for (std::size_t j = 0; j < len; ++j) r[j] *= inv_tau;
  double r_min = 0.0;
  double r_max = 0.0;
  lowpass::StepRange(r, len, &r_min, &r_max);
  if (!(r_min >= 0.0 && r_max <= 1.0)) {  // gaps, or τ below the sample period
    FirstOrderExp(r, len, k);
    return;
  }
  const int degree = FirstOrderDegree(r_max);
  if (degree <= 3) {
    FirstOrderSeries<3>(r, len, k);
  } else if (degree <= 5) {
    FirstOrderSeries<5>(r, len, k);
  } else if (degree <= 7) {
    FirstOrderSeries<7>(r, len, k);
  } else if (degree <= 10) {
    FirstOrderSeries<10>(r, len, k);
  } else if (degree <= 13) {
    FirstOrderSeries<13>(r, len, k);
  } else {
    FirstOrderSeries<16>(r, len, k);
  }
}

/// The recursion over the rows of a chunk for B columns at once (their states in registers). Row i
/// of column b is y[b][i − y_off] (y_off 0: whole columns; a stream's window otherwise).
template <int B>
void FirstOrderBlock(const FirstOrderChunk& k, std::size_t i0, std::size_t len,
                     const double* const* x, double* const* y, std::ptrdiff_t y_off,
                     const std::uint8_t* restart) {
  double yp[B];
  double xp[B];
  const auto at = [&](std::size_t i) { return static_cast<std::ptrdiff_t>(i) - y_off; };
  for (int b = 0; b < B; ++b) {
    yp[b] = y[b][at(i0 - 1)];
    xp[b] = x[b][i0 - 1];
  }
  for (std::size_t j = 0; j < len; ++j) {
    const std::size_t i = i0 + j;
    if (restart != nullptr && restart[i] != 0) {  // a new recording: at rest at its first input
      for (int b = 0; b < B; ++b) y[b][at(i)] = yp[b] = xp[b] = x[b][i];
      continue;
    }
    const double a = k.a[j];
    const double b0 = k.b0[j];
    const double b1 = k.b1[j];
    for (int b = 0; b < B; ++b) {
      const double xi = x[b][i];
      yp[b] = a * yp[b] + b0 * xi + b1 * xp[b];
      xp[b] = xi;
      y[b][at(i)] = yp[b];
    }
  }
}

/// FirstOrderBlock<8> without restarts, the eight columns' states in four-wide vectors: the same
/// products and sums in the same order per column (vector lanes round like scalars, and no FMA:
/// lowpass_kernels.hpp), so the same bits (and faster: docs/diagnosis.md).
void FirstOrderBlock8(const FirstOrderChunk& k, std::size_t i0, std::size_t len,
                      const double* const* x, double* const* y, std::ptrdiff_t y_off) {
  using V4 = double __attribute__((vector_size(32)));
  const auto at = [&](std::size_t i) { return static_cast<std::ptrdiff_t>(i) - y_off; };
  // (Out-parameters: a lambda returning a 32-byte vector is an ABI note without AVX.)
  const auto load = [](const double* const* p, int b0, std::ptrdiff_t i, V4* v) {
    *v = V4{p[b0][i], p[b0 + 1][i], p[b0 + 2][i], p[b0 + 3][i]};
  };
  V4 ylo;
  V4 yhi;
  V4 xlo;
  V4 xhi;
  load(y, 0, at(i0 - 1), &ylo);
  load(y, 4, at(i0 - 1), &yhi);
  load(x, 0, static_cast<std::ptrdiff_t>(i0 - 1), &xlo);
  load(x, 4, static_cast<std::ptrdiff_t>(i0 - 1), &xhi);
  for (std::size_t j = 0; j < len; ++j) {
    const auto i = static_cast<std::ptrdiff_t>(i0 + j);
    const V4 a = {k.a[j], k.a[j], k.a[j], k.a[j]};
    const V4 b0 = {k.b0[j], k.b0[j], k.b0[j], k.b0[j]};
    const V4 b1 = {k.b1[j], k.b1[j], k.b1[j], k.b1[j]};
    V4 nlo;
    V4 nhi;
    load(x, 0, i, &nlo);
    load(x, 4, i, &nhi);
    ylo = a * ylo + b0 * nlo + b1 * xlo;
    yhi = a * yhi + b0 * nhi + b1 * xhi;
    xlo = nlo;
    xhi = nhi;
    const std::ptrdiff_t o = at(i0 + j);
    for (int b = 0; b < 4; ++b) {
      y[b][o] = ylo[b];
      y[b + 4][o] = yhi[b];
    }
  }
}

/// FirstOrderBlock for 0 ≤ m < 8 columns.
void FirstOrderBlocks(std::size_t m, const FirstOrderChunk& k, std::size_t i0, std::size_t len,
                      const double* const* x, double* const* y, std::ptrdiff_t y_off,
                      const std::uint8_t* restart) {
  if (m == 7) FirstOrderBlock<7>(k, i0, len, x, y, y_off, restart);
  if (m == 6) FirstOrderBlock<6>(k, i0, len, x, y, y_off, restart);
  if (m == 5) FirstOrderBlock<5>(k, i0, len, x, y, y_off, restart);
  if (m == 4) FirstOrderBlock<4>(k, i0, len, x, y, y_off, restart);
  if (m == 3) FirstOrderBlock<3>(k, i0, len, x, y, y_off, restart);
  if (m == 2) FirstOrderBlock<2>(k, i0, len, x, y, y_off, restart);
  if (m == 1) FirstOrderBlock<1>(k, i0, len, x, y, y_off, restart);
}

/// Rows [i_begin, i_end) (i_begin ≥ 1, i_begin − 1 a multiple of kChunk, so that every caller
/// computes the coefficients over the same chunks and gets the same bits) of m columns, row i of
/// column c at y[c][i − y_off]; row i_begin − 1 must be there already.
// Flattened: every helper inlined, which the compiler does not do on its own here and which is
// measurably faster (the loops are then compiled with what the caller knows).
FTSTACK_LOWPASS_TARGETS [[gnu::flatten]] void FirstOrderRows(
    const double* t_s, std::size_t i_begin, std::size_t i_end, double tau_s, const double* const* x,
    double* const* y, std::ptrdiff_t y_off, std::size_t m, const std::uint8_t* restart,
    FirstOrderChunk* k) {
  for (std::size_t i0 = i_begin; i0 < i_end; i0 += kChunk) {
    const std::size_t len = std::min(kChunk, i_end - i0);
    FirstOrderCoefficients(t_s, i0, len, tau_s, k);
    // All columns of a chunk in one pass (up to eight: every input and output stream at once is
    // what the memory system likes best here).
    std::size_t c = 0;
    for (; c + 8 <= m; c += 8) {
      if (restart == nullptr) {
        FirstOrderBlock8(*k, i0, len, x + c, y + c, y_off);
      } else {
        FirstOrderBlock<8>(*k, i0, len, x + c, y + c, y_off, restart);
      }
    }
    FirstOrderBlocks(m - c, *k, i0, len, x + c, y + c, y_off, restart);
  }
}

}  // namespace

void FirstOrderLowPass(const double* t_s, const double* x, std::size_t n, double tau_s, double* y) {
  FirstOrderLowPassColumns(t_s, n, tau_s, &x, &y, 1);
}

void FirstOrderLowPassColumns(const double* t_s, std::size_t n, double tau_s,
                              const double* const* x, double* const* y, std::size_t m,
                              const std::uint8_t* restart) {
  if (n == 0) return;
  for (std::size_t c = 0; c < m; ++c) y[c][0] = x[c][0];
  FirstOrderChunk k;
  FirstOrderRows(t_s, 1, n, tau_s, x, y, 0, m, restart, &k);
}

static_assert(LowPassWindows::kRows % kChunk == 0, "windows must start on chunk bounds");

LowPassWindows::LowPassWindows(const double* t_s, std::size_t n, const double* const* x,
                               std::size_t m, const std::uint8_t* restart)
    : t_s_(t_s), n_(n), x_(x, x + m), restart_(restart), y_(m), buf_(m * (kRows + 2)) {
  for (std::size_t c = 0; c < m; ++c) y_[c] = buf_.data() + c * (kRows + 2);
}

bool LowPassWindows::Next() {
  if (next_ >= n_) return false;
  const std::size_t m = x_.size();
  // Slot 0 of a column holds row begin − 1 (the last output), slot s row begin − 1 + s.
  if (next_ == 0) {
    begin_ = 0;
    for (std::size_t c = 0; c < m; ++c) y_[c][1] = x_[c][0];
    Start();
    next_ = 1;
  } else {
    begin_ = next_;
    for (std::size_t c = 0; c < m; ++c) y_[c][0] = y_[c][size_];
  }
  const std::size_t end = std::min(n_, next_ + kRows);
  FilterRows(next_, end, static_cast<std::ptrdiff_t>(begin_) - 1);
  size_ = end - begin_;
  next_ = end;
  return true;
}

struct FirstOrderLowPassStream::Coefficients {
  FirstOrderChunk k;
};

FirstOrderLowPassStream::FirstOrderLowPassStream(const double* t_s, std::size_t n, double tau_s,
                                                 const double* const* x, std::size_t m,
                                                 const std::uint8_t* restart)
    : LowPassWindows(t_s, n, x, m, restart), tau_s_(tau_s), k_(std::make_unique<Coefficients>()) {}

FirstOrderLowPassStream::~FirstOrderLowPassStream() = default;

void FirstOrderLowPassStream::FilterRows(std::size_t i_begin, std::size_t i_end,
                                         std::ptrdiff_t y_off) {
  FirstOrderRows(t_s_, i_begin, i_end, tau_s_, x_.data(), y_.data(), y_off, x_.size(), restart_,
                 &k_->k);
}

}  // namespace ftstack::diag
