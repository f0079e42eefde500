// A per-context memo of the load's first-order lags kept at the rows a parameter search reads.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace ftstack::diag {

/// The lag LP_τ[load] at a set of rows depends on the context's load and clock and on τ only (not
/// on the target, the hold-out split or the effect), and every full search of a lag-type effect
/// starts on the same grid of τ: each fit in the singles, pairs, backfits, confounders and pieces
/// would filter every row again for each grid point. The memo keeps the most recently used lags
/// within a byte budget; thread-safe (the fits run in parallel). A lag is found only for exactly
/// the same τ (its bits) and the same rows, so what it returns is what the filter would give.
class LagCache {
 public:
  explicit LagCache(std::size_t budget_bytes) : budget_bytes_(budget_bytes) {}

  /// The kept lag of (tau, rows), or nullptr.
  [[nodiscard]] std::shared_ptr<const Eigen::MatrixXd> Find(double tau,
                                                            const std::vector<int>& rows);
  /// Keeps a lag, evicting the least recently used ones beyond the budget (a lag larger than the
  /// budget is not kept).
  void Insert(double tau, const std::vector<int>& rows, std::shared_ptr<const Eigen::MatrixXd> lag);
  /// Lags found and not found so far (the debug output's figures).
  [[nodiscard]] std::uint64_t hits() const { return hits_; }
  [[nodiscard]] std::uint64_t misses() const { return misses_; }

 private:
  struct Entry {
    std::uint64_t tau_bits = 0;
    std::shared_ptr<const std::vector<int>> rows;
    std::shared_ptr<const Eigen::MatrixXd> lag;
    std::uint64_t last_use = 0;
  };
  [[nodiscard]] Entry* Lookup(std::uint64_t tau_bits, const std::vector<int>& rows);

  std::mutex mu_;
  std::vector<Entry> entries_;
  std::size_t bytes_ = 0;
  std::size_t budget_bytes_;
  std::uint64_t clock_ = 0;
  std::uint64_t hits_ = 0;
  std::uint64_t misses_ = 0;
};

}  // namespace ftstack::diag
