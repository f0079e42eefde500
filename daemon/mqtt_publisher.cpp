#include "daemon/mqtt_publisher.hpp"

#include <mosquitto.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <mutex>
#include <thread>

#include "calibration/file/cal_file.hpp"

namespace ftstack::daemon {

using sparkplug::DataType;
using sparkplug::MessageType;
using sparkplug::Metric;

namespace {

constexpr std::uint32_t kFirstBackoffMs = 100;
constexpr std::uint32_t kMaxBackoffMs = 5000;
constexpr const char* kRebirth = "Node Control/Rebirth";

std::uint64_t UtcUs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u +
         static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

/// '/', '+', '#' and blanks (not allowed in a Sparkplug name element) become '_'.
std::string Sanitised(std::string id) {
  for (char& c : id) {
    if (c == '/' || c == '+' || c == '#' || c == ' ' || c == '\t') c = '_';
  }
  return id;
}

std::string HostName() {
  char buf[256] = {};
  if (gethostname(buf, sizeof(buf) - 1) != 0 || buf[0] == 0) return "ftd";
  return Sanitised(buf);
}

void CheckId(const char* option, const std::string& id) {
  if (!sparkplug::ValidId(id)) {
    throw FtdError(std::string(option) + " '" + id +
                   "': a Sparkplug name must be non-empty and contain no '/', '+' or '#'");
  }
}

}  // namespace

BrokerUrl ParseBrokerUrl(const std::string& url) {
  BrokerUrl b;
  std::string rest;
  if (url.rfind("mqtt://", 0) == 0) {
    rest = url.substr(7);
  } else if (url.rfind("mqtts://", 0) == 0) {
    rest = url.substr(8);
    b.tls = true;
    b.port = 8883;
  } else {
    throw FtdError("--mqtt '" + url + "': expected mqtt://HOST[:PORT] or mqtts://HOST[:PORT]");
  }
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  if (rest.find('@') != std::string::npos) {
    throw FtdError("--mqtt '" + url +
                   "': no user or password in the URL (a command line is visible to every user "
                   "of the machine); put them in --mqtt-credentials FILE");
  }
  const std::size_t colon = rest.rfind(':');
  if (colon != std::string::npos && rest.find(']') == std::string::npos) {
    std::string host;
    ParseHostPort(rest, &host, &b.port);  // names --modbus-tcp in its message: replaced below
    rest = host;
  }
  if (rest.empty()) throw FtdError("--mqtt '" + url + "': no host");
  if (b.port == 0) throw FtdError("--mqtt '" + url + "': port 0");
  b.host = rest;
  return b;
}

std::string DefaultDeviceId(const FtdOptions& opt, std::uint8_t slot, std::uint32_t cal_crc) {
  const std::string& path = slot == 0 ? opt.cal : opt.cal_b;
  if (!path.empty()) {
    try {
      const std::string serial = Sanitised(cal::LoadCalFile(path).serial);
      if (!serial.empty() && serial != "unknown") return serial;
    } catch (const std::exception&) {  // the slot was refused: named by its CRC below
    }
  }
  char buf[16];
  std::snprintf(buf, sizeof(buf), "ft-%08x", cal_crc);
  return buf;
}

MqttPublisher::MqttPublisher(const FtdOptions& options, fw::RegisterMap* map, std::string device_id)
    : opt_(options), map_(map), device_(std::move(device_id)) {}

MqttPublisher::~MqttPublisher() {
  if (mosq_ != nullptr) mosquitto_destroy(mosq_);
}

void MqttPublisher::Open() {
  try {
    url_ = ParseBrokerUrl(opt_.mqtt);
  } catch (const FtdError& e) {
    const std::string m = e.what();
    if (m.rfind("--modbus-tcp", 0) != 0) throw;
    throw FtdError("--mqtt" + m.substr(m.find(' ')));
  }
  node_ = opt_.edge_node.empty() ? HostName() : opt_.edge_node;
  if (!opt_.device.empty()) device_ = opt_.device;
  CheckId("--sparkplug-group", opt_.sparkplug_group);
  CheckId("--edge-node", node_);
  CheckId("--device", device_);
  if (!(opt_.mqtt_rate_hz > 0 && opt_.mqtt_rate_hz <= 1000)) {
    throw FtdError("--mqtt-rate-hz must be in (0, 1000]");
  }
  window_us_ = static_cast<std::uint32_t>(1e6 / opt_.mqtt_rate_hz);
  if (opt_.mqtt_keepalive_s < 5) throw FtdError("--mqtt-keepalive-s must be at least 5");

  static std::once_flag init;
  std::call_once(init, [] { mosquitto_lib_init(); });
  const std::string client_id = "ftd:" + opt_.sparkplug_group + ":" + node_ + ":" + device_;
  mosq_ = mosquitto_new(client_id.c_str(), true, this);
  if (mosq_ == nullptr) throw FtdError("MQTT: mosquitto_new failed");
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  mosquitto_connect_callback_set(mosq_, [](mosquitto*, void* self, int rc) {
    static_cast<MqttPublisher*>(self)->OnConnect(rc);
  });
  mosquitto_message_callback_set(mosq_, [](mosquitto*, void* self, const mosquitto_message* m) {
    static_cast<MqttPublisher*>(self)->OnMessage(*m);
  });
  if (!opt_.mqtt_credentials.empty()) {
    const auto [user, password] = ReadCredentialsFile("--mqtt-credentials", opt_.mqtt_credentials);
    if (mosquitto_username_pw_set(mosq_, user.c_str(), password.c_str()) != MOSQ_ERR_SUCCESS) {
      throw FtdError("--mqtt-credentials: refused by libmosquitto");
    }
  }
  if (url_.tls) {
    if (opt_.mqtt_cert.empty() != opt_.mqtt_key.empty()) {
      throw FtdError("--mqtt-cert and --mqtt-key go together");
    }
    const int rc =
        mosquitto_tls_set(mosq_, opt_.mqtt_ca.empty() ? nullptr : opt_.mqtt_ca.c_str(),
                          opt_.mqtt_ca.empty() ? "/etc/ssl/certs" : nullptr,
                          opt_.mqtt_cert.empty() ? nullptr : opt_.mqtt_cert.c_str(),
                          opt_.mqtt_key.empty() ? nullptr : opt_.mqtt_key.c_str(), nullptr);
    if (rc != MOSQ_ERR_SUCCESS) {
      throw FtdError(std::string("MQTT TLS set-up (--mqtt-ca/--mqtt-cert/--mqtt-key): ") +
                     mosquitto_strerror(rc));
    }
  } else if (!opt_.mqtt_ca.empty() || !opt_.mqtt_cert.empty() || !opt_.mqtt_key.empty()) {
    throw FtdError("--mqtt-ca/--mqtt-cert/--mqtt-key need an mqtts:// broker URL");
  }
  state_.write_protected = opt_.mqtt_write_protect;
  std::fprintf(stderr, "ftd: Sparkplug B edge node spBv1.0/%s/%s, device %s, broker %s (%g Hz)\n",
               opt_.sparkplug_group.c_str(), node_.c_str(), device_.c_str(), opt_.mqtt.c_str(),
               opt_.mqtt_rate_hz);
}

void MqttPublisher::Push(const fw::DeviceSample& d) {
  const std::uint64_t t = d.publish_time_us;
  for (std::size_t i = 0; i < 6; ++i) window_.sum_lsb[i] += d.sample.wrench[i];
  ++window_.samples;
  window_.last_sequence = d.sample.sequence;
  window_.end_us = t;
  window_.status_or |= d.sample.status;
  window_.invalid_axes |= d.sample.invalid_axes;
  // A window is a whole number of published samples (the expected period, so a late sample
  // does not shorten it): 1000 Hz at 20 Hz averages 50 samples.
  const std::uint32_t period_us = std::max<std::uint32_t>(d.publish_period_us, 1);
  const std::uint32_t per_window =
      std::max<std::uint32_t>(1, (window_us_ + period_us / 2) / period_us);
  if (window_.samples < per_window) return;
  const std::uint64_t h = head_.load(std::memory_order_relaxed);
  if (h - tail_.load(std::memory_order_acquire) >= kQueueSize) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
  } else {
    queue_[h % kQueueSize] = window_;
    head_.store(h + 1, std::memory_order_release);
  }
  window_ = WrenchWindow{};
}

std::vector<std::uint8_t> MqttPublisher::DeathPayload() const {
  return sparkplug::Encode(UtcUs() / 1000, std::nullopt,
                           {sparkplug::UInt("bdSeq", DataType::kUInt64, bd_seq_)});
}

void MqttPublisher::Connect() {
  bd_seq_ = next_bd_seq_++;
  const std::string death = sparkplug::Topic(MessageType::kNDeath, opt_.sparkplug_group, node_);
  const std::vector<std::uint8_t> will = DeathPayload();
  mosquitto_will_set(mosq_, death.c_str(), static_cast<int>(will.size()), will.data(), 1, false);
  const int rc = mosquitto_connect(mosq_, url_.host.c_str(), url_.port,
                                   static_cast<int>(opt_.mqtt_keepalive_s));
  if (rc == MOSQ_ERR_SUCCESS) {
    socket_open_ = true;  // CONNACK arrives through mosquitto_loop (OnConnect)
    return;
  }
  if (backoff_ms_ == 0 || ever_connected_) {
    std::fprintf(stderr, "ftd: MQTT broker %s: %s; retrying with back-off\n", opt_.mqtt.c_str(),
                 rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc));
  }
  Disconnected();
}

void MqttPublisher::Disconnected() {
  if (connected_) {
    std::fprintf(stderr, "ftd: MQTT connection to %s lost; reconnecting\n", opt_.mqtt.c_str());
  }
  connected_ = false;
  connected_flag_ = false;
  socket_open_ = false;
  backoff_ms_ = backoff_ms_ == 0 ? kFirstBackoffMs : std::min(2 * backoff_ms_, kMaxBackoffMs);
  next_attempt_us_ = fw::MonotonicUs() + std::uint64_t{backoff_ms_} * 1000u;
}

void MqttPublisher::OnConnect(int rc) {
  if (rc != 0) {
    std::fprintf(stderr, "ftd: MQTT broker %s refused the connection: %s\n", opt_.mqtt.c_str(),
                 mosquitto_connack_string(rc));
    mosquitto_disconnect(mosq_);
    Disconnected();
    return;
  }
  if (ever_connected_) reconnects_.fetch_add(1, std::memory_order_relaxed);
  std::fprintf(stderr, "ftd: MQTT connected to %s (bdSeq %u)\n", opt_.mqtt.c_str(),
               static_cast<unsigned>(bd_seq_));
  ever_connected_ = true;
  connected_ = true;
  connected_flag_ = true;
  backoff_ms_ = 0;
  birth_due_ = true;
  const std::string ncmd = sparkplug::Topic(MessageType::kNCmd, opt_.sparkplug_group, node_);
  const std::string dcmd =
      sparkplug::Topic(MessageType::kDCmd, opt_.sparkplug_group, node_, device_);
  mosquitto_subscribe(mosq_, nullptr, ncmd.c_str(), 1);
  mosquitto_subscribe(mosq_, nullptr, dcmd.c_str(), 1);
}

void MqttPublisher::OnMessage(const mosquitto_message& msg) {
  const std::string topic = msg.topic != nullptr ? msg.topic : "";
  const auto metrics = sparkplug::Decode(msg.payload, static_cast<std::size_t>(msg.payloadlen));
  if (!metrics) {
    std::fprintf(stderr, "ftd: MQTT %s: not a Sparkplug B payload; ignored\n", topic.c_str());
    return;
  }
  if (topic == sparkplug::Topic(MessageType::kNCmd, opt_.sparkplug_group, node_)) {
    for (const Metric& m : *metrics) {
      if (m.name == kRebirth && m.type == DataType::kBoolean && m.b) birth_due_ = true;
    }
  } else if (topic == sparkplug::Topic(MessageType::kDCmd, opt_.sparkplug_group, node_, device_)) {
    HandleCommands(*metrics);
  }
}

void MqttPublisher::HandleCommands(const std::vector<Metric>& metrics) {
  for (const Metric& m : metrics) {
    std::uint16_t command = fw::kCmdNone;
    if (m.name == "Device Control/Tare") command = fw::kCmdTare;
    if (m.name == "Device Control/Clear Peaks") command = fw::kCmdClearPeaks;
    if (command != fw::kCmdNone && !(m.type == DataType::kBoolean && m.b)) continue;  // false: none
    std::string result;
    if (command == fw::kCmdNone) {
      result = "refused: not a command of this device";
    } else if (opt_.mqtt_write_protect) {
      result = "refused: write-protected";
    } else {
      const fw::ModbusException e =
          map_->WriteHolding(fw::kHoldCommand, &command, 1, fw::TareSource::kMqtt);
      result = e == fw::ModbusException::kNone
                   ? "accepted"
                   : "refused: register map exception " + std::to_string(static_cast<int>(e));
    }
    ++state_.commands;
    state_.last_command = m.name;
    state_.last_result = result;
    commands_.fetch_add(1, std::memory_order_relaxed);
  }
}

DeviceState MqttPublisher::ReadState() {
  DeviceState s = state_;
  (void)map_->device().ReadLatest(&s.latest);  // false only when starved: keeps the previous
  std::array<std::uint16_t, 12> regs{};
  if (map_->ReadHolding(fw::kHoldFilterLength, 2, regs.data()) == fw::ModbusException::kNone) {
    s.filter_length = regs[0];
    s.decimation = regs[1];
  }
  if (map_->ReadHolding(fw::kHoldTransform, 12, regs.data()) == fw::ModbusException::kNone) {
    for (std::size_t i = 0; i < 6; ++i) s.transform[i] = fw::UnpackFloat32(&regs[2 * i]);
  }
  if (map_->ReadHolding(fw::kHoldGravityComp, 1, regs.data()) == fw::ModbusException::kNone) {
    s.gravity_comp = regs[0] != 0;
  }
  s.mqtt_dropped = dropped_.load(std::memory_order_relaxed);
  s.mqtt_reconnects = reconnects_.load(std::memory_order_relaxed);
  state_ = s;
  return s;
}

bool MqttPublisher::Send(const std::string& topic, const std::vector<std::uint8_t>& payload,
                         int qos) {
  const int rc = mosquitto_publish(mosq_, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                                   payload.data(), qos, false);
  if (rc != MOSQ_ERR_SUCCESS) return false;
  published_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

void MqttPublisher::PublishBirth() {
  birth_due_ = false;
  births_.fetch_add(1, std::memory_order_relaxed);
  const std::uint64_t now_ms = UtcUs() / 1000;
  seq_ = 0;
  const std::vector<Metric> node = {sparkplug::UInt("bdSeq", DataType::kUInt64, bd_seq_),
                                    sparkplug::Bool(kRebirth, false)};
  Send(sparkplug::Topic(MessageType::kNBirth, opt_.sparkplug_group, node_),
       sparkplug::Encode(now_ms, seq_++, node), 0);
  const std::int64_t utc_offset =
      static_cast<std::int64_t>(UtcUs()) - static_cast<std::int64_t>(fw::MonotonicUs());
  std::vector<Metric> device = WrenchMetrics(last_window_, utc_offset);
  sent_ = ExceptionMetrics(ReadState());
  device.insert(device.end(), sent_.begin(), sent_.end());
  for (Metric& m : CommandMetrics()) device.push_back(std::move(m));
  Send(sparkplug::Topic(MessageType::kDBirth, opt_.sparkplug_group, node_, device_),
       sparkplug::Encode(now_ms, seq_++, device), 0);
}

void MqttPublisher::PublishWindow(const WrenchWindow& w) {
  last_window_ = w;
  const std::int64_t utc_offset =
      static_cast<std::int64_t>(UtcUs()) - static_cast<std::int64_t>(fw::MonotonicUs());
  std::vector<Metric> metrics = WrenchMetrics(w, utc_offset);
  const std::vector<Metric> now = ExceptionMetrics(ReadState());
  for (Metric& m : Changed(now, sent_)) metrics.push_back(std::move(m));
  const std::uint8_t seq = seq_;
  if (Send(sparkplug::Topic(MessageType::kDData, opt_.sparkplug_group, node_, device_),
           sparkplug::Encode(UtcUs() / 1000, seq, metrics), 0)) {
    ++seq_;
    sent_ = now;
  } else {
    dropped_.fetch_add(1, std::memory_order_relaxed);
  }
}

void MqttPublisher::Run(const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed)) {
    if (!socket_open_ && fw::MonotonicUs() >= next_attempt_us_) Connect();
    if (socket_open_) {
      const int rc = mosquitto_loop(mosq_, 5, 1);
      if (rc != MOSQ_ERR_SUCCESS && socket_open_) Disconnected();
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (connected_ && birth_due_) PublishBirth();
    std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    while (tail != head_.load(std::memory_order_acquire)) {
      const WrenchWindow w = queue_[tail % kQueueSize];
      tail_.store(++tail, std::memory_order_release);
      if (connected_) {
        PublishWindow(w);
      } else {
        last_window_ = w;
        dropped_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    counters_.connected.store(connected_ ? 1 : 0, std::memory_order_relaxed);
    counters_.published.store(static_cast<std::uint32_t>(published_.load()),
                              std::memory_order_relaxed);
    counters_.dropped.store(static_cast<std::uint32_t>(dropped_.load()), std::memory_order_relaxed);
    counters_.reconnects.store(reconnects_.load(), std::memory_order_relaxed);
  }
  if (connected_) {  // a clean stop: the death certificate now, not at the broker's timeout
    const std::vector<std::uint8_t> death = DeathPayload();
    Send(sparkplug::Topic(MessageType::kNDeath, opt_.sparkplug_group, node_), death, 0);
    mosquitto_disconnect(mosq_);
    for (int i = 0; i < 10 && mosquitto_want_write(mosq_); ++i) mosquitto_loop(mosq_, 5, 1);
  }
}

MqttStats MqttPublisher::stats() const {
  MqttStats s;
  s.connected = connected_flag_.load(std::memory_order_relaxed);
  s.published = published_.load(std::memory_order_relaxed);
  s.dropped = dropped_.load(std::memory_order_relaxed);
  s.reconnects = reconnects_.load(std::memory_order_relaxed);
  s.births = births_.load(std::memory_order_relaxed);
  s.commands = commands_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace ftstack::daemon
