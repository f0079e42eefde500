// Declared bridge units (measurement/units.hpp): converter descriptions against closed forms.
#include "measurement/units.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace ftstack {
namespace {

Recording WithMeta(std::vector<std::string> meta) {
  Recording r = ParseRecording("t,b0\n0,1\n", "x.csv");
  r.metadata = std::move(meta);
  return r;
}

TEST(Units, ConverterCodesAndScaleFollowTheDatasheetFormulas) {
  const Converter u = ParseConverter("bits=10, coding=unsigned, gain=200", "t");
  EXPECT_EQ(MinCode(u), 0);
  EXPECT_EQ(MaxCode(u), 1023);
  EXPECT_EQ(ZeroCode(u), 0);
  // Ratiometric, reference = excitation: 1 code = 1/1024 of the excitation at the converter.
  EXPECT_DOUBLE_EQ(MvvPerCount(u, 0.0), 1000.0 / 200.0 / 1024.0);
  const Converter s = ParseConverter("bits=24,coding=signed,gain=128,reference_ratio=0.5", "t");
  EXPECT_EQ(MinCode(s), -8388608);
  EXPECT_EQ(MaxCode(s), 8388607);
  EXPECT_DOUBLE_EQ(MvvPerCount(s, 0.0) * 8388608.0, 3.90625);  // the built-in sensor's ADC
  const Converter o =
      ParseConverter("bits=16,coding=offset-binary,ratiometric=no,reference_v=2.5,gain=64", "t");
  EXPECT_EQ(ZeroCode(o), 32768);
  EXPECT_EQ(MvvPerCount(o, 0.0), 0.0);  // not ratiometric: needs the excitation
  EXPECT_DOUBLE_EQ(MvvPerCount(o, 5.0), 1000.0 * 2.5 / 5.0 / 64.0 / 32768.0);
  const Converter f = ParseConverter("bits=12,full_scale_mvv=4", "t");
  EXPECT_DOUBLE_EQ(MvvPerCount(f, 0.0), 4.0 / 2048.0);
  EXPECT_EQ(ParseConverter(FormatConverter(o), "t").reference_v, 2.5);
}

TEST(Units, BadDescriptionsAreRefusedNamingTheKey) {
  EXPECT_THROW((void)ParseConverter("coding=unsigned", "t"), std::invalid_argument);
  EXPECT_THROW((void)ParseConverter("bits=40", "t"), std::invalid_argument);
  EXPECT_THROW((void)ParseConverter("bits=10,gain=-1", "t"), std::invalid_argument);
  try {
    (void)ParseConverter("bits=10,vref=3", "where");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "where: unknown converter key 'vref'");
  }
  EXPECT_THROW((void)ResolveInputUnit(WithMeta({"bridge_unit: counts"})), RecordingError);
  EXPECT_THROW((void)ResolveInputUnit(WithMeta({"bridge_unit: V"})), RecordingError);
  EXPECT_THROW((void)ResolveInputUnit(WithMeta({"bridge_unit: furlongs"})), RecordingError);
}

TEST(Units, MetadataAndCommandLineResolveAndConvertToMvv) {
  Recording r = WithMeta({"converter: bits=16, coding=offset-binary, full_scale_mvv=2"});
  r.Column("b0")[0] = 32768 + 16384;
  InputUnit u = ResolveInputUnit(r);
  EXPECT_EQ(u.unit, BridgeUnit::kCounts);
  EXPECT_EQ(u.source, "metadata");
  ConvertBridgesToMvv(&r, 1, u);
  EXPECT_DOUBLE_EQ(r.Column("b0")[0], 1.0);  // half of +full scale
  Recording v = WithMeta({"bridge_unit: V", "excitation_v: 5"});
  v.Column("b0")[0] = 0.01;
  u = ResolveInputUnit(v);
  ConvertBridgesToMvv(&v, 1, u);
  EXPECT_DOUBLE_EQ(v.Column("b0")[0], 2.0);
  UnitOverrides cli;
  cli.unit = "mV/V";
  u = ResolveInputUnit(WithMeta({"bridge_unit: V", "excitation_v: 5"}), cli);
  EXPECT_EQ(u.unit, BridgeUnit::kMvv);
  EXPECT_EQ(u.source, "command line");
}

TEST(Units, RangeCheckNamesLineColumnValueAndRange) {
  Recording r = ParseRecording("# a\nt,b0,b1\n0,1,2\n1,1,9\n", "mem.csv");
  ValueRange range{-3.0, 3.0, "mV/V", "the assumed range"};
  try {
    CheckBridgeRange(r, 2, range, 0.0);
    FAIL();
  } catch (const RecordingError& e) {
    // Not a file on disk: the column falls back to the field number + 1.
    EXPECT_EQ(std::string(e.what()).rfind("mem.csv:4:3: b1 = 9 lies outside the assumed range "
                                          "[-3, 3] mV/V; declare the unit",
                                          0),
              0u)
        << e.what();
  }
  EXPECT_NO_THROW(CheckBridgeRange(r, 1, range, 0.0));
}

}  // namespace
}  // namespace ftstack
