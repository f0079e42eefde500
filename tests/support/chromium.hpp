// Renders an HTML report to a PNG with headless Chromium (Debian's `chromium`), bounded in time.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace ftstack::test {

/// True when Debian's chromium is installed (tests that render reports skip the rendering without).
inline bool HaveChromium() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

/// Screenshots `html` into `png` (width × height px) with a fresh profile in `profile_dir`.
/// Flags as the machine notes give them (no background networking: the sandbox has no network).
/// Each attempt is bounded by `timeout` (a headless Chromium occasionally hangs at start-up on a
/// loaded machine); a second attempt follows a timeout. True when a non-empty PNG was written.
inline bool RenderWithChromium(const std::string& html, const std::string& png,
                               const std::string& profile_dir, int width = 1200,
                               int height = 1600) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    std::error_code ec;
    std::filesystem::remove(png, ec);
    const std::string cmd =
        "timeout -k 5 90 chromium --headless --no-sandbox --disable-gpu --disable-quic "
        "--no-first-run --disable-background-networking --disable-component-update --disable-sync "
        "--disable-dev-shm-usage --user-data-dir=" +
        profile_dir + "_" + std::to_string(attempt) + " --screenshot=" + png +
        " --window-size=" + std::to_string(width) + "," + std::to_string(height) + " file://" +
        html + " > /dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0 && std::filesystem::exists(png) &&
        std::filesystem::file_size(png) > 0) {
      return true;
    }
  }
  return false;
}

}  // namespace ftstack::test
