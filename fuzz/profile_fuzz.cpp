// libFuzzer harness: load-profile keyframe files (JSON "ftstack-profile/1"). Refusals are
// ProfileError; the reader takes a path, so each input goes through a file of this process's own.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "sim/load_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path =
      "/tmp/ftstack_fuzz_profile_" + std::to_string(::getpid()) + ".json";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  ftstack::Wrench rated;
  rated << 200, 200, 400, 10, 10, 8;
  try {
    (void)ftstack::sim::MakeProfile(path, rated, 1, 0.0);
  } catch (const ftstack::sim::ProfileError&) {
  }
  std::remove(path.c_str());  // libFuzzer may end with _exit: leave nothing behind each time
  return 0;
}
