#include "diagnosis/loader/data.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <mutex>
#include <thread>

#include "measurement/units.hpp"

namespace ftstack::diag {
namespace {

struct ProgressRelay {
  ProgressFn fn;
  void* user;
  double base;
  double span;
  const char* stage;
};

void Relay(std::size_t done, std::size_t total, void* user) {
  const auto* r = static_cast<const ProgressRelay*>(user);
  if (r->fn != nullptr && total > 0) {
    r->fn(r->base + r->span * static_cast<double>(done) / static_cast<double>(total), r->stage,
          r->user);
  }
}

/// The progress of two files read side by side, passed on as their mean (the callback is called
/// from one thread at a time).
struct TwoReaders {
  ProgressFn fn = nullptr;
  void* user = nullptr;
  std::mutex mu;
  double sim = 0.0;
  double real = 0.0;

  static void Sim(double fraction, const char* stage, void* self) {
    static_cast<TwoReaders*>(self)->Update(&TwoReaders::sim, fraction, stage);
  }
  static void Real(double fraction, const char* stage, void* self) {
    static_cast<TwoReaders*>(self)->Update(&TwoReaders::real, fraction, stage);
  }
  void Update(double TwoReaders::*which, double fraction, const char* stage) {
    const std::lock_guard<std::mutex> lock(mu);
    this->*which = fraction;
    if (fn != nullptr) fn(0.5 * (sim + real), stage, user);
  }
};

/// The declared unit's symbol and its values per mV/V (0 when the scale is not known).
void UnitScale(const InputUnit& u, std::string* symbol, double* per_mvv) {
  *symbol = ToString(u.unit);
  *per_mvv = 1.0;
  if (u.unit == BridgeUnit::kCounts) {
    const double mvv_per_count = MvvPerCount(u.converter, u.excitation_v);
    *per_mvv = mvv_per_count > 0 ? 1.0 / mvv_per_count : 0.0;
  } else if (u.unit == BridgeUnit::kVolts) {
    *per_mvv = u.excitation_v * 1e-3;
  }
}

/// Converts `rec`'s bridge columns from the unit its declaration (overridden by `cli`) says to
/// mV/V, refusing values outside the declared converter's codes or, undeclared, outside the
/// assumed converter (±3.90625 mV/V); returns that unit.
InputUnit DeclaredToMvv(Recording* rec, bool check_assumed, const UnitOverrides& cli) {
  const InputUnit u = ResolveInputUnit(*rec, cli);
  const std::size_t n = rec->BridgeCount();
  ValueRange r;
  r.unit = ToString(u.unit);
  if (u.unit == BridgeUnit::kCounts) {
    r.min = static_cast<double>(MinCode(u.converter));
    r.max = static_cast<double>(MaxCode(u.converter));
    r.what = "the codes of the " + std::to_string(u.converter.bits) + "-bit " +
             ToString(u.converter.coding) + " converter";
    CheckBridgeRange(*rec, n, r, 0.5);
  } else if (u.source == "format default" && check_assumed) {
    r.min = -3.90625;
    r.max = 3.90625;
    r.what = "the range of the assumed converter";
    CheckBridgeRange(*rec, n, r, 0.0);
  }
  ConvertBridgesToMvv(rec, n, u);
  return u;
}

/// Converts `rec`'s bridges to mV/V by `units`; one line naming the unit and its source.
std::string ToMvv(Recording* rec, bool check_assumed, const RealUnits& units,
                  std::string* symbol = nullptr, double* per_mvv = nullptr,
                  bool* ratiometric = nullptr) {
  const InputUnit u = units.rule ? units.rule(rec) : DeclaredToMvv(rec, check_assumed, units.cli);
  if (symbol != nullptr && per_mvv != nullptr) UnitScale(u, symbol, per_mvv);
  if (ratiometric != nullptr) {
    *ratiometric =
        u.unit == BridgeUnit::kCounts && u.source != "format default" && u.converter.ratiometric;
  }
  return Describe(u);
}

Recording Read(const std::string& path, ProgressRelay* relay, DiagData* unit_of, bool check_assumed,
               const RealUnits& units) {
  ReadOptions opt;
  opt.required = {"t"};
  opt.require_bridges = true;
  if (relay != nullptr && relay->fn != nullptr) {
    opt.progress = &Relay;
    opt.progress_user = relay;
  }
  Recording rec = ReadRecording(path, opt);
  if (unit_of != nullptr) {
    unit_of->real_unit = ToMvv(&rec, check_assumed, units, &unit_of->real_unit_symbol,
                               &unit_of->real_units_per_mvv, &unit_of->real_ratiometric);
  } else {
    (void)ToMvv(&rec, check_assumed, units);
  }
  return rec;
}

bool HasWrench(const Recording& r) {
  for (const auto& w : WrenchColumns()) {
    if (!r.Has(w)) return false;
  }
  return true;
}

Eigen::MatrixXd Bridges(const Recording& r, std::size_t n) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(r.rows()), static_cast<Eigen::Index>(n));
  for (std::size_t c = 0; c < n; ++c) {
    const auto& col = r.Column("b" + std::to_string(c));
    for (std::size_t i = 0; i < col.size(); ++i)
      m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = col[i];
  }
  return m;
}

Eigen::MatrixXf WrenchOf(const Recording& r) {
  Eigen::MatrixXf m(static_cast<Eigen::Index>(r.rows()), 6);
  for (int k = 0; k < 6; ++k) {
    const auto& col = r.Column(WrenchColumns()[static_cast<std::size_t>(k)]);
    for (std::size_t i = 0; i < col.size(); ++i) {
      m(static_cast<Eigen::Index>(i), k) = static_cast<float>(col[i]);
    }
  }
  return m;
}

void CheckUsable(const DiagData& d) {
  if (d.rows() < 64) {
    throw DiagInputError(d.real_name + ": " + std::to_string(d.rows()) +
                         " rows; a diagnosis needs at least 64");
  }
}

}  // namespace

double DiagData::rate_hz() const {
  if (t_s.size() < 2) return 0.0;
  std::vector<double> dt(t_s.size() - 1);
  for (std::size_t i = 1; i < t_s.size(); ++i) dt[i - 1] = t_s[i] - t_s[i - 1];
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return 1.0 / dt[dt.size() / 2];
}

std::vector<int> FindSegments(const Recording& real) {
  std::vector<int> seg(real.rows(), 0);
  int count = real.rows() > 0 ? 1 : 0;
  if (real.Has("segment")) {
    const auto& col = real.Column("segment");
    std::map<double, int> seen;  // value → number, in order of first row
    for (std::size_t i = 0; i < col.size(); ++i) {
      const auto it = seen.emplace(col[i], static_cast<int>(seen.size())).first;
      seg[i] = it->second;
    }
    count = static_cast<int>(seen.size());
  } else if (real.Has("t") && real.rows() > 2) {
    const auto& t = real.Column("t");
    std::vector<double> dt(t.size() - 1);
    for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
    std::vector<double> sorted = dt;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double gap = kSegmentGapPeriods * sorted[sorted.size() / 2];
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (dt[i - 1] > gap) ++count;
      seg[i] = count - 1;
    }
  }
  if (count <= 1) seg.clear();
  return seg;
}

namespace {

/// Frees the bridge columns of `rec` once they are copied (memory: 8 bytes × rows each).
void ReleaseBridges(Recording* rec, std::size_t n) {
  for (std::size_t c = 0; c < n; ++c) {
    std::vector<double>().swap(rec->Column("b" + std::to_string(c)));
  }
}

/// The pair from the sim recording (its `ns` bridge columns already copied into sim_mvv: they may
/// have been released) and the real one, checked; `release_real` (the real recording, or nullptr)
/// has its bridge columns released once copied.
DiagData Assemble(const Recording& sim, std::size_t ns, Eigen::MatrixXd sim_mvv,
                  const Recording& real, Recording* release_real) {
  const std::size_t nr = real.BridgeCount();
  if (nr == 0) throw DiagInputError(real.path + ": no bridge columns b0…");
  if (ns != nr) {
    throw DiagInputError(sim.path + ": has " + std::to_string(ns) + " bridge columns but " +
                         real.path + " has " + std::to_string(nr));
  }
  try {
    CheckAligned(sim, real);
  } catch (const RecordingError& e) {
    throw DiagInputError(e.what());
  }
  DiagData d;
  d.sim_name = sim.path;
  d.real_name = real.path;
  d.sim_mvv = std::move(sim_mvv);
  d.real_mvv = Bridges(real, nr);
  if (release_real != nullptr) ReleaseBridges(release_real, nr);
  if (HasWrench(real)) {
    d.wrench = WrenchOf(real);
  } else if (HasWrench(sim)) {
    d.wrench = WrenchOf(sim);
  }
  d.t_s = real.Column("t");
  if (real.Has("temp_C")) d.temp_c = real.Column("temp_C");
  d.segment = FindSegments(real);
  CheckUsable(d);
  return d;
}

}  // namespace

DiagData FromRecordings(const Recording& sim, const Recording& real) {
  const std::size_t ns = sim.BridgeCount();
  return Assemble(sim, ns, Bridges(sim, ns), real, nullptr);
}

DiagData LoadSimReal(const std::string& sim_path, const std::string& real_path, ProgressFn progress,
                     void* user, const RealUnits& units) {
  // The two files are read side by side, each on its own thread; the progress shown is their
  // mean. Memory: both recordings at once (about twice the columns of one), then the sim's bridges
  // are copied and its recording released, and the real's bridges once copied.
  TwoReaders both;
  both.fn = progress;
  both.user = user;
  ProgressRelay r1{&TwoReaders::Sim, &both, 0.0, 1.0, "reading sim and real"};
  ProgressRelay r2{&TwoReaders::Real, &both, 0.0, 1.0, "reading sim and real"};
  try {
    DiagData unit_of;
    Recording sim;
    std::exception_ptr sim_error;
    std::thread sim_reader([&] {
      try {
        sim = Read(sim_path, &r1, nullptr, false, RealUnits{});
      } catch (...) {
        sim_error = std::current_exception();
      }
    });
    Recording real;
    std::exception_ptr real_error;
    try {
      real = Read(real_path, &r2, &unit_of, true, units);
    } catch (...) {
      real_error = std::current_exception();
    }
    sim_reader.join();
    // The sim's error first, as when the files were read one after the other.
    if (sim_error) std::rethrow_exception(sim_error);
    if (real_error) std::rethrow_exception(real_error);
    const std::size_t ns = sim.BridgeCount();
    Eigen::MatrixXd sim_mvv = Bridges(sim, ns);
    ReleaseBridges(&sim, ns);
    std::vector<std::size_t>().swap(sim.data_lines);
    DiagData d = Assemble(sim, ns, std::move(sim_mvv), real, &real);
    d.real_unit = unit_of.real_unit;
    d.real_unit_symbol = unit_of.real_unit_symbol;
    d.real_units_per_mvv = unit_of.real_units_per_mvv;
    d.real_ratiometric = unit_of.real_ratiometric;
    return d;
  } catch (const RecordingError& e) {
    throw DiagInputError(e.what());
  }
}

DiagData LoadPredictedReal(const std::string& real_path, const std::string& model_name,
                           int channels, const BridgePredictor& predict, ProgressFn progress,
                           void* user, const RealUnits& units) {
  ProgressRelay r1{progress, user, 0.0, 0.8, "reading real"};
  Recording real;
  std::string unit;
  std::string symbol;
  double per_mvv = 1.0;
  bool ratiometric = false;
  try {
    ReadOptions opt;
    opt.required = {"t"};
    opt.require_bridges = true;
    opt.require_wrench = true;
    if (progress != nullptr) {
      opt.progress = &Relay;
      opt.progress_user = &r1;
    }
    real = ReadRecording(real_path, opt);
    unit = ToMvv(&real, true, units, &symbol, &per_mvv, &ratiometric);
  } catch (const RecordingError& e) {
    throw DiagInputError(e.what());
  }
  const std::size_t nr = real.BridgeCount();
  if (static_cast<int>(nr) != channels) {
    throw DiagInputError(real_path + ": has " + std::to_string(nr) +
                         " bridge columns but the model " + model_name + " has " +
                         std::to_string(channels));
  }
  DiagData d;
  d.sim_name = model_name;
  d.real_name = real_path;
  d.real_unit = unit;
  d.real_unit_symbol = symbol;
  d.real_units_per_mvv = per_mvv;
  d.real_ratiometric = ratiometric;
  d.t_s = real.Column("t");
  d.real_mvv = Bridges(real, nr);
  d.wrench = WrenchOf(real);
  if (real.Has("temp_C")) d.temp_c = real.Column("temp_C");
  d.segment = FindSegments(real);
  const auto n = static_cast<Eigen::Index>(d.t_s.size());
  d.sim_mvv.resize(n, static_cast<Eigen::Index>(nr));
  const std::vector<double>* wc[6];
  for (std::size_t k = 0; k < 6; ++k) wc[k] = &real.Column(WrenchColumns()[k]);
  for (Eigen::Index i = 0; i < n; ++i) {
    Wrench w;  // from the file's columns (double), not the stored single-precision copy
    for (std::size_t k = 0; k < 6; ++k)
      w(static_cast<int>(k)) = (*wc[k])[static_cast<std::size_t>(i)];
    const double temp = d.temp_c.empty() ? 20.0 : d.temp_c[static_cast<std::size_t>(i)];
    Eigen::VectorXd b(static_cast<Eigen::Index>(nr));
    predict(w, temp, b.data());
    d.sim_mvv.row(i) = b.transpose();
    if (progress != nullptr && (i % 20000) == 0) {
      progress(0.8 + 0.2 * static_cast<double>(i) / static_cast<double>(n), "simulating", user);
    }
  }
  CheckUsable(d);
  return d;
}

}  // namespace ftstack::diag
