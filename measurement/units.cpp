#include "measurement/units.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace ftstack {
namespace {

std::string Trim(const std::string& s) {
  std::size_t a = 0;
  std::size_t b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t')) --b;
  return s.substr(a, b - a);
}

double ParsePositive(const std::string& value, const std::string& key, const std::string& where) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || !std::isfinite(v) || !(v > 0)) {
    throw std::invalid_argument(where + ": converter " + key + " = '" + value +
                                "' is not a positive number");
  }
  return v;
}

bool ParseYesNo(const std::string& value, const std::string& key, const std::string& where) {
  if (value == "yes" || value == "true" || value == "1") return true;
  if (value == "no" || value == "false" || value == "0") return false;
  throw std::invalid_argument(where + ": converter " + key + " = '" + value + "' is not yes/no");
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

BridgeUnit ParseBridgeUnit(const std::string& text) {
  if (text == "mV/V" || text == "mv/v") return BridgeUnit::kMvv;
  if (text == "V" || text == "volts" || text == "v") return BridgeUnit::kVolts;
  if (text == "counts") return BridgeUnit::kCounts;
  throw std::invalid_argument("bridge unit '" + text + "' is not one of mV/V, V, counts");
}

const char* ToString(BridgeUnit unit) {
  switch (unit) {
    case BridgeUnit::kMvv:
      return "mV/V";
    case BridgeUnit::kVolts:
      return "V";
    case BridgeUnit::kCounts:
      return "counts";
  }
  return "?";
}

const char* ToString(AdcCoding coding) {
  switch (coding) {
    case AdcCoding::kSigned:
      return "signed";
    case AdcCoding::kUnsigned:
      return "unsigned";
    case AdcCoding::kOffsetBinary:
      return "offset-binary";
  }
  return "?";
}

namespace {

/// One `key=value` item of a converter description into `c` (throws naming `where`).
void ApplyConverterItem(const std::string& item, const std::string& where, Converter* c,
                        bool* have_bits) {
  const std::size_t eq = item.find('=');
  if (eq == std::string::npos) {
    throw std::invalid_argument(where + ": converter item '" + item + "' is not key=value");
  }
  const std::string key = Trim(item.substr(0, eq));
  const std::string value = Trim(item.substr(eq + 1));
  if (key == "bits") {
    const double v = ParsePositive(value, key, where);
    if (v != std::floor(v) || v < 2 || v > 31) {
      throw std::invalid_argument(where + ": converter bits = " + value + " is not 2 … 31");
    }
    c->bits = static_cast<int>(v);
    *have_bits = true;
  } else if (key == "coding") {
    if (value == "signed" || value == "twos-complement") {
      c->coding = AdcCoding::kSigned;
    } else if (value == "unsigned") {
      c->coding = AdcCoding::kUnsigned;
    } else if (value == "offset-binary") {
      c->coding = AdcCoding::kOffsetBinary;
    } else {
      throw std::invalid_argument(where + ": converter coding '" + value +
                                  "' is not signed, unsigned or offset-binary");
    }
  } else if (key == "gain") {
    c->gain = ParsePositive(value, key, where);
  } else if (key == "ratiometric") {
    c->ratiometric = ParseYesNo(value, key, where);
  } else if (key == "reference_ratio") {
    c->reference_ratio = ParsePositive(value, key, where);
  } else if (key == "reference_v") {
    c->reference_v = ParsePositive(value, key, where);
  } else if (key == "full_scale_mvv") {
    c->full_scale_mvv = ParsePositive(value, key, where);
  } else {
    throw std::invalid_argument(where + ": unknown converter key '" + key + "'");
  }
}

}  // namespace

Converter ParseConverter(const std::string& text, const std::string& where) {
  Converter c;
  bool have_bits = false;
  std::size_t a = 0;
  while (a <= text.size()) {
    std::size_t b = text.find(',', a);
    if (b == std::string::npos) b = text.size();
    const std::string item = Trim(text.substr(a, b - a));
    a = b + 1;
    if (!item.empty()) ApplyConverterItem(item, where, &c, &have_bits);
  }
  if (!have_bits) throw std::invalid_argument(where + ": converter description lacks bits=");
  return c;
}

std::string FormatConverter(const Converter& c) {
  std::string s = "bits=" + std::to_string(c.bits) + ", coding=" + ToString(c.coding) +
                  ", gain=" + Num(c.gain) + ", ratiometric=" + (c.ratiometric ? "yes" : "no");
  if (c.ratiometric) s += ", reference_ratio=" + Num(c.reference_ratio);
  if (c.reference_v > 0) s += ", reference_v=" + Num(c.reference_v);
  if (c.full_scale_mvv > 0) s += ", full_scale_mvv=" + Num(c.full_scale_mvv);
  return s;
}

InputUnit ResolveInputUnit(const Recording& rec, const UnitOverrides& cli) {
  InputUnit u;
  std::string unit = rec.Meta("bridge_unit");
  std::string conv = rec.Meta("converter");
  const std::string exc = rec.Meta("excitation_v");
  std::string where = rec.path + ": metadata";
  if (!unit.empty() || !conv.empty() || !exc.empty()) u.source = "metadata";
  try {
    if (!exc.empty()) u.excitation_v = ParsePositive(exc, "excitation_v", where);
    if (cli.excitation_v > 0) u.excitation_v = cli.excitation_v;
    if (!cli.unit.empty()) unit = cli.unit;
    if (!cli.converter.empty()) {
      conv = cli.converter;
      where = "--converter";
    }
    if (!cli.unit.empty() || !cli.converter.empty() || cli.excitation_v > 0) {
      u.source = "command line";
    }
    if (!conv.empty()) {
      u.converter = ParseConverter(conv, where);
      u.has_converter = true;
    }
    u.unit = !unit.empty() ? ParseBridgeUnit(unit)
                           : (u.has_converter ? BridgeUnit::kCounts : BridgeUnit::kMvv);
  } catch (const std::invalid_argument& e) {
    throw RecordingError(e.what());
  }
  if (u.unit == BridgeUnit::kCounts && !u.has_converter) {
    throw RecordingError(rec.path +
                         ": bridge_unit counts needs a converter description (# converter: "
                         "bits=…, coding=…; or --converter)");
  }
  if (u.unit == BridgeUnit::kVolts && !(u.excitation_v > 0)) {
    throw RecordingError(rec.path +
                         ": bridge_unit V needs the excitation (# excitation_v: …; or "
                         "--excitation-v)");
  }
  return u;
}

std::string Describe(const InputUnit& u) {
  std::string s = std::string("bridge unit ") + ToString(u.unit);
  if (u.unit == BridgeUnit::kCounts) s += " of converter (" + FormatConverter(u.converter) + ")";
  if (u.excitation_v > 0) s += ", excitation " + Num(u.excitation_v) + " V";
  return s + " [" + u.source + "]";
}

std::int64_t MinCode(const Converter& c) {
  return c.coding == AdcCoding::kSigned ? -(std::int64_t{1} << (c.bits - 1)) : 0;
}

std::int64_t MaxCode(const Converter& c) {
  return c.coding == AdcCoding::kSigned ? (std::int64_t{1} << (c.bits - 1)) - 1
                                        : (std::int64_t{1} << c.bits) - 1;
}

std::int64_t ZeroCode(const Converter& c) {
  return c.coding == AdcCoding::kOffsetBinary ? std::int64_t{1} << (c.bits - 1) : 0;
}

double MvvPerCount(const Converter& c, double excitation_v) {
  const double steps =
      c.coding == AdcCoding::kUnsigned ? std::ldexp(1.0, c.bits) : std::ldexp(1.0, c.bits - 1);
  if (c.full_scale_mvv > 0) return c.full_scale_mvv / steps;
  if (c.ratiometric) return 1000.0 * c.reference_ratio / c.gain / steps;
  if (c.reference_v > 0 && excitation_v > 0) {
    return 1000.0 * c.reference_v / excitation_v / c.gain / steps;
  }
  return 0.0;
}

std::size_t FieldColumn(const Recording& rec, std::size_t line, std::size_t field) {
  std::ifstream in(rec.path);
  std::string text;
  for (std::size_t i = 0; i < line && std::getline(in, text); ++i) {
  }
  if (!in) return field + 1;
  std::size_t col = 1;
  std::size_t k = 0;
  for (std::size_t i = 0; i < text.size() && k < field; ++i) {
    if (text[i] == ',') {
      ++k;
      col = i + 2;
    }
  }
  return col;
}

void CheckBridgeRange(const Recording& rec, std::size_t channels, const ValueRange& range,
                      double tolerance) {
  std::vector<const std::vector<double>*> cols;
  for (std::size_t c = 0; c < channels; ++c) cols.push_back(&rec.Column("b" + std::to_string(c)));
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    for (std::size_t c = 0; c < channels; ++c) {
      const double v = (*cols[c])[i];
      if (v >= range.min - tolerance && v <= range.max + tolerance) continue;
      const std::string name = "b" + std::to_string(c);
      const std::size_t line = i < rec.data_lines.size() ? rec.data_lines[i] : i + 2;
      const auto field = static_cast<std::size_t>(rec.Find(name));
      throw RecordingError(rec.path + ":" + std::to_string(line) + ":" +
                           std::to_string(FieldColumn(rec, line, field)) + ": " + name + " = " +
                           Num(v) + " lies outside " + range.what + " [" + Num(range.min) + ", " +
                           Num(range.max) + "] " + range.unit +
                           "; declare the unit (# bridge_unit: mV/V|V|counts and # converter: "
                           "bits=…, or --bridge-unit/--converter)");
    }
  }
}

void ConvertBridgesToMvv(Recording* rec, std::size_t channels, const InputUnit& from) {
  double scale = 1.0;
  double zero = 0.0;
  if (from.unit == BridgeUnit::kVolts) {
    scale = 1000.0 / from.excitation_v;
  } else if (from.unit == BridgeUnit::kCounts) {
    scale = MvvPerCount(from.converter, from.excitation_v);
    zero = static_cast<double>(ZeroCode(from.converter));
    if (!(scale > 0)) {
      throw RecordingError(rec->path +
                           ": the converter's counts cannot be converted to mV/V: declare "
                           "full_scale_mvv=, or ratiometric=yes, or reference_v= with "
                           "excitation_v");
    }
  }
  if (scale == 1.0 && zero == 0.0) return;
  for (std::size_t c = 0; c < channels; ++c) {
    for (double& x : rec->Column("b" + std::to_string(c))) x = (x - zero) * scale;
  }
}

void ConvertCodesToCounts(Recording* rec, std::size_t channels, const InputUnit& from) {
  if (from.unit != BridgeUnit::kCounts) {
    throw RecordingError(rec->path + ": bridge columns are not counts");
  }
  const double zero = static_cast<double>(ZeroCode(from.converter));
  if (zero == 0.0) return;
  for (std::size_t c = 0; c < channels; ++c) {
    for (double& x : rec->Column("b" + std::to_string(c))) x -= zero;
  }
}

}  // namespace ftstack
