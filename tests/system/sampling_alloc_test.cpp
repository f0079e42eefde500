// The per-sample path allocates nothing (issue 17 item 12): a counting global allocator watches
// the sampling step of the simulated backend (physical sensor model → bridges → SimAdc → core →
// device) and of a scripted converter, after start-up.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <atomic>
#include <cstdlib>
#include <new>

#include "firmware/core.hpp"
#include "firmware/device.hpp"
#include "hal/sim/sim_adc.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/wrench_source.hpp"

// This file replaces the global operator new/delete with malloc/free. GCC (12, -O1 and above,
// more so under -fsanitize) then reports operator new paired with free as a mismatch, although
// both halves of the pair are ours.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// malloc itself (Eigen allocates with it directly): the program links with -Wl,--wrap=malloc.
extern "C" void* __real_malloc(std::size_t n);   // NOLINT(bugprone-reserved-identifier)
extern "C" void* __wrap_malloc(std::size_t n) {  // NOLINT(bugprone-reserved-identifier)
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __real_malloc(n);
}

// Every operator new of this test program goes through here.
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace ftstack {
namespace {

TEST(SamplingPath, AllocatorCountsWhatItShould) {
  // The counters themselves work (a test that cannot fail proves nothing): operator new, and
  // malloc as Eigen calls it.
  const long before = g_allocations.load();
  void* p = ::operator new(16);
  ::operator delete(p);
  const long after_new = g_allocations.load();
  EXPECT_GE(after_new - before, 1);
  const Eigen::VectorXd v = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(before % 7 + 5));
  EXPECT_GE(g_allocations.load() - after_new, 1);
  EXPECT_GT(v.sum(), 0.0);
}

TEST(SamplingPath, SimulatedBackendStepsWithoutAllocating) {
  const sim::SensorDescription desc = sim::DefaultSensorDescription();
  Wrench w;
  w << 10.0, -5.0, -50.0, 0.2, 0.1, -0.05;
  sim::ConstantWrench source(w);
  hal::sim::SimAdcParams params = sim::AdcParamsAt(desc, 1000);
  params.realtime = false;  // as fast as it can: the test measures allocations, not time
  sim::SimulatedAdc simulated(desc, source, params);
  hal::sim::SimAdc& adc = simulated.adc();
  fw::WrenchCore core;
  fw::Device device(adc, core);
  fw::DeviceConfig cfg;
  fw::FloatCalibration fc;
  fc.channel_count = static_cast<std::uint8_t>(desc.model->channel_count());
  for (std::size_t i = 0; i < 6 && i < fc.channel_count; ++i) fc.matrix[i][i] = 100.0;
  hal::AdcConfig probe;
  probe.channel_count = fc.channel_count;
  probe.gain = desc.adc_gain;
  probe.rate_hz = 1000;
  ASSERT_EQ(adc.Configure(probe), hal::Status::kOk);
  fw::LoadReport report;
  ASSERT_EQ(fw::LoadCalibration(fc, adc.Info(), &cfg.slots[0].fixed, &report), fw::LoadStatus::kOk);
  cfg.slots[0].present = true;
  cfg.adc = probe;
  ASSERT_EQ(device.Start(cfg), fw::DeviceStatus::kOk);
  bool published = false;
  for (int i = 0; i < 100; ++i) ASSERT_EQ(device.Step(&published), hal::Status::kOk);  // warm up
  const long before = g_allocations.load();
  for (int i = 0; i < 5000; ++i) ASSERT_EQ(device.Step(&published), hal::Status::kOk);
  EXPECT_EQ(g_allocations.load() - before, 0) << "allocations in 5000 sampling steps";
}

}  // namespace
}  // namespace ftstack
