// Coalesces what the OPC UA server sends on one TCP connection within one server iteration into
// one send (open62541 sends each message, e.g. each subscription's publish response, on its own).
#pragma once

#include <open62541.h>

#include <cstdint>
#include <vector>

namespace ftstack::daemon {

/// The server's connection callback as the TCP layer was given it at start-up, with its context:
/// what a connection without a socket is fed through (fuzz/opcua_fuzz.cpp).
struct OpcuaServerEntry {
  UA_ConnectionManager_connectionCallback callback = nullptr;
  void* application = nullptr;
  UA_EventLoop* event_loop = nullptr;
};
/// The entry of the server started last in this process (empty before one started).
[[nodiscard]] OpcuaServerEntry OpcuaServerEntryPoint();

/// Installed on a server's TCP connection manager before the server starts; active on the thread
/// that called Begin until End. While active, messages are collected per connection in order and
/// sent by Flush; a connection's messages are sent before it is closed and dropped when the peer
/// is gone. Elsewhere (another thread, no batch active) messages are sent at once, as before.
class OpcuaSendBatch {
 public:
  /// Wraps the "tcp" connection manager of `server`'s event loop; false if it has none.
  [[nodiscard]] static bool Install(UA_Server* server);
  /// Collects this thread's sends into this batch until End.
  void Begin();
  /// Sends what was collected, one send per connection.
  void Flush();
  /// Flushes and stops collecting.
  void End();

  struct Pending {
    UA_ConnectionManager* cm = nullptr;
    std::uintptr_t id = 0;
    std::vector<UA_Byte> bytes;
  };
  /// The connections that have messages waiting (reused between rounds).
  std::vector<Pending> pending;
};

}  // namespace ftstack::daemon
