// Calibration files and A/B slots: bit flips, truncation and NaN are refused with a clear
// message and the previous calibration stays active.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "calibration/file/cal_file.hpp"
#include "calibration/file/slots.hpp"
#include "sim/default_sensor.hpp"
#include "sim/ideal_calibration.hpp"

namespace ftstack::cal {
namespace {

using sim::IdealCalibration;

namespace fs = std::filesystem;

class Slots : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cal_slots_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    model_ = sim::MakeDefaultSensor();
  }
  void TearDown() override { fs::remove_all(dir_); }

  CalFile Cal(const std::string& serial) const {
    CalFile f = IdealCalibration(*model_, DefaultAdc(6));
    f.serial = serial;
    return f;
  }
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  static std::string Text(const CalFile& f) { return ToJson(f).dump(2) + "\n"; }

  fs::path dir_;
  std::unique_ptr<sim::SensorModel> model_;
};

TEST_F(Slots, InstallAlternatesAndLoadsTheActiveOne) {
  CalSlots slots((dir_ / "dev").string());
  EXPECT_EQ(slots.active(), 0);
  EXPECT_EQ(slots.Install(Cal("first")), 'A');
  EXPECT_EQ(slots.Install(Cal("second")), 'B');
  char slot = 0;
  std::string note;
  EXPECT_EQ(slots.LoadActive(&slot, &note).serial, "second");
  EXPECT_EQ(slot, 'B');
  EXPECT_TRUE(note.empty());
  EXPECT_EQ(slots.Install(Cal("third")), 'A');  // overwrites the oldest, never the active one
  EXPECT_EQ(LoadCalFile(slots.SlotPath('B')).serial, "second");
}

TEST_F(Slots, EveryBitFlipIsRefusedOrHarmlessAndThePreviousStaysActive) {
  CalSlots slots((dir_ / "dev").string());
  ASSERT_EQ(slots.Install(Cal("previous")), 'A');
  const CalFile next = Cal("next");
  const std::string good = Text(next);
  const std::string canonical = ToJson(next).dump();
  int refused = 0;
  int harmless = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ (1 << (i % 8)));
    const std::string p = Write("flip.json", bad);
    try {
      (void)slots.InstallFromPath(p);
      // Accepted only if the content is the same calibration (e.g. exponent 'e' → 'E').
      char s = 0;
      std::string note;
      EXPECT_EQ(ToJson(slots.LoadActive(&s, &note)).dump(), canonical) << "byte " << i;
      ++harmless;
      ASSERT_EQ(slots.Install(Cal("previous")), s == 'A' ? 'B' : 'A');  // restore
      // Keep the "previous" calibration active for the next flip.
    } catch (const CalFileError& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("flip.json"), std::string::npos) << e.what();
      if (i % 64 == 0) {  // full verification of the active slot is slower; sample it
        char s = 0;
        std::string note;
        ASSERT_EQ(slots.LoadActive(&s, &note).serial, "previous") << "byte " << i;
      }
      ASSERT_EQ(slots.active(), 'A') << "byte " << i;  // never switched by a refused file
    }
  }
  EXPECT_GT(refused, static_cast<int>(good.size()) * 99 / 100);
  std::printf("bit flips: %d refused, %d harmless (same content)\n", refused, harmless);
}

TEST_F(Slots, TruncatedFilesAreRefusedWithLineAndColumn) {
  CalSlots slots((dir_ / "dev").string());
  ASSERT_EQ(slots.Install(Cal("previous")), 'A');
  const std::string good = Text(Cal("next"));
  for (std::size_t len = 0; len + 1 < good.size();
       len += std::max<std::size_t>(1, good.size() / 97)) {
    const std::string p = Write("cut.json", good.substr(0, len));
    try {
      (void)slots.InstallFromPath(p);
      ADD_FAILURE() << "accepted a file truncated to " << len << " bytes";
    } catch (const CalFileError& e) {
      const std::string what = e.what();
      // "PATH:LINE:COLUMN: not valid JSON (truncated or corrupt)"
      EXPECT_EQ(what.rfind(p + ":", 0), 0u) << what;
      EXPECT_NE(what.find("truncated"), std::string::npos) << what;
    }
    char s = 0;
    std::string note;
    ASSERT_EQ(slots.LoadActive(&s, &note).serial, "previous");
  }
}

TEST_F(Slots, NanIsRefusedEverywhere) {
  CalSlots slots((dir_ / "dev").string());
  ASSERT_EQ(slots.Install(Cal("previous")), 'A');
  // In memory: the loader refuses, nothing is written.
  CalFile bad = Cal("nan");
  bad.cal.matrix[2][3] = std::nan("");
  EXPECT_THROW(slots.Install(bad), CalFileError);
  EXPECT_EQ(slots.active(), 'A');
  // On disk: JSON has no NaN; the literal is a syntax error, null is "not a number".
  std::string text = Text(Cal("next"));
  const std::size_t m = text.find("\"matrix\"");
  const std::size_t num = text.find_first_of("-0123456789", m);
  const std::size_t end = text.find_first_of(",\n]", num);
  for (const char* lit : {"NaN", "null", "1e999"}) {
    std::string t = text;
    t.replace(num, end - num, lit);
    const std::string p = Write("nan.json", t);
    try {
      (void)slots.InstallFromPath(p);
      ADD_FAILURE() << lit << " accepted";
    } catch (const CalFileError& e) {
      EXPECT_NE(std::string(e.what()).find("nan.json"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slots.active(), 'A');
  }
}

TEST_F(Slots, CorruptActiveSlotFallsBackToThePreviousCalibration) {
  CalSlots slots((dir_ / "dev").string());
  ASSERT_EQ(slots.Install(Cal("old")), 'A');
  ASSERT_EQ(slots.Install(Cal("new")), 'B');
  // The storage corrupts the active slot afterwards (one flipped digit).
  std::string text;
  {
    std::ifstream in(slots.SlotPath('B'));
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const std::size_t d = text.find_first_of("123456789", text.find("\"matrix\""));
  text[d] = text[d] == '9' ? '8' : static_cast<char>(text[d] + 1);
  std::ofstream(slots.SlotPath('B')) << text;
  char s = 0;
  std::string note;
  const CalFile f = slots.LoadActive(&s, &note);
  EXPECT_EQ(f.serial, "old");
  EXPECT_EQ(s, 'A');
  EXPECT_NE(note.find("CRC mismatch"), std::string::npos) << note;
  EXPECT_NE(note.find("slot A"), std::string::npos) << note;
}

TEST(CalFileFormat, ExtendedTermsRoundTripAndCrcIsZlibs) {
  // CRC-32 check value of "123456789" (IEEE 802.3 / zlib).
  EXPECT_EQ(Crc32("123456789"), 0xCBF43926u);
  CalFile f;
  f.cal.channel_count = 3;
  f.adc = DefaultAdc(3);
  for (std::size_t r = 0; r < 6; ++r) {
    for (std::size_t c = 0; c < 3; ++c) f.cal.matrix[r][c] = 100.0 * (1 + r) - 37.0 * c;
  }
  f.cal.product_count = 2;
  f.cal.products[0] = {0, 1};
  f.cal.products[1] = {2, 2};
  f.cal.product_matrix[4][1] = -3.5;
  f.cal.temperature_compensated = true;
  f.cal.temp_ref_c = 21.5;
  f.cal.temp_min_c = 0;
  f.cal.temp_max_c = 50;
  f.cal.bias_slope_mvv_per_c[1] = 2e-4;
  f.cal.gain_slope_per_c[2] = -1e-4;
  const nlohmann::json j = ToJson(f);
  EXPECT_EQ(j["schema"], kCalSchema);
  const CalFile g = FromJson(j, "mem");
  EXPECT_EQ(g.cal.product_count, 2);
  EXPECT_EQ(g.cal.products[1].a, 2);
  EXPECT_DOUBLE_EQ(g.cal.product_matrix[4][1], -3.5);
  EXPECT_TRUE(g.cal.temperature_compensated);
  EXPECT_DOUBLE_EQ(g.cal.gain_slope_per_c[2], -1e-4);
  EXPECT_EQ(ToJson(g), j);
  // A product naming a channel that does not exist is refused even with a valid CRC.
  nlohmann::json bad = j;
  bad["model"]["products"][0] = {0, 3};
  bad["crc32"] = "0x00000000";
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", ContentCrc(bad));
  bad["crc32"] = buf;
  EXPECT_THROW((void)FromJson(bad, "mem"), CalFileError);
  // A fixed-point form that does not match the matrix is refused (valid CRC, edited coef).
  nlohmann::json edited = j;
  edited["fixed_point"]["coef"][0][0] = edited["fixed_point"]["coef"][0][0].get<std::int64_t>() + 1;
  std::snprintf(buf, sizeof buf, "0x%08x", ContentCrc(edited));
  edited["crc32"] = buf;
  try {
    (void)FromJson(edited, "mem");
    ADD_FAILURE() << "edited fixed-point form accepted";
  } catch (const CalFileError& e) {
    EXPECT_NE(std::string(e.what()).find("fixed_point.coef"), std::string::npos) << e.what();
  }
}

/// A JSON calibration with its CRC recomputed after an edit.
nlohmann::json WithCrc(nlohmann::json j) {
  j["crc32"] = "0x00000000";
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", ContentCrc(j));
  j["crc32"] = buf;
  return j;
}

TEST(CalFile, InvalidAxesTravelOnlyWithSchema3) {
  CalFile f;
  f.cal.channel_count = 6;
  f.adc = DefaultAdc(6);
  f.rated = {200, 200, 400, 10, 10, 8};
  for (std::size_t r = 0; r < 6; ++r) f.cal.matrix[r][r] = 100.0;
  // Without flags: schema 2 and no field (files of before read and write unchanged).
  EXPECT_EQ(ToJson(f)["schema"], kCalSchema);
  EXPECT_FALSE(ToJson(f).contains("invalid_axes"));
  f.cal.invalid_axes = (1u << 3) | (1u << 5);
  const nlohmann::json j = ToJson(f);
  EXPECT_EQ(j["schema"], kCalSchemaV3);  // a reader without the field refuses the file
  EXPECT_EQ(j["invalid_axes"], nlohmann::json::array({"Mx", "Mz"}));
  const CalFile g = FromJson(j, "mem");
  EXPECT_EQ(g.cal.invalid_axes, (1u << 3) | (1u << 5));
  EXPECT_EQ(ToJson(g), j);
  // Into the fixed-point form the board loads.
  EXPECT_EQ(ToFixed(g, g.adc).invalid_axes, (1u << 3) | (1u << 5));
  // The field without schema 3, schema 3 without the field, unknown or repeated names: refused.
  nlohmann::json bad = j;
  bad["schema"] = kCalSchema;
  EXPECT_THROW((void)FromJson(WithCrc(bad), "mem"), CalFileError);
  bad = j;
  bad.erase("invalid_axes");
  EXPECT_THROW((void)FromJson(WithCrc(bad), "mem"), CalFileError);
  bad = j;
  bad["invalid_axes"] = {"Mz", "Mq"};
  EXPECT_THROW((void)FromJson(WithCrc(bad), "mem"), CalFileError);
  bad["invalid_axes"] = {"Mz", "Mz"};
  EXPECT_THROW((void)FromJson(WithCrc(bad), "mem"), CalFileError);
}

}  // namespace
}  // namespace ftstack::cal
