// ftdiag's memory savings change nothing: the consuming context and diagnosis, the noise
// replacement of the second pass, the column-releasing loader, the searches' compact buffers and
// the streamed fits give what the plain paths give.
#include <gtest/gtest.h>
#include <malloc.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
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
// residual must be real − sim (rounded once to single precision), and the data must keep its width
// without its matrices. One of the two fixtures' diagnoses runs the noise-refined second pass, on
// the reused context (SetNoise), in both paths (FTDIAG_DEBUG shows six contexts for the four
// diagnoses).
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
  EXPECT_TRUE(set.load.matrix() == made.load.matrix());
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

/// The creep fixture as if joined from three recordings (segments restart the filters).
testing::Fixture SegmentedFixture() {
  testing::Fixture f = testing::MakeFixture({{"creep", 8}}, 5, 200.0, kNoise, 4.0);
  const std::size_t n = f.data.rows();
  f.data.segment.assign(n, 0);
  for (std::size_t i = n / 3; i < n; ++i) f.data.segment[i] = i < 2 * n / 3 ? 1 : 2;
  return f;
}

// The searches' compact buffers hold exactly what the whole filters give at the rows they keep:
// the lag of the load (LowPassLoadRows) and the ringing over a window starting at rest inside
// the record (RingingAt), with segment restarts inside.
TEST(DiagMemory, CompactSearchBuffersHoldTheWholeFiltersRows) {
  const testing::Fixture f = SegmentedFixture();
  const Context cx = MakeContext(f.data);
  ASSERT_EQ(cx.segments, 3);
  const auto n = static_cast<std::size_t>(cx.n);
  const double* t = cx.data->t_s.data();
  std::vector<std::vector<double>> whole(static_cast<std::size_t>(cx.nc), std::vector<double>(n));
  std::vector<const double*> in;
  std::vector<double*> out;
  for (int c = 0; c < cx.nc; ++c) {
    in.push_back(cx.load.col(c).data());
    out.push_back(whole[static_cast<std::size_t>(c)].data());
  }
  std::vector<int> rows;
  for (int i = 0; i < cx.n; i += 7) rows.push_back(i);
  Eigen::MatrixXd lag;
  fx::LowPassLoadRows(cx, 2.5, rows, &lag);
  FirstOrderLowPassColumns(t, n, 2.5, in.data(), out.data(), in.size(), cx.restart.data());
  ASSERT_EQ(lag.rows(), static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (int c = 0; c < cx.nc; ++c) {
      ASSERT_EQ(lag(static_cast<Eigen::Index>(r), c), whole[static_cast<std::size_t>(c)][rows[r]]);
    }
  }
  // Ringing of channels 4 and 1 over rows [i0, i0 + m), every 3rd row, at rest at i0.
  const std::vector<int> chans{4, 1};
  const int i0 = cx.n / 4 + 5;
  const int m = cx.n / 2;
  Eigen::MatrixXd h;
  fx::RingingAt(cx, 7.0, 0.05, chans, i0, m, 3, &h);
  ASSERT_EQ(h.rows(), (m + 2) / 3);
  for (std::size_t k = 0; k < chans.size(); ++k) {
    const double* x = cx.load.col(chans[k]).data() + i0;
    std::vector<double> y(static_cast<std::size_t>(m));
    double* yp = y.data();
    SecondOrderLowPassColumns(t + i0, static_cast<std::size_t>(m), 7.0, 0.05, &x, &yp, 1,
                              cx.restart.data() + i0);
    for (int r = 0; r < h.rows(); ++r) {
      ASSERT_EQ(h(r, static_cast<Eigen::Index>(k)), y[static_cast<std::size_t>(3 * r)] - x[3 * r])
          << "row " << i0 + 3 * r;
    }
  }
}

// The streamed final fits sum what FitChannels sums, in its order: the same fit to the last bit,
// on a feature streamed by ForLaggedLoad and on the whole filter's columns.
TEST(DiagMemory, StreamedChannelSumsAreFitChannels) {
  const testing::Fixture f = SegmentedFixture();
  const Context cx = MakeContext(f.data);
  const double tau = 4.0;
  fx::ChannelSums sums(cx, 2);
  fx::ForLaggedLoad(cx, &tau, 1, [&](int i, int c, const double* lag) {
    if (!cx.train[static_cast<std::size_t>(i)]) return;
    const double x[2] = {lag[0], cx.load(i, c)};
    sums.Add(c, x, cx.resid(i, c));
  });
  const fx::ChannelFit got = sums.Solve(cx);
  Eigen::MatrixXd lp(cx.n, cx.nc);
  std::vector<const double*> in;
  std::vector<double*> out;
  for (int c = 0; c < cx.nc; ++c) {
    in.push_back(cx.load.col(c).data());
    out.push_back(lp.col(c).data());
  }
  FirstOrderLowPassColumns(cx.data->t_s.data(), static_cast<std::size_t>(cx.n), tau, in.data(),
                           out.data(), in.size(), cx.restart.data());
  const fx::ChannelFit ref = fx::FitChannels(
      cx, cx.resid, 2,
      [&](int i, int c, double* x) {
        x[0] = lp(i, c);
        x[1] = cx.load(i, c);
      },
      nullptr);
  EXPECT_TRUE(got.beta == ref.beta);
  EXPECT_TRUE(got.sse == ref.sse);
  EXPECT_EQ(got.sse_w, ref.sse_w);
  for (int c = 0; c < cx.nc; ++c) {
    EXPECT_TRUE(got.cov[static_cast<std::size_t>(c)] == ref.cov[static_cast<std::size_t>(c)]);
  }
  EXPECT_GT(got.beta.row(0).cwiseAbs().maxCoeff(), 0.0);  // the creep fixture's lag is fitted
}

// RowCorr reads the single-precision columns in place: the same correlation, to the last bit, as
// the double copies of the columns.
TEST(DiagMemory, RowCorrInPlaceIsTheCorrelationOfDoubleCopies) {
  const auto fx = testing::MakeFixture({{"creep", 8}}, 4, 200.0, kNoise, 4.0);
  const Context cx = MakeContext(fx.data);
  const auto fit = fx::FitOverloadShift(cx, cx.resid);
  ASSERT_TRUE(fit.has_value());
  for (int c = 0; c < cx.nc; ++c) {
    const Eigen::VectorXd a = cx.resid.col(c).cast<double>();
    const Eigen::VectorXd b = fit->pred.col(c).cast<double>();
    EXPECT_EQ(fx::RowCorr(cx, cx.resid, fit->pred, c),
              Correlation(a.data(), b.data(), static_cast<std::size_t>(cx.n)));
  }
}

/// Resident memory, kB, of a /proc/self/status line ("VmHWM:"; -1 when absent).
long StatusKb(const char* key) {
  long kb = -1;
  if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f) != nullptr) {
      if (std::strncmp(line, key, std::strlen(key)) == 0) kb = std::atol(line + std::strlen(key));
    }
    std::fclose(f);
  }
  return kb;
}

/// Resets the process's resident high-water mark to its current size (false when not allowed).
bool ResetPeak() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (f == nullptr) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// The overload shift's split is the argmax of the suffix sums' gain (the earliest of equal gains),
// found without a table of them: the reference here builds the whole m × N table. Its fit holds
// its prediction and the list of training rows, not a table of 8 bytes a row and channel (the
// resident peak of the fit stays under 1.6 predictions; with the table it is about 2.4).
TEST(DiagMemory, OverloadShiftHoldsNoSuffixTable) {
  // Large buffers mapped and returned when freed (the resident peak then counts what the fit
  // allocates, not heap memory freed before it).
  // (A sanitizer's allocator ignores it: the peak is then not checked.)
  const bool mapped = mallopt(M_MMAP_THRESHOLD, 1 << 20) == 1;
  const auto fx = testing::MakeFixture({{"overload_shift", 8}}, 3, 2000.0, kNoise, 6.0);
  const Context cx = MakeContext(fx.data);
  std::vector<int> rows;
  for (int i = 0; i < cx.n; ++i) {
    if (cx.train[static_cast<std::size_t>(i)] != 0) rows.push_back(i);
  }
  const auto m = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd suffix = Eigen::MatrixXd::Zero(m + 1, cx.nc);
  for (Eigen::Index j = m - 1; j >= 0; --j) {
    for (int c = 0; c < cx.nc; ++c) {
      suffix(j, c) = suffix(j + 1, c) + cx.resid(rows[static_cast<std::size_t>(j)], c);
    }
  }
  double best = -1.0;
  Eigen::Index bj = 0;
  for (Eigen::Index j = 10; j + 10 < m; ++j) {
    double g = 0.0;
    for (int c = 0; c < cx.nc; ++c) g += cx.weight(c) * suffix(j, c) * suffix(j, c);
    g /= static_cast<double>(m - j);
    if (g > best * (1.0 + 1e-12)) {
      best = g;
      bj = j;
    }
  }
  const double t_after = cx.data->t_s[static_cast<std::size_t>(rows[static_cast<std::size_t>(bj)])];
  const std::size_t before = rows[static_cast<std::size_t>(bj - 1)];
  const double onset = rows[static_cast<std::size_t>(bj)] - static_cast<int>(before) > 1
                           ? 0.5 * (cx.data->t_s[before] + t_after)
                           : t_after;
  suffix = Eigen::MatrixXd();
  malloc_trim(0);
  const bool peak_known = ResetPeak();
  const long before_kb = StatusKb("VmRSS:");
  const auto fit = fx::FitOverloadShift(cx, cx.resid);
  const long peak_kb = StatusKb("VmHWM:");
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->params["onset_s"].get<double>(), onset, 1e-12);
  const double pred_kb = static_cast<double>(cx.resid.size()) * sizeof(float) / 1024.0;
  ASSERT_GT(pred_kb, 4000.0);  // large enough to see a table of the rows
  if (kSanitized || !mapped || !peak_known || before_kb < 0 || peak_kb < 0) {
    GTEST_SKIP() << "resident peak not measurable here";
  }
  std::printf("resident peak of the fit %ld kB, its prediction %.0f kB\n", peak_kb - before_kb,
              pred_kb);
  EXPECT_LT(static_cast<double>(peak_kb - before_kb), 1.6 * pred_kb)
      << "resident peak of the fit " << peak_kb - before_kb << " kB, prediction " << pred_kb;
}

}  // namespace
}  // namespace ftstack::diag
