#include "daemon/opcua_send_batch.hpp"

#include <sys/socket.h>
#include <sys/types.h>

#include <algorithm>
#include <atomic>
#include <cstring>

namespace ftstack::daemon {
namespace {

using SendFn = UA_StatusCode (*)(UA_ConnectionManager*, std::uintptr_t, const UA_KeyValueMap*,
                                 UA_ByteString*);
using CloseFn = UA_StatusCode (*)(UA_ConnectionManager*, std::uintptr_t);
using OpenFn = UA_StatusCode (*)(UA_ConnectionManager*, const UA_KeyValueMap*, void*, void*,
                                 UA_ConnectionManager_connectionCallback);

// open62541's own functions (one TCP implementation per process, so one of each).
std::atomic<SendFn> g_send{nullptr};
std::atomic<CloseFn> g_close{nullptr};
std::atomic<OpenFn> g_open{nullptr};
std::atomic<UA_ConnectionManager_connectionCallback> g_callback{nullptr};
std::atomic<void*> g_application{nullptr};
std::atomic<UA_EventLoop*> g_event_loop{nullptr};

thread_local OpcuaSendBatch* t_batch = nullptr;

OpcuaSendBatch::Pending* Find(OpcuaSendBatch* b, UA_ConnectionManager* cm, std::uintptr_t id) {
  for (OpcuaSendBatch::Pending& p : b->pending) {
    if (p.cm == cm && p.id == id) return &p;
  }
  return nullptr;
}

void SendNow(OpcuaSendBatch::Pending* p) {
  if (p->bytes.empty()) return;
  UA_ByteString buf;
  if (UA_ByteString_allocBuffer(&buf, p->bytes.size()) == UA_STATUSCODE_GOOD) {
    std::memcpy(buf.data, p->bytes.data(), p->bytes.size());
    // A failed send shuts the connection down; the server hears of it through the callback.
    (void)g_send.load()(p->cm, p->id, nullptr, &buf);
  }
  p->bytes.clear();
}

UA_StatusCode BatchedSend(UA_ConnectionManager* cm, std::uintptr_t id, const UA_KeyValueMap* params,
                          UA_ByteString* buf) {
  OpcuaSendBatch* b = t_batch;
  if (b == nullptr) return g_send.load()(cm, id, params, buf);
  OpcuaSendBatch::Pending* p = Find(b, cm, id);
  if (p == nullptr) {
    p = Find(b, nullptr, 0);  // a free slot (its buffer kept)
    if (p == nullptr) p = &b->pending.emplace_back();
    p->cm = cm;
    p->id = id;
  }
  p->bytes.insert(p->bytes.end(), buf->data, buf->data + buf->length);
  UA_ByteString_clear(buf);
  return UA_STATUSCODE_GOOD;
}

UA_StatusCode BatchedClose(UA_ConnectionManager* cm, std::uintptr_t id) {
  if (OpcuaSendBatch* b = t_batch) {
    if (OpcuaSendBatch::Pending* p = Find(b, cm, id)) SendNow(p);  // e.g. an error message
  }
  return g_close.load()(cm, id);
}

/// The server's connection callback, seen first. A connection the peer ended (or that failed) is
/// closing: what waits for it is sent as far as the socket takes it without blocking (a client
/// that half-closes after its request still gets the answer, as when every message left at once),
/// then forgotten before the socket number can be given to a new connection. The TCP manager's
/// connection id is the socket, and the socket is still open during this callback.
void ConnectionEvent(UA_ConnectionManager* cm, std::uintptr_t id, void* application, void** context,
                     UA_ConnectionState state, const UA_KeyValueMap* params, UA_ByteString msg) {
  if (state == UA_CONNECTIONSTATE_CLOSING) {
    if (OpcuaSendBatch* b = t_batch) {
      if (OpcuaSendBatch::Pending* p = Find(b, cm, id)) {
        std::size_t sent = 0;
        while (sent < p->bytes.size()) {
          const ssize_t n = ::send(static_cast<int>(id), p->bytes.data() + sent,
                                   p->bytes.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
          if (n <= 0) break;
          sent += static_cast<std::size_t>(n);
        }
        p->bytes.clear();
        p->cm = nullptr;
        p->id = 0;
      }
    }
  }
  g_callback.load()(cm, id, application, context, state, params, msg);
}

UA_StatusCode BatchedOpen(UA_ConnectionManager* cm, const UA_KeyValueMap* params, void* application,
                          void* context, UA_ConnectionManager_connectionCallback callback) {
  g_callback.store(callback);
  g_application.store(application);
  g_event_loop.store(cm->eventSource.eventLoop);
  return g_open.load()(cm, params, application, context, ConnectionEvent);
}

}  // namespace

OpcuaServerEntry OpcuaServerEntryPoint() {
  return {g_callback.load(), g_application.load(), g_event_loop.load()};
}

bool OpcuaSendBatch::Install(UA_Server* server) {
  UA_ServerConfig* config = UA_Server_getConfig(server);
  if (config == nullptr || config->eventLoop == nullptr) return false;
  for (UA_EventSource* es = config->eventLoop->eventSources; es != nullptr; es = es->next) {
    if (es->eventSourceType != UA_EVENTSOURCETYPE_CONNECTIONMANAGER) continue;
    auto* cm = reinterpret_cast<UA_ConnectionManager*>(es);
    const UA_String tcp = UA_STRING(const_cast<char*>("tcp"));
    if (!UA_String_equal(&cm->protocol, &tcp)) continue;
    if (cm->sendWithConnection == BatchedSend) return true;
    g_send.store(cm->sendWithConnection);
    g_close.store(cm->closeConnection);
    g_open.store(cm->openConnection);
    cm->sendWithConnection = BatchedSend;
    cm->closeConnection = BatchedClose;
    cm->openConnection = BatchedOpen;
    return true;
  }
  return false;
}

void OpcuaSendBatch::Begin() { t_batch = this; }

void OpcuaSendBatch::Flush() {
  for (Pending& p : pending) {
    if (p.cm != nullptr) SendNow(&p);
  }
}

void OpcuaSendBatch::End() {
  Flush();
  if (t_batch == this) t_batch = nullptr;
}

}  // namespace ftstack::daemon
