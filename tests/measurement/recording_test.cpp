// The recording reader/writer: columns by name, and refusals that name file, line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "measurement/recording.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim {
namespace {

std::string ErrorOf(const std::string& text, const ReadOptions& opt = {}) {
  try {
    (void)ParseRecording(text, "rec.csv", opt);
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

TEST(Recording, ReadsColumnsByNameKeepsUnknownColumnsAndMetadata) {
  const std::string text =
      "# sensor: demo-3beam\n# rate_hz: 200\n"
      "t,Fx,Fy,Fz,Mx,My,Mz,b0,b1,extra,temp_C\r\n"
      "0.0,1,2,3,0.1,0.2,0.3,0.0003572,-4.639e-4,7,23.45\n"
      "0.005, -1 ,+2,3e0,0.1,0.2,0.3,1,2,8,23.5\n\n";
  ReadOptions opt;
  opt.require_wrench = true;
  opt.require_bridges = true;
  const Recording r = ParseRecording(text, "rec.csv", opt);
  EXPECT_EQ(r.rows(), 2u);
  EXPECT_EQ(r.BridgeCount(), 2u);
  EXPECT_EQ(r.Meta("sensor"), "demo-3beam");
  EXPECT_EQ(r.Meta("rate_hz"), "200");
  EXPECT_DOUBLE_EQ(r.Column("b0")[0], 0.0003572);
  EXPECT_DOUBLE_EQ(r.Column("b1")[0], -4.639e-4);
  EXPECT_DOUBLE_EQ(r.Column("Fx")[1], -1.0);
  EXPECT_DOUBLE_EQ(r.Column("Fy")[1], 2.0);
  EXPECT_DOUBLE_EQ(r.Column("extra")[1], 8.0);
  EXPECT_DOUBLE_EQ(r.Column("temp_C")[1], 23.5);
  EXPECT_EQ(r.data_lines[1], 5u);
  EXPECT_THROW((void)r.Column("nope"), RecordingError);
}

TEST(Recording, RefusalsNameLineAndColumn) {
  EXPECT_EQ(ErrorOf("t,b0\n0,1\n1,abc\n"), "rec.csv:3:3: column 'b0': 'abc' is not a number");
  EXPECT_EQ(ErrorOf("t,b0\n0,1\n1,nan\n"), "rec.csv:3:3: column 'b0': NaN/infinity is not allowed");
  EXPECT_EQ(ErrorOf("t,b0\n0,inf\n"), "rec.csv:2:3: column 'b0': NaN/infinity is not allowed");
  EXPECT_EQ(ErrorOf("t,b0\n0,1\n0,2\n"), "rec.csv:3:1: t is not strictly increasing");
  EXPECT_EQ(ErrorOf("b0,t\n1,0.5\n2,0.4\n"), "rec.csv:3:3: t is not strictly increasing");
  EXPECT_EQ(ErrorOf("t,b0\n0,1,2\n"), "rec.csv:2:5: more fields than the header's 2 columns");
  EXPECT_EQ(ErrorOf("t,b0\n0\n"), "rec.csv:2:2: row has 1 fields, header has 2");
  EXPECT_EQ(ErrorOf("t,b0\n0,\n"), "rec.csv:2:3: column 'b0': '' is not a number");
  EXPECT_EQ(ErrorOf("t,,b0\n"), "rec.csv:1:3: empty column name in header");
  EXPECT_EQ(ErrorOf("t,b0,t\n"), "rec.csv:1:6: duplicate column 't'");
  EXPECT_EQ(ErrorOf("# only comments\n"), "rec.csv: no header line");
  ReadOptions opt;
  opt.require_wrench = true;
  EXPECT_EQ(ErrorOf("t,Fx,Fy,Fz,Mx,My\n", opt), "rec.csv:1:17: header lacks required column 'Mz'");
  opt = {};
  opt.require_bridges = true;
  EXPECT_EQ(ErrorOf("t,Fx\n", opt), "rec.csv:1:5: header lacks required column 'b0'");
}

TEST(Recording, WriteThenReadRoundTripsAndAlignmentIsChecked) {
  const test::TempDir tmp("rec");
  const std::filesystem::path& dir = tmp.path();
  Recording r;
  r.metadata = {"sensor: test"};
  r.names = {"t", "b0", "b1"};
  r.columns = {{0.0, 0.001, 0.002}, {1.234567891e-4, -2.5, 3.0}, {0.5, 0.25, -0.125}};
  const std::string path = (dir / "a.csv").string();
  WriteRecording(path, r);
  const Recording back = ReadRecording(path);
  EXPECT_EQ(back.Meta("sensor"), "test");
  ASSERT_EQ(back.rows(), 3u);
  for (std::size_t c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(back.columns[c][i], r.columns[c][i], 1e-9 * std::fabs(r.columns[c][i]));
    }
  }
  CheckAligned(back, r);  // same t
  Recording shifted = back;
  shifted.path = "sim.csv";
  shifted.Column("t")[2] += 2e-6;
  try {
    CheckAligned(shifted, r);
    FAIL() << "misaligned t accepted";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("sim.csv:"), std::string::npos) << e.what();
  }
  Recording shorter = back;
  shorter.path = "sim.csv";
  for (auto& col : shorter.columns) col.pop_back();
  EXPECT_THROW(CheckAligned(shorter, r), RecordingError);
  EXPECT_THROW((void)ReadRecording((dir / "missing.csv").string()), RecordingError);
}

TEST(Recording, StreamingWriterRefusesWrongWidth) {
  const test::TempDir tmp("rec");
  const std::string path = tmp / "w.csv";
  RecordingWriter w(path, {}, {"t", "b0"});
  w.WriteRow({0.0, 1.0});
  EXPECT_THROW(w.WriteRow({1.0}), RecordingError);
  w.Flush();
  const Recording back = ReadRecording(path);
  EXPECT_EQ(back.rows(), 1u);
}

TEST(Recording, FileIsReadInChunksAcrossLineBoundaries) {
  // ReadRecording streams the file in 1 MiB chunks: rows cut by a chunk's end, a metadata line
  // longer than a chunk, CRLF endings and a last line without '\n' must read as the text does.
  const test::TempDir tmp("rec");
  const std::string path = tmp / "big.csv";
  std::string text = "# note: " + std::string(1500000, 'x') + "\r\nt,b0,b1\r\n";
  const std::size_t rows = 120000;  // ~3 MB: several chunk boundaries inside rows
  char line[96];
  for (std::size_t i = 0; i < rows; ++i) {
    const int n = std::snprintf(line, sizeof line, "%zu.5,%zu,-%zu.25%s", i, 3 * i, i,
                                i + 1 == rows ? "" : "\r\n");
    text.append(line, static_cast<std::size_t>(n));
  }
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), f), text.size());
    std::fclose(f);
  }
  const Recording r = ReadRecording(path);
  ASSERT_EQ(r.rows(), rows);
  EXPECT_EQ(r.Meta("note").size(), 1500000u);
  for (std::size_t i = 0; i < rows; ++i) {
    const auto k = static_cast<double>(i);
    ASSERT_EQ(r.Column("t")[i], k + 0.5) << i;
    ASSERT_EQ(r.Column("b0")[i], 3.0 * k) << i;
    ASSERT_EQ(r.Column("b1")[i], -(k + 0.25)) << i;
    ASSERT_EQ(r.data_lines[i], i + 3) << i;
  }
  // An error deep in the file names its line (the line number counts across chunks).
  const std::size_t bad = text.rfind("\r\n") + 2;  // start of the last row
  text.replace(bad, 1, "z");
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), f), text.size());
    std::fclose(f);
  }
  try {
    (void)ReadRecording(path);
    FAIL() << "a bad number was accepted";
  } catch (const RecordingError& e) {
    const std::string want = path + ":" + std::to_string(rows + 2) + ":1: column 't'";
    EXPECT_EQ(std::string(e.what()).substr(0, want.size()), want) << e.what();
  }
}

}  // namespace
}  // namespace ftstack::sim
