// libFuzzer harness: load-profile keyframe files (JSON "ftstack-profile/1"). Refusals are
// ProfileError. The text goes to ParseProfileJson, what MakeProfile runs on a .json file's text
// (no temporary file per input); an accepted profile has increasing keyframe times and finite
// loads.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "sim/load_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ftstack::sim::LoadProfile p = ftstack::sim::ParseProfileJson(text, "fuzz.json", 0.0);
    const auto& t = p.key_times_s();
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!std::isfinite(t[i]) || (i > 0 && !(t[i] > t[i - 1]))) std::abort();
      if (!p.key_loads()[i].allFinite()) std::abort();
    }
    if (!(p.duration_s() > 0.0) || !(p.default_rate_hz() > 0.0)) std::abort();
  } catch (const ftstack::sim::ProfileError&) {
  }
  return 0;
}
