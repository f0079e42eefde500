#include "diagnosis/engine/nonlinear_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>

#include "measurement/numerics.hpp"

namespace ftstack::diag {

namespace {
std::atomic<SearchLog*> g_search_log{nullptr};
}  // namespace

SearchLog::SearchLog() { g_search_log.store(this); }
SearchLog::~SearchLog() { g_search_log.store(nullptr); }

std::vector<SearchedRange> SearchLog::Ranges() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return ranges_;
}

void SearchLog::Note(const char* key, double lo, double hi) {
  SearchLog* log = g_search_log.load(std::memory_order_relaxed);
  if (log == nullptr) return;
  const std::lock_guard<std::mutex> lock(log->mutex_);
  log->ranges_.push_back({key, lo, hi});
}

double BestPoint(const LogObjective& f, const std::vector<std::vector<double>>& points,
                 std::vector<double>* best) {
  double best_value = std::numeric_limits<double>::infinity();
  for (const auto& p : points) {
    const double v = f(p);
    if (v < best_value) {
      best_value = v;
      *best = p;
    }
  }
  return best_value;
}

void GoldenRounds(const LogObjective& f, const std::vector<LogBounds>& bounds,
                  const std::vector<double>& step, int first, int last,
                  const std::function<void(int)>& before, std::vector<double>* x) {
  std::vector<double>& p = *x;
  for (const LogBounds& b : bounds) SearchLog::Note("", std::exp(b.lo), std::exp(b.hi));
  for (int round = first; round < last; ++round) {
    if (before) before(round);
    for (std::size_t j = 0; j < p.size(); ++j) {
      const LogBounds b = bounds[j];
      std::vector<double> grid;
      for (int k = -2; k <= 2; ++k) {
        const double v = std::clamp(p[j] + step[j] * k / (round + 1), b.lo, b.hi);
        if (grid.empty() || v > grid.back()) grid.push_back(v);
      }
      std::vector<double> at = p;
      p[j] = numerics::MinimizeOnGrid(
          [&](double v) {
            at[j] = std::clamp(v, b.lo, b.hi);
            return f(at);
          },
          grid, 7, nullptr);
      p[j] = std::clamp(p[j], b.lo, b.hi);
    }
  }
}

}  // namespace ftstack::diag
