// Sparkplug B messages: metric values, topic names and the protobuf payload (protobuf-c encoder).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ftstack::daemon::sparkplug {

/// Sparkplug B data types used here (the numbers of the DataType enum in sparkplug_b.proto).
enum class DataType : std::uint32_t {
  kUInt8 = 5,
  kUInt16 = 6,
  kUInt32 = 7,
  kUInt64 = 8,
  kFloat = 9,
  kDouble = 10,
  kBoolean = 11,
  kString = 12,
};

/// One metric: a name, a type and the value field that type uses (or null: no valid value).
struct Metric {
  std::string name;
  DataType type = DataType::kDouble;
  std::uint64_t u = 0;  ///< kUInt8 … kUInt64
  double d = 0;         ///< kFloat, kDouble
  bool b = false;       ///< kBoolean
  std::string s;        ///< kString
  bool is_null = false;
  std::uint64_t timestamp_ms = 0;  ///< 0: none (the payload's timestamp applies)

  [[nodiscard]] bool operator==(const Metric& o) const {
    return name == o.name && type == o.type && u == o.u && d == o.d && b == o.b && s == o.s &&
           is_null == o.is_null;
  }
};

[[nodiscard]] Metric UInt(std::string name, DataType type, std::uint64_t v);
[[nodiscard]] Metric Real(std::string name, DataType type, double v, bool is_null = false);
[[nodiscard]] Metric Bool(std::string name, bool v);
[[nodiscard]] Metric Text(std::string name, std::string v);

/// Message types of the Sparkplug B topic namespace.
enum class MessageType { kNBirth, kNDeath, kNData, kNCmd, kDBirth, kDDeath, kDData, kDCmd };

/// "spBv1.0/<group>/<type>/<edge node>[/<device>]" (device only for the D… types).
[[nodiscard]] std::string Topic(MessageType type, const std::string& group,
                                const std::string& edge_node, const std::string& device = "");

/// A Sparkplug identifier element: non-empty, without '/', '+' or '#' (the spec's rule).
[[nodiscard]] bool ValidId(const std::string& id);

/// Encodes a Payload (timestamp, seq when given, metrics with name, datatype and value).
[[nodiscard]] std::vector<std::uint8_t> Encode(std::uint64_t timestamp_ms,
                                               std::optional<std::uint64_t> seq,
                                               const std::vector<Metric>& metrics);

/// Decodes a received payload's metrics (commands: NCMD/DCMD). nullopt when it is not a payload.
[[nodiscard]] std::optional<std::vector<Metric>> Decode(const void* data, std::size_t size);

}  // namespace ftstack::daemon::sparkplug
