// OpcuaSendBatch on open62541's TCP connection manager: what is sent while a batch is active leaves
// in one send per connection at Flush, in order; a close sends what waits first; without a batch
// a message leaves at once. The connection is one end of a SOCK_SEQPACKET pair (the TCP manager's
// connection id is the socket), so each send arrives as one record.
#include "daemon/opcua_send_batch.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <string>

namespace ftstack::daemon {
namespace {

UA_ConnectionManager* TcpManager(UA_Server* server) {
  for (UA_EventSource* es = UA_Server_getConfig(server)->eventLoop->eventSources; es != nullptr;
       es = es->next) {
    auto* cm = reinterpret_cast<UA_ConnectionManager*>(es);
    if (es->eventSourceType == UA_EVENTSOURCETYPE_CONNECTIONMANAGER &&
        std::string(reinterpret_cast<const char*>(cm->protocol.data), cm->protocol.length) ==
            "tcp") {
      return cm;
    }
  }
  return nullptr;
}

void Send(UA_ConnectionManager* cm, int fd, const std::string& text) {
  UA_ByteString b;
  ASSERT_EQ(UA_ByteString_allocBuffer(&b, text.size()), UA_STATUSCODE_GOOD);
  std::memcpy(b.data, text.data(), text.size());
  ASSERT_EQ(cm->sendWithConnection(cm, static_cast<std::uintptr_t>(fd), nullptr, &b),
            UA_STATUSCODE_GOOD);
}

/// The next record waiting on `fd`, "" when none.
std::string NextRecord(int fd) {
  char buf[256];
  const ssize_t n = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

TEST(OpcuaSendBatch, OneSendPerConnectionInOrder) {
  UA_Server* server = UA_Server_new();
  ASSERT_NE(server, nullptr);
  ASSERT_TRUE(OpcuaSendBatch::Install(server));
  UA_ConnectionManager* cm = TcpManager(server);
  ASSERT_NE(cm, nullptr);
  int a[2];
  int b[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, a), 0);
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, b), 0);

  OpcuaSendBatch batch;
  batch.Begin();
  Send(cm, a[0], "one,");
  Send(cm, b[0], "other");
  Send(cm, a[0], "two,");
  Send(cm, a[0], "three");
  EXPECT_EQ(NextRecord(a[1]), "");  // nothing leaves before the flush
  batch.Flush();
  EXPECT_EQ(NextRecord(a[1]), "one,two,three");
  EXPECT_EQ(NextRecord(a[1]), "");
  EXPECT_EQ(NextRecord(b[1]), "other");

  // A close sends what waits first (the TCP manager does not know this socket: it only refuses).
  Send(cm, a[0], "last words");
  (void)cm->closeConnection(cm, static_cast<std::uintptr_t>(a[0]));
  EXPECT_EQ(NextRecord(a[1]), "last words");

  batch.End();
  Send(cm, a[0], "at once");
  EXPECT_EQ(NextRecord(a[1]), "at once");

  for (int fd : {a[0], a[1], b[0], b[1]}) close(fd);
  UA_Server_delete(server);
}

}  // namespace
}  // namespace ftstack::daemon
