// Streaming rainflow count of one load axis (four-point rule), integer, fixed-size residue.
#pragma once

#include <array>
#include <cstdint>

namespace ftstack::fw {

/// Turning points are confirmed once the signal has come back by more than `gate` from its extreme
/// (noise below the gate makes none); each new turning point closes every cycle the four-point
/// rule finds (A B C D with |B−C| ≤ |A−B| and |B−C| ≤ |C−D|: B–C is a full cycle). Cycles with a
/// range of at least `count_range` are counted, and every full cycle goes to one of kBins range
/// bins. The residue holds kResidue points; an overflowing residue forgets its oldest point (a
/// half cycle lost). The residue's half cycles (the history's open end) are in no count.
class RainflowCounter {
 public:
  static constexpr std::size_t kResidue = 32;
  static constexpr std::size_t kBins = 8;
  /// Bin k holds full cycles with edges[k − 1] ≤ range < edges[k] (bin 0 from 0, the last bin
  /// unbounded); ascending.
  using BinEdges = std::array<std::int32_t, kBins - 1>;
  using Bins = std::array<std::uint32_t, kBins>;

  void Configure(std::int32_t gate, std::int32_t count_range, const BinEdges& edges) {
    gate_ = gate;
    count_range_ = count_range;
    edges_ = edges;
    Clear();
  }
  void Clear() {
    n_ = 0;
    dir_ = 0;
    started_ = false;
    cycles_ = 0;
    bins_ = {};
  }
  /// Adds one sample; true when a full cycle closed (the counts changed).
  bool Add(std::int32_t v);
  [[nodiscard]] std::uint32_t cycles() const { return cycles_; }
  /// Full cycles per range bin (each saturates at 2³² − 1).
  [[nodiscard]] const Bins& bins() const { return bins_; }
  /// The residue: turning points not yet closed into a full cycle, oldest first.
  [[nodiscard]] std::size_t residue_size() const { return n_; }
  [[nodiscard]] std::int32_t residue(std::size_t i) const { return residue_[i]; }

 private:
  bool Push(std::int32_t turning_point);

  std::array<std::int32_t, kResidue> residue_{};
  std::size_t n_ = 0;
  std::int32_t gate_ = 1;
  std::int32_t count_range_ = 1;
  std::int32_t extreme_ = 0;
  int dir_ = 0;  ///< +1 rising towards extreme_, −1 falling, 0 not yet known
  bool started_ = false;
  std::uint32_t cycles_ = 0;
  BinEdges edges_{};
  Bins bins_{};
};

}  // namespace ftstack::fw
