// Inputs of a sim-vs-real diagnosis: aligned time, reference wrench, temperature, predicted and
// measured bridges.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "measurement/recording.hpp"
#include "measurement/units.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::diag {

/// Input that cannot be diagnosed; what() is one line naming the file (and line:column where
/// known).
class DiagInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One aligned pair of recordings, column-major (row i is sample i).
struct DiagData {
  std::vector<double> t_s;  ///< sample times, s, strictly increasing
  /// n × 6: Fx Fy Fz (N) Mx My Mz (N·m), 0 columns when absent; single precision (memory: the
  /// rounding, 6e-8 of the value, is far below any reference rig's uncertainty).
  Eigen::MatrixXf wrench;
  std::vector<double> temp_c;  ///< body temperature, °C; empty when the real file has none
  Eigen::MatrixXd sim_mvv;     ///< n × N predicted bridge outputs, mV/V
  Eigen::MatrixXd real_mvv;    ///< n × N measured bridge outputs, mV/V
  std::string sim_name;        ///< where the prediction came from (file or sensor description)
  std::string real_name;       ///< the real recording's path
  /// Recording of every row (0, 1, …) when separate recordings were joined: the real file's
  /// `segment` column, else a new one after every time gap over kSegmentGapPeriods median
  /// periods. Empty: one recording.
  std::vector<int> segment;
  std::string real_unit = "mV/V";  ///< the real file's declared bridge unit (converted to mV/V)
  std::string real_unit_symbol = "mV/V";  ///< that unit's symbol: mV/V, V or counts
  double real_units_per_mvv = 1.0;  ///< the declared unit's values per mV/V (0: scale unknown)
  /// The real file declares the codes of a ratiometric converter (its reference follows the
  /// bridge excitation): a drift of the excitation cancels in every reading.
  bool real_ratiometric = false;
  /// Bridges whose sim_mvv and real_mvv became a context's load and residual
  /// (MakeContext(DiagData*), which leaves both matrices empty to save their memory); 0 while they
  /// are held here.
  int released_channels = 0;

  [[nodiscard]] std::size_t rows() const { return t_s.size(); }
  [[nodiscard]] int channels() const {
    return real_mvv.cols() > 0 ? static_cast<int>(real_mvv.cols()) : released_channels;
  }
  [[nodiscard]] bool has_wrench() const { return wrench.cols() == 6; }
  [[nodiscard]] bool has_temp() const { return !temp_c.empty(); }
  /// Median sample rate, Hz.
  [[nodiscard]] double rate_hz() const;
};

/// A time step longer than this many median sample periods starts a new segment.
inline constexpr double kSegmentGapPeriods = 10.0;

/// Segments of a recording (see DiagData::segment): its `segment` column (rows with equal values
/// form one segment, renumbered in order of first row), else the time gaps; empty for one segment.
[[nodiscard]] std::vector<int> FindSegments(const Recording& real);

/// Progress callback: (fraction done 0…1, what is happening).
using ProgressFn = void (*)(double fraction, const char* stage, void* user);

/// How the real recording's bridge unit is decided: `rule`, where given, converts the bridge
/// columns in place to mV/V (refusing what cannot be its unit) and returns the unit they were in
/// and the source that decided it; else the recording's declaration, overridden by `cli`, with
/// the range of the declared converter (undeclared: of the assumed one, ±3.90625 mV/V).
struct RealUnits {
  UnitOverrides cli;
  std::function<InputUnit(Recording* real)> rule;
};

/// Builds the pair from two recordings already read: checks bridge counts and alignment.
[[nodiscard]] DiagData FromRecordings(const Recording& sim, const Recording& real);
/// Reads SIM.csv and REAL.csv (recording-format.md) and aligns them.
[[nodiscard]] DiagData LoadSimReal(const std::string& sim_path, const std::string& real_path,
                                   ProgressFn progress = nullptr, void* user = nullptr,
                                   const RealUnits& units = {});
/// Predicts the outputs (mV/V) of every bridge for a wrench (N, N·m) and a temperature (°C).
using BridgePredictor = std::function<void(const Wrench& w, double temperature_c, double* out_mvv)>;
/// Reads REAL.csv and predicts its bridges with `predict` (a model of `channels` bridges named
/// `model_name`) from the real wrench and temp_C (20 °C where absent).
[[nodiscard]] DiagData LoadPredictedReal(const std::string& real_path,
                                         const std::string& model_name, int channels,
                                         const BridgePredictor& predict,
                                         ProgressFn progress = nullptr, void* user = nullptr,
                                         const RealUnits& units = {});

}  // namespace ftstack::diag
