// `ftdiag demo`: a recording from the simulator with one effect hidden in it, and its truth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace ftstack::diag {

struct DemoRequest {
  std::string effect;   ///< effect from the vocabulary, NAME[:k=v,...] ("none": no effect)
  std::string out_dir;  ///< "" → ftdiag-demo-NAME
  std::uint64_t seed = 1;
  double duration_s = 150.0;
};

/// What MakeDemo wrote.
struct DemoFiles {
  std::string name;     ///< the effect's name
  std::string profile;  ///< rig or thermal
  std::string dir, sim_csv, real_csv, truth_json;
  std::size_t rows = 0;
  std::string truth_strongest;  ///< the strongest hidden effect, from the truth
};

/// Records sim.csv, real.csv (the effect hidden in it) and truth.json into the folder. Throws on
/// a bad effect specification or an unwritable folder.
[[nodiscard]] DemoFiles MakeDemo(const DemoRequest& request);

}  // namespace ftstack::diag
