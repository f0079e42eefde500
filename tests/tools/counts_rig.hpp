// A synthetic rig for the unit tests of the programs: a 3-D-printed 8-bridge sensor read by a
// 10-bit unipolar converter behind a gain-200 amplifier, its recordings written with or without
// the unit declared, and the ftcal runs the tests share.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace ftstack::test {

namespace fs = std::filesystem;

/// A per-process temporary folder, removed at the end.
struct Tmp {
  fs::path dir;
  explicit Tmp(const std::string& name = "ftcal_units")
      : dir(fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    fs::create_directories(dir);
  }
  ~Tmp() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

/// The generator's rated range (ftcal fit needs --sensor or --rated; a counts recording has no
/// sensor description).
inline const std::string kRated = " --rated 40,40,80,2,2,1.5";

/// Runs ftcal ARGS, stderr into `err`; the exit code.
inline int RunFtcal(const std::string& args, const std::string& err) {
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/ftcal " + args + " >/dev/null 2>" + err;
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// One row of the synthetic rig: pose, reference wrench, 8 codes.
struct Row {
  double t = 0;
  int pose = 0;
  std::array<double, 6> w{};
  std::array<int, 8> code{};
};

/// A 3-D-printed 8-bridge sensor read by a 10-bit unipolar converter (codes 0 … 1023) at about
/// 150 Hz with ±30 % timestamp jitter; 47 static poses recorded separately and joined in a
/// shuffled order (a `segment` column and a `pose` column mark them). Written for this test
/// only: a random 8 × 6 sensitivity, mid-scale offsets, 0.6-count Gaussian noise, rounding.
/// `counts_per_unit` and `offset_codes`, where given, receive the sensitivity (codes per N or
/// N·m) and the zero-load codes.
inline std::vector<Row> Generate(unsigned seed,
                                 Eigen::Matrix<double, 8, 6>* counts_per_unit_out = nullptr,
                                 std::array<double, 8>* offset_codes = nullptr) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const std::array<double, 6> rated = {40.0, 40.0, 80.0, 2.0, 2.0, 1.5};
  Eigen::Matrix<double, 8, 6> counts_per_unit;
  for (int c = 0; c < 8; ++c) {
    for (int a = 0; a < 6; ++a) counts_per_unit(c, a) = uni(rng) * 70.0 / rated[a];
  }
  std::array<double, 8> offset{};
  for (double& o : offset) o = 512.0 + 60.0 * uni(rng);
  if (counts_per_unit_out != nullptr) *counts_per_unit_out = counts_per_unit;
  if (offset_codes != nullptr) *offset_codes = offset;
  std::vector<int> order(47);
  for (int p = 0; p < 47; ++p) order[static_cast<std::size_t>(p)] = p;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::array<double, 6>> pose_w(47);
  for (auto& w : pose_w) {
    for (int a = 0; a < 6; ++a) w[static_cast<std::size_t>(a)] = uni(rng) * rated[a];
  }
  std::vector<Row> rows;
  double t = 0.0;
  for (const int p : order) {
    const int n = 150 + static_cast<int>(60 * uni(rng));
    for (int i = 0; i < n; ++i) {
      Row r;
      t += (1.0 + 0.3 * uni(rng)) / 150.0;
      r.t = t;
      r.pose = p;
      r.w = pose_w[static_cast<std::size_t>(p)];
      Eigen::Map<const Eigen::Matrix<double, 6, 1>> w(r.w.data());
      const Eigen::Matrix<double, 8, 1> b = counts_per_unit * w;
      for (int c = 0; c < 8; ++c) {
        const double v = offset[static_cast<std::size_t>(c)] + b(c) + 0.6 * gauss(rng);
        r.code[static_cast<std::size_t>(c)] = static_cast<int>(std::lround(v));
      }
      rows.push_back(r);
    }
    t += 2.0;  // the next file started later
  }
  return rows;
}

/// Writes the rows of the test set (pose % 5 == held_out_mod) or of the training set, with the
/// converter declared in the metadata or not.
inline void Write(const std::string& path, const std::vector<Row>& rows, bool declare,
                  bool test_set, int held_out_mod) {
  std::ofstream out(path);
  out << "# sensor: printed-8-bridge\n";
  if (declare) out << "# bridge_unit: counts\n# converter: bits=10, coding=unsigned, gain=200\n";
  out << "t,segment,pose,Fx,Fy,Fz,Mx,My,Mz,b0,b1,b2,b3,b4,b5,b6,b7\n";
  char buf[64];
  for (const Row& r : rows) {
    if ((r.pose % 5 == held_out_mod) != test_set) continue;
    std::snprintf(buf, sizeof buf, "%.6f", r.t);
    out << buf << ',' << r.pose << ',' << r.pose;
    for (const double w : r.w) out << ',' << w;
    for (const int c : r.code) out << ',' << c;
    out << '\n';
  }
}

/// The data lines of a written recording (metadata lines dropped).
inline std::string DataLines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::string out;
  while (std::getline(in, line))
    if (line.empty() || line[0] != '#') out += line + "\n";
  return out;
}

/// Fits tmp/cal.json (linear) from the declared training rows of split 2.
inline bool FitDeclared(const Tmp& tmp, const std::vector<Row>& rows) {
  Write(tmp / "train.csv", rows, true, false, 2);
  const int rc = RunFtcal("fit --in " + (tmp / "train.csv") + " --out " + (tmp / "cal.json") +
                              " --model linear" + kRated,
                          tmp / "fit.err");
  if (rc != 0) ADD_FAILURE() << Slurp(tmp / "fit.err");
  return rc == 0;
}

}  // namespace ftstack::test
