// The diagnosis context: the residual, its noise, the hold-out split and what every effect shares,
// and the hold-out scores of a prediction.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "diagnosis/engine/conditioning.hpp"
#include "diagnosis/engine/lag_cache.hpp"
#include "diagnosis/engine/quantisation.hpp"
#include "diagnosis/loader/data.hpp"

namespace ftstack::diag {

/// A per-row series of every channel (n × N, mV/V) held in single precision: the residual, the
/// fits' targets and their predictions. Memory: 4 bytes a value (at 10^6 rows × 8 channels, 32 MB
/// instead of 64 MB); the rounding, 6e-8 of the value, is far below the noise of any recording.
/// Every sum over a Series is accumulated in double.
using Series = Eigen::MatrixXf;

/// The sim's load (n × N, mV/V) as the context holds it: read-only once made and shared by the
/// context's copies, so that a copy for a piece of the record (other training rows) holds the
/// handle and not the n × N values.
class SharedLoad {
 public:
  SharedLoad() : m_(std::make_shared<const Eigen::MatrixXd>()) {}
  SharedLoad& operator=(Eigen::MatrixXd m) {
    m_ = std::make_shared<const Eigen::MatrixXd>(std::move(m));
    return *this;
  }
  [[nodiscard]] double operator()(Eigen::Index i, Eigen::Index c) const { return (*m_)(i, c); }
  [[nodiscard]] auto col(Eigen::Index c) const { return m_->col(c); }
  [[nodiscard]] Eigen::Index rows() const { return m_->rows(); }
  [[nodiscard]] Eigen::Index cols() const { return m_->cols(); }
  [[nodiscard]] const Eigen::MatrixXd& matrix() const { return *m_; }
  operator const Eigen::MatrixXd&() const { return *m_; }  // NOLINT(google-explicit-constructor)

 private:
  std::shared_ptr<const Eigen::MatrixXd> m_;
};

/// Everything the effect models share, computed once from the data.
struct Context {
  const DiagData* data = nullptr;
  int n = 0;                        ///< rows
  int nc = 0;                       ///< channels
  Series resid;                     ///< n × N real − sim, mV/V
  Eigen::VectorXd sigma;            ///< robust noise per channel, mV/V
  Eigen::VectorXd weight;           ///< 1/σ² per channel
  std::vector<std::uint8_t> train;  ///< 1 = row used for fitting, 0 = held out (or excluded)
  /// 1 = row kept out of every fit and every hold-out score (a converter glitch, a load transition
  /// the real load lagged: conditioning.hpp); empty when none is.
  std::vector<std::uint8_t> excluded;
  Conditioning conditioning;  ///< glitches, transitions and quiet noise found before the fits
  /// The real bridges' value grid (declared or inferred): effects within kResolvableSteps of it
  /// are not claimed (NotResolved).
  Quantisation quantisation;
  std::size_t n_train = 0;
  std::size_t n_hold = 0;
  double block_s = 0.0;        ///< length of the interleaved hold-out blocks
  Eigen::VectorXd zero;        ///< sim at zero wrench per channel (regression intercept), mV/V
  SharedLoad load;             ///< n × N: sim − zero (the load-induced part); shared by copies
  Eigen::MatrixXd sens;        ///< N × 6 sim sensitivity d(mV/V)/d(wrench) by regression
  Eigen::VectorXd load_range;  ///< per channel max − min of load, mV/V
  std::vector<double> dtemp;   ///< temp − 20 °C; empty without temperature
  bool uniform = true;         ///< sampling uniform to 1e-6 relative
  double dt = 0.0;             ///< median sample interval, s
  double rate_hz = 0.0;
  int search_stride =
      1;  ///< row step used inside nonlinear parameter searches (final fits use all)
  /// 1 at the first row of every segment after the first (DiagData::segment): stateful models
  /// restart there and hold-out blocks never straddle it. Empty for one recording.
  std::vector<std::uint8_t> restart;
  int segments = 1;             ///< number of joined recordings
  std::vector<double> peak_hz;  ///< prominent lines of the residual spectrum, strongest first
  /// The load's lags the searches computed (lag_cache.hpp); shared by the fits on this context.
  std::shared_ptr<LagCache> lag_cache;
  std::vector<double> peak_ratio;
  /// Worker threads (≥ 1) for the engine's own per-channel and per-piece work on this context;
  /// the results do not depend on it.
  int threads = 1;

  /// Whether row i is a held-out row (not trained on, not excluded).
  [[nodiscard]] bool held_out(std::size_t i) const {
    return train[i] == 0 && (excluded.empty() || excluded[i] == 0);
  }

  /// The sim's output of row i, channel c, mV/V (load + zero: the data's sim_mvv may be released).
  [[nodiscard]] double sim_mvv(int i, int c) const { return load(i, c) + zero(c); }
};

/// Builds the context: residual, noise, hold-out blocks (every third block of ~block_s).
/// `sigma` (one per channel), when given, replaces the robust noise estimate.
/// `threads`: as DiagnoseOptions::threads (0: the machine's).
[[nodiscard]] Context MakeContext(const DiagData& d, double block_s = 0.5,
                                  const Eigen::VectorXd* sigma = nullptr, int threads = 0);
/// The same, taking the memory of d->real_mvv and d->sim_mvv for the residual and the load (both
/// are left empty; d->released_channels keeps their width). Memory: two n × N matrices fewer.
[[nodiscard]] Context MakeContext(DiagData* d, double block_s = 0.5,
                                  const Eigen::VectorXd* sigma = nullptr, int threads = 0);
/// A copy of *cx for refits on other training rows (the pieces of the record): it shares the load
/// and leaves the residual out (a refit fits a target of its own), so it holds the row masks and
/// the temperature only. Leaves *cx as it was.
[[nodiscard]] Context RefitCopy(Context* cx);
/// Replaces the context's noise per channel (and what depends on it: weights, spectral lines);
/// the same as MakeContext with `sigma`, without the data's bridge matrices.
void SetNoise(Context* cx, const Eigen::VectorXd& sigma);

/// Whitened sums over train or hold-out rows.
struct Sums {
  double train_sse = 0.0;
  double hold_sse = 0.0;
  double hold_pp = 0.0;  ///< Σ (pred)²/σ² on hold-out rows
};
[[nodiscard]] Sums Score(const Context& cx, const Series& target, const Series* pred);
/// Score(cx, target, &(a + b)) without the n × N sum (the same sums, element by element).
[[nodiscard]] Sums ScoreSum(const Context& cx, const Series& target, const Series& a,
                            const Series& b);

}  // namespace ftstack::diag
