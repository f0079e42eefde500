// ftdiag's memory savings change nothing: the consuming context and diagnosis, the noise
// replacement of the second pass and the column-releasing loader give what the plain paths give.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "diagnosis/diagnose.hpp"
#include "measurement/recording.hpp"
#include "tests/diagnosis/diag_fixture.hpp"

namespace ftstack::diag {
namespace {

constexpr double kNoise = 1e-4;

void ExpectSameReport(const Report& a, const Report& b) {
  EXPECT_EQ(a.verdict, b.verdict);
  EXPECT_TRUE(a.noise_rms == b.noise_rms);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (std::size_t k = 0; k < a.candidates.size(); ++k) {
    EXPECT_EQ(a.candidates[k].name, b.candidates[k].name);
    EXPECT_EQ(a.candidates[k].score, b.candidates[k].score) << a.candidates[k].name;
  }
  ASSERT_EQ(a.effects.size(), b.effects.size());
  for (std::size_t k = 0; k < a.effects.size(); ++k) {
    EXPECT_EQ(a.effects[k].fit.params.dump(), b.effects[k].fit.params.dump());
    EXPECT_TRUE(a.effects[k].fit.pred == b.effects[k].fit.pred) << a.effects[k].fit.name;
  }
  EXPECT_TRUE(a.model == b.model);
}

// Diagnose(DiagData*) takes the bridges' memory for the residual and the load. The reference is
// the const path on an untouched copy: every score, parameter and prediction must be equal, the
// residual must be real − sim (rounded once to single precision), and the data must keep its width without its matrices.
// One of the two fixtures' diagnoses runs the noise-refined second pass, on the reused context
// (SetNoise), in both paths (FTDIAG_DEBUG shows six contexts for the four diagnoses).
TEST(DiagMemory, ConsumingDiagnosisGivesTheSameReport) {
  for (const char* effect : {"creep", "time_skew"}) {
    const auto fx = testing::MakeFixture({{effect, 8}}, 4, 200.0, kNoise, 4.0);
    const Report ref = Diagnose(fx.data);
    DiagData data = fx.data;
    const Report got = Diagnose(&data);
    SCOPED_TRACE(effect);
    ExpectSameReport(ref, got);
    EXPECT_EQ(data.sim_mvv.size(), 0);
    EXPECT_EQ(data.real_mvv.size(), 0);
    EXPECT_EQ(data.channels(), fx.data.channels());
    EXPECT_EQ(got.cx.nc, fx.data.channels());
    // Formed in double and rounded once to the single-precision series.
    EXPECT_TRUE(got.cx.resid == (fx.data.real_mvv - fx.data.sim_mvv).cast<float>());
    // The sim is still reachable through the context, as load + zero, to rounding.
    for (int c = 0; c < got.cx.nc; ++c) {
      for (int i = 0; i < got.cx.n; i += 97) {
        EXPECT_NEAR(got.cx.sim_mvv(i, c), fx.data.sim_mvv(i, c), 1e-14);
      }
    }
  }
}

// The second pass reuses the first pass's context with a new noise (SetNoise): it must equal a
// context made from the data with that noise, in every field that depends on it.
TEST(DiagMemory, SetNoiseEqualsAContextMadeWithThatNoise) {
  const auto fx = testing::MakeFixture({{"resonance", 8}}, 2, 200.0, kNoise, 4.0);
  Eigen::VectorXd sigma(fx.data.channels());
  for (int c = 0; c < sigma.size(); ++c) sigma(c) = kNoise * (0.5 + 0.1 * c);
  const Context made = MakeContext(fx.data, 0.5, &sigma);
  Context set = MakeContext(fx.data, 0.5);
  ASSERT_FALSE(set.sigma == sigma);
  SetNoise(&set, sigma);
  EXPECT_TRUE(set.sigma == made.sigma);
  EXPECT_TRUE(set.weight == made.weight);
  EXPECT_EQ(set.peak_hz, made.peak_hz);
  EXPECT_EQ(set.peak_ratio, made.peak_ratio);
  EXPECT_TRUE(set.resid == made.resid);
  EXPECT_TRUE(set.load == made.load);
  EXPECT_EQ(set.train, made.train);
}

/// Writes columns of `d` (bridges of `m`) as a recording; the wrench and temperature optional.
void WriteCsv(const std::string& path, const DiagData& d, const Eigen::MatrixXd& m, bool wrench,
              bool temp, bool segment) {
  std::vector<std::string> names{"t"};
  if (wrench) names.insert(names.end(), {"Fx", "Fy", "Fz", "Mx", "My", "Mz"});
  if (temp) names.push_back("temp_C");
  if (segment) names.push_back("segment");
  for (int c = 0; c < m.cols(); ++c) names.push_back("b" + std::to_string(c));
  RecordingWriter w(path, {"format: ftstack-recording/1"}, names);
  std::vector<double> row;
  for (std::size_t i = 0; i < d.rows(); ++i) {
    row.assign(1, d.t_s[i]);
    const auto r = static_cast<Eigen::Index>(i);
    if (wrench) {
      for (int k = 0; k < 6; ++k) row.push_back(d.wrench(r, k));
    }
    if (temp) row.push_back(d.temp_c[i]);
    if (segment) row.push_back(i < d.rows() / 3 ? 7.0 : 2.0);
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    w.WriteRow(row);
  }
}

// LoadSimReal releases each file's columns as it copies them; FromRecordings (both files read
// whole) is the reference, with the wrench in the real file or only in the sim, and segments.
TEST(DiagMemory, LoaderReleasingColumnsReadsWhatFromRecordingsBuilds) {
  const auto fx = testing::MakeFixture({{"zero_offset", 6}}, 3, 200.0, kNoise, 2.0);
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("diag_mem_" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);
  for (bool real_wrench : {true, false}) {
    SCOPED_TRACE(real_wrench);
    const std::string sim_path = dir + "/sim.csv";
    const std::string real_path = dir + "/real.csv";
    WriteCsv(sim_path, fx.data, fx.data.sim_mvv, true, false, false);
    WriteCsv(real_path, fx.data, fx.data.real_mvv, real_wrench, true, true);
    const DiagData got = LoadSimReal(sim_path, real_path);
    const DiagData ref = FromRecordings(ReadRecording(sim_path), ReadRecording(real_path));
    EXPECT_EQ(got.t_s, ref.t_s);
    EXPECT_TRUE(got.sim_mvv == ref.sim_mvv);
    EXPECT_TRUE(got.real_mvv == ref.real_mvv);
    EXPECT_TRUE(got.wrench == ref.wrench);
    EXPECT_EQ(got.temp_c, ref.temp_c);
    EXPECT_EQ(got.segment, ref.segment);
    EXPECT_EQ(got.segment.front(), 0);
    EXPECT_EQ(got.segment.back(), 1);
    EXPECT_EQ(got.sim_name, ref.sim_name);
    EXPECT_EQ(got.real_name, ref.real_name);
    EXPECT_EQ(got.wrench.cols(), 6);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ftstack::diag
