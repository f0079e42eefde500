#include "daemon/daemon.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "calibration/file/cal_file.hpp"
#include "daemon/hardware_adc.hpp"
#include "daemon/realtime.hpp"
#include "daemon/replay_backend.hpp"

namespace ftstack::daemon {

void ParseHostPort(const std::string& text, std::string* host, std::uint16_t* port) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    throw FtdError("--modbus-tcp '" + text + "': expected HOST:PORT");
  }
  const std::string p = text.substr(colon + 1);
  std::size_t used = 0;
  long v = -1;
  try {
    v = std::stol(p, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != p.size() || v < 0 || v > 65535) {
    throw FtdError("--modbus-tcp '" + text + "': port '" + p + "' is not 0 … 65535");
  }
  *host = text.substr(0, colon);
  *port = static_cast<std::uint16_t>(v);
}

std::pair<std::string, std::string> ReadCredentialsFile(const std::string& option,
                                                        const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FtdError(option + " " + path + ": cannot be read");
  std::string user, password;
  std::getline(in, user);
  std::getline(in, password);
  for (std::string* s : {&user, &password}) {
    if (!s->empty() && s->back() == '\r') s->pop_back();
  }
  if (user.empty()) throw FtdError(option + " " + path + ":1: no user name");
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 && (st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    std::fprintf(stderr, "ftd: warning: %s %s is readable by others (chmod 600)\n", option.c_str(),
                 path.c_str());
  }
  return {user, password};
}

Ftd::Ftd(FtdOptions options, SimulatorFactory simulator)
    : opt_(std::move(options)), simulator_(simulator) {}

Ftd::~Ftd() { Stop(); }

void Ftd::MakeBackend() {
  try {
    if (opt_.adc == "sim") {
      if (simulator_ == nullptr) {
        throw FtdError("this ftd was built for a board without the simulator; use --adc hx711|spi");
      }
      backend_ = simulator_(opt_);
    } else if (opt_.adc == "replay") {
      backend_ = MakeReplayBackend(opt_);
    } else {
      backend_ = MakeHardwareBackend(opt_);
      if (opt_.cal.empty()) throw FtdError("--adc " + opt_.adc + " needs --cal CAL.json");
    }
  } catch (const FtdError&) {
    throw;
  } catch (const std::exception& e) {
    throw FtdError(e.what());
  }
}

void Ftd::Start() {
  if (running_) return;
  char dir_slot = 0;  // with --cal-dir: the slot the directory makes active ('A', 'B'; 0: none)
  if (!opt_.cal_dir.empty()) dir_slot = ResolveSlotDirectory(&opt_);
  MakeBackend();
  hal::Adc& adc = backend_->adc();

  fw::DeviceConfig cfg;
  cfg.adc.channel_count = backend_->channel_count();
  cfg.adc.rate_hz = opt_.rate_hz;
  cfg.adc.gain = backend_->gain();
  // Configure once to learn the ADC's scaling, which the fixed-point calibration is made for.
  if (const hal::Status s = adc.Configure(cfg.adc); s != hal::Status::kOk) {
    throw FtdError(std::string("ADC configuration failed: ") + hal::ToString(s));
  }
  LoadCalibrationSet(opt_, dir_slot, *backend_, adc.Info(), &cfg);
  if (!opt_.payload.empty()) LoadPayload(opt_.payload, &cfg);
  cfg.health_watch = opt_.health_watch;

  core_ = std::make_unique<fw::WrenchCore>();
  device_ = std::make_unique<fw::Device>(adc, *core_);
  switch (device_->Start(cfg)) {
    case fw::DeviceStatus::kOk:
      break;
    case fw::DeviceStatus::kAdcConfig:
      throw FtdError("ADC configuration failed");
    case fw::DeviceStatus::kNoCalibration:
      throw FtdError("no calibration in the initial slot");
    case fw::DeviceStatus::kBadRated:
      throw FtdError("rated range outside what the overload rule accepts");
  }
  map_ = std::make_unique<fw::RegisterMap>(*device_);
  servers_.Open(opt_, *map_);
  if (!opt_.mqtt.empty()) {
    const std::uint8_t slot = cfg.initial_slot;
    mqtt_ = std::make_unique<MqttPublisher>(opt_, map_.get(),
                                            DefaultDeviceId(opt_, slot, cfg.slots[slot].crc32));
    mqtt_->Open();
    map_->SetMqttCounters(&mqtt_->counters());
  }
  if (!opt_.http.empty()) OpenHttp(cfg);
  if (!opt_.opcua.empty()) OpenOpcua(cfg);
  if (!opt_.log.empty()) {
    // The paced simulator stamps wall-clock conversion times (n / (rate · speed)): scaled by
    // the speed, the log's t is the simulated time the samples were composed at.
    const bool sim_paced = opt_.adc == "sim" && opt_.paced && opt_.sim_speed > 0;
    log_.Open(opt_.log,
              {"source: ftd", "adc: " + opt_.adc, "rate_hz: " + std::to_string(opt_.rate_hz),
               "wrench: measured (tool frame), N and N·m"},
              sim_paced ? opt_.sim_speed : 1.0);
  }
  StartThreads();
}

void Ftd::StartThreads() {
  stop_ = false;
  start_us_ = fw::MonotonicUs();
  stop_us_ = 0;
  running_ = true;
  // Memory first (before the threads' stacks), then the sampling thread's policy; one line says
  // what the system granted. A benchmark run (--unpaced) never asks: it would hog a core.
  const std::string memory = opt_.paced ? LockMemory() : "memory not locked (--unpaced)";
  if (!SizeThreadStacks()) std::fprintf(stderr, "ftd: thread stacks keep the default size\n");
  threads_.emplace_back([this] { SamplingLoop(); });
  pthread_setname_np(threads_.back().native_handle(), "ftd-sampler");
  bool rt = false;
  const std::string sched = opt_.paced ? MakeRealtime(threads_.back().native_handle(), &rt)
                                       : "default scheduler (--unpaced)";
  realtime_ = "sampling thread: " + sched + ", " + memory;
  std::fprintf(stderr, "ftd: %s%s\n", realtime_.c_str(),
               rt ? "" : " — samples may be late under load (late_samples counts them)");
  servers_.Spawn(&threads_, stop_);
  if (mqtt_) {
    threads_.emplace_back([this] { mqtt_->Run(stop_); });
    pthread_setname_np(threads_.back().native_handle(), "ftd-mqtt");
  }
  if (http_) {
    threads_.emplace_back([this] { http_->Run(stop_); });
    pthread_setname_np(threads_.back().native_handle(), "ftd-http");
  }
  if (opcua_) {
    threads_.emplace_back([this] { opcua_->Run(stop_); });
    pthread_setname_np(threads_.back().native_handle(), "ftd-opcua");
  }
}

void Ftd::OpenHttp(const fw::DeviceConfig& cfg) {
  WebStaticInfo info;
  for (std::size_t i = 0; i < 6; ++i) {
    info.rated[i] = static_cast<double>(cfg.rated_lsb[i]) * fw::AxisLsb(i);
  }
  const std::string files[2] = {opt_.cal, opt_.cal_b};
  for (std::size_t k = 0; k < 2; ++k) {
    WebCalLabel& l = info.slots[k];
    l.present = cfg.slots[k].present;
    if (!l.present) continue;
    l.file = files[k];
    if (files[k].empty()) {
      l.serial = "built-in (" + opt_.adc + ")";
      continue;
    }
    try {
      const cal::CalFile f = cal::LoadCalFile(files[k]);
      l.serial = f.serial;
      l.date = f.date;
    } catch (const std::exception&) {
      l.serial = "unknown";  // the slot loaded it a moment ago; a file changed since is not fatal
    }
  }
  info.rate_hz = opt_.rate_hz;
  info.adc = opt_.adc;
  http_ = std::make_unique<HttpServer>(opt_, map_.get(), std::move(info),
                                       [this] { return WebRuntime(); });
  http_->Open();
  const unsigned port = http_->port();
  std::fprintf(stderr, "ftd: serving the web page on %s:%u — open %s://%s:%u/\n",
               http_->host().c_str(), port, http_->tls() ? "https" : "http", http_->host().c_str(),
               port);
}

void Ftd::OpenOpcua(const fw::DeviceConfig& cfg) {
  OpcuaDeviceInfo info;
  for (std::size_t i = 0; i < 6; ++i) {
    info.rated[i] = static_cast<double>(cfg.rated_lsb[i]) * fw::AxisLsb(i);
  }
  const std::uint8_t slot = cfg.initial_slot;
  const std::string file = slot == 0 ? opt_.cal : opt_.cal_b;
  info.cal_crc = cfg.slots[slot].crc32;
  info.serial = "built-in (" + opt_.adc + ")";
  if (!file.empty()) {
    try {
      const cal::CalFile f = cal::LoadCalFile(file);
      info.serial = f.serial;
      info.cal_date = f.date;
    } catch (const std::exception&) {
      info.serial =
          "unknown";  // the slot loaded it a moment ago; a file changed since is not fatal
    }
  }
  info.adc = opt_.adc;
  info.rate_hz = opt_.rate_hz;
  opcua_ = std::make_unique<OpcuaServer>(opt_, map_.get(), std::move(info));
  opcua_->Open();
  std::fprintf(stderr, "ftd: serving OPC UA on opc.tcp://%s:%u (%s)\n", opcua_->host().c_str(),
               static_cast<unsigned>(opcua_->port()),
               opcua_->secure() ? "Basic256Sha256 Sign&Encrypt" : "security None, loopback");
}

nlohmann::json Ftd::WebRuntime() const {
  const FtdStats st = stats();
  nlohmann::json j = {
      {"sample_rate_hz", st.elapsed_s > 0 ? static_cast<double>(st.samples) / st.elapsed_s : 0.0},
      {"samples", st.samples},
      {"late_samples", st.late_samples},
      {"adc_errors", st.adc_errors},
      {"uptime_s", st.elapsed_s}};
  nlohmann::json clients = nlohmann::json::object();
  if (const fw::ServerCounters* c = servers_.tcp_counters()) {
    clients["modbus_tcp"] = {{"connections_accepted", c->connections.load()},
                             {"requests", c->requests.load()},
                             {"exceptions", c->exceptions.load()}};
  }
  if (const RdtServer* r = servers_.rdt()) {
    const RdtStats rs = r->stats();
    clients["rdt"] = {{"requests", rs.requests}, {"packets_sent", rs.packets_sent}};
  }
  if (mqtt_) {
    const MqttStats ms = mqtt_->stats();
    clients["mqtt"] = {{"connected", ms.connected}, {"published", ms.published}};
  }
  j["clients"] = clients;
  return j;
}

void Ftd::BackOff(std::uint32_t pause_us) {
  // In slices, so that Stop() is not kept waiting for a whole pause.
  const std::uint64_t until = fw::MonotonicUs() + pause_us;
  for (std::uint64_t now = fw::MonotonicUs(); now < until && !stop_.load(std::memory_order_relaxed);
       now = fw::MonotonicUs()) {
    const std::uint64_t slice = std::min<std::uint64_t>(until - now, 10000);
    timespec ts{static_cast<time_t>(slice / 1000000), static_cast<long>(slice % 1000000) * 1000};
    nanosleep(&ts, nullptr);
  }
}

void Ftd::SamplingLoop() {
  bool published = false;
  const std::uint32_t period_us = device_->sample_period_us();
  std::uint32_t backoff_us = 0;
  RdtServer* const rdt = servers_.rdt();
  MqttPublisher* const mqtt = mqtt_.get();
  while (!stop_.load(std::memory_order_relaxed)) {
    const std::uint64_t t0 = fw::MonotonicUs();
    const hal::Status s = device_->Step(&published);
    if (s == hal::Status::kEndOfData || s == hal::Status::kNotConfigured ||
        s == hal::Status::kUnavailable) {
      ended_ = true;
      return;
    }
    if (s != hal::Status::kOk) {
      // The step published the fault (bit 3, and bit 8 once no sample comes); an error that
      // returns at once must not turn this loop into a busy one: pause, doubling from one
      // period up to kMaxBackoffUs, until a step succeeds.
      adc_errors_.fetch_add(1, std::memory_order_relaxed);
      if (fw::MonotonicUs() - t0 < period_us) {
        backoff_us = backoff_us == 0 ? std::max<std::uint32_t>(period_us, 1)
                                     : std::min(2 * backoff_us, kMaxBackoffUs);
        backoffs_.fetch_add(1, std::memory_order_relaxed);
        BackOff(backoff_us);
      }
      continue;
    }
    backoff_us = 0;
    samples_.fetch_add(1, std::memory_order_relaxed);
    if (!published) continue;
    if (rdt != nullptr) rdt->Publish(device_->last_published());
    if (mqtt != nullptr) mqtt->Push(device_->last_published());
    log_.Push(device_->last_published());
  }
}

void Ftd::DrainLog() {
  if (log_.enabled()) log_.Drain(device_->adc_info());
}

void Ftd::Stop() {
  if (!running_) return;
  stop_ = true;
  stop_us_ = fw::MonotonicUs();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  running_ = false;
  DrainLog();
  log_.Flush();
}

std::uint16_t Ftd::tcp_port() const { return servers_.tcp_port(); }

const fw::ServerCounters* Ftd::tcp_counters() const { return servers_.tcp_counters(); }

FtdStats Ftd::stats() const {
  FtdStats s;
  s.samples = samples_.load(std::memory_order_relaxed);
  const std::uint64_t end_us = stop_us_ != 0 ? stop_us_ : fw::MonotonicUs();
  s.elapsed_s = static_cast<double>(end_us - start_us_) * 1e-6;
  s.logged_rows = log_.logged_rows();
  s.log_dropped = log_.dropped();
  s.sampling_ended = ended_.load(std::memory_order_relaxed);
  s.adc_errors = adc_errors_.load(std::memory_order_relaxed);
  s.backoffs = backoffs_.load(std::memory_order_relaxed);
  s.realtime = realtime_;
  fw::DeviceSample d{};
  if (device_ && device_->ReadLatest(&d)) s.late_samples = d.late_samples;
  return s;
}

std::string Ftd::StatusLine() const {
  fw::DeviceSample d{};
  if (!device_ || !device_->ReadLatest(&d)) return "no sample";
  const FtdStats st = stats();
  char buf[256];
  const auto& w = d.sample.wrench;
  std::snprintf(buf, sizeof(buf),
                "seq=%-9u F=[%9.3f %9.3f %9.3f] N  M=[%8.4f %8.4f %8.4f] N·m  status=0x%04x  "
                "%.0f Hz",
                d.sample.sequence, w[0] * fw::kForceLsbN, w[1] * fw::kForceLsbN,
                w[2] * fw::kForceLsbN, w[3] * fw::kMomentLsbNm, w[4] * fw::kMomentLsbNm,
                w[5] * fw::kMomentLsbNm, d.sample.status,
                st.elapsed_s > 0 ? static_cast<double>(st.samples) / st.elapsed_s : 0.0);
  std::string line = buf;
  if (d.health_on) {  // NE 107 state, findings and coverage: bit (cause − 1), as input 100–101, 196
    std::snprintf(buf, sizeof(buf), "  health=%d findings=0x%02x covers=0x%02x",
                  static_cast<int>(d.health.state), d.health.findings, d.health.coverage);
    line += buf;
  }
  if (const fw::ServerCounters* c = servers_.tcp_counters()) {
    line += "  tcp " + std::to_string(c->requests.load()) + " req";
  }
  return line;
}

}  // namespace ftstack::daemon
