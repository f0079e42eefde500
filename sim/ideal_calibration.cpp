#include "sim/ideal_calibration.hpp"

namespace ftstack::sim {

cal::CalFile IdealCalibration(const SensorModel& model, const hal::AdcInfo& adc) {
  const Eigen::MatrixXd s = model.Sensitivity();
  const Eigen::MatrixXd m = s.completeOrthogonalDecomposition().pseudoInverse();  // 6 × N
  const Eigen::VectorXd zero = model.BridgeOutputs(Wrench::Zero(), 20.0);
  cal::CalFile f;
  f.serial = model.name();
  f.source = "ideal";
  f.cal.channel_count = static_cast<std::uint8_t>(model.channel_count());
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < model.channel_count(); ++c) {
      f.cal.matrix[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] = m(r, c);
    }
  }
  for (int c = 0; c < model.channel_count(); ++c)
    f.cal.offset_mvv[static_cast<std::size_t>(c)] = zero(c);
  f.adc = adc;
  f.adc.channel_count = f.cal.channel_count;
  const Wrench rated = model.rated();
  for (int i = 0; i < 6; ++i) f.rated[static_cast<std::size_t>(i)] = rated(i);
  return f;
}

}  // namespace ftstack::sim
