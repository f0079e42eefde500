// Calibration with known masses: reference wrenches from mass, arm and gravity; jig identification.
#pragma once

#include <array>
#include <stdexcept>
#include <string>

#include "measurement/recording.hpp"

namespace ftstack::cal {

/// A known-mass recording whose jig cannot be identified; what() says why and what to add.
class JigIdentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The columns of a known-mass recording (docs/spec/recording-format.md): the known mass hung on
/// the jig, the point it hangs from (lever arm, sensor frame) and gravity in the sensor frame.
inline constexpr const char* kKnownMassColumns[7] = {"mass_kg", "arm_x_m", "arm_y_m", "arm_z_m",
                                                     "gx_mps2", "gy_mps2", "gz_mps2"};

/// True if `rec` has a mass_kg column (it is then a known-mass recording).
[[nodiscard]] bool IsKnownMassRecording(const Recording& rec);

/// Adds (replaces) Fx … Mz: F = m·g, M = arm × (m·g) per row. Throws RecordingError naming the
/// file for a missing column and the line for a negative mass or a |g| outside 1 … 50 m/s².
[[nodiscard]] Recording WithReferenceFromMasses(const Recording& rec);

/// The loading jig (everything between the sensor and the known masses that is always there).
struct JigEstimate {
  double mass_kg = 0;
  std::array<double, 3> com_m{};
  double mass_sigma_kg = 0;  ///< 1 σ, from the weighted residuals
  std::array<double, 3> com_sigma_m{};
  double condition = 0;               ///< condition number of the (normalised) jig normal matrix
  double surviving_fraction_min = 0;  ///< least share of a jig column not explained by [1, b]
};

/// Identifies the jig from a recording with bridges b0… and reference Fx … Mz (from masses) and
/// the gravity columns: solves the known load + the jig's load (m_j·g, (m_j·c_j) × g) = an
/// affine function of the bridges, jointly, by least squares (the calibration eliminated by
/// projection; axes weighted by their residual σ from a first pass). Throws JigIdentError when
/// the holds cannot separate the jig from the calibration's offsets (e.g. one orientation only).
[[nodiscard]] JigEstimate IdentifyJig(const Recording& rec);

/// Adds the jig's load to Fx … Mz of every row (the reference then is everything the sensor
/// carries).
[[nodiscard]] Recording WithJig(const Recording& rec, const JigEstimate& jig);

}  // namespace ftstack::cal
