// Composition of resolved effects into bridge outputs (docs/effects.md, "Order of application"):
// the load the sensor sees, the model, dynamics on the load part, read-out and additive signals,
// clipping; plus the slow wander and the overload an overload_shift needs.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "measurement/numerics.hpp"
#include "sim/effects.hpp"

namespace ftstack::sim {
namespace {

Eigen::Matrix3d Rotation(int axis, double angle_deg) {
  const Eigen::Vector3d ax = Eigen::Vector3d::Unit(axis);
  return Eigen::AngleAxisd(angle_deg * std::numbers::pi / 180.0, ax).toRotationMatrix();
}

constexpr int kPlays = 8;
using PlayState = std::array<double, 6 * kPlays>;

// Prandtl–Ishlinskii: the mean of kPlays play operators with thresholds width·rated·j/kPlays,
// each normalised to ±1, scaled to amplitude·rated. `first` starts the plays relaxed.
Wrench HysteresisOffset(const Effect& e, const Wrench& w, const Wrench& r, const PlayState& thr,
                        PlayState& play, bool first) {
  Wrench d = Wrench::Zero();
  for (int k = 0; k < 6; ++k) {
    for (int j = 0; j < kPlays; ++j) {
      const auto idx = static_cast<std::size_t>(k * kPlays + j);
      double& pj = play[idx];
      pj = first ? w(k) : numerics::PlayStep(pj, w(k), thr[idx]);
      d(k) += (pj - w(k)) / thr[idx];
    }
    d(k) *= e.num.at("amplitude") * r(k) / kPlays;
  }
  return d;
}

// Stage 1: the load the sensor actually sees (time skew, misalignment, load stiffening,
// geometric nonlinearity, hysteresis, in the effects' order).
std::vector<Wrench> SeenLoad(const std::vector<Effect>& effects, const ComposeInput& in) {
  const Wrench& r = in.rated;
  double delay = 0.0;
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kTimeSkew) delay += e.num.at("delay_s");
  }
  std::vector<PlayState> play(effects.size());
  std::vector<PlayState> thresholds(effects.size());
  std::vector<Eigen::Matrix3d> rot_t(effects.size(), Eigen::Matrix3d::Identity());
  for (std::size_t ei = 0; ei < effects.size(); ++ei) {
    const Effect& e = effects[ei];
    if (e.kind == EffectKind::kHysteresis) {
      for (int k = 0; k < 6; ++k) {
        for (int j = 0; j < kPlays; ++j) {
          thresholds[ei][static_cast<std::size_t>(k * kPlays + j)] =
              e.num.at("width") * r(k) * (j + 1) / kPlays;
        }
      }
    } else if (e.kind == EffectKind::kMisalignment) {
      rot_t[ei] = Rotation(e.axis, e.num.at("angle_deg")).transpose();
    }
  }
  std::vector<Wrench> seen(in.t_s.size());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    Wrench w = in.profile->LoadAt(in.t_s[i] - delay);
    for (std::size_t ei = 0; ei < effects.size(); ++ei) {
      const Effect& e = effects[ei];
      switch (e.kind) {
        case EffectKind::kMisalignment: {
          // Sensor frame rotated by angle about the axis: it sees the load's components Rᵀ·F, Rᵀ·M.
          const Eigen::Matrix3d& rt = rot_t[ei];
          const Eigen::Vector3d f = rt * w.head<3>();
          const Eigen::Vector3d m = rt * w.tail<3>();
          w.head<3>() = f;
          w.tail<3>() = m;
          break;
        }
        case EffectKind::kLoadStiffening: {
          const double g = e.num.at("coef") * w(2) / r(2);
          for (const int k : {0, 1, 3, 4}) w(k) *= 1.0 + g;
          break;
        }
        case EffectKind::kGeometricNonlinearity:
          for (int k = 0; k < 6; ++k)
            w(k) += e.num.at("coef") * w(k) * (w(k) / r(k)) * (w(k) / r(k));
          break;
        case EffectKind::kHysteresis:
          w += HysteresisOffset(e, w, r, thresholds[ei], play[ei], i == 0);
          break;
        default:
          break;
      }
    }
    seen[i] = w;
  }
  return seen;
}

// Stage 3: dynamics (creep, resonance) and sensitivity changes (thermal span drift, gain error) on
// the load part `load` (N × samples), sampled every h_s.
void LoadPartEffects(const std::vector<Effect>& effects, const ComposeInput& in, double h_s,
                     Eigen::MatrixXd& load) {
  const std::size_t ns = in.t_s.size();
  auto row = [&](int ch) {
    std::vector<double> u(ns);
    for (std::size_t i = 0; i < ns; ++i) u[i] = load(ch, static_cast<Eigen::Index>(i));
    return u;
  };
  for (const auto& e : effects) {
    if (e.kind != EffectKind::kCreep) continue;
    const numerics::FohSystem sys = numerics::FirstOrderLagFoh(e.num.at("tau_s"), h_s);
    for (const int ch : e.channels) {
      const auto u = row(ch);
      const auto x = numerics::FohResponse(sys, Eigen::RowVectorXd::Ones(1),
                                           Eigen::VectorXd::Constant(1, u[0]), u);
      for (std::size_t i = 0; i < ns; ++i)
        load(ch, static_cast<Eigen::Index>(i)) += e.num.at("fraction") * x[i];
    }
  }
  for (const auto& e : effects) {
    if (e.kind != EffectKind::kResonance) continue;
    const numerics::FohSystem sys =
        numerics::SecondOrderFoh(e.num.at("freq_hz"), e.num.at("damping_ratio"), h_s);
    Eigen::RowVectorXd c(2);
    c << 1.0, 0.0;
    for (const int ch : e.channels) {
      const auto u = row(ch);
      const auto y = numerics::FohResponse(sys, c, Eigen::Vector2d(u[0], 0.0), u);
      // Only the mode's share of the output rings: L + p·(y − L).
      const double p = e.num.at("participation");
      for (std::size_t i = 0; i < ns; ++i) {
        load(ch, static_cast<Eigen::Index>(i)) = u[i] + p * (y[i] - u[i]);
      }
    }
  }
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kThermalSpanDrift) {
      for (const int ch : e.channels) {
        for (std::size_t i = 0; i < ns; ++i) {
          load(ch, static_cast<Eigen::Index>(i)) *=
              1.0 + e.num.at("coef_per_K") * (in.temp_c[i] - e.num.at("t0_c"));
        }
      }
    } else if (e.kind == EffectKind::kGainError) {
      for (const int ch : e.channels) load.row(ch) *= e.num.at("gain");
    }
  }
}

// Stage 5: additive signals on the whole output.
void AdditiveEffects(const std::vector<Effect>& effects, const ComposeInput& in,
                     Eigen::MatrixXd& out) {
  const std::size_t ns = in.t_s.size();
  for (const auto& e : effects) {
    switch (e.kind) {
      case EffectKind::kZeroOffset:
        for (const int ch : e.channels)
          out.row(ch).array() += e.per_channel[static_cast<std::size_t>(ch)];
        break;
      case EffectKind::kZeroDrift: {
        for (const int ch : e.channels) {
          const auto d =
              Wander(in.t_s, e.num.at("amplitude_mvv"), e.num.at("corner_hz"),
                     e.seed + static_cast<std::uint64_t>(ch) * 0x9E3779B9ULL, in.span_t_s);
          for (std::size_t i = 0; i < ns; ++i) out(ch, static_cast<Eigen::Index>(i)) += d[i];
        }
        break;
      }
      case EffectKind::kThermalZeroDrift:
        for (const int ch : e.channels) {
          for (std::size_t i = 0; i < ns; ++i) {
            out(ch, static_cast<Eigen::Index>(i)) +=
                e.per_channel[static_cast<std::size_t>(ch)] * (in.temp_c[i] - e.num.at("t0_c"));
          }
        }
        break;
      case EffectKind::kOverloadShift:
        for (std::size_t i = 0; i < ns; ++i) {
          if (in.t_s[i] >= e.num.at("onset_s")) {
            for (Eigen::Index ch = 0; ch < out.rows(); ++ch)
              out(ch, static_cast<Eigen::Index>(i)) += e.per_channel[static_cast<std::size_t>(ch)];
          }
        }
        break;
      case EffectKind::kMainsInterference: {
        const double w = 2.0 * std::numbers::pi * e.num.at("freq_hz");
        const double ph = e.num.at("phase_deg") * std::numbers::pi / 180.0;
        for (std::size_t i = 0; i < ns; ++i) {
          const double v = e.num.at("amplitude_mvv") * std::sin(w * in.t_s[i] + ph);
          for (const int ch : e.channels) out(ch, static_cast<Eigen::Index>(i)) += v;
        }
        break;
      }
      default:
        break;
    }
  }
}

/// `count` wrong codes at seeded rows (never the first or last two, at least five rows apart),
/// each on one of the effect's channels, ± offset_mvv with a seeded sign.
void AddConverterGlitches(const Effect& e, const ComposeInput& in, Eigen::MatrixXd& out) {
  const auto ns = static_cast<int>(in.span_rows > 0 ? in.span_rows : out.cols());
  const auto row0 = static_cast<int>(in.row0);
  const auto count = static_cast<int>(e.num.at("count"));
  if (ns < 5 || e.channels.empty()) return;
  SeededRandom rng(e.seed ^ 0x6C62272E07BB0142ULL);
  std::vector<int> rows;
  for (int tries = 0; static_cast<int>(rows.size()) < count && tries < 100 * count; ++tries) {
    const int row = 2 + rng.Index(ns - 4);
    const bool near =
        std::any_of(rows.begin(), rows.end(), [row](int r) { return std::abs(r - row) < 5; });
    if (near) continue;
    rows.push_back(row);
    const int ch =
        e.channels[static_cast<std::size_t>(rng.Index(static_cast<int>(e.channels.size())))];
    const double offset = (rng.Uniform() < 0.5 ? -1.0 : 1.0) * e.num.at("offset_mvv");
    if (row >= row0 && row - row0 < out.cols()) out(ch, row - row0) += offset;
  }
}

}  // namespace

std::vector<double> Wander(const std::vector<double>& t_s, double amplitude, double corner_hz,
                           std::uint64_t seed, const std::vector<double>* span_t_s) {
  std::vector<double> d(t_s.size(), 0.0);
  const std::vector<double>& grid = span_t_s != nullptr ? *span_t_s : t_s;
  if (grid.size() < 2 || amplitude == 0.0) return d;
  SeededRandom rng(seed ^ 0xD1B54A32D192ED03ULL);
  const double span = grid.back() - grid.front();
  const double f_lo = std::min(0.25 / span, 0.5 * corner_hz);
  constexpr int kTerms = 12;
  std::array<double, kTerms> freq{};
  std::array<double, kTerms> amp{};
  std::array<double, kTerms> phase{};
  for (int k = 0; k < kTerms; ++k) {
    const auto j = static_cast<std::size_t>(k);
    freq[j] = f_lo * std::pow(corner_hz / f_lo, static_cast<double>(k) / (kTerms - 1));
    amp[j] = std::abs(rng.Normal()) / freq[j];
    phase[j] = rng.Uniform(0.0, 2.0 * std::numbers::pi);
  }
  const auto at = [&](double t) {
    double v = 0.0;
    for (std::size_t j = 0; j < kTerms; ++j) {
      v += amp[j] * (std::sin(2.0 * std::numbers::pi * freq[j] * (t - grid.front()) + phase[j]) -
                     std::sin(phase[j]));
    }
    return v;
  };
  double ss = 0.0;
  for (const double t : grid) {
    const double v = at(t);
    ss += v * v;
  }
  const double rms = std::sqrt(ss / static_cast<double>(grid.size()));
  const double scale = rms > 0 ? amplitude / rms : 1.0;
  for (std::size_t i = 0; i < t_s.size(); ++i) d[i] = at(t_s[i]) * scale;
  return d;
}

Eigen::MatrixXd Compose(const std::vector<Effect>& effects, const ComposeInput& in) {
  const SensorModel& model = *in.model;
  const int n = model.channel_count();
  const std::size_t ns = in.t_s.size();

  // 1. The load the sensor actually sees.
  const std::vector<Wrench> seen = SeenLoad(effects, in);

  // 2. The model, split into its zero (temperature only) and the load part.
  Eigen::MatrixXd out(n, static_cast<Eigen::Index>(ns));
  Eigen::MatrixXd zero(n, static_cast<Eigen::Index>(ns));
  double last_t = NAN;
  Eigen::VectorXd z;
  for (std::size_t i = 0; i < ns; ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    out.col(c) = model.BridgeOutputs(seen[i], in.temp_c[i]);
    if (!(in.temp_c[i] == last_t)) {
      z = model.BridgeOutputs(Wrench::Zero(), in.temp_c[i]);
      last_t = in.temp_c[i];
    }
    zero.col(c) = z;
  }
  Eigen::MatrixXd load = out - zero;

  // 3. Dynamics and sensitivity changes on the load part.
  LoadPartEffects(effects, in, ns > 1 ? in.t_s[1] - in.t_s[0] : 1.0, load);
  out = zero + load;

  // 4. Bridge and read-out effects on the whole output.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kBridgeNonlinearity) {
      for (const int ch : e.channels) {
        out.row(ch) += e.num.at("coef") * out.row(ch).cwiseAbs2();
      }
    } else if (e.kind == EffectKind::kExcitationDrift) {
      const auto d =
          Wander(in.t_s, e.num.at("amplitude"), e.num.at("corner_hz"), e.seed, in.span_t_s);
      for (std::size_t i = 0; i < ns; ++i) out.col(static_cast<Eigen::Index>(i)) *= 1.0 + d[i];
    }
  }

  // 5. Additive signals.
  AdditiveEffects(effects, in, out);

  // 6. Clipping of the amplifier.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kSaturation) {
      const double lim = e.num.at("limit");
      for (const int ch : e.channels) out.row(ch) = out.row(ch).cwiseMax(-lim).cwiseMin(lim);
    }
  }
  // 7. Isolated wrong codes of the converter: after everything the analogue side does.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kConverterGlitch) AddConverterGlitches(e, in, out);
  }
  return out;
}

void InsertOverload(const Effect& e, LoadProfile& profile, const Wrench& rated) {
  const double t = e.num.at("onset_s");
  Wrench over = Wrench::Zero();
  over(e.axis) = e.num.at("factor") * rated(e.axis);
  profile.Splice(t - 0.7, t + 1.4, {t - 0.5, t - 0.3, t, t + 0.3, t + 0.6, t + 1.2},
                 {Wrench::Zero(), Wrench::Zero(), over, over, Wrench::Zero(), Wrench::Zero()});
}

}  // namespace ftstack::sim
