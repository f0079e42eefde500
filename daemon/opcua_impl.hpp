// The OPC UA server's state shared by its configuration (opcua_server.cpp) and its address space
// (opcua_nodes.cpp); internal to the daemon.
#pragma once

#include <open62541.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "daemon/opcua_send_batch.hpp"
#include "daemon/opcua_server.hpp"

namespace ftstack::daemon {

/// What one variable node shows (its node context): a register-map value, decoded.
struct OpcuaSource {
  enum class Kind : std::uint8_t {
    kWrench,          ///< axis: float32 N or N·m, status code from the status bits
    kPeak,            ///< axis: peak since ClearPeaks
    kTemperature,     ///< °C, Bad where the ADC has none
    kStatus,          ///< the status bits (input 1)
    kSequence,        ///< published sample number
    kOverloadEvents,  ///< overload events since start
    kLateSamples,     ///< missed sampling deadlines
    kCalSlot,         ///< active calibration slot
    kDeviceHealth,    ///< NE 107 state as DI DeviceHealthEnumeration
    kHealth,          ///< the health watch's findings (cause, error per axis) as JSON
    kTareHistory,     ///< the last tares as JSON
  };
  Kind kind;
  int axis = 0;
  void* owner = nullptr;  ///< the OpcuaServer::Impl that reads it
};

/// What one method node does (its method context): a command register write or a slot choice.
struct OpcuaMethod {
  std::uint16_t addr = 0;
  std::uint16_t value = 0;
  bool select_slot = false;  ///< SelectSlot(Slot): unlock, then holding 3 = Slot
  void* owner = nullptr;     ///< the OpcuaServer::Impl that runs it
};

struct OpcuaServer::Impl {
  Impl(const FtdOptions& o, fw::RegisterMap* m, OpcuaDeviceInfo i)
      : opt(o), map(m), info(std::move(i)) {}
  ~Impl();

  /// The input table of one published sample, copied once per server iteration (all values
  /// served in one iteration, e.g. every monitored item of a round, come from one sample);
  /// nullptr when the map could not be read.
  const std::uint16_t* Snapshot();
  /// The UTC time of the sample clock's `sample_us` (anchored at the first read: the newest
  /// sample is taken as converted then).
  UA_DateTime SourceTime(std::uint64_t sample_us);
  /// Fills `value` from the snapshot for `src` (value, status code, source timestamp).
  void Read(const OpcuaSource& src, UA_DataValue* value);
  /// Builds the device object, its variables and methods (opcua_nodes.cpp); throws FtdError.
  void BuildAddressSpace();
  /// The DI-named properties of the device object and its DeviceHealth variable.
  void AddDeviceProperties(const UA_NodeId& dev);
  UA_NodeId AddObject(const UA_NodeId& parent, const std::string& id, const char* name,
                      const char* description);
  /// A variable read from the map; `analog`: an AnalogItemType (EURange, EngineeringUnits).
  UA_NodeId AddVariable(const UA_NodeId& parent, const std::string& id, const char* name,
                        const char* description, OpcuaSource::Kind kind, int axis, int type,
                        bool analog);
  /// The EngineeringUnits property: a UNECE code (`unit_id`) with its symbol and words.
  void AddUnit(const UA_NodeId& node, UA_Int32 unit_id, const char* symbol, const char* words);
  void AddMethod(const UA_NodeId& parent, const std::string& id, const char* name,
                 const char* description, std::uint16_t addr, std::uint16_t value,
                 bool select_slot);
  /// One command through the register map (the Modbus path); Bad* when refused.
  UA_StatusCode Command(std::uint16_t addr, std::uint16_t value);
  UA_StatusCode SelectSlot(std::uint16_t slot);

  const FtdOptions& opt;
  fw::RegisterMap* map;
  OpcuaDeviceInfo info;
  UA_Server* server = nullptr;
  UA_UInt16 ns = 1;
  UA_UInt16 di_ns = 2;
  std::vector<std::unique_ptr<OpcuaSource>> sources;
  std::vector<std::unique_ptr<OpcuaMethod>> methods;
  std::vector<std::uint16_t> in = std::vector<std::uint16_t>(fw::kInputAddressSpan, 0);
  bool in_ok = false;
  std::uint64_t in_iteration = 0;           ///< the iteration `in` was copied in
  std::atomic<std::uint64_t> iteration{1};  ///< counts the server's iterations
  bool clock_anchored = false;
  UA_DateTime clock_base = 0;  ///< UTC of sample clock 0
  OpcuaSendBatch send_batch;   ///< the server thread's sends, one per connection and iteration
  std::atomic<std::uint64_t> method_calls{0};
  std::atomic<std::uint64_t> method_refused{0};
};

}  // namespace ftstack::daemon
