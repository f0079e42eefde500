// Data conditioning before the effect fits: isolated converter glitches, load transitions whose
// real load settles later than the reference says, and each channel's noise in its quietest holds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ftstack::diag {

struct Context;

/// One isolated wrong code: a sample far from its four neighbours, which agree with each other.
struct Glitch {
  int row = 0;
  int channel = 0;
  double t_s = 0.0;
  double offset_mvv = 0.0;  ///< the sample minus the line through its four neighbours, mV/V
};

/// One change of the reference load between two holds, and the rows where the real load had not
/// reached it (application, bounce): those rows are kept out of every fit and every hold-out score.
struct Transition {
  int first_row = 0;  ///< first row of the reference's change
  /// The lagging channel whose real load is off the reference over the most rows (its own
  /// window), else (none lags) the channel with the largest change relative to its range.
  int channel = 0;
  double t_s = 0.0;            ///< time of the reference's change
  double step_mvv = 0.0;       ///< the reference's change on `channel`, mV/V
  double application_s = 0.0;  ///< the real load's 10–90 % rise time / 0.8 (a linear ramp's length)
  double excluded_from_s = 0.0;
  double excluded_to_s = 0.0;  ///< 0 rows excluded when from > to
  bool excluded = false;       ///< the real load lagged the reference: its rows are excluded
};

/// A channel's noise measured in its quietest holds (robust σ of first differences).
struct QuietNoise {
  double sigma_mvv = 0.0;  ///< 0 when no hold was long enough
  /// The median σ of the long-enough holds within kQuietClass × the quietest (the quietest of many
  /// holds alone reads low): what the fit weights use; 0 when no hold was long enough.
  double typical_sigma_mvv = 0.0;
  double from_s = 0.0;  ///< the hold it was measured in
  double to_s = 0.0;
  int holds = 0;  ///< holds long enough to measure in
};

/// What the conditioning found; the context's `excluded` rows follow from it.
struct Conditioning {
  std::vector<Glitch> glitches;
  std::vector<Transition> transitions;
  std::vector<QuietNoise> noise;  ///< per channel
  std::size_t excluded_rows = 0;  ///< rows out of every fit and score (glitches, transitions)
};

/// A glitch lies this many robust σ of first differences from the line through its neighbours (a
/// load step never does: its neighbours leave that line by as much as it does).
inline constexpr double kGlitchSigmas = 30.0;
/// ... and as many σ of the first differences about their median within kGlitchReach rows each
/// side of it (a knock or a bouncing weight raises those; a steady ramp does not).
inline constexpr int kGlitchReach = 10;
/// Rows a hold needs before its noise is preferred (the robust σ of n differences scatters by about
/// 1.17/√n: 8 % here), so the quietest hold is not merely the luckiest short one.
inline constexpr int kQuietHoldRows = 200;
/// Holds within this factor of the quietest one's σ count as quiet for the typical quiet σ.
inline constexpr double kQuietClass = 1.5;
/// A transition's rows are those where the normalised real load is further than this from the
/// normalised reference (bounce and ringing of a few % stay in).
inline constexpr double kTransitionBand = 0.1;
/// A lagging change's window reaches back over rows further than this many robust σ (of the level
/// before the change) from that level: a smooth ramp's foot, already well out of the noise.
inline constexpr double kTransitionFootSigmas = 4.0;
/// ... and on while the activity over a second is more than this factor above the level it settles
/// to 3 to kSettleSeconds seconds later: a bounce that dies within seconds (a swing that lasts
/// minutes never is).
inline constexpr double kBounceDecayFactor = 2.0;
inline constexpr int kSettleSeconds = 5;

/// Finds glitches and transitions in the context's residual and load, replaces glitch samples of
/// the residual by the line through their neighbours, marks glitch and lagging-transition rows in
/// cx->excluded (out of train and hold-out rows, counts updated) and measures the quiet noise.
void ConditionData(Context* cx);

}  // namespace ftstack::diag
