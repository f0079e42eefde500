#include "firmware/overload.hpp"

#include <bit>
#include <limits>

namespace ftstack::fw {

std::uint32_t ISqrt64(std::uint64_t n) {
  if (n == 0) return 0;
  std::uint64_t root = 0;
  // Start at the highest even power of two not above n (one instruction instead of a loop).
  std::uint64_t bit = std::uint64_t{1} << ((63 - std::countl_zero(n)) & ~1);
  while (bit != 0) {
    if (n >= root + bit) {
      n -= root + bit;
      root = (root >> 1) + bit;
    } else {
      root >>= 1;
    }
    bit >>= 2;
  }
  return static_cast<std::uint32_t>(root);
}

bool OverloadMonitor::Configure(const WrenchLsb& rated_lsb) {
  for (const std::int32_t r : rated_lsb) {
    if (r < 1 || r > kMaxRatedLsb) return false;
  }
  for (std::size_t i = 0; i < kAxes; ++i) {
    recip_[i] = (std::uint64_t{1} << 48) / static_cast<std::uint64_t>(rated_lsb[i]);
    clamp_[i] = std::int64_t{8} * rated_lsb[i];
  }
  configured_ = true;
  overloaded_ = false;
  return true;
}

std::uint32_t OverloadMonitor::ShareQ24(std::int32_t v, std::size_t axis) const {
  std::int64_t a = v < 0 ? -static_cast<std::int64_t>(v) : v;
  if (a > clamp_[axis]) a = clamp_[axis];
  // a ≤ 8·rated, recip ≤ 2^48/rated: the product is below 2^51.
  return static_cast<std::uint32_t>((static_cast<std::uint64_t>(a) * recip_[axis]) >> 24);
}

LoadShares OverloadMonitor::Shares(const WrenchLsb& w) const {
  LoadShares s{};
  if (!configured_) return s;
  const std::uint64_t fx = ShareQ24(w[0], 0);
  const std::uint64_t fy = ShareQ24(w[1], 1);
  const std::uint64_t mx = ShareQ24(w[3], 3);
  const std::uint64_t my = ShareQ24(w[4], 4);
  // Shares are below 2^27 (8 × rated in Q24): squares below 2^54, sums below 2^55.
  s.fxy_mz = ISqrt64(fx * fx + fy * fy) + ShareQ24(w[5], 5);
  s.fz_mxy = ShareQ24(w[2], 2) + ISqrt64(mx * mx + my * my);
  return s;
}

bool OverloadMonitor::Update(const WrenchLsb& w, bool saturated) {
  for (std::size_t i = 0; i < kAxes; ++i) {
    const std::int32_t a = w[i] == std::numeric_limits<std::int32_t>::min()
                               ? std::numeric_limits<std::int32_t>::max()
                               : (w[i] < 0 ? -w[i] : w[i]);
    if (a > peaks_[i]) peaks_[i] = a;
  }
  const LoadShares s = Shares(w);
  const std::uint64_t worst = s.fxy_mz > s.fz_mxy ? s.fxy_mz : s.fz_mxy;
  const bool above = worst * kOverloadShareDen > kOverloadShareNum * kShareOne;
  const bool released = worst * kReleaseShareDen <= kReleaseShareNum * kShareOne;
  const bool over = configured_ && (saturated || above || (overloaded_ && !released));
  if (over && !overloaded_ && events_ != std::numeric_limits<std::uint32_t>::max()) ++events_;
  overloaded_ = over;
  return over;
}

void OverloadMonitor::Clear() {
  events_ = 0;
  peaks_ = {};
  overloaded_ = false;
}

}  // namespace ftstack::fw
