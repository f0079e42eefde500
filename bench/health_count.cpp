// count_health: runs the health watch on bench_health's input for a number of samples, or only
// prepares it, so that an instruction counter (qemu's exec trace for aarch64, callgrind on the
// host) run twice gives the watch's instructions per sample as the difference over the samples.
// Usage: count_health RATE_HZ SAMPLES MODE   (MODE: 0 prepare only, 1 step the watch,
// 2 SAMPLES times the worst sample's extra work — a ringing analysis's level slice and first
// crossing slice together, an upper bound —, 3 SAMPLES whole ringing analyses of one axis)
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/health_inputs.hpp"
#include "firmware/health_signal.hpp"
#include "firmware/health_watch.hpp"

namespace {

ftstack::fw::HealthWatch watch;  // 13 KiB: static, as in the daemon
ftstack::fw::RingingScan scan;

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: count_health RATE_HZ SAMPLES MODE (0 … 3)\n");
    return 2;
  }
  const auto rate = static_cast<std::uint32_t>(std::strtoul(argv[1], nullptr, 10));
  const auto samples = static_cast<std::size_t>(std::strtoull(argv[2], nullptr, 10));
  const int mode = std::atoi(argv[3]);
  if (rate < 100 || rate > 100000 || (mode < 0 || mode > 3)) {
    std::fprintf(stderr, "count_health: RATE_HZ 100 … 100000, MODE 0 … 3\n");
    return 2;
  }
  // Both are prepared in every mode, so that the difference between modes is the watch alone.
  const std::vector<ftstack::fw::HealthInput> in = ftstack::bench::HealthInputs(rate);
  const std::vector<std::int32_t> capture = ftstack::bench::RingingCapture();
  if (!watch.Configure(rate, ftstack::bench::kHealthRated)) return 1;
  std::uint64_t sink = 0;
  for (std::size_t i = 0; i < samples && mode != 0; ++i) {
    if (mode == 1) {
      watch.Step(in[i % in.size()]);
      sink += watch.report().findings;
    } else if (mode == 2) {
      scan.Start(capture.data(), capture.size(), 1000, 40);
      sink += scan.Advance(ftstack::fw::HealthWatch::kRingSlice) ? 1 : 0;
      sink += scan.Advance(ftstack::fw::HealthWatch::kRingSlice) ? 1 : 0;
    } else {
      sink += static_cast<std::uint64_t>(
          ftstack::fw::MeasureRinging(capture.data(), capture.size(), 1000, 40).freq_mhz);
    }
  }
  std::printf("%llu\n", static_cast<unsigned long long>(sink));
  return 0;
}
