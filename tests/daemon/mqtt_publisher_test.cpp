// ftd's MQTT publisher without a broker: URL parsing, the sampling thread's windows and bounded
// queue, the wrench means and report by exception (the broker side: tests/system/ftd_mqtt_test.py).
#include "daemon/mqtt_publisher.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/status_bits.hpp"
#include "firmware/wrench.hpp"

namespace ftstack::daemon {
namespace {

TEST(MqttUrl, SchemesPortsAndRefusals) {
  BrokerUrl u = ParseBrokerUrl("mqtt://broker.plant");
  EXPECT_FALSE(u.tls);
  EXPECT_EQ(u.host, "broker.plant");
  EXPECT_EQ(u.port, 1883);
  u = ParseBrokerUrl("mqtts://10.0.0.5:8884/");
  EXPECT_TRUE(u.tls);
  EXPECT_EQ(u.host, "10.0.0.5");
  EXPECT_EQ(u.port, 8884);
  EXPECT_EQ(ParseBrokerUrl("mqtts://h").port, 8883);
  for (const char* bad : {"http://h", "mqtt://", "mqtt://h:0", "mqtt://h:70000", "mqtt://h:x",
                          "mqtt://user:pw@h", "tcp://h:1883"}) {
    EXPECT_THROW((void)ParseBrokerUrl(bad), FtdError) << bad;
  }
}

fw::DeviceSample Sample(std::uint32_t seq, const fw::WrenchLsb& w, std::uint16_t status = 0) {
  fw::DeviceSample d;
  d.sample.sequence = seq;
  d.sample.wrench = w;
  d.sample.status = status;
  d.publish_time_us = 1000u * seq;
  d.publish_period_us = 1000;
  return d;
}

TEST(MqttPublisherQueue, WindowsOfWholeSamplesAndDropsWhenNobodyDrains) {
  FtdOptions opt;
  opt.mqtt = "mqtt://127.0.0.1:1";
  opt.edge_node = "n";
  opt.mqtt_rate_hz = 50;  // 1000 Hz samples: windows of 20
  MqttPublisher p(opt, nullptr, "dev");
  p.Open();  // no connection: Run is not started, so nothing drains the 256-window queue
  const fw::WrenchLsb w = {1000, -2000, 3000, 40, -50, 60};
  std::uint32_t seq = 0;
  for (int window = 0; window < 256; ++window) {
    for (int i = 0; i < 20; ++i) p.Push(Sample(++seq, w));
  }
  EXPECT_EQ(p.stats().dropped, 0u);
  for (int i = 0; i < 19; ++i) p.Push(Sample(++seq, w));
  EXPECT_EQ(p.stats().dropped, 0u) << "a window is complete only with its 20th sample";
  p.Push(Sample(++seq, w));
  EXPECT_EQ(p.stats().dropped, 1u);
  for (int i = 0; i < 40; ++i) p.Push(Sample(++seq, w));
  EXPECT_EQ(p.stats().dropped, 3u);
}

TEST(SparkplugMetrics, WindowMeanInSiUnitsAndNullForInvalidAxes) {
  WrenchWindow w;
  w.samples = 3;
  w.sum_lsb = {3001, -3, 0, 30, -300, 7};  // LSB: 1 mN, 10 µN·m
  w.last_sequence = 42;
  w.end_us = 5'000'000;
  w.invalid_axes = 1u << 5;
  const auto m = WrenchMetrics(w, 1'000'000);
  ASSERT_EQ(m.size(), 9u);
  EXPECT_EQ(m[0].name, "Wrench/Fx_n");
  EXPECT_DOUBLE_EQ(m[0].d, 3001.0 / 3 * 1e-3);
  EXPECT_DOUBLE_EQ(m[1].d, -1e-3);
  EXPECT_EQ(m[3].name, "Wrench/Mx_nm");
  EXPECT_DOUBLE_EQ(m[3].d, 10 * 1e-5);
  EXPECT_DOUBLE_EQ(m[4].d, -100 * 1e-5);
  EXPECT_TRUE(m[5].is_null);
  EXPECT_FALSE(m[4].is_null);
  EXPECT_EQ(m[6].u, 3u);
  EXPECT_EQ(m[7].u, 42u);
  EXPECT_EQ(m[8].u, 6'000'000u);
  w.status_or = fw::kStatusCalInvalid;
  for (std::size_t i = 0; i < 6; ++i) EXPECT_TRUE(WrenchMetrics(w, 0)[i].is_null) << i;
}

TEST(SparkplugMetrics, ReportByExceptionSendsWhatChangedAndTheWholeAcknowledgement) {
  DeviceState s;
  const auto before = ExceptionMetrics(s);
  EXPECT_TRUE(Changed(before, before).empty());
  s.latest.sample.status = fw::kStatusTareActive;
  s.latest.overload_events = 2;
  auto changed = Changed(ExceptionMetrics(s), before);
  std::vector<std::string> names;
  for (const auto& m : changed) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"Status/Bits", "Status/Tare Active",
                                             "Events/Overload Events"}));
  // Two commands with the same result: the second acknowledgement still carries name and result.
  s.commands = 1;
  s.last_command = "Device Control/Tare";
  s.last_result = "accepted";
  const auto first = ExceptionMetrics(s);
  s.commands = 2;
  changed = Changed(ExceptionMetrics(s), first);
  names.clear();
  for (const auto& m : changed) names.push_back(m.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"Device Control/Commands", "Device Control/Last Command",
                                      "Device Control/Last Result"}));
}

TEST(SparkplugPayload, TopicsAndNames) {
  using sparkplug::MessageType;
  EXPECT_EQ(sparkplug::Topic(MessageType::kNBirth, "g", "n"), "spBv1.0/g/NBIRTH/n");
  EXPECT_EQ(sparkplug::Topic(MessageType::kDData, "g", "n", "d"), "spBv1.0/g/DDATA/n/d");
  EXPECT_EQ(sparkplug::Topic(MessageType::kDCmd, "g", "n", "d"), "spBv1.0/g/DCMD/n/d");
  EXPECT_TRUE(sparkplug::ValidId("cell-7_a"));
  for (const char* bad : {"", "a/b", "a+", "#"}) EXPECT_FALSE(sparkplug::ValidId(bad)) << bad;
}

}  // namespace
}  // namespace ftstack::daemon
