// Writes the ftdiag clock benchmark's recording pair (bench/diag_jitter_data.hpp) as SIM.csv and
// REAL.csv, so that bench/run.sh can measure the peak memory of the real `ftdiag diagnose`.
// Usage: bench_diag_data ROWS JITTER(0|1) SIM.csv REAL.csv
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/diag_jitter_data.hpp"
#include "measurement/recording.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: bench_diag_data ROWS JITTER(0|1) SIM.csv REAL.csv\n");
    return 2;
  }
  const int rows = std::atoi(argv[1]);
  const bool jitter = std::atoi(argv[2]) != 0;
  const auto d = ftstack::bench::MakeJitterData(rows, jitter);
  std::vector<std::string> names = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  for (int c = 0; c < d.channels(); ++c) names.push_back("b" + std::to_string(c));
  const std::vector<std::string> meta = {"bridge_unit: mV/V"};
  for (const bool real : {false, true}) {
    ftstack::RecordingWriter w(argv[real ? 4 : 3], meta, names);
    std::vector<double> row(names.size());
    for (int i = 0; i < rows; ++i) {
      row[0] = d.t_s[static_cast<std::size_t>(i)];
      for (int k = 0; k < 6; ++k) row[static_cast<std::size_t>(1 + k)] = d.wrench(i, k);
      const auto& b = real ? d.real_mvv : d.sim_mvv;
      for (int c = 0; c < d.channels(); ++c) row[static_cast<std::size_t>(7 + c)] = b(i, c);
      w.WriteRow(row);
    }
  }
  return 0;
}
