#include "daemon/daemon.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "calibration/cal_file.hpp"
#include "calibration/payload_file.hpp"
#include "calibration/slots.hpp"
#include "daemon/hardware_adc.hpp"
#include "daemon/realtime.hpp"
#include "measurement/recording.hpp"

namespace ftstack::daemon {
namespace {

constexpr std::size_t kLogRingCapacity = std::size_t{1} << 15;

void AppendLe(std::string* out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}

/// One calibration slot from a file: fixed-point form for `adc`, CRC of the file's content.
fw::CalSlot SlotFromFile(const std::string& path, const hal::AdcInfo& adc,
                         std::array<double, 6>* rated) {
  const cal::CalFile file = cal::LoadCalFile(path);  // verifies schema and CRC; throws
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  fw::CalSlot slot;
  slot.fixed = cal::ToFixed(file, cal::AdcForDevice(file, adc));
  std::fprintf(stderr, "ftd: calibration %s: input unit %s\n", path.c_str(),
               file.input_unit.c_str());
  slot.crc32 = j.is_discarded() ? FixedFormCrc(slot.fixed) : cal::ContentCrc(j);
  slot.present = true;
  if (rated != nullptr) *rated = file.rated;
  return slot;
}

/// Loads a calibration file into `slot`. A file that cannot be used (missing, corrupt, bad CRC,
/// refused by the fixed-point loader) leaves the slot empty and is reported on stderr in one line
/// naming it (file:line:column for syntax errors): the device still comes up.
void LoadSlot(const std::string& path, const char* name, const hal::AdcInfo& adc, fw::CalSlot* slot,
              std::array<double, 6>* rated) {
  try {
    *slot = SlotFromFile(path, adc, rated);
    if (slot->fixed.invalid_axes != 0) {
      std::fprintf(stderr,
                   "ftd: calibration slot %s (%s) flags axis %s invalid (not calibrated): served "
                   "as NaN / 0 with status bit 10\n",
                   name, path.c_str(), cal::AxisList(slot->fixed.invalid_axes).c_str());
    }
  } catch (const std::exception& e) {
    *slot = fw::CalSlot{};
    std::fprintf(stderr, "ftd: calibration slot %s refused: %s\n", name, e.what());
  }
}

/// Loads `path` as gravity compensation's payload into `cfg`; a refused file stops ftd (FtdError):
/// unlike a calibration, a robot relying on compensation must not run with none.
void LoadPayload(const std::string& path, fw::DeviceConfig* cfg) {
  cal::PayloadFile p;
  try {
    p = cal::LoadPayloadFile(path);
  } catch (const std::exception& e) {
    throw FtdError(std::string("--payload refused: ") + e.what());
  }
  if (fw::MakeFixedPayload(p.mass_kg, p.com_m, p.force_bias_n, p.moment_bias_nm, &cfg->payload) !=
      fw::PayloadStatus::kOk) {
    throw FtdError("--payload " + path + ": outside what the firmware accepts (0 < mass ≤ " +
                   std::to_string(fw::kMaxPayloadMassKg) + " kg, |m·c| ≤ 100 kg·m)");
  }
  cfg->payload_crc = p.crc32;
  std::fprintf(stderr,
               "ftd: payload %s: %.4g kg at (%.1f, %.1f, %.1f) mm; gravity compensation off "
               "until holding 28 = 1\n",
               path.c_str(), p.mass_kg, p.com_m[0] * 1e3, p.com_m[1] * 1e3, p.com_m[2] * 1e3);
}

/// A hardware converter (HX711 over GPIO, ADS131M over SPI); needs a calibration file.
class HardwareBackend final : public AdcBackend {
 public:
  HardwareBackend(std::unique_ptr<hal::Adc> adc, std::uint8_t channels)
      : adc_(std::move(adc)), channels_(channels) {}
  hal::Adc& adc() override { return *adc_; }
  [[nodiscard]] std::uint8_t channel_count() const override { return channels_; }

 private:
  std::unique_ptr<hal::Adc> adc_;
  std::uint8_t channels_;
};

std::unique_ptr<AdcBackend> MakeHardwareBackend(const FtdOptions& opt) {
  constexpr std::uint8_t kChannels = 6;
  std::string error;
  HardwareAdcOptions hw{opt.adc, opt.gpiochip, opt.spidev, kChannels};
  std::unique_ptr<hal::Adc> adc = MakeHardwareAdc(hw, &error);
  if (adc == nullptr) throw FtdError(error);
  return std::make_unique<HardwareBackend>(std::move(adc), kChannels);
}

}  // namespace

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

std::uint32_t FixedFormCrc(const fw::FixedCalibration& cal) {
  std::string bytes;
  AppendLe(&bytes, cal.channel_count, 1);
  for (std::size_t r = 0; r < fw::kAxes; ++r) {
    for (std::size_t c = 0; c < cal.channel_count; ++c) {
      AppendLe(&bytes, static_cast<std::uint64_t>(cal.coef[r][c]), 8);
    }
    AppendLe(&bytes, static_cast<std::uint64_t>(cal.bias[r]), 8);
    AppendLe(&bytes, cal.shift[r], 1);
  }
  AppendLe(&bytes, static_cast<std::uint32_t>(cal.min_counts), 4);
  AppendLe(&bytes, static_cast<std::uint32_t>(cal.max_counts), 4);
  return cal::Crc32(bytes);
}

Ftd::Ftd(FtdOptions options, SimulatorFactory simulator)
    : opt_(std::move(options)), simulator_(simulator) {}

Ftd::~Ftd() { Stop(); }

char Ftd::ResolveSlotDirectory() {
  const cal::CalSlots slots(opt_.cal_dir);
  opt_.cal = slots.SlotPath('A');
  opt_.cal_b = std::filesystem::exists(slots.SlotPath('B')) ? slots.SlotPath('B') : "";
  char slot = 0;
  std::string note;
  try {
    (void)slots.LoadActive(&slot, &note);
  } catch (const cal::CalFileError& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return 0;
  }
  if (!note.empty()) std::fprintf(stderr, "ftd: %s: %s\n", opt_.cal_dir.c_str(), note.c_str());
  return slot;
}

void Ftd::Start() {
  if (running_) return;
  char dir_slot = 0;  // with --cal-dir: the slot the directory makes active ('A', 'B'; 0: none)
  if (!opt_.cal_dir.empty()) dir_slot = ResolveSlotDirectory();
  try {
    if (opt_.adc == "sim") {
      if (simulator_ == nullptr) {
        throw FtdError("this ftd was built for a board without the simulator; use --adc hx711|spi");
      }
      backend_ = simulator_(opt_);
    } else {
      backend_ = MakeHardwareBackend(opt_);
      if (opt_.cal.empty()) throw FtdError("--adc " + opt_.adc + " needs --cal CAL.json");
    }
  } catch (const FtdError&) {
    throw;
  } catch (const std::exception& e) {
    throw FtdError(e.what());
  }
  hal::Adc& adc = backend_->adc();

  fw::DeviceConfig cfg;
  cfg.adc.channel_count = backend_->channel_count();
  cfg.adc.rate_hz = opt_.rate_hz;
  cfg.adc.gain = backend_->gain();
  // Configure once to learn the ADC's scaling, which the fixed-point calibration is made for.
  if (const hal::Status s = adc.Configure(cfg.adc); s != hal::Status::kOk) {
    throw FtdError(std::string("ADC configuration failed: ") + hal::ToString(s));
  }
  const hal::AdcInfo info = adc.Info();
  std::array<double, 6> rated{};
  std::array<double, 6> rated_b{};
  if (opt_.cal.empty()) {
    try {
      const std::optional<cal::CalFile> builtin = backend_->BuiltinCalibration(info);
      if (!builtin) throw FtdError("--adc " + opt_.adc + " needs --cal CAL.json");
      cfg.slots[0].fixed = cal::ToFixed(*builtin, info);
      cfg.slots[0].crc32 = FixedFormCrc(cfg.slots[0].fixed);
      cfg.slots[0].present = true;
      rated = builtin->rated;
    } catch (const FtdError&) {
      throw;
    } catch (const std::exception& e) {
      throw FtdError(e.what());
    }
  } else {
    LoadSlot(opt_.cal, "A", info, &cfg.slots[0], &rated);
  }
  if (!opt_.cal_b.empty()) LoadSlot(opt_.cal_b, "B", info, &cfg.slots[1], &rated_b);
  // A field device comes up whatever its calibration files hold: on slot A if it is valid, else
  // on a valid slot B (and says so), else without calibration (status bit 4, wrench invalid).
  cfg.allow_uncalibrated = true;
  if (dir_slot == 'B' && cfg.slots[1].present) {
    cfg.initial_slot = 1;
    rated = rated_b;
    std::fprintf(stderr, "ftd: running on calibration slot B (%s, active in %s)\n",
                 opt_.cal_b.c_str(), opt_.cal_dir.c_str());
  } else if (!cfg.slots[0].present && cfg.slots[1].present) {
    cfg.initial_slot = 1;
    rated = rated_b;
    std::fprintf(stderr, "ftd: running on calibration slot B (%s)\n", opt_.cal_b.c_str());
  } else if (!cfg.slots[0].present) {
    std::fprintf(stderr,
                 "ftd: no valid calibration: serving with status bit 4 set and the wrench "
                 "registers invalid\n");
  }
  for (std::size_t i = 0; i < fw::kAxes; ++i) {
    const double lsb = rated[i] / fw::AxisLsb(i);
    if (!std::isfinite(lsb) || lsb < 0 || lsb > fw::kMaxRatedLsb) {
      throw FtdError("calibration's rated range of axis " + std::to_string(i) + " is unusable");
    }
    cfg.rated_lsb[i] = static_cast<std::int32_t>(std::llround(lsb));
  }
  bool any_zero = false;
  for (const std::int32_t r : cfg.rated_lsb) any_zero = any_zero || r == 0;
  if (any_zero) cfg.rated_lsb = {};  // no complete rating: overload rule off

  if (!opt_.payload.empty()) LoadPayload(opt_.payload, &cfg);

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

  if (!opt_.modbus_tcp.empty()) {
    std::string host;
    std::uint16_t port = 0;
    ParseHostPort(opt_.modbus_tcp, &host, &port);
    tcp_ = std::make_unique<fw::ModbusTcpServer>(*map_);
    const fw::ServerStatus s =
        tcp_->Open(host.c_str(), port, static_cast<std::uint8_t>(opt_.unit_id));
    if (s != fw::ServerStatus::kOk) {
      throw FtdError("Modbus TCP on " + opt_.modbus_tcp + ": " + fw::ToString(s));
    }
  }
  if (!opt_.modbus_rtu.empty()) {
    rtu_ = std::make_unique<fw::ModbusRtuServer>(*map_);
    const fw::ServerStatus s = rtu_->Open(opt_.modbus_rtu.c_str(), static_cast<int>(opt_.baud),
                                          opt_.parity, static_cast<std::uint8_t>(opt_.unit_id));
    if (s != fw::ServerStatus::kOk) {
      throw FtdError("Modbus RTU on " + opt_.modbus_rtu + ": " + fw::ToString(s) + " (" +
                     std::system_category().message(errno) + ")");
    }
  }
  if (!opt_.rdt.empty()) StartRdt();
  if (!opt_.log.empty()) PrepareLog();

  stop_ = false;
  start_us_ = fw::MonotonicUs();
  stop_us_ = 0;
  running_ = true;
  // Memory first (before the threads' stacks), then the sampling thread's policy; one line says
  // what the system granted. A benchmark run (--unpaced) never asks: it would hog a core.
  const std::string memory = opt_.paced ? LockMemory() : "memory not locked (--unpaced)";
  threads_.emplace_back([this] { SamplingLoop(); });
  pthread_setname_np(threads_.back().native_handle(), "ftd-sampler");
  bool rt = false;
  const std::string sched = opt_.paced ? MakeRealtime(threads_.back().native_handle(), &rt)
                                       : "default scheduler (--unpaced)";
  realtime_ = "sampling thread: " + sched + ", " + memory;
  std::fprintf(stderr, "ftd: %s%s\n", realtime_.c_str(),
               rt ? "" : " — samples may be late under load (late_samples counts them)");
  if (tcp_) threads_.emplace_back([this] { tcp_->Run(stop_); });
  if (rtu_) threads_.emplace_back([this] { rtu_->Run(stop_); });
  if (rdt_) threads_.emplace_back([this] { rdt_->Run(stop_); });
}

void Ftd::PrepareLog() {
  std::FILE* f = std::fopen(opt_.log.c_str(), "w");
  if (f == nullptr) {
    throw FtdError(opt_.log + ": cannot write: " + std::system_category().message(errno));
  }
  std::fclose(f);
  ring_.resize(kLogRingCapacity);
}

void Ftd::StartRdt() {
  RdtOptions ro;
  try {
    ParseHostPort(opt_.rdt, &ro.host, &ro.port);
  } catch (const FtdError& e) {  // its message names --modbus-tcp
    const std::string m = e.what();
    throw FtdError("--rdt" + m.substr(m.find(' ')));
  }
  if (!(opt_.rdt_counts_per_n > 0) || !(opt_.rdt_counts_per_nm > 0) ||
      !std::isfinite(opt_.rdt_counts_per_n) || !std::isfinite(opt_.rdt_counts_per_nm)) {
    throw FtdError("--rdt-counts-per-n and --rdt-counts-per-nm must be positive");
  }
  ro.counts_per_n = opt_.rdt_counts_per_n;
  ro.counts_per_nm = opt_.rdt_counts_per_nm;
  ro.buffer_records = opt_.rdt_buffer;
  ro.status_mask = opt_.rdt_status_mask;
  rdt_ = std::make_unique<RdtServer>(ro, map_.get());
  std::string error;
  if (!rdt_->Open(&error)) throw FtdError("RDT on " + opt_.rdt + ": " + error);
  std::fprintf(stderr, "ftd: serving RDT on %s:%u (%g counts/N, %g counts/N·m)\n", ro.host.c_str(),
               static_cast<unsigned>(rdt_->port()), ro.counts_per_n, ro.counts_per_nm);
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
    if (published && rdt_) rdt_->Publish(device_->last_published());
    if (!published || ring_.empty()) continue;
    const std::uint64_t head = ring_head_.load(std::memory_order_relaxed);
    if (head - ring_tail_.load(std::memory_order_acquire) >= ring_.size()) {
      log_dropped_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    ring_[head % ring_.size()] = device_->last_published();
    ring_head_.store(head + 1, std::memory_order_release);
  }
}

void Ftd::DrainLog() {
  if (ring_.empty()) return;
  const std::uint64_t head = ring_head_.load(std::memory_order_acquire);
  std::uint64_t tail = ring_tail_.load(std::memory_order_relaxed);
  if (tail == head) return;
  const hal::AdcInfo& adc = device_->adc_info();
  const double mvv_per_count =
      adc.max_counts > 0 ? static_cast<double>(adc.full_scale_nvv) * 1e-6 / adc.max_counts : 0.0;
  std::vector<double> row;
  for (; tail != head; ++tail) {
    const fw::DeviceSample& d = ring_[tail % ring_.size()];
    const fw::PublishedSample& s = d.sample;
    if (!writer_) {
      std::vector<std::string> names{"t"};
      for (std::size_t c = 0; c < s.channel_count; ++c) names.push_back("b" + std::to_string(c));
      for (std::size_t c = 0; c < s.channel_count; ++c) names.push_back("raw" + std::to_string(c));
      for (const std::string& n : WrenchColumns()) names.push_back(n);
      if (s.has_temperature) names.push_back("temp_C");
      names.push_back("status");
      std::vector<std::string> meta{"source: ftd", "adc: " + opt_.adc,
                                    "rate_hz: " + std::to_string(opt_.rate_hz),
                                    "wrench: measured (tool frame), N and N·m"};
      writer_ = std::make_unique<RecordingWriter>(opt_.log, meta, names);
      log_started_ = true;
    }
    if (log_started_ && logged_rows_ > 0 && s.timestamp_us < last_log_timestamp_us_) {
      log_time_base_us_ += std::uint64_t{1} << 32;  // the 32-bit µs timestamp wrapped
    }
    last_log_timestamp_us_ = s.timestamp_us;
    row.clear();
    row.push_back(static_cast<double>(log_time_base_us_ + s.timestamp_us) * 1e-6);
    for (std::size_t c = 0; c < s.channel_count; ++c) {
      row.push_back(s.raw_counts[c] * mvv_per_count);
    }
    for (std::size_t c = 0; c < s.channel_count; ++c) row.push_back(s.raw_counts[c]);
    for (std::size_t i = 0; i < fw::kAxes; ++i) row.push_back(s.wrench[i] * fw::AxisLsb(i));
    if (s.has_temperature) row.push_back(s.temperature_mdegc * 1e-3);
    row.push_back(s.status);
    writer_->WriteRow(row);
    ++logged_rows_;
    last_logged_sequence_ = s.sequence;
  }
  ring_tail_.store(tail, std::memory_order_release);
}

void Ftd::Stop() {
  if (!running_) return;
  stop_ = true;
  stop_us_ = fw::MonotonicUs();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  running_ = false;
  DrainLog();
  if (writer_) writer_->Flush();
}

std::uint16_t Ftd::tcp_port() const { return tcp_ ? tcp_->port() : 0; }

const fw::ServerCounters* Ftd::tcp_counters() const { return tcp_ ? &tcp_->counters() : nullptr; }

FtdStats Ftd::stats() const {
  FtdStats s;
  s.samples = samples_.load(std::memory_order_relaxed);
  const std::uint64_t end_us = stop_us_ != 0 ? stop_us_ : fw::MonotonicUs();
  s.elapsed_s = static_cast<double>(end_us - start_us_) * 1e-6;
  s.logged_rows = logged_rows_;
  s.log_dropped = log_dropped_.load(std::memory_order_relaxed);
  s.sampling_ended = ended_.load(std::memory_order_relaxed);
  s.adc_errors = adc_errors_.load(std::memory_order_relaxed);
  s.backoffs = backoffs_.load(std::memory_order_relaxed);
  s.realtime = realtime_;
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
  if (tcp_) {
    line += "  tcp " + std::to_string(tcp_->counters().requests.load()) + " req";
  }
  return line;
}

}  // namespace ftstack::daemon
