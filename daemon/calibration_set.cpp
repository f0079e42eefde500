#include "daemon/calibration_set.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "calibration/file/cal_file.hpp"
#include "calibration/file/payload_file.hpp"
#include "calibration/file/slots.hpp"

namespace ftstack::daemon {
namespace {

void AppendLe(std::string* out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}

/// One calibration slot from a file: fixed-point form for `adc`, CRC of the file's content.
fw::CalSlot SlotFromFile(const std::string& path, const hal::AdcInfo& adc,
                         std::array<double, 6>* rated) {
  const cal::CalFile file = cal::LoadCalFile(path);  // verifies schema and CRC; throws
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  fw::CalSlot slot;
  slot.fixed = cal::ToFixed(file, cal::AdcForDevice(file, adc));
  // Which converter the file was fitted from, beside what this ADC makes of it: a calibration in
  // mV/V reads any converter through the HAL's scale; one in counts only the same rails.
  const std::string fitted = file.extra.value("recording_unit", std::string());
  const std::string converter = file.extra.value("converter", std::string());
  std::string origin;
  if (!fitted.empty()) {
    origin = " (fitted from " + fitted +
             (converter.empty() ? "" : " of converter (" + converter + ")") + ")";
  }
  std::fprintf(stderr, "ftd: calibration %s: input unit %s%s, read from this ADC's counts\n",
               path.c_str(), file.input_unit.c_str(), origin.c_str());
  slot.crc32 = j.is_discarded() ? FixedFormCrc(slot.fixed) : cal::ContentCrc(j);
  slot.present = true;
  if (rated != nullptr) *rated = file.rated;
  return slot;
}

/// Loads a calibration file into `slot`. A file that cannot be used (missing, corrupt, bad CRC,
/// refused by the fixed-point loader) leaves the slot empty and is reported on stderr in one line
/// naming it (file:line:column for syntax errors): the device still comes up.
void LoadSlot(const std::string& path, const char* name, const hal::AdcInfo& adc, fw::CalSlot* slot,
              std::array<double, 6>* rated) {
  try {
    *slot = SlotFromFile(path, adc, rated);
    if (slot->fixed.invalid_axes != 0) {
      std::fprintf(stderr,
                   "ftd: calibration slot %s (%s) flags axis %s invalid (not calibrated): served "
                   "as NaN / 0 with status bit 10\n",
                   name, path.c_str(), cal::AxisList(slot->fixed.invalid_axes).c_str());
    }
  } catch (const std::exception& e) {
    *slot = fw::CalSlot{};
    std::fprintf(stderr, "ftd: calibration slot %s refused: %s\n", name, e.what());
  }
}

/// Slot 0 from the backend's own calibration (a simulated sensor's); throws FtdError.
void LoadBuiltin(const FtdOptions& opt, AdcBackend& backend, const hal::AdcInfo& info,
                 fw::CalSlot* slot, std::array<double, 6>* rated) {
  try {
    const std::optional<cal::CalFile> builtin = backend.BuiltinCalibration(info);
    if (!builtin) throw FtdError("--adc " + opt.adc + " needs --cal CAL.json");
    slot->fixed = cal::ToFixed(*builtin, info);
    slot->crc32 = FixedFormCrc(slot->fixed);
    slot->present = true;
    *rated = builtin->rated;
  } catch (const FtdError&) {
    throw;
  } catch (const std::exception& e) {
    throw FtdError(e.what());
  }
}

/// The overload rule's rated range in LSB (all zero, i.e. off, without a complete rating).
void SetRated(const std::array<double, 6>& rated, fw::DeviceConfig* cfg) {
  for (std::size_t i = 0; i < fw::kAxes; ++i) {
    const double lsb = rated[i] / fw::AxisLsb(i);
    if (!std::isfinite(lsb) || lsb < 0 || lsb > fw::kMaxRatedLsb) {
      throw FtdError("calibration's rated range of axis " + std::to_string(i) + " is unusable");
    }
    cfg->rated_lsb[i] = static_cast<std::int32_t>(std::llround(lsb));
  }
  bool any_zero = false;
  for (const std::int32_t r : cfg->rated_lsb) any_zero = any_zero || r == 0;
  if (any_zero) cfg->rated_lsb = {};  // no complete rating: overload rule off
}

}  // namespace

std::uint32_t FixedFormCrc(const fw::FixedCalibration& cal) {
  std::string bytes;
  AppendLe(&bytes, cal.channel_count, 1);
  for (std::size_t r = 0; r < fw::kAxes; ++r) {
    for (std::size_t c = 0; c < cal.channel_count; ++c) {
      AppendLe(&bytes, static_cast<std::uint64_t>(cal.coef[r][c]), 8);
    }
    AppendLe(&bytes, static_cast<std::uint64_t>(cal.bias[r]), 8);
    AppendLe(&bytes, cal.shift[r], 1);
  }
  AppendLe(&bytes, static_cast<std::uint32_t>(cal.min_counts), 4);
  AppendLe(&bytes, static_cast<std::uint32_t>(cal.max_counts), 4);
  return cal::Crc32(bytes);
}

char ResolveSlotDirectory(FtdOptions* opt) {
  const cal::CalSlots slots(opt->cal_dir);
  opt->cal = slots.SlotPath('A');
  opt->cal_b = std::filesystem::exists(slots.SlotPath('B')) ? slots.SlotPath('B') : "";
  char slot = 0;
  std::string note;
  try {
    (void)slots.LoadActive(&slot, &note);
  } catch (const cal::CalFileError& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return 0;
  }
  if (!note.empty()) std::fprintf(stderr, "ftd: %s: %s\n", opt->cal_dir.c_str(), note.c_str());
  return slot;
}

void LoadCalibrationSet(const FtdOptions& opt, char dir_slot, AdcBackend& backend,
                        const hal::AdcInfo& info, fw::DeviceConfig* cfg) {
  std::array<double, 6> rated{};
  std::array<double, 6> rated_b{};
  if (opt.cal.empty()) {
    LoadBuiltin(opt, backend, info, &cfg->slots[0], &rated);
  } else {
    LoadSlot(opt.cal, "A", info, &cfg->slots[0], &rated);
  }
  if (!opt.cal_b.empty()) LoadSlot(opt.cal_b, "B", info, &cfg->slots[1], &rated_b);
  // A field device comes up whatever its calibration files hold: on slot A if it is valid, else
  // on a valid slot B (and says so), else without calibration (status bit 4, wrench invalid).
  cfg->allow_uncalibrated = true;
  if (dir_slot == 'B' && cfg->slots[1].present) {
    cfg->initial_slot = 1;
    rated = rated_b;
    std::fprintf(stderr, "ftd: running on calibration slot B (%s, active in %s)\n",
                 opt.cal_b.c_str(), opt.cal_dir.c_str());
  } else if (!cfg->slots[0].present && cfg->slots[1].present) {
    cfg->initial_slot = 1;
    rated = rated_b;
    std::fprintf(stderr, "ftd: running on calibration slot B (%s)\n", opt.cal_b.c_str());
  } else if (!cfg->slots[0].present) {
    std::fprintf(stderr,
                 "ftd: no valid calibration: serving with status bit 4 set and the wrench "
                 "registers invalid\n");
  }
  SetRated(rated, cfg);
}

void LoadPayload(const std::string& path, fw::DeviceConfig* cfg) {
  cal::PayloadFile p;
  try {
    p = cal::LoadPayloadFile(path);
  } catch (const std::exception& e) {
    throw FtdError(std::string("--payload refused: ") + e.what());
  }
  if (fw::MakeFixedPayload(p.mass_kg, p.com_m, p.force_bias_n, p.moment_bias_nm, &cfg->payload) !=
      fw::PayloadStatus::kOk) {
    throw FtdError("--payload " + path + ": outside what the firmware accepts (0 < mass ≤ " +
                   std::to_string(fw::kMaxPayloadMassKg) + " kg, |m·c| ≤ 100 kg·m)");
  }
  cfg->payload_crc = p.crc32;
  std::fprintf(stderr,
               "ftd: payload %s: %.4g kg at (%.1f, %.1f, %.1f) mm; gravity compensation off "
               "until holding 28 = 1\n",
               path.c_str(), p.mass_kg, p.com_m[0] * 1e3, p.com_m[1] * 1e3, p.com_m[2] * 1e3);
}

}  // namespace ftstack::daemon
