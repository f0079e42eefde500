#include "tools/ftd/mqtt_options.hpp"

#include <cstdio>

namespace ftstack::tools {

void AddMqttOptions(CLI::App& app, daemon::FtdOptions& opt) {
  auto* mqtt = app.add_option(
      "--mqtt", opt.mqtt,
      "publish Sparkplug B to the MQTT broker at mqtt://HOST[:PORT] or mqtts://HOST[:PORT]");
  const auto needs_mqtt = [&](CLI::Option* o) { o->needs(mqtt); };
  needs_mqtt(app.add_option("--mqtt-ca", opt.mqtt_ca, "CA certificate of the broker (mqtts)")
                 ->check(CLI::ExistingFile));
  needs_mqtt(app.add_option("--mqtt-cert", opt.mqtt_cert, "client certificate (mqtts)")
                 ->check(CLI::ExistingFile));
  needs_mqtt(app.add_option("--mqtt-key", opt.mqtt_key, "client certificate's key (mqtts)")
                 ->check(CLI::ExistingFile));
  needs_mqtt(app.add_option("--mqtt-credentials", opt.mqtt_credentials,
                            "file with the broker user name (line 1) and password (line 2)")
                 ->check(CLI::ExistingFile));
  needs_mqtt(app.add_option("--sparkplug-group", opt.sparkplug_group,
                            "Sparkplug group id (default: ftstack)"));
  needs_mqtt(app.add_option("--edge-node", opt.edge_node,
                            "Sparkplug edge node id (default: the host name)"));
  needs_mqtt(app.add_option("--device", opt.device,
                            "Sparkplug device id (default: the calibration's serial)"));
  needs_mqtt(app.add_option("--mqtt-rate-hz", opt.mqtt_rate_hz,
                            "wrench publications per second, each the mean over its window "
                            "(default: 10)")
                 ->check(CLI::Range(0.01, 1000.0)));
  needs_mqtt(app.add_option("--mqtt-keepalive-s", opt.mqtt_keepalive_s,
                            "MQTT keep-alive, s: the broker publishes NDEATH after 1.5 x this "
                            "without a packet (default: 10)")
                 ->check(CLI::Range(5u, 3600u)));
  needs_mqtt(app.add_flag("--mqtt-write-protect", opt.mqtt_write_protect,
                          "refuse every command from the broker (tare, clear peaks)"));
}

void PrintMqttSummary(const daemon::Ftd& ftd) {
  if (ftd.mqtt() == nullptr) return;
  const daemon::MqttStats s = ftd.mqtt()->stats();
  std::fprintf(stderr,
               "ftd: MQTT %llu messages published, %llu wrench windows dropped, %u reconnects, "
               "%u births, %u commands\n",
               static_cast<unsigned long long>(s.published),
               static_cast<unsigned long long>(s.dropped), s.reconnects, s.births, s.commands);
}

}  // namespace ftstack::tools
