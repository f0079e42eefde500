#include "calibration/file/payload_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "calibration/file/cal_file.hpp"

namespace ftstack::cal {
namespace {

double Number(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j.contains(key)) throw PayloadFileError(path + ": missing \"" + key + "\"");
  const nlohmann::json& v = j.at(key);
  if (!v.is_number()) throw PayloadFileError(path + ": \"" + key + "\" is not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw PayloadFileError(path + ": \"" + key + "\" is not finite");
  return d;
}

std::array<double, 3> Vec3(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j.contains(key) || !j.at(key).is_array() || j.at(key).size() != 3) {
    throw PayloadFileError(path + ": \"" + key + "\" must be an array of 3 numbers");
  }
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    const nlohmann::json& v = j.at(key)[i];
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw PayloadFileError(path + ": \"" + key + "\"[" + std::to_string(i) +
                             "] is not a finite number");
    }
    out[i] = v.get<double>();
  }
  return out;
}

}  // namespace

nlohmann::json PayloadToJson(const PayloadFile& p) {
  nlohmann::json j;
  j["schema"] = kPayloadSchema;
  j["date"] = p.date;
  j["source"] = p.source;
  j["units"] = {{"mass", "kg"},    {"com", "m"},         {"force", "N"},
                {"moment", "N*m"}, {"gravity", "m/s^2"}, {"frame", "sensor"}};
  j["mass_kg"] = p.mass_kg;
  j["com_m"] = p.com_m;
  j["force_bias_n"] = p.force_bias_n;
  j["moment_bias_nm"] = p.moment_bias_nm;
  j["sigma"] = {{"mass_kg", p.mass_sigma_kg},
                {"com_m", p.com_sigma_m},
                {"force_bias_n", p.force_bias_sigma_n},
                {"moment_bias_nm", p.moment_bias_sigma_nm}};
  j["readings"] = p.readings;
  j["residual_rms"] = {{"force_n", p.force_rms_n}, {"moment_nm", p.moment_rms_nm}};
  j["crc32"] = ContentCrc(j);
  return j;
}

PayloadFile PayloadFromJson(const nlohmann::json& j, const std::string& path) {
  if (!j.is_object()) throw PayloadFileError(path + ": not a JSON object");
  if (!j.contains("schema") || j.at("schema") != kPayloadSchema) {
    throw PayloadFileError(path + ": not a payload file (schema must be \"" +
                           std::string(kPayloadSchema) + "\")");
  }
  if (!j.contains("crc32") || !j.at("crc32").is_number_unsigned()) {
    throw PayloadFileError(path + ": missing \"crc32\"");
  }
  const std::uint32_t stored = j.at("crc32").get<std::uint32_t>();
  const std::uint32_t computed = ContentCrc(j);
  if (stored != computed) {
    char buf[96];
    std::snprintf(buf, sizeof buf, ": CRC mismatch (stored 0x%08x, computed 0x%08x): corrupt",
                  stored, computed);
    throw PayloadFileError(path + buf);
  }
  PayloadFile p;
  p.crc32 = stored;
  p.date = j.value("date", "");
  p.source = j.value("source", "");
  p.mass_kg = Number(j, "mass_kg", path);
  if (!(p.mass_kg > 0)) throw PayloadFileError(path + ": \"mass_kg\" must be > 0");
  p.com_m = Vec3(j, "com_m", path);
  p.force_bias_n = Vec3(j, "force_bias_n", path);
  p.moment_bias_nm = Vec3(j, "moment_bias_nm", path);
  if (j.contains("sigma") && j.at("sigma").is_object()) {
    const nlohmann::json& s = j.at("sigma");
    p.mass_sigma_kg = Number(s, "mass_kg", path);
    p.com_sigma_m = Vec3(s, "com_m", path);
    p.force_bias_sigma_n = Vec3(s, "force_bias_n", path);
    p.moment_bias_sigma_nm = Vec3(s, "moment_bias_nm", path);
  }
  if (j.contains("readings") && j.at("readings").is_number_unsigned()) {
    p.readings = j.at("readings").get<std::size_t>();
  }
  if (j.contains("residual_rms") && j.at("residual_rms").is_object()) {
    p.force_rms_n = Number(j.at("residual_rms"), "force_n", path);
    p.moment_rms_nm = Number(j.at("residual_rms"), "moment_nm", path);
  }
  return p;
}

PayloadFile LoadPayloadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PayloadFileError(path + ": cannot open: " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParsePayloadFile(ss.str(), path);
}

PayloadFile ParsePayloadFile(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = ParseJsonText(text, path);
  } catch (const CalFileError& e) {
    throw PayloadFileError(e.what());
  }
  try {
    return PayloadFromJson(j, path);
  } catch (const nlohmann::json::exception& e) {
    throw PayloadFileError(path + ": " + e.what());
  }
}

void SavePayloadFile(const std::string& path, const PayloadFile& p) {
  try {
    WriteFileAtomic(path, PayloadToJson(p).dump(2) + "\n");
  } catch (const CalFileError& e) {
    throw PayloadFileError(e.what());
  }
}

}  // namespace ftstack::cal
