// libFuzzer harness: sensor descriptions (JSON: linear and flexure models). Refusals are
// SensorDescriptionError; an accepted sensor gives finite bridge outputs at zero load.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "sim/sensor_description.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ftstack::sim::SensorDescription d =
        ftstack::sim::ParseSensorDescription(text, "fuzz.json");
    const Eigen::VectorXd b = d.model->BridgeOutputs(ftstack::Wrench::Zero(), 20.0);
    if (b.size() != d.model->channel_count()) std::abort();
    for (Eigen::Index i = 0; i < b.size(); ++i) {
      if (!std::isfinite(b(i))) std::abort();
    }
  } catch (const ftstack::sim::SensorDescriptionError&) {
  }
  return 0;
}
