#include "sim/wrench_source.hpp"

#include <algorithm>
#include <stdexcept>

namespace ftstack::sim {

bool ConstantWrench::At(double /*t_s*/, Wrench* w, double* temperature_c) const {
  *w = w_;
  *temperature_c = temperature_c_;
  return true;
}

ProfileWrench::ProfileWrench(std::vector<Key> keys, bool finite)
    : keys_(std::move(keys)), finite_(finite) {
  if (keys_.empty()) throw std::invalid_argument("a wrench profile needs at least one keyframe");
  for (std::size_t i = 1; i < keys_.size(); ++i) {
    if (!(keys_[i].t_s > keys_[i - 1].t_s)) {
      throw std::invalid_argument("wrench profile times must increase strictly");
    }
  }
}

bool ProfileWrench::At(double t_s, Wrench* w, double* temperature_c) const {
  if (finite_ && t_s > keys_.back().t_s + 1e-9) return false;
  if (t_s <= keys_.front().t_s) {
    *w = keys_.front().w;
    *temperature_c = keys_.front().temperature_c;
    return true;
  }
  if (t_s >= keys_.back().t_s) {
    *w = keys_.back().w;
    *temperature_c = keys_.back().temperature_c;
    return true;
  }
  const auto it = std::upper_bound(keys_.begin(), keys_.end(), t_s,
                                   [](double t, const Key& k) { return t < k.t_s; });
  const Key& b = *it;
  const Key& a = *(it - 1);
  const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
  *w = a.w + f * (b.w - a.w);
  *temperature_c = a.temperature_c + f * (b.temperature_c - a.temperature_c);
  return true;
}

std::unique_ptr<ProfileWrench> ReplayWrench(const Recording& rec) {
  const auto& t = rec.Column("t");
  std::vector<const std::vector<double>*> cols;
  for (const auto& name : WrenchColumns()) cols.push_back(&rec.Column(name));
  const bool has_temp = rec.Has("temp_C");
  std::vector<ProfileWrench::Key> keys;
  keys.reserve(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    ProfileWrench::Key k;
    k.t_s = t[i] - t[0];
    for (int j = 0; j < 6; ++j) k.w(j) = (*cols[static_cast<std::size_t>(j)])[i];
    k.temperature_c = has_temp ? rec.Column("temp_C")[i] : 20.0;
    keys.push_back(k);
  }
  return std::make_unique<ProfileWrench>(std::move(keys), true);
}

}  // namespace ftstack::sim
