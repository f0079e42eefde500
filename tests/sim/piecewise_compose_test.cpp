// A recording composed piece by piece (and streamed to a converter) against the same recording
// composed whole.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "sim/piecewise_compose.hpp"
#include "sim/record.hpp"
#include "sim/sensor_description.hpp"
#include "sim/streamed_bridges.hpp"

namespace ftstack::sim {
namespace {

constexpr double kRateHz = 1000.0;
constexpr std::size_t kPieceRows = 4096;

/// Every effect with a memory or a span-wide layout, on a 60 s taps profile (60 001 rows: the
/// span's grid is every row, so wanders and limits match the whole exactly).
const std::vector<std::string> kEffects = {
    "creep:tau_s=0.4,fraction=0.01",
    "resonance:freq_hz=30,damping_ratio=0.05",
    "mains_interference:freq_hz=50,amplitude_mvv=0.01",
    "zero_drift:amplitude_mvv=0.01",
    "thermal_zero_drift",
    "converter_glitch:count=20",
    "overload_shift:onset_s=30,shift=0.01",
};

struct Whole {
  SensorDescription desc = DefaultSensorDescription();
  LoadProfile profile;
  Eigen::MatrixXd mvv;
  std::vector<double> temp_c;
  std::unique_ptr<PiecewiseComposition> pieces;
};

Whole Compose(const std::vector<std::string>& effects) {
  Whole w;
  const SensorModel& model = *w.desc.model;
  w.profile = MakeProfile("taps", model.rated(), 3, 60.0);
  LoadProfile whole_profile = w.profile;
  ComposeSetup setup = SetUpCompose(model, whole_profile, kRateHz, ParseEffects(effects), 3);
  w.mvv = ComposeWithEffects(&setup);
  w.temp_c = setup.in.temp_c;
  LoadProfile piece_profile = w.profile;
  std::vector<Effect> resolved =
      ResolveEffects(model, piece_profile, kRateHz, ParseEffects(effects), 3);
  w.pieces = std::make_unique<PiecewiseComposition>(model, piece_profile, kRateHz,
                                                    std::move(resolved), kPieceRows);
  return w;
}

TEST(PiecewiseCompose, PiecesEqualTheWholeRecording) {
  Whole w = Compose(kEffects);
  ASSERT_EQ(w.pieces->rows(), static_cast<std::size_t>(w.mvv.cols()));
  ASSERT_EQ(w.pieces->pieces(), (w.pieces->rows() + kPieceRows - 1) / kPieceRows);
  // Creep forgets its start within 12 τ (4.8 s; the resonance's 12 decay times are 1.3 s).
  EXPECT_NEAR(static_cast<double>(w.pieces->warm_up_rows()), 4800.0, 1.0);
  double worst = 0.0;
  for (std::size_t p = 0; p < w.pieces->pieces(); ++p) {
    const ComposedPiece piece = w.pieces->Compose(p);
    ASSERT_EQ(piece.first_row, p * kPieceRows);
    for (Eigen::Index c = 0; c < piece.mvv.cols(); ++c) {
      const auto row = static_cast<Eigen::Index>(piece.first_row) + c;
      worst = std::max(worst, (piece.mvv.col(c) - w.mvv.col(row)).cwiseAbs().maxCoeff());
      ASSERT_EQ(piece.temp_c[static_cast<std::size_t>(c)], w.temp_c[static_cast<std::size_t>(row)]);
    }
  }
  // What is left of a transient after 12 time constants (e^-12 of a 1 mV/V load's 1 % creep:
  // 6e-8 mV/V), far below the converter's step.
  EXPECT_LT(worst, 1e-7);
  std::printf("largest difference from the whole: %.3g mV/V\n", worst);
}

TEST(PiecewiseCompose, StreamedBridgesServeEveryRowInOrderAndAfterAJump) {
  Whole w = Compose(kEffects);
  const auto rows = static_cast<std::size_t>(w.mvv.cols());
  StreamedBridges stream(std::move(w.pieces), kRateHz);
  ASSERT_EQ(stream.channel_count(), w.mvv.rows());
  std::vector<double> b(static_cast<std::size_t>(w.mvv.rows()));
  double temp = 0.0;
  const auto check = [&](std::size_t row) {
    ASSERT_TRUE(stream.Sample(static_cast<double>(row) / kRateHz, b.data(), &temp));
    for (Eigen::Index c = 0; c < w.mvv.rows(); ++c) {
      ASSERT_NEAR(b[static_cast<std::size_t>(c)], w.mvv(c, static_cast<Eigen::Index>(row)), 1e-7)
          << "row " << row;
    }
    ASSERT_EQ(temp, w.temp_c[row]);
  };
  for (std::size_t row = 0; row < rows; ++row) check(row);
  check(10);        // back to the first piece
  check(rows / 2);  // forward past the piece composed ahead
  // After the span the last row holds.
  ASSERT_TRUE(stream.Sample(1e6, b.data(), &temp));
  EXPECT_NEAR(b[0], w.mvv(0, w.mvv.cols() - 1), 1e-7);
}

}  // namespace
}  // namespace ftstack::sim
