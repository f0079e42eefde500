#include "sim/sensor_description.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/default_sensor.hpp"

namespace ftstack::sim {
namespace {

double Num(const nlohmann::json& v, const std::string& path, const std::string& what) {
  if (!v.is_number()) throw SensorDescriptionError(path + ": " + what + " is not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw SensorDescriptionError(path + ": " + what + " is not finite");
  return d;
}

std::string LineCol(const std::string& text, std::size_t byte) {
  std::size_t line = 1;
  std::size_t col = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::to_string(line) + ":" + std::to_string(col);
}

}  // namespace

SensorDescription DefaultSensorDescription() {
  SensorDescription d;
  d.name = "builtin";
  d.model = MakeDefaultSensor();
  d.adc.noise_rms_mvv = kDefaultNoiseMvv;
  return d;
}

SensorDescription LoadSensorDescription(const std::string& path) {
  if (path.empty() || path == "builtin") return DefaultSensorDescription();
  std::ifstream in(path);
  if (!in) throw SensorDescriptionError(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw SensorDescriptionError(path + ":" + LineCol(text, e.byte) + ": not valid JSON");
  }
  if (!j.is_object() || j.value("schema", "") != "ftstack-sensor/1") {
    throw SensorDescriptionError(path + ": schema is not 'ftstack-sensor/1'");
  }
  SensorDescription d;
  d.name = j.value("name", path);
  const auto& m = j.at("model");
  const std::string type = m.value("type", "");
  if (type != "linear") {
    throw SensorDescriptionError(path + ": unknown model type '" + type + "'");
  }
  const auto& s = m.at("sensitivity_mvv");
  if (!s.is_array() || s.empty() || s.size() > 8) {
    throw SensorDescriptionError(path + ": model.sensitivity_mvv needs 1..8 rows");
  }
  const int n = static_cast<int>(s.size());
  Eigen::MatrixXd sens(n, 6);
  for (int i = 0; i < n; ++i) {
    if (!s[static_cast<std::size_t>(i)].is_array() || s[static_cast<std::size_t>(i)].size() != 6) {
      throw SensorDescriptionError(path + ": sensitivity row " + std::to_string(i) +
                                   " needs 6 numbers");
    }
    for (int k = 0; k < 6; ++k) {
      sens(i, k) =
          Num(s[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)], path, "sensitivity");
    }
  }
  Wrench rated = DefaultRated();
  if (m.contains("rated")) {
    for (int k = 0; k < 6; ++k)
      rated(k) = Num(m["rated"].at(static_cast<std::size_t>(k)), path, "rated");
  }
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  if (m.contains("zero_mvv")) {
    for (int i = 0; i < n; ++i)
      zero(i) = Num(m["zero_mvv"].at(static_cast<std::size_t>(i)), path, "zero_mvv");
  }
  d.model = std::make_shared<LinearSensorModel>(sens, rated, d.name, zero);
  d.adc.noise_rms_mvv = kDefaultNoiseMvv;
  if (j.contains("adc")) {
    const auto& a = j["adc"];
    if (a.contains("noise_mvv")) d.adc.noise_rms_mvv = Num(a["noise_mvv"], path, "adc.noise_mvv");
    if (a.contains("bits"))
      d.adc.resolution_bits = static_cast<int>(Num(a["bits"], path, "adc.bits"));
    if (a.contains("reference_ratio"))
      d.adc.reference_ratio = Num(a["reference_ratio"], path, "adc.reference_ratio");
    if (a.contains("gain"))
      d.adc_gain = static_cast<std::uint16_t>(Num(a["gain"], path, "adc.gain"));
    if (a.contains("rate_hz")) d.rate_hz = Num(a["rate_hz"], path, "adc.rate_hz");
  }
  return d;
}

}  // namespace ftstack::sim
