// The memo of first-order lags (lag_cache.hpp).
#include "diagnosis/engine/lag_cache.hpp"

#include <algorithm>
#include <bit>
#include <utility>

namespace ftstack::diag {
namespace {

std::size_t Bytes(const Eigen::MatrixXd& m, const std::vector<int>& rows) {
  return static_cast<std::size_t>(m.size()) * sizeof(double) + rows.size() * sizeof(int);
}

}  // namespace

LagCache::Entry* LagCache::Lookup(std::uint64_t tau_bits, const std::vector<int>& rows) {
  for (Entry& e : entries_) {
    if (e.tau_bits == tau_bits && *e.rows == rows) return &e;
  }
  return nullptr;
}

std::shared_ptr<const Eigen::MatrixXd> LagCache::Find(double tau, const std::vector<int>& rows) {
  const std::lock_guard<std::mutex> lock(mu_);
  Entry* e = Lookup(std::bit_cast<std::uint64_t>(tau), rows);
  if (e == nullptr) {
    ++misses_;
    return nullptr;
  }
  ++hits_;
  e->last_use = ++clock_;
  return e->lag;
}

void LagCache::Insert(double tau, const std::vector<int>& rows,
                      std::shared_ptr<const Eigen::MatrixXd> lag) {
  const std::size_t bytes = Bytes(*lag, rows);
  if (bytes > budget_bytes_) return;
  const std::lock_guard<std::mutex> lock(mu_);
  const auto bits = std::bit_cast<std::uint64_t>(tau);
  if (Lookup(bits, rows) != nullptr) return;  // another thread filtered it meanwhile
  while (!entries_.empty() && bytes_ + bytes > budget_bytes_) {
    const auto oldest =
        std::min_element(entries_.begin(), entries_.end(),
                         [](const Entry& a, const Entry& b) { return a.last_use < b.last_use; });
    bytes_ -= Bytes(*oldest->lag, *oldest->rows);
    entries_.erase(oldest);
  }
  // A search keeps the same rows for every τ it tries: consecutive entries share one copy.
  std::shared_ptr<const std::vector<int>> kept;
  if (!entries_.empty() && *entries_.back().rows == rows) kept = entries_.back().rows;
  if (!kept) kept = std::make_shared<const std::vector<int>>(rows);
  entries_.push_back(Entry{bits, std::move(kept), std::move(lag), ++clock_});
  bytes_ += bytes;
}

}  // namespace ftstack::diag
