#include "calibration/file/cal_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace ftstack::cal {
namespace {

std::array<std::uint32_t, 256> MakeCrcTable() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

std::string Hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

double Finite(const nlohmann::json& v, const std::string& path, const std::string& what) {
  if (!v.is_number()) throw CalFileError(path + ": " + what + " is not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw CalFileError(path + ": " + what + " is not finite");
  return d;
}

}  // namespace

std::uint32_t Crc32(const std::string& bytes) {
  static const auto kTable = MakeCrcTable();
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : bytes) c = kTable[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint32_t ContentCrc(const nlohmann::json& j) {
  nlohmann::json copy = j;
  copy.erase("crc32");
  return Crc32(copy.dump());
}

hal::AdcInfo DefaultAdc(std::uint8_t channels) {
  hal::AdcInfo a;
  a.channel_count = channels;
  a.max_counts = (1 << 23) - 1;
  a.min_counts = -(1 << 23);
  a.full_scale_nvv = 3906250;
  a.rate_hz = 1000;
  return a;
}

hal::AdcInfo AdcForDevice(const CalFile& file, const hal::AdcInfo& device) {
  if (file.input_unit != "counts") return device;
  if (device.min_counts != file.adc.min_counts || device.max_counts != file.adc.max_counts) {
    throw CalFileError("calibration " + file.serial + " is in counts of a converter with rails " +
                       std::to_string(file.adc.min_counts) + " … " +
                       std::to_string(file.adc.max_counts) + ", this ADC's are " +
                       std::to_string(device.min_counts) + " … " +
                       std::to_string(device.max_counts));
  }
  hal::AdcInfo a = device;
  a.full_scale_nvv = file.adc.full_scale_nvv;
  return a;
}

fw::FixedCalibration ToFixed(const CalFile& file, const hal::AdcInfo& adc, fw::LoadReport* report) {
  fw::FixedCalibration fixed{};
  fw::LoadReport rep{};
  const fw::LoadStatus s = fw::LoadCalibration(file.cal, adc, &fixed, &rep);
  if (report != nullptr) *report = rep;
  if (s != fw::LoadStatus::kOk) {
    throw CalFileError(std::string("calibration refused by the fixed-point loader: ") +
                       fw::ToString(s));
  }
  return fixed;
}

std::string AxisList(std::uint8_t axes) {
  std::string s;
  for (std::size_t a = 0; a < 6; ++a) {
    if ((axes & (1u << a)) == 0) continue;
    if (!s.empty()) s += ", ";
    s += kAxisNames[a];
  }
  return s;
}

nlohmann::json ToJson(const CalFile& f) {
  using nlohmann::json;
  const std::size_t n = f.cal.channel_count;
  json j = f.extra.is_object() ? f.extra : json::object();
  j["schema"] = kCalSchema;
  j["serial"] = f.serial;
  j["date"] = f.date;
  j["source"] = f.source;
  j["channels"] = n;
  j["input_unit"] = f.input_unit;
  j["units"] = {{"force", "N"}, {"moment", "N*m"}};
  j["adc"] = {{"min_counts", f.adc.min_counts},
              {"max_counts", f.adc.max_counts},
              {"full_scale_nvv", f.adc.full_scale_nvv}};
  json m = json::array();
  for (std::size_t r = 0; r < 6; ++r) {
    json row = json::array();
    for (std::size_t c = 0; c < n; ++c) row.push_back(f.cal.matrix[r][c]);
    m.push_back(row);
  }
  j["matrix"] = m;
  j["offset_mvv"] = std::vector<double>(f.cal.offset_mvv.begin(), f.cal.offset_mvv.begin() + n);
  j["bias"] = f.cal.bias;
  j["rated"] = f.rated;
  j["uncertainty"] = f.uncertainty;
  if (f.cal.invalid_axes != 0) {
    j["schema"] = kCalSchemaV3;
    json names = json::array();
    for (std::size_t a = 0; a < 6; ++a) {
      if ((f.cal.invalid_axes & (1u << a)) != 0) names.push_back(kAxisNames[a]);
    }
    j["invalid_axes"] = names;
  }
  if (f.cal.product_count > 0) {
    json terms = json::array();
    json pm = json::array();
    for (std::size_t k = 0; k < f.cal.product_count; ++k) {
      terms.push_back({f.cal.products[k].a, f.cal.products[k].b});
    }
    for (std::size_t r = 0; r < 6; ++r) {
      pm.push_back(std::vector<double>(f.cal.product_matrix[r].begin(),
                                       f.cal.product_matrix[r].begin() + f.cal.product_count));
    }
    j["model"] = {{"products", terms}, {"product_matrix", pm}};
  }
  if (f.cal.temperature_compensated) {
    j["temperature"] = {
        {"ref_C", f.cal.temp_ref_c},
        {"min_C", f.cal.temp_min_c},
        {"max_C", f.cal.temp_max_c},
        {"bias_slope_mvv_per_C", std::vector<double>(f.cal.bias_slope_mvv_per_c.begin(),
                                                     f.cal.bias_slope_mvv_per_c.begin() + n)},
        {"gain_slope_per_C",
         std::vector<double>(f.cal.gain_slope_per_c.begin(), f.cal.gain_slope_per_c.begin() + n)}};
  }
  fw::LoadReport rep{};
  const fw::FixedCalibration fx = ToFixed(f, f.adc, &rep);
  json fp = json::object();
  fp["shift"] = fx.shift;
  json coef = json::array();
  const std::size_t features = n + fx.extra_count;
  for (std::size_t r = 0; r < 6; ++r) {
    coef.push_back(std::vector<std::int64_t>(fx.coef[r].begin(), fx.coef[r].begin() + features));
  }
  fp["coef"] = coef;
  fp["bias"] = fx.bias;
  json feats = json::array();
  for (std::size_t c = 0; c < n; ++c) feats.push_back("counts" + std::to_string(c));
  for (std::size_t k = 0; k < fx.extra_count; ++k) {
    const fw::FixedFeature& e = fx.extra[k];
    switch (e.kind) {
      case fw::FeatureKind::kTemperature:
        feats.push_back("dT_mdegC");
        break;
      case fw::FeatureKind::kProduct:
        feats.push_back("x" + std::to_string(e.a) + "*x" + std::to_string(e.b) + ">>" +
                        std::to_string(e.shift));
        break;
      case fw::FeatureKind::kTempProduct:
        feats.push_back("x" + std::to_string(e.a) + "*dT>>" + std::to_string(e.shift));
        break;
    }
  }
  fp["features"] = feats;
  if (fx.extra_count > 0) {
    fp["zero_counts"] = std::vector<std::int32_t>(fx.zero.begin(), fx.zero.begin() + n);
  }
  fp["worst_case_error"] = rep.worst_case_error_si;
  fp["worst_case_error_lsb"] = rep.worst_case_error_lsb;
  fp["output_lsb"] = {fw::kForceLsbN,   fw::kForceLsbN,   fw::kForceLsbN,
                      fw::kMomentLsbNm, fw::kMomentLsbNm, fw::kMomentLsbNm};
  j["fixed_point"] = fp;
  j["crc32"] = Hex32(ContentCrc(j));
  return j;
}

namespace {

/// The invalid_axes list (schema 3 only) into the calibration's bit mask.
void ReadInvalidAxes(const nlohmann::json& j, const std::string& path, fw::FloatCalibration* cal) {
  // Only with schema 3, so that no reader that ignores the field ever sees it.
  if (j["schema"] != kCalSchemaV3 || !j.contains("invalid_axes")) {
    throw CalFileError(path + ": invalid_axes and schema '" + kCalSchemaV3 + "' go together");
  }
  const auto& a = j["invalid_axes"];
  if (!a.is_array() || a.empty()) {
    throw CalFileError(path + ": invalid_axes must list axis names (Fx … Mz)");
  }
  for (const auto& name : a) {
    std::size_t axis = 6;
    for (std::size_t i = 0; i < 6; ++i) {
      if (name.is_string() && name.get<std::string>() == kAxisNames[i]) axis = i;
    }
    if (axis == 6 || (cal->invalid_axes & (1u << axis)) != 0) {
      throw CalFileError(path + ": invalid_axes: " + name.dump() +
                         " is not an axis name (Fx … Mz) or is listed twice");
    }
    cal->invalid_axes = static_cast<std::uint8_t>(cal->invalid_axes | (1u << axis));
  }
}

/// The second-order model: product pairs and their 6 × K matrix.
void ReadProducts(const nlohmann::json& model, const std::string& path, int n,
                  fw::FloatCalibration* cal) {
  const auto& terms = model.at("products");
  const auto& pm = model.at("product_matrix");
  if (!terms.is_array() || terms.size() > fw::kMaxProducts) {
    throw CalFileError(path + ": model.products must list at most " +
                       std::to_string(fw::kMaxProducts) + " pairs");
  }
  const std::size_t k_count = terms.size();
  cal->product_count = static_cast<std::uint8_t>(k_count);
  for (std::size_t k = 0; k < k_count; ++k) {
    const auto& t = terms[k];
    if (!t.is_array() || t.size() != 2 || !t[0].is_number_integer() || !t[1].is_number_integer()) {
      throw CalFileError(path + ": model.products[" + std::to_string(k) + "] must be [a, b]");
    }
    const int a = t[0].get<int>();
    const int b = t[1].get<int>();
    if (a < 0 || b < a || b >= n) {
      throw CalFileError(path + ": model.products[" + std::to_string(k) +
                         "] names a channel outside 0.." + std::to_string(n - 1));
    }
    cal->products[k] = fw::ProductTerm{static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
  }
  if (!pm.is_array() || pm.size() != 6) {
    throw CalFileError(path + ": model.product_matrix must have 6 rows");
  }
  for (std::size_t r = 0; r < 6; ++r) {
    if (!pm[r].is_array() || pm[r].size() != k_count) {
      throw CalFileError(path + ": model.product_matrix row " + std::to_string(r) + " must have " +
                         std::to_string(k_count) + " entries");
    }
    for (std::size_t k = 0; k < k_count; ++k) {
      cal->product_matrix[r][k] =
          Finite(pm[r][k], path,
                 "model.product_matrix[" + std::to_string(r) + "][" + std::to_string(k) + "]");
    }
  }
}

/// The temperature compensation: reference, range and per-channel slopes.
void ReadTemperature(const nlohmann::json& t, const std::string& path, int n,
                     fw::FloatCalibration* cal) {
  cal->temperature_compensated = true;
  cal->temp_ref_c = Finite(t.at("ref_C"), path, "temperature.ref_C");
  cal->temp_min_c = Finite(t.at("min_C"), path, "temperature.min_C");
  cal->temp_max_c = Finite(t.at("max_C"), path, "temperature.max_C");
  auto slopes = [&](const char* key, double* out) {
    const auto& a = t.at(key);
    if (!a.is_array() || a.size() != static_cast<std::size_t>(n)) {
      throw CalFileError(path + ": temperature." + key + " must have " + std::to_string(n) +
                         " entries");
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      out[i] =
          Finite(a[i], path, std::string("temperature.") + key + "[" + std::to_string(i) + "]");
    }
  };
  slopes("bias_slope_mvv_per_C", cal->bias_slope_mvv_per_c.data());
  slopes("gain_slope_per_C", cal->gain_slope_per_c.data());
}

}  // namespace

CalFile FromJson(const nlohmann::json& j, const std::string& path) {
  if (!j.is_object()) throw CalFileError(path + ": not a JSON object");
  if (!j.contains("schema") ||
      (j["schema"] != kCalSchema && j["schema"] != kCalSchemaV1 && j["schema"] != kCalSchemaV3)) {
    throw CalFileError(path + ": schema is not '" + std::string(kCalSchema) + "' (or '" +
                       kCalSchemaV1 + "', '" + kCalSchemaV3 + "')");
  }
  if (!j.contains("crc32") || !j["crc32"].is_string()) {
    throw CalFileError(path + ": no crc32 field");
  }
  const std::uint32_t want = ContentCrc(j);
  const std::string have = j["crc32"].get<std::string>();
  if (have != Hex32(want)) {
    throw CalFileError(path + ": CRC mismatch (file says " + have + ", content gives " +
                       Hex32(want) + "): the file is corrupt or was edited");
  }
  CalFile f;
  auto str = [&](const char* key, std::string* out) {
    if (j.contains(key) && j[key].is_string()) *out = j[key].get<std::string>();
  };
  str("serial", &f.serial);
  str("date", &f.date);
  str("source", &f.source);
  str("input_unit", &f.input_unit);
  if (!j.contains("channels") || !j["channels"].is_number_integer()) {
    throw CalFileError(path + ": channels missing");
  }
  const int n = j["channels"].get<int>();
  if (n < 1 || n > static_cast<int>(hal::kMaxChannels)) {
    throw CalFileError(path + ": channels must be 1..8, not " + std::to_string(n));
  }
  f.cal.channel_count = static_cast<std::uint8_t>(n);
  const auto& m = j.at("matrix");
  if (!m.is_array() || m.size() != 6) throw CalFileError(path + ": matrix must have 6 rows");
  for (std::size_t r = 0; r < 6; ++r) {
    if (!m[r].is_array() || m[r].size() != static_cast<std::size_t>(n)) {
      throw CalFileError(path + ": matrix row " + std::to_string(r) + " must have " +
                         std::to_string(n) + " entries");
    }
    for (std::size_t c = 0; c < static_cast<std::size_t>(n); ++c) {
      f.cal.matrix[r][c] =
          Finite(m[r][c], path, "matrix[" + std::to_string(r) + "][" + std::to_string(c) + "]");
    }
  }
  auto vec = [&](const char* key, std::size_t len, double* out, bool required) {
    if (!j.contains(key)) {
      if (required) throw CalFileError(path + ": " + key + " missing");
      return;
    }
    const auto& a = j[key];
    if (!a.is_array() || a.size() != len) {
      throw CalFileError(path + ": " + key + " must have " + std::to_string(len) + " entries");
    }
    for (std::size_t i = 0; i < len; ++i)
      out[i] = Finite(a[i], path, std::string(key) + "[" + std::to_string(i) + "]");
  };
  vec("offset_mvv", static_cast<std::size_t>(n), f.cal.offset_mvv.data(), true);
  vec("bias", 6, f.cal.bias.data(), true);
  vec("rated", 6, f.rated.data(), true);
  vec("uncertainty", 6, f.uncertainty.data(), false);
  if (j.contains("invalid_axes") || j["schema"] == kCalSchemaV3) ReadInvalidAxes(j, path, &f.cal);
  if (j.contains("model")) ReadProducts(j["model"], path, n, &f.cal);
  if (j.contains("temperature")) ReadTemperature(j["temperature"], path, n, &f.cal);
  const auto& adc = j.at("adc");
  f.adc.channel_count = static_cast<std::uint8_t>(n);
  f.adc.min_counts = adc.at("min_counts").get<std::int32_t>();
  f.adc.max_counts = adc.at("max_counts").get<std::int32_t>();
  f.adc.full_scale_nvv = adc.at("full_scale_nvv").get<std::int64_t>();
  for (const auto& [key, value] : j.items()) {
    static const char* kKnown[] = {
        "schema",      "serial",      "date",   "source",     "channels",    "input_unit",
        "units",       "adc",         "matrix", "offset_mvv", "bias",        "rated",
        "uncertainty", "fixed_point", "crc32",  "model",      "temperature", "invalid_axes"};
    bool known = false;
    for (const char* k : kKnown) known = known || key == k;
    if (!known) f.extra[key] = value;
  }
  try {
    (void)ToFixed(f, f.adc);
  } catch (const CalFileError& e) {
    throw CalFileError(path + ": " + e.what());
  }
  // The stored fixed-point form must be the one this matrix gives (a file written by another
  // loader version, or edited with a recomputed CRC, is refused rather than run differently).
  if (j.contains("fixed_point")) {
    const nlohmann::json expect = ToJson(f).at("fixed_point");
    for (const char* key : {"shift", "coef", "bias"}) {
      if (!j["fixed_point"].contains(key) || j["fixed_point"][key] != expect[key]) {
        throw CalFileError(path + ": fixed_point." + key +
                           " does not match the matrix (recompute with this version)");
      }
    }
  }
  return f;
}

CalFile LoadCalFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CalFileError(path + ": cannot open: " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseCalFile(ss.str(), path);
}

nlohmann::json ParseJsonText(const std::string& text, const std::string& path) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Turn the byte offset into line:column.
    std::size_t line = 1;
    std::size_t col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw CalFileError(path + ":" + std::to_string(line) + ":" + std::to_string(col) +
                       ": not valid JSON (truncated or corrupt)");
  } catch (const nlohmann::json::exception& e) {  // e.g. a number out of double's range
    throw CalFileError(path + ": not valid JSON (corrupt): " + e.what());
  }
}

CalFile ParseCalFile(const std::string& text, const std::string& path) {
  const nlohmann::json j = ParseJsonText(text, path);
  try {
    return FromJson(j, path);
  } catch (const nlohmann::json::exception& e) {
    throw CalFileError(path + ": " + e.what());
  }
}

void CrashPoint(const std::string& step) {
  const char* at = std::getenv("FTSTACK_CRASH_AT");
  if (at != nullptr && step == at) ::raise(SIGKILL);
}

void WriteFileAtomic(const std::string& path, const std::string& text, const char* crash_tag) {
  const std::string tag = crash_tag != nullptr ? crash_tag : "";
  auto crash = [&](const char* step) {
    if (crash_tag != nullptr) CrashPoint(tag + "-" + step);
  };
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw CalFileError(tmp + ": cannot write: " + std::strerror(errno));
  // The torn-write injection stops after half the bytes.
  const char* at = crash_tag != nullptr ? std::getenv("FTSTACK_CRASH_AT") : nullptr;
  const bool torn = at != nullptr && tag + "-write" == at;
  const std::size_t size = torn ? text.size() / 2 : text.size();
  std::size_t done = 0;
  while (done < size) {
    const ssize_t w = ::write(fd, text.data() + done, size - done);
    if (w < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      throw CalFileError(tmp + ": write failed: " + std::strerror(errno));
    }
    done += static_cast<std::size_t>(w);
  }
  crash("write");
  crash("fsync");
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    throw CalFileError(tmp + ": fsync/close failed: " + std::strerror(errno));
  }
  crash("rename");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    throw CalFileError(path + ": rename failed: " + std::strerror(errno));
  }
  crash("dirsync");
  // The rename is durable only once the directory entry is on disk.
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd < 0) throw CalFileError(dir.string() + ": cannot open the directory to sync it");
  const int rc = ::fsync(dfd);
  ::close(dfd);
  if (rc != 0)
    throw CalFileError(dir.string() + ": directory fsync failed: " + std::strerror(errno));
}

void SaveCalFile(const std::string& path, const CalFile& file) {
  WriteFileAtomic(path, ToJson(file).dump(2) + "\n");
}

}  // namespace ftstack::cal
