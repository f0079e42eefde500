#include "daemon/sparkplug.hpp"

#include <sparkplug_b.pb-c.h>

namespace ftstack::daemon::sparkplug {

using PbPayload = Org__Eclipse__Tahu__Protobuf__Payload;
using PbMetric = Org__Eclipse__Tahu__Protobuf__Payload__Metric;

Metric UInt(std::string name, DataType type, std::uint64_t v) {
  Metric m;
  m.name = std::move(name);
  m.type = type;
  m.u = v;
  return m;
}

Metric Real(std::string name, DataType type, double v, bool is_null) {
  Metric m;
  m.name = std::move(name);
  m.type = type;
  m.d = is_null ? 0.0 : v;
  m.is_null = is_null;
  return m;
}

Metric Bool(std::string name, bool v) {
  Metric m;
  m.name = std::move(name);
  m.type = DataType::kBoolean;
  m.b = v;
  return m;
}

Metric Text(std::string name, std::string v) {
  Metric m;
  m.name = std::move(name);
  m.type = DataType::kString;
  m.s = std::move(v);
  return m;
}

std::string Topic(MessageType type, const std::string& group, const std::string& edge_node,
                  const std::string& device) {
  static constexpr const char* kNames[] = {"NBIRTH", "NDEATH", "NDATA", "NCMD",
                                           "DBIRTH", "DDEATH", "DDATA", "DCMD"};
  std::string t = "spBv1.0/" + group + "/" + kNames[static_cast<int>(type)] + "/" + edge_node;
  if (type >= MessageType::kDBirth) t += "/" + device;
  return t;
}

bool ValidId(const std::string& id) {
  return !id.empty() && id.find_first_of("/+#") == std::string::npos;
}

namespace {

void SetValue(const Metric& m, PbMetric* pb) {
  if (m.is_null) {
    pb->has_is_null = 1;
    pb->is_null = 1;
    return;
  }
  switch (m.type) {
    case DataType::kUInt8:
    case DataType::kUInt16:
    case DataType::kUInt32:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_INT_VALUE;
      pb->int_value = static_cast<std::uint32_t>(m.u);
      break;
    case DataType::kUInt64:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_LONG_VALUE;
      pb->long_value = m.u;
      break;
    case DataType::kFloat:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_FLOAT_VALUE;
      pb->float_value = static_cast<float>(m.d);
      break;
    case DataType::kDouble:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_DOUBLE_VALUE;
      pb->double_value = m.d;
      break;
    case DataType::kBoolean:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_BOOLEAN_VALUE;
      pb->boolean_value = m.b ? 1 : 0;
      break;
    case DataType::kString:
      pb->value_case = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_STRING_VALUE;
      pb->string_value = const_cast<char*>(m.s.c_str());  // read only by the packer
      break;
  }
}

}  // namespace

std::vector<std::uint8_t> Encode(std::uint64_t timestamp_ms, std::optional<std::uint64_t> seq,
                                 const std::vector<Metric>& metrics) {
  // protobuf-c packs from plain structs that point into `metrics`; nothing here is owned by it.
  std::vector<PbMetric> pb(metrics.size());
  std::vector<PbMetric*> ptrs(metrics.size());
  for (std::size_t i = 0; i < metrics.size(); ++i) {
    const Metric& m = metrics[i];
    org__eclipse__tahu__protobuf__payload__metric__init(&pb[i]);
    pb[i].name = const_cast<char*>(m.name.c_str());
    pb[i].has_datatype = 1;
    pb[i].datatype = static_cast<std::uint32_t>(m.type);
    if (m.timestamp_ms != 0) {
      pb[i].has_timestamp = 1;
      pb[i].timestamp = m.timestamp_ms;
    }
    SetValue(m, &pb[i]);
    ptrs[i] = &pb[i];
  }
  PbPayload p;
  org__eclipse__tahu__protobuf__payload__init(&p);
  p.has_timestamp = 1;
  p.timestamp = timestamp_ms;
  if (seq) {
    p.has_seq = 1;
    p.seq = *seq;
  }
  p.n_metrics = ptrs.size();
  p.metrics = ptrs.data();
  std::vector<std::uint8_t> out(org__eclipse__tahu__protobuf__payload__get_packed_size(&p));
  org__eclipse__tahu__protobuf__payload__pack(&p, out.data());
  return out;
}

std::optional<std::vector<Metric>> Decode(const void* data, std::size_t size) {
  PbPayload* p = org__eclipse__tahu__protobuf__payload__unpack(
      nullptr, size, static_cast<const std::uint8_t*>(data));
  if (p == nullptr) return std::nullopt;
  std::vector<Metric> out;
  for (std::size_t i = 0; i < p->n_metrics; ++i) {
    const PbMetric& pb = *p->metrics[i];
    Metric m;
    m.name = pb.name != nullptr ? pb.name : "";
    m.type = static_cast<DataType>(pb.has_datatype ? pb.datatype : 0);
    m.is_null = pb.has_is_null && pb.is_null;
    switch (pb.value_case) {
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_INT_VALUE:
        m.u = pb.int_value;
        break;
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_LONG_VALUE:
        m.u = pb.long_value;
        break;
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_FLOAT_VALUE:
        m.d = pb.float_value;
        break;
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_DOUBLE_VALUE:
        m.d = pb.double_value;
        break;
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_BOOLEAN_VALUE:
        m.b = pb.boolean_value != 0;
        break;
      case ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_STRING_VALUE:
        m.s = pb.string_value != nullptr ? pb.string_value : "";
        break;
      default:
        m.is_null = true;  // a value type ftd does not take commands in
        break;
    }
    out.push_back(std::move(m));
  }
  org__eclipse__tahu__protobuf__payload__free_unpacked(p, nullptr);
  return out;
}

}  // namespace ftstack::daemon::sparkplug
