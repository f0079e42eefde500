// Physical effects a sensor model may leave out, injected into simulated recordings
// (docs/effects.md).
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "measurement/effect_vocabulary.hpp"
#include "sim/load_profile.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// An --effect argument that cannot be used: unknown name or key, value not a finite number, …
class EffectSpecError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The effect kinds of the vocabulary (measurement/effect_vocabulary.hpp, docs/spec/diagnosis.md).
using ftstack::EffectKind;

/// All effect names, in vocabulary order.
[[nodiscard]] const std::vector<std::string>& EffectNames();
/// Keys the injector accepts for an effect, from the vocabulary (throws EffectSpecError for an
/// unknown name). Aliases (older keys, docs/effects.md) are accepted too and read as these keys.
[[nodiscard]] std::vector<std::string> EffectKeys(const std::string& name);

/// A parsed `NAME[:k=v,k=v,...]`. Values are kept as text until resolved against a sensor.
/// Lists are written `[a,b,c]` or `a/b/c`; channels are 0-based bridge indices or `all`.
struct EffectSpec {
  std::string text;  ///< as given, for messages
  std::string name;
  std::vector<std::pair<std::string, std::string>> params;
};

/// Parses and checks name, keys and value syntax (numbers finite, lists well formed, axis names).
[[nodiscard]] EffectSpec ParseEffectSpec(const std::string& text);

/// An effect with every parameter fixed (defaults filled in, deterministic per seed).
struct Effect {
  EffectKind kind = EffectKind::kNone;
  std::string name = "none";
  std::map<std::string, double> num;  ///< scalar parameters (tau_s, gain, limit, …)
  std::vector<double> per_channel;    ///< per-channel values (offset, coef_per_K), size N, or empty
  std::string per_channel_key;        ///< name of that parameter
  std::vector<int> channels;          ///< bridges affected (output-side effects)
  int axis = -1;                      ///< misalignment: 0 x, 1 y, 2 z; overload: wrench index
  std::uint64_t seed = 0;             ///< for generated signals (drift wander)
};

/// What resolving defaults needs to know about the recording being made.
struct EffectContext {
  int channels = 6;
  Wrench rated = Wrench::Ones();
  Eigen::MatrixXd sensitivity;  ///< N × 6, mV/V per N or N·m
  double duration_s = 0.0;
  double rate_hz = 200.0;
  double t0_c = 20.0;  ///< temperature at t = 0
  std::uint64_t seed = 1;
};

/// Fills in defaults and checks ranges against the sensor; `index` decorrelates several effects.
[[nodiscard]] Effect ResolveEffect(const EffectSpec& spec, const EffectContext& ctx, int index);

/// The effect's axis as written in params: x/y/z (misalignment), Fx…Mz (overload), "" if none.
[[nodiscard]] std::string EffectAxisName(const Effect& e);

/// The sampled inputs every effect works from.
struct ComposeInput {
  const SensorModel* model = nullptr;
  const LoadProfile* profile = nullptr;
  std::vector<double> t_s;     ///< sample times, uniform
  std::vector<double> temp_c;  ///< body temperature per sample
  Wrench rated = Wrench::Ones();
  /// When t_s is one piece of a longer recording: a grid of the whole recording's times (slow
  /// wanders are laid out and scaled to their RMS over it), the piece's first row in the
  /// recording and the recording's rows (converter glitches are placed over all of them).
  const std::vector<double>* span_t_s = nullptr;
  std::size_t row0 = 0;
  std::size_t span_rows = 0;
};

/// Bridge outputs (N × samples, mV/V, noise-free) with `effects` applied; no effects gives the
/// model's own prediction. Effects combine in a fixed physical order (docs/effects.md).
[[nodiscard]] Eigen::MatrixXd Compose(const std::vector<Effect>& effects, const ComposeInput& in);

/// Inserts the overload that an overload_shift effect needs into the load: a trapezoid on the
/// effect's axis reaching factor × rated at onset_s, held 0.3 s, back to zero 0.6 s after onset.
void InsertOverload(const Effect& e, LoadProfile& profile, const Wrench& rated);

/// Slow random wander (sum of 12 sinusoids with 1/f amplitudes between ≈1/(4·duration) and
/// corner_hz, random phases), zero at t[0] and scaled to RMS `amplitude` over t. With `span_t_s`
/// the duration, the zero and the RMS are those of that grid (t_s a piece of it).
[[nodiscard]] std::vector<double> Wander(const std::vector<double>& t_s, double amplitude,
                                         double corner_hz, std::uint64_t seed,
                                         const std::vector<double>* span_t_s = nullptr);

}  // namespace ftstack::sim
