// Payload files: a tool's mass, centre of mass and the sensor bias (JSON with units, CRC-32, date).
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace ftstack::cal {

/// A payload file that cannot be used. what() names the file (and line:column for syntax).
class PayloadFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Schema identifier of payload files.
inline constexpr const char* kPayloadSchema = "ftstack-payload/1";

/// What gravity compensation needs, all in the sensor frame: the reading of a static sensor
/// carrying the payload is F = m·g + F_b, M = c × (m·g) + M_b (g: gravity, m/s²).
struct PayloadFile {
  std::string date;                        ///< ISO 8601 date of the identification
  std::string source = "ftcal payload";    ///< what produced it
  double mass_kg = 0;                      ///< m
  std::array<double, 3> com_m{};           ///< c, centre of mass, m
  std::array<double, 3> force_bias_n{};    ///< F_b, N
  std::array<double, 3> moment_bias_nm{};  ///< M_b, N·m
  /// Standard uncertainties (1 σ) of the same quantities.
  double mass_sigma_kg = 0;
  std::array<double, 3> com_sigma_m{};
  std::array<double, 3> force_bias_sigma_n{};
  std::array<double, 3> moment_bias_sigma_nm{};
  std::size_t readings = 0;  ///< static readings the fit used
  double force_rms_n = 0;    ///< RMS residual of the force equations
  double moment_rms_nm = 0;  ///< RMS residual of the moment equations
  std::uint32_t crc32 = 0;   ///< the file's CRC-32 (set when read; written files get a fresh one)
};

/// Serialises with "units" and the "crc32" field (CRC-32 of the compact dump without "crc32",
/// as calibration files).
[[nodiscard]] nlohmann::json PayloadToJson(const PayloadFile& p);
/// Parses and checks (schema, CRC, finiteness, mass > 0); `path` names the file in messages.
[[nodiscard]] PayloadFile PayloadFromJson(const nlohmann::json& j, const std::string& path);
/// Reads and verifies a payload file; syntax errors name line and column.
[[nodiscard]] PayloadFile LoadPayloadFile(const std::string& path);
/// The same for a file's text already in memory; `path` only names it in messages.
[[nodiscard]] PayloadFile ParsePayloadFile(const std::string& text, const std::string& path);
/// Writes atomically (temporary file, fsync, rename).
void SavePayloadFile(const std::string& path, const PayloadFile& p);

}  // namespace ftstack::cal
