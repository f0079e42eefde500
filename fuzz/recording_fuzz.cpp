// libFuzzer harness: the recording CSV reader. Refusals are RecordingError; what it accepts holds
// the format's promises (equal columns, finite numbers, strictly increasing t).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "measurement/recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  ftstack::ReadOptions options;  // the first byte chooses what the reader requires
  options.require_bridges = (data[0] & 1) != 0;
  options.require_wrench = (data[0] & 2) != 0;
  if ((data[0] & 4) != 0) options.required = {"t"};
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const ftstack::Recording rec = ftstack::ParseRecording(text, "fuzz.csv", options);
    for (const auto& col : rec.columns) {
      if (col.size() != rec.rows()) std::abort();
      for (const double v : col) {
        if (!std::isfinite(v)) std::abort();
      }
    }
    if (rec.Has("t")) {
      const auto& t = rec.Column("t");
      for (std::size_t i = 1; i < t.size(); ++i) {
        if (!(t[i] > t[i - 1])) std::abort();
      }
    }
  } catch (const ftstack::RecordingError&) {
  }
  return 0;
}
