#include "sim/record.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "hal/sim/sim_adc.hpp"

namespace ftstack::sim {
namespace {

// Feeds precomputed bridge outputs (one column per sample) to the simulated ADC.
class MatrixSource final : public hal::sim::BridgeSignalSource {
 public:
  MatrixSource(const Eigen::MatrixXd& mvv, const std::vector<double>& temp_c)
      : mvv_(mvv), temp_c_(temp_c) {}
  [[nodiscard]] std::uint8_t channel_count() const override {
    return static_cast<std::uint8_t>(mvv_.rows());
  }
  [[nodiscard]] bool Sample(double /*t_s*/, double* bridge_mvv, double* temperature_c) override {
    if (next_ >= mvv_.cols()) return false;
    for (Eigen::Index c = 0; c < mvv_.rows(); ++c) bridge_mvv[c] = mvv_(c, next_);
    *temperature_c = temp_c_[static_cast<std::size_t>(next_)];
    ++next_;
    return true;
  }

 private:
  const Eigen::MatrixXd& mvv_;
  const std::vector<double>& temp_c_;
  Eigen::Index next_ = 0;
};

std::string Fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

nlohmann::json ParamsJson(const Effect& e) {
  nlohmann::json p = nlohmann::json::object();
  for (const auto& [k, v] : e.num) p[k] = v;
  if (!e.per_channel_key.empty()) p[e.per_channel_key] = e.per_channel;
  const std::string axis = EffectAxisName(e);
  if (!axis.empty()) p["axis"] = axis;
  p["channels"] = e.channels;
  return p;
}

// Where an effect's own contribution (noise-free, alone) stands out.
nlohmann::json Footprint(const Eigen::MatrixXd& c, const std::vector<double>& t, double sigma) {
  const Eigen::Index n = c.rows();
  std::vector<double> peak(static_cast<std::size_t>(n));
  std::vector<double> rms(static_cast<std::size_t>(n));
  double peak_all = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    peak[static_cast<std::size_t>(i)] = c.row(i).cwiseAbs().maxCoeff();
    rms[static_cast<std::size_t>(i)] =
        std::sqrt(c.row(i).squaredNorm() / static_cast<double>(c.cols()));
    peak_all = std::max(peak_all, peak[static_cast<std::size_t>(i)]);
  }
  const double thr = std::max(sigma, 0.02 * peak_all);
  std::vector<int> channels;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (peak_all > 0 &&
        peak[static_cast<std::size_t>(i)] > std::max(0.5 * sigma, 0.05 * peak_all)) {
      channels.push_back(static_cast<int>(i));
    }
  }
  nlohmann::json windows = nlohmann::json::array();
  if (peak_all > 0) {
    double start = NAN;
    double end = NAN;
    for (Eigen::Index k = 0; k < c.cols(); ++k) {
      if (c.col(k).cwiseAbs().maxCoeff() <= thr) continue;
      const double tk = t[static_cast<std::size_t>(k)];
      if (std::isnan(start)) {
        start = end = tk;
      } else if (tk - end > 1.0) {
        windows.push_back({start, end});
        start = end = tk;
      } else {
        end = tk;
      }
    }
    if (!std::isnan(start)) windows.push_back({start, end});
  }
  nlohmann::json f;
  f["channels"] = channels;
  f["windows"] = windows;
  f["peak_mvv"] = peak;
  f["rms_mvv"] = rms;
  f["size_sigma"] = sigma > 0 ? peak_all / sigma : 0.0;
  return f;
}

}  // namespace

std::vector<EffectSpec> ParseEffects(const std::vector<std::string>& texts) {
  std::vector<EffectSpec> out;
  for (const auto& t : texts) out.push_back(ParseEffectSpec(t));
  return out;
}

namespace {

/// Checks the request's numbers; returns the ADC noise to use, mV/V RMS.
double CheckedNoise(const RecordRequest& req) {
  if (!std::isfinite(req.duration_s) || req.duration_s < 0 || req.duration_s > 1e6) {
    throw std::invalid_argument("--duration-s must be a finite number in [0, 1e6] s");
  }
  if (!std::isfinite(req.rate_hz) || req.rate_hz < 0 || req.rate_hz > 100000) {
    throw std::invalid_argument("--rate-hz must be a finite number in (0, 100000] Hz");
  }
  const double noise = req.noise_mvv.value_or(req.sensor.adc.noise_rms_mvv);
  if (!std::isfinite(noise) || noise < 0) {
    throw std::invalid_argument("--noise-mvv must be a finite number >= 0");
  }
  return noise;
}

/// The real recording's bridges after the simulated ADC, back in mV/V, and its temperature.
struct AdcOutput {
  std::vector<std::vector<double>> bridges_mvv;  // per channel
  std::vector<double> temp_c;
  double counts_per_mvv = 0.0;
};

/// Through the simulated ADC: noise, quantisation to counts, rails; back to mV/V.
AdcOutput ThroughAdc(const RecordRequest& req, const Eigen::MatrixXd& clean_real,
                     const std::vector<double>& temp_c, double rate, double noise) {
  const auto n = static_cast<int>(clean_real.rows());
  const auto rows = static_cast<std::size_t>(clean_real.cols());
  hal::sim::SimAdcParams adc_params = req.sensor.adc;
  adc_params.noise_rms_mvv = noise;
  adc_params.seed = req.seed * 0x9E3779B97F4A7C15ULL + 0xADC;
  adc_params.realtime = false;
  MatrixSource source(clean_real, temp_c);
  hal::sim::SimAdc adc(source, adc_params);
  hal::AdcConfig cfg;
  cfg.channel_count = static_cast<std::uint8_t>(n);
  cfg.gain = req.sensor.adc_gain;
  cfg.rate_hz = static_cast<std::uint32_t>(std::max(1.0, std::round(rate)));
  if (adc.Configure(cfg) != hal::Status::kOk) {
    throw std::invalid_argument("record: the sensor's ADC parameters are not usable");
  }
  AdcOutput out;
  out.counts_per_mvv = adc.counts_per_mvv();
  out.bridges_mvv.assign(static_cast<std::size_t>(n), std::vector<double>(rows));
  out.temp_c.resize(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    hal::AdcSample s;
    if (adc.WaitDataReady(1000) != hal::Status::kOk || adc.Read(s) != hal::Status::kOk) {
      throw std::runtime_error("record: simulated ADC failed at row " + std::to_string(i));
    }
    for (int c = 0; c < n; ++c) {
      out.bridges_mvv[static_cast<std::size_t>(c)][i] =
          s.counts[static_cast<std::size_t>(c)] / out.counts_per_mvv;
    }
    out.temp_c[i] = s.has_temperature ? s.temperature_mdegc / 1000.0 : temp_c[i];
  }
  return out;
}

/// The two recordings: they share t, the reference wrench and temp_C.
void FillRecordings(const RecordRequest& req, const ComposeInput& in, const Eigen::MatrixXd& sim,
                    const AdcOutput& adc, double rate, RecordResult* res) {
  const auto n = static_cast<int>(sim.rows());
  const std::size_t rows = in.t_s.size();
  std::vector<std::vector<double>> wrench(6, std::vector<double>(rows));
  for (std::size_t i = 0; i < rows; ++i) {
    const Wrench w = res->profile.LoadAt(in.t_s[i]);
    for (int k = 0; k < 6; ++k) wrench[static_cast<std::size_t>(k)][i] = w(k);
  }
  const auto bnames = BridgeColumns(static_cast<std::size_t>(n));
  for (Recording* r : {&res->real, &res->sim}) {
    r->SetColumn("t", in.t_s);
    for (int k = 0; k < 6; ++k)
      r->SetColumn(WrenchColumns()[static_cast<std::size_t>(k)],
                   wrench[static_cast<std::size_t>(k)]);
  }
  for (int c = 0; c < n; ++c) {
    res->real.SetColumn(bnames[static_cast<std::size_t>(c)],
                        adc.bridges_mvv[static_cast<std::size_t>(c)]);
    std::vector<double> v(rows);
    for (std::size_t i = 0; i < rows; ++i) v[i] = sim(c, static_cast<Eigen::Index>(i));
    res->sim.SetColumn(bnames[static_cast<std::size_t>(c)], std::move(v));
  }
  if (req.temperature) {
    res->real.SetColumn("temp_C", adc.temp_c);
    res->sim.SetColumn("temp_C", adc.temp_c);
  }
  const std::vector<std::string> common = {
      "sensor: " + req.sensor.name, "profile: " + res->profile.name(),
      "seed: " + std::to_string(req.seed), "rate_hz: " + Fmt(rate)};
  res->real.metadata = common;
  res->real.metadata.insert(res->real.metadata.begin(),
                            "source: ftsim record (simulated measurement)");
  res->sim.metadata = common;
  res->sim.metadata.insert(res->sim.metadata.begin(),
                           "source: ftsim record (model prediction, " + in.model->name() + ")");
}

/// Truth: every effect with its exact parameters and where its own contribution shows.
nlohmann::json MakeTruth(const RecordRequest& req, const ComposeInput& in,
                         const Eigen::MatrixXd& sim, const RecordResult& res, double rate,
                         double noise, double counts_per_mvv) {
  nlohmann::json truth;
  truth["schema"] = "ftsim-truth/1";
  truth["sensor"] = req.sensor.name;
  truth["model"] = in.model->name();
  truth["profile"] = res.profile.name();
  truth["seed"] = req.seed;
  truth["rate_hz"] = rate;
  truth["rows"] = in.t_s.size();
  truth["duration_s"] = in.t_s.back();
  truth["noise_rms_mvv"] = noise;
  truth["lsb_mvv"] = 1.0 / counts_per_mvv;
  truth["effects"] = nlohmann::json::array();
  std::string strongest = "none";
  double strongest_rms = 0.0;
  for (const auto& e : res.effects) {
    if (e.kind == EffectKind::kNone) continue;
    const Eigen::MatrixXd c = Compose({e}, in) - sim;
    nlohmann::json j;
    j["name"] = e.name;
    j["params"] = ParamsJson(e);
    j["footprint"] = Footprint(c, in.t_s, noise);
    truth["effects"].push_back(j);
    const double r = std::sqrt(c.squaredNorm() / static_cast<double>(c.size()));
    if (r > strongest_rms) {
      strongest_rms = r;
      strongest = e.name;
    }
  }
  truth["strongest"] = strongest;
  return truth;
}

}  // namespace

void DefaultSaturationLimits(const Eigen::MatrixXd& sim, std::vector<Effect>* effects) {
  for (auto& e : *effects) {
    if (e.kind != EffectKind::kSaturation || !std::isnan(e.num["limit"])) continue;
    std::vector<double> mags;
    for (Eigen::Index i = 0; i < sim.cols(); ++i) {
      double m = 0.0;
      for (const int ch : e.channels) m = std::max(m, std::abs(sim(ch, i)));
      mags.push_back(m);
    }
    const auto q =
        mags.begin() + static_cast<std::ptrdiff_t>(0.995 * static_cast<double>(mags.size() - 1));
    std::nth_element(mags.begin(), q, mags.end());
    e.num["limit"] = 0.9 * *q;
    if (!(*q > 0)) throw std::invalid_argument("saturation: the recording has no load to clip");
  }
}

std::vector<Effect> ResolveEffects(const SensorModel& model, LoadProfile& profile, double rate_hz,
                                   const std::vector<EffectSpec>& specs, std::uint64_t seed) {
  const auto rows = static_cast<std::size_t>(std::floor(profile.duration_s() * rate_hz + 1e-9)) + 1;
  EffectContext ctx;
  ctx.channels = model.channel_count();
  ctx.rated = model.rated();
  ctx.sensitivity = model.Sensitivity();
  ctx.duration_s = static_cast<double>(rows - 1) / rate_hz;
  ctx.rate_hz = rate_hz;
  ctx.t0_c = profile.TemperatureAt(0.0);
  ctx.seed = seed;
  std::vector<Effect> effects;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    effects.push_back(ResolveEffect(specs[i], ctx, static_cast<int>(i)));
  }
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kOverloadShift) InsertOverload(e, profile, ctx.rated);
  }
  return effects;
}

ComposeSetup SetUpCompose(const SensorModel& model, LoadProfile& profile, double rate_hz,
                          const std::vector<EffectSpec>& specs, std::uint64_t seed) {
  const auto rows = static_cast<std::size_t>(std::floor(profile.duration_s() * rate_hz + 1e-9)) + 1;
  ComposeSetup setup;
  ComposeInput& in = setup.in;
  in.model = &model;
  in.profile = &profile;
  in.rated = model.rated();
  in.t_s.resize(rows);
  for (std::size_t i = 0; i < rows; ++i) in.t_s[i] = static_cast<double>(i) / rate_hz;
  setup.effects = ResolveEffects(model, profile, rate_hz, specs, seed);
  in.temp_c.resize(rows);
  for (std::size_t i = 0; i < rows; ++i) in.temp_c[i] = profile.TemperatureAt(in.t_s[i]);
  return setup;
}

Eigen::MatrixXd ComposeWithEffects(ComposeSetup* setup) {
  DefaultSaturationLimits(Compose({}, setup->in), &setup->effects);
  return Compose(setup->effects, setup->in);
}

RecordResult MakeRecording(const RecordRequest& req) {
  if (!req.sensor.model) throw std::invalid_argument("record: no sensor model");
  const SensorModel& model = *req.sensor.model;
  const Wrench rated = model.rated();
  const double noise = CheckedNoise(req);

  RecordResult res;
  res.profile = MakeProfile(req.profile, rated, req.seed, req.duration_s);
  LoadProfile& profile = res.profile;
  const double rate = req.rate_hz > 0 ? req.rate_hz : profile.default_rate_hz();
  const double dur = profile.duration_s();
  const auto rows = static_cast<std::size_t>(std::floor(dur * rate + 1e-9)) + 1;
  if (rows < 2 || rows > 20000000) {
    throw std::invalid_argument("recording of " + std::to_string(rows) +
                                " rows: choose --duration-s and --rate-hz for 2 … 2e7 rows");
  }

  ComposeSetup setup = SetUpCompose(model, profile, rate, req.effects, req.seed);
  const ComposeInput& in = setup.in;
  res.effects = std::move(setup.effects);

  const Eigen::MatrixXd sim = Compose({}, in);
  DefaultSaturationLimits(sim, &res.effects);
  res.clean_real = Compose(res.effects, in);
  const AdcOutput adc = ThroughAdc(req, res.clean_real, in.temp_c, rate, noise);
  FillRecordings(req, in, sim, adc, rate, &res);
  res.truth = MakeTruth(req, in, sim, res, rate, noise, adc.counts_per_mvv);
  return res;
}

void WriteTruth(const std::string& path, const nlohmann::json& truth) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << truth.dump(2) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace ftstack::sim
