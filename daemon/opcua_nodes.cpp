// The OPC UA address space: the device object, its variables (read from the register map) and
// methods (written through it).
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "daemon/opcua_impl.hpp"
#include "daemon/web_state.hpp"
#include "firmware/health_registers.hpp"

#ifndef FTSTACK_VERSION
#define FTSTACK_VERSION "unknown"
#endif

namespace ftstack::daemon {
namespace {

constexpr const char* kAxes[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
/// UNECE Recommendation 20 codes as OPC UA unit ids (Part 8: the code's characters, one per byte).
constexpr const char* kUneceUri = "http://www.opcfoundation.org/UA/units/un/cefact";
constexpr UA_Int32 kUnitNewton = ('N' << 16) | ('E' << 8) | 'W';   // "NEW"
constexpr UA_Int32 kUnitNewtonMetre = ('N' << 8) | 'U';            // "NU"
constexpr UA_Int32 kUnitCelsius = ('C' << 16) | ('E' << 8) | 'L';  // "CEL"

// Status bits of input register 1 (docs/spec/modbus-map.md).
constexpr std::uint16_t kBitSaturated = 1u << 0;
constexpr std::uint16_t kBitOverload = 1u << 1;
constexpr std::uint16_t kBitBridgeFault = 1u << 2;
constexpr std::uint16_t kBitAdcFault = 1u << 3;
constexpr std::uint16_t kBitCalInvalid = 1u << 4;
constexpr std::uint16_t kBitTemperatureOut = 1u << 6;
constexpr std::uint16_t kBitStale = 1u << 8;

/// The quality of a wrench value: Bad where the status says there is no valid value, Uncertain
/// where it is a value outside what the calibration vouches for.
UA_StatusCode WrenchQuality(std::uint16_t status, float value) {
  if ((status & kBitCalInvalid) != 0) return UA_STATUSCODE_BADCONFIGURATIONERROR;
  if ((status & kBitAdcFault) != 0) return UA_STATUSCODE_BADDEVICEFAILURE;
  if ((status & kBitBridgeFault) != 0) return UA_STATUSCODE_BADSENSORFAILURE;
  if ((status & kBitSaturated) != 0) return UA_STATUSCODE_BADOUTOFRANGE;
  if (std::isnan(value)) return UA_STATUSCODE_BADCONFIGURATIONERROR;  // axis invalid (bit 10)
  if ((status & kBitStale) != 0) return UA_STATUSCODE_UNCERTAINLASTUSABLEVALUE;
  if ((status & kBitOverload) != 0) return UA_STATUSCODE_UNCERTAINENGINEERINGUNITSEXCEEDED;
  if ((status & kBitTemperatureOut) != 0) return UA_STATUSCODE_UNCERTAINSENSORNOTACCURATE;
  return UA_STATUSCODE_GOOD;
}

void SetDouble(UA_DataValue* v, double x) {
  UA_Variant_setScalarCopy(&v->value, &x, &UA_TYPES[UA_TYPES_DOUBLE]);
  v->hasValue = true;
}

template <typename T>
void SetScalar(UA_DataValue* v, T x, int type) {
  UA_Variant_setScalarCopy(&v->value, &x, &UA_TYPES[type]);
  v->hasValue = true;
}

void SetString(UA_DataValue* v, const std::string& s) {
  UA_String u = UA_STRING(const_cast<char*>(s.c_str()));
  UA_Variant_setScalarCopy(&v->value, &u, &UA_TYPES[UA_TYPES_STRING]);
  v->hasValue = true;
}

UA_StatusCode ReadSource(UA_Server*, const UA_NodeId*, void*, const UA_NodeId*, void* node_context,
                         UA_Boolean, const UA_NumericRange* range, UA_DataValue* value) {
  if (range != nullptr) {
    value->hasStatus = true;
    value->status = UA_STATUSCODE_BADINDEXRANGEINVALID;
    return UA_STATUSCODE_GOOD;
  }
  auto* src = static_cast<OpcuaSource*>(node_context);
  static_cast<OpcuaServer::Impl*>(src->owner)->Read(*src, value);
  return UA_STATUSCODE_GOOD;
}

UA_StatusCode CallMethod(UA_Server*, const UA_NodeId*, void*, const UA_NodeId*,
                         void* method_context, const UA_NodeId*, void*, size_t input_size,
                         const UA_Variant* input, size_t, UA_Variant*) {
  auto* m = static_cast<OpcuaMethod*>(method_context);
  auto* impl = static_cast<OpcuaServer::Impl*>(m->owner);
  if (m->select_slot) {
    if (input_size != 1 || !UA_Variant_hasScalarType(&input[0], &UA_TYPES[UA_TYPES_UINT16])) {
      return UA_STATUSCODE_BADARGUMENTSMISSING;
    }
    return impl->SelectSlot(*static_cast<const UA_UInt16*>(input[0].data));
  }
  return impl->Command(m->addr, m->value);
}

/// A property (HasProperty, PropertyType) of `parent` holding `value`.
void AddProperty(UA_Server* server, const UA_NodeId& parent, const UA_QualifiedName& name,
                 const UA_Variant& value, const UA_NodeId& data_type) {
  UA_VariableAttributes a = UA_VariableAttributes_default;
  a.displayName.locale = UA_STRING(const_cast<char*>("en"));
  a.displayName.text = name.name;
  a.value = value;
  a.dataType = data_type;
  a.valueRank = UA_VALUERANK_SCALAR;
  a.accessLevel = UA_ACCESSLEVELMASK_READ;
  const UA_StatusCode rc =
      UA_Server_addVariableNode(server, UA_NODEID_NUMERIC(parent.namespaceIndex, 0), parent,
                                UA_NODEID_NUMERIC(0, UA_NS0ID_HASPROPERTY), name,
                                UA_NODEID_NUMERIC(0, UA_NS0ID_PROPERTYTYPE), a, nullptr, nullptr);
  if (rc != UA_STATUSCODE_GOOD) {
    throw FtdError(std::string("OPC UA: cannot add a property: ") + UA_StatusCode_name(rc));
  }
}

/// Sets the child `name` (namespace 0) of `node` to `value`, adding it as a property if the type
/// did not instantiate it.
void SetChild(UA_Server* server, const UA_NodeId& node, const char* name, const UA_Variant& value,
              const UA_NodeId& data_type) {
  const UA_QualifiedName qn = UA_QUALIFIEDNAME(0, const_cast<char*>(name));
  UA_BrowsePathResult r = UA_Server_browseSimplifiedBrowsePath(server, node, 1, &qn);
  const bool found = r.statusCode == UA_STATUSCODE_GOOD && r.targetsSize > 0;
  if (found) UA_Server_writeValue(server, r.targets[0].targetId.nodeId, value);
  UA_BrowsePathResult_clear(&r);
  if (!found) AddProperty(server, node, qn, value, data_type);
}

UA_NodeId StringId(UA_UInt16 ns, const std::string& id) {
  UA_NodeId n;
  n.namespaceIndex = ns;
  n.identifierType = UA_NODEIDTYPE_STRING;
  n.identifier.string = UA_STRING_ALLOC(id.c_str());
  return n;
}

}  // namespace

OpcuaServer::Impl::~Impl() {
  if (server != nullptr) UA_Server_delete(server);
}

const std::uint16_t* OpcuaServer::Impl::Snapshot() {
  const std::uint64_t now = iteration.load(std::memory_order_relaxed);
  if (in_ok && in_iteration == now) return in.data();
  in_ok = map->ReadInput(0, fw::kInputAddressSpan, in.data()) == fw::ModbusException::kNone;
  in_iteration = now;
  return in_ok ? in.data() : nullptr;
}

UA_DateTime OpcuaServer::Impl::SourceTime(std::uint64_t sample_us) {
  const auto t = static_cast<UA_DateTime>(sample_us) * UA_DATETIME_USEC;
  if (!clock_anchored) {
    clock_base = UA_DateTime_now() - t;
    clock_anchored = true;
  }
  return clock_base + t;
}

void OpcuaServer::Impl::Read(const OpcuaSource& src, UA_DataValue* v) {
  const std::uint16_t* r = Snapshot();
  v->hasStatus = true;
  if (r == nullptr) {
    v->status = UA_STATUSCODE_BADWAITINGFORINITIALDATA;
    return;
  }
  const std::uint16_t status = r[fw::kInStatus];
  const std::uint64_t us = (static_cast<std::uint64_t>(r[fw::kInTimestampWraps]) << 32) |
                           fw::UnpackU32(r + fw::kInTimestampUs);
  v->hasSourceTimestamp = true;
  v->sourceTimestamp = SourceTime(us);
  v->status = UA_STATUSCODE_GOOD;
  switch (src.kind) {
    case OpcuaSource::Kind::kWrench: {
      const float x = fw::UnpackFloat32(r + fw::kInWrenchFloat + 2 * src.axis);
      v->status = WrenchQuality(status, x);
      if (UA_StatusCode_isBad(v->status)) return;  // no value rather than a guessed one
      SetDouble(v, static_cast<double>(x));
      return;
    }
    case OpcuaSource::Kind::kPeak: {
      const float x = fw::UnpackFloat32(r + fw::kInPeaks + 2 * src.axis);
      if (std::isnan(x)) {
        v->status = UA_STATUSCODE_BADCONFIGURATIONERROR;
        return;
      }
      SetDouble(v, static_cast<double>(x));
      return;
    }
    case OpcuaSource::Kind::kTemperature: {
      const float x = fw::UnpackFloat32(r + fw::kInTemperature);
      if (std::isnan(x)) {
        v->status = UA_STATUSCODE_BADNODATAAVAILABLE;  // the ADC has no temperature sensor
        return;
      }
      if ((status & kBitTemperatureOut) != 0)
        v->status = UA_STATUSCODE_UNCERTAINENGINEERINGUNITSEXCEEDED;
      SetDouble(v, static_cast<double>(x));
      return;
    }
    case OpcuaSource::Kind::kStatus:
      SetScalar<UA_UInt16>(v, status, UA_TYPES_UINT16);
      return;
    case OpcuaSource::Kind::kSequence:
      SetScalar<UA_UInt32>(v, fw::UnpackU32(r + fw::kInSequence), UA_TYPES_UINT32);
      return;
    case OpcuaSource::Kind::kOverloadEvents:
      SetScalar<UA_UInt32>(v, fw::UnpackU32(r + fw::kInOverloadEvents), UA_TYPES_UINT32);
      return;
    case OpcuaSource::Kind::kLateSamples:
      SetScalar<UA_UInt32>(v, fw::UnpackU32(r + fw::kInLateSamples), UA_TYPES_UINT32);
      return;
    case OpcuaSource::Kind::kCalSlot:
      SetScalar<UA_UInt16>(v, r[fw::kInCalSlot], UA_TYPES_UINT16);
      return;
    case OpcuaSource::Kind::kDeviceHealth:
      // DI's DeviceHealthEnumeration has the NE 107 states in the map's order (0 normal,
      // 1 failure, 2 check function, 3 off specification, 4 maintenance required).
      SetScalar<UA_Int32>(v, static_cast<UA_Int32>(r[fw::kInHealthState]), UA_TYPES_INT32);
      return;
    case OpcuaSource::Kind::kHealth:
    case OpcuaSource::Kind::kTareHistory: {
      std::vector<std::uint16_t> hold(fw::kHoldingRegisterSpan, 0);
      if (map->ReadHolding(0, fw::kHoldingRegisterSpan, hold.data()) !=
          fw::ModbusException::kNone) {
        v->status = UA_STATUSCODE_BADWAITINGFORINITIALDATA;
        return;
      }
      const nlohmann::json s = StateFromRegisters(r, hold.data(), WebStaticInfo{});
      SetString(v, s[src.kind == OpcuaSource::Kind::kHealth ? "health" : "tare_history"].dump());
      return;
    }
  }
}

UA_NodeId OpcuaServer::Impl::AddVariable(const UA_NodeId& parent, const std::string& id,
                                         const char* name, const char* description,
                                         OpcuaSource::Kind kind, int axis, int type, bool analog) {
  sources.push_back(std::make_unique<OpcuaSource>(OpcuaSource{kind, axis, this}));
  UA_VariableAttributes a = UA_VariableAttributes_default;
  a.displayName = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(name));
  a.description = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(description));
  a.dataType = UA_TYPES[type].typeId;
  a.valueRank = UA_VALUERANK_SCALAR;
  a.accessLevel = UA_ACCESSLEVELMASK_READ;
  a.minimumSamplingInterval = kOpcuaMinIntervalMs;
  UA_NodeId node = StringId(ns, id);
  UA_DataSource ds{ReadSource, nullptr};
  const UA_StatusCode rc = UA_Server_addDataSourceVariableNode(
      server, node, parent, UA_NODEID_NUMERIC(0, UA_NS0ID_HASCOMPONENT),
      UA_QUALIFIEDNAME(ns, const_cast<char*>(name)),
      UA_NODEID_NUMERIC(0, analog ? UA_NS0ID_ANALOGITEMTYPE : UA_NS0ID_BASEDATAVARIABLETYPE), a, ds,
      sources.back().get(), nullptr);
  if (rc != UA_STATUSCODE_GOOD) {
    UA_NodeId_clear(&node);
    throw FtdError("OPC UA: cannot add " + id + ": " + UA_StatusCode_name(rc));
  }
  return node;
}

void OpcuaServer::Impl::AddUnit(const UA_NodeId& node, UA_Int32 unit_id, const char* symbol,
                                const char* words) {
  UA_EUInformation eu;
  UA_EUInformation_init(&eu);
  eu.namespaceUri = UA_STRING(const_cast<char*>(kUneceUri));
  eu.unitId = unit_id;
  eu.displayName = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(symbol));
  eu.description = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(words));
  UA_Variant v;
  UA_Variant_setScalar(&v, &eu, &UA_TYPES[UA_TYPES_EUINFORMATION]);
  SetChild(server, node, "EngineeringUnits", v, UA_TYPES[UA_TYPES_EUINFORMATION].typeId);
}

void OpcuaServer::Impl::AddMethod(const UA_NodeId& parent, const std::string& id, const char* name,
                                  const char* description, std::uint16_t addr, std::uint16_t value,
                                  bool select_slot) {
  methods.push_back(std::make_unique<OpcuaMethod>(OpcuaMethod{addr, value, select_slot, this}));
  UA_MethodAttributes a = UA_MethodAttributes_default;
  a.displayName = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(name));
  a.description = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(description));
  a.executable = true;
  a.userExecutable = true;
  UA_Argument arg;
  UA_Argument_init(&arg);
  arg.name = UA_STRING(const_cast<char*>("Slot"));
  arg.description =
      UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>("calibration slot: 0 A, 1 B"));
  arg.dataType = UA_TYPES[UA_TYPES_UINT16].typeId;
  arg.valueRank = UA_VALUERANK_SCALAR;
  UA_NodeId node = StringId(ns, id);
  const UA_StatusCode rc = UA_Server_addMethodNode(
      server, node, parent, UA_NODEID_NUMERIC(0, UA_NS0ID_HASCOMPONENT),
      UA_QUALIFIEDNAME(ns, const_cast<char*>(name)), a, CallMethod, select_slot ? 1 : 0,
      select_slot ? &arg : nullptr, 0, nullptr, methods.back().get(), nullptr);
  UA_NodeId_clear(&node);
  if (rc != UA_STATUSCODE_GOOD) {
    throw FtdError("OPC UA: cannot add method " + id + ": " + UA_StatusCode_name(rc));
  }
}

UA_NodeId OpcuaServer::Impl::AddObject(const UA_NodeId& parent, const std::string& id,
                                       const char* name, const char* description) {
  UA_ObjectAttributes a = UA_ObjectAttributes_default;
  a.displayName = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(name));
  a.description = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(description));
  UA_NodeId node = StringId(ns, id);
  const bool top = parent.namespaceIndex == 0 && parent.identifierType == UA_NODEIDTYPE_NUMERIC &&
                   parent.identifier.numeric == UA_NS0ID_OBJECTSFOLDER;
  const UA_NodeId ref = UA_NODEID_NUMERIC(0, top ? UA_NS0ID_ORGANIZES : UA_NS0ID_HASCOMPONENT);
  const UA_StatusCode rc = UA_Server_addObjectNode(
      server, node, parent, ref, UA_QUALIFIEDNAME(ns, const_cast<char*>(name)),
      UA_NODEID_NUMERIC(0, UA_NS0ID_BASEOBJECTTYPE), a, nullptr, nullptr);
  if (rc != UA_STATUSCODE_GOOD) {
    UA_NodeId_clear(&node);
    throw FtdError("OPC UA: cannot add " + id + ": " + UA_StatusCode_name(rc));
  }
  return node;
}

void OpcuaServer::Impl::AddDeviceProperties(const UA_NodeId& dev) {
  // The DI device properties, with DI's browse names (the DI type nodes are not loaded).
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08X", static_cast<unsigned>(info.cal_crc));
  const std::string model = "ftstack 6-axis F/T sensor (" + info.adc + " ADC)";
  const std::string cal_rev = std::string(crc) + (info.cal_date.empty() ? "" : " " + info.cal_date);
  struct Text {
    const char* name;
    std::string value;
    bool localized;
  };
  const Text texts[] = {{"Manufacturer", "ftstack", true},
                        {"Model", model, true},
                        {"SerialNumber", info.serial, false},
                        {"SoftwareRevision", FTSTACK_VERSION, false},
                        {"DeviceRevision", cal_rev, false}};
  for (const Text& t : texts) {
    UA_Variant v;
    UA_LocalizedText lt =
        UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>(t.value.c_str()));
    UA_String str = UA_STRING(const_cast<char*>(t.value.c_str()));
    if (t.localized) {
      UA_Variant_setScalar(&v, &lt, &UA_TYPES[UA_TYPES_LOCALIZEDTEXT]);
    } else {
      UA_Variant_setScalar(&v, &str, &UA_TYPES[UA_TYPES_STRING]);
    }
    AddProperty(server, dev, UA_QUALIFIEDNAME(di_ns, const_cast<char*>(t.name)), v,
                UA_TYPES[t.localized ? UA_TYPES_LOCALIZEDTEXT : UA_TYPES_STRING].typeId);
  }
  // DeviceHealth is a live value: a data-source variable with DI's browse name.
  {
    sources.push_back(
        std::make_unique<OpcuaSource>(OpcuaSource{OpcuaSource::Kind::kDeviceHealth, 0, this}));
    UA_VariableAttributes a = UA_VariableAttributes_default;
    a.displayName = UA_LOCALIZEDTEXT(const_cast<char*>("en"), const_cast<char*>("DeviceHealth"));
    a.description = UA_LOCALIZEDTEXT(
        const_cast<char*>("en"),
        const_cast<char*>("NE 107 state: 0 NORMAL, 1 FAILURE, 2 CHECK_FUNCTION, 3 OFF_SPEC, "
                          "4 MAINTENANCE_REQUIRED"));
    a.dataType = UA_TYPES[UA_TYPES_INT32].typeId;
    a.accessLevel = UA_ACCESSLEVELMASK_READ;
    a.minimumSamplingInterval = kOpcuaMinIntervalMs;
    UA_NodeId id = StringId(ns, "Sensor.DeviceHealth");
    const UA_StatusCode rc = UA_Server_addDataSourceVariableNode(
        server, id, dev, UA_NODEID_NUMERIC(0, UA_NS0ID_HASCOMPONENT),
        UA_QUALIFIEDNAME(di_ns, const_cast<char*>("DeviceHealth")),
        UA_NODEID_NUMERIC(0, UA_NS0ID_BASEDATAVARIABLETYPE), a, UA_DataSource{ReadSource, nullptr},
        sources.back().get(), nullptr);
    UA_NodeId_clear(&id);
    if (rc != UA_STATUSCODE_GOOD) throw FtdError("OPC UA: cannot add DeviceHealth");
  }
}

void OpcuaServer::Impl::BuildAddressSpace() {
  const UA_NodeId objects = UA_NODEID_NUMERIC(0, UA_NS0ID_OBJECTSFOLDER);
  UA_NodeId dev = AddObject(objects, "Sensor", "ForceTorqueSensor",
                            "the six-axis force/torque sensor ftd serves (OPC UA for Devices "
                            "properties in the DI namespace)");
  AddDeviceProperties(dev);

  using K = OpcuaSource::Kind;
  UA_NodeId wrench = AddObject(dev, "Sensor.Wrench", "Wrench",
                               "the measured wrench, tool frame (tared, payload-compensated)");
  UA_NodeId peaks = AddObject(dev, "Sensor.Peaks", "Peaks", "peak magnitudes since ClearPeaks");
  for (int i = 0; i < 6; ++i) {
    const bool force = i < 3;
    const std::string axis = kAxes[i];
    UA_NodeId n =
        AddVariable(wrench, "Sensor.Wrench." + axis, kAxes[i], force ? "force, N" : "moment, N·m",
                    K::kWrench, i, UA_TYPES_DOUBLE, true);
    const double rated = info.rated[static_cast<std::size_t>(i)];
    UA_Range range;
    range.low = rated > 0 ? -rated : -std::numeric_limits<double>::infinity();
    range.high = rated > 0 ? rated : std::numeric_limits<double>::infinity();
    UA_Variant rv;
    UA_Variant_setScalar(&rv, &range, &UA_TYPES[UA_TYPES_RANGE]);
    SetChild(server, n, "EURange", rv, UA_TYPES[UA_TYPES_RANGE].typeId);
    if (force) {
      AddUnit(n, kUnitNewton, "N", "newton");
    } else {
      AddUnit(n, kUnitNewtonMetre, "N·m", "newton metre");
    }
    UA_NodeId_clear(&n);
    UA_NodeId p = AddVariable(peaks, "Sensor.Peaks." + axis, kAxes[i],
                              force ? "peak force, N" : "peak moment, N·m", K::kPeak, i,
                              UA_TYPES_DOUBLE, false);
    UA_NodeId_clear(&p);
  }
  UA_NodeId t = AddVariable(dev, "Sensor.Temperature", "Temperature",
                            "bridge temperature, °C (Bad: the ADC has none)", K::kTemperature, 0,
                            UA_TYPES_DOUBLE, false);
  AddUnit(t, kUnitCelsius, "°C", "degree Celsius");
  UA_NodeId_clear(&t);
  struct Plain {
    const char* id;
    const char* name;
    const char* description;
    K kind;
    int type;
  };
  const Plain plain[] = {
      {"Sensor.Status", "Status", "status bits (Modbus input register 1)", K::kStatus,
       UA_TYPES_UINT16},
      {"Sensor.Sequence", "Sequence", "published sample number", K::kSequence, UA_TYPES_UINT32},
      {"Sensor.OverloadEvents", "OverloadEvents", "overload events since start", K::kOverloadEvents,
       UA_TYPES_UINT32},
      {"Sensor.LateSamples", "LateSamples", "missed sampling deadlines since start",
       K::kLateSamples, UA_TYPES_UINT32},
      {"Sensor.CalibrationSlot", "CalibrationSlot", "active calibration slot: 0 A, 1 B",
       K::kCalSlot, UA_TYPES_UINT16},
      {"Sensor.Health", "Health",
       "health watch: NE 107 state, findings with cause and error per axis (JSON, docs/web.md)",
       K::kHealth, UA_TYPES_STRING},
      {"Sensor.TareHistory", "TareHistory",
       "the last tares, newest first: number, source, time, temperature, load (JSON)",
       K::kTareHistory, UA_TYPES_STRING},
  };
  for (const Plain& p : plain) {
    UA_NodeId n = AddVariable(dev, p.id, p.name, p.description, p.kind, 0, p.type, false);
    UA_NodeId_clear(&n);
  }
  AddMethod(dev, "Sensor.Tare", "Tare", "zero the wrench at the present load", fw::kHoldCommand,
            fw::kCmdTare, false);
  AddMethod(dev, "Sensor.ClearTare", "ClearTare", "remove the tare", fw::kHoldCommand,
            fw::kCmdClearTare, false);
  AddMethod(dev, "Sensor.ClearPeaks", "ClearPeaks", "restart the peak magnitudes", fw::kHoldCommand,
            fw::kCmdClearPeaks, false);
  AddMethod(dev, "Sensor.SelectSlot", "SelectSlot", "make calibration slot Slot (0 A, 1 B) active",
            fw::kHoldCalSlot, 0, true);
  UA_NodeId_clear(&wrench);
  UA_NodeId_clear(&peaks);
  UA_NodeId_clear(&dev);
}

}  // namespace ftstack::daemon
