// ftd's web API end to end: the real ftd with --http, read with curl (an independent HTTP client)
// and compared with a libmodbus read of the same sample; bad requests, credentials, write
// protection, and a tare over the API recorded in the tare history with source 4 (web).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "firmware/health_registers.hpp"
#include "firmware/register_map.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/mbpoll.hpp"

namespace ftstack {
namespace {

constexpr double kForceLsbN = 0.001;    // input registers 18–23 (int32 mN): one LSB
constexpr double kMomentLsbNm = 0.001;  // the same in mN·m

/// Runs curl; returns the HTTP status and fills `body` (and `headers` when given).
int Curl(const std::string& args, std::string* body, std::string* headers = nullptr) {
  test::TempDir dir;
  const std::string b = (dir.path() / "body").string();
  const std::string h = (dir.path() / "headers").string();
  std::string out;
  test::RunShell("curl -s -m 10 -o " + b + " -D " + h + " -w '%{http_code}' " + args, &out);
  std::ifstream bin(b), hin(h);
  body->assign(std::istreambuf_iterator<char>(bin), {});
  if (headers != nullptr) headers->assign(std::istreambuf_iterator<char>(hin), {});
  try {
    return std::stoi(out);
  } catch (const std::exception&) {
    return -1;
  }
}

class Modbus {
 public:
  explicit Modbus(int port) : ctx_(modbus_new_tcp("127.0.0.1", port)) {
    modbus_set_response_timeout(ctx_, 2, 0);
    ok_ = modbus_connect(ctx_) == 0;
  }
  ~Modbus() {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  bool ok() const { return ok_; }
  bool ReadInput(int addr, int count, std::uint16_t* out) {
    return modbus_read_input_registers(ctx_, addr, count, out) == count;
  }
  bool Write(int addr, std::uint16_t v) { return modbus_write_register(ctx_, addr, v) == 1; }

 private:
  modbus_t* ctx_;
  bool ok_ = false;
};

struct Ftd {
  explicit Ftd(std::vector<std::string> extra) : proc(Args(std::move(extra))) {
    http = proc.ServedPort("the web page");
  }
  static std::vector<std::string> Args(std::vector<std::string> extra) {
    std::vector<std::string> a = {
        "--modbus-tcp", "127.0.0.1:0", "--http",       "127.0.0.1:0",
        "--print-hz",   "0",           "--sim-wrench", "10,-4,-50,0.2,0.5,-0.1"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  std::string Url(const std::string& path) const {
    return "http://127.0.0.1:" + std::to_string(http) + path;
  }
  test::FtdProcess proc;
  int http = -1;
};

TEST(FtdHttp, WrenchMatchesAModbusReadOfTheSameSampleWithinOneLsb) {
  Ftd ftd({});
  ASSERT_GT(ftd.proc.port(), 0) << ftd.proc.Stderr();
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  Modbus mb(ftd.proc.port());
  ASSERT_TRUE(mb.ok());
  // One published sample a second: the API and Modbus can read the same one (same sequence).
  ASSERT_TRUE(mb.Write(fw::kHoldDecimation, 1000));
  int compared = 0;
  for (int attempt = 0; attempt < 20 && compared < 2; ++attempt) {
    std::array<std::uint16_t, 30> regs{};
    ASSERT_TRUE(mb.ReadInput(0, 30, regs.data()));
    std::string body;
    ASSERT_EQ(Curl(ftd.Url("/api/v1/wrench"), &body), 200) << body;
    const nlohmann::json j = nlohmann::json::parse(body);
    if (j["sequence"].get<std::uint32_t>() != fw::UnpackU32(&regs[fw::kInSequence])) continue;
    for (int a = 0; a < 6; ++a) {
      const double lsb = a < 3 ? kForceLsbN : kMomentLsbNm;
      const double modbus_float = fw::UnpackFloat32(&regs[fw::kInWrenchFloat + 2 * a]);
      const double modbus_int = fw::UnpackI32(&regs[fw::kInWrenchInt + 2 * a]) * lsb;
      EXPECT_NEAR(j["wrench_n_nm"][a].get<double>(), modbus_float, lsb) << "axis " << a;
      EXPECT_NEAR(j["wrench_mn_mnm"][a].get<double>() * lsb, modbus_int, lsb) << "axis " << a;
    }
    EXPECT_EQ(j["status"]["bits"].get<int>(), regs[fw::kInStatus]);
    // The applied wrench, as an independent reference (the simulator's noise is far below 1 N).
    EXPECT_NEAR(j["wrench_n_nm"][2].get<double>(), -50.0, 1.0);
    ++compared;
  }
  EXPECT_EQ(compared, 2) << "no API read hit the sample a Modbus read returned";
}

TEST(FtdHttp, CoverageIsInputRegister196CausePerCause) {
  Ftd ftd({});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  Modbus mb(ftd.proc.port());
  ASSERT_TRUE(mb.ok());
  // Under a held load the watch judges some causes within seconds (the tones and the noise floor);
  // the coverage changes at most once a second, so two reads in a row agree between its updates.
  int agreed = 0;
  for (int attempt = 0; attempt < 40 && agreed < 2; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    std::uint16_t before = 0;
    std::uint16_t after = 0;
    ASSERT_TRUE(mb.ReadInput(fw::kInCoverage, 1, &before));
    std::string body;
    ASSERT_EQ(Curl(ftd.Url("/api/v1/wrench"), &body), 200) << body;
    ASSERT_TRUE(mb.ReadInput(fw::kInCoverage, 1, &after));
    if (before != after || before == 0) continue;
    const nlohmann::json h = nlohmann::json::parse(body)["health"];
    EXPECT_EQ(h["coverage_bits"].get<int>(), before);
    ASSERT_EQ(h["coverage"].size(), static_cast<std::size_t>(fw::kHealthCauses));
    for (const auto& c : h["coverage"]) {
      const int cause = c["cause"].get<int>();
      EXPECT_EQ(c["judged_last_hour"].get<bool>(), (before >> (cause - 1) & 1) != 0) << cause;
    }
    ++agreed;
  }
  EXPECT_EQ(agreed, 2) << "the watch judged nothing, or the API never matched input 196";
}

TEST(FtdHttp, UnknownPathsWrongMethodsAndBadBodiesAreRefusedWithoutDisturbingSampling) {
  Ftd ftd({});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  Modbus mb(ftd.proc.port());
  ASSERT_TRUE(mb.ok());
  std::array<std::uint16_t, 2> late0{};
  ASSERT_TRUE(mb.ReadInput(fw::kInLateSamples, 2, late0.data()));
  std::string body, headers;
  EXPECT_EQ(Curl(ftd.Url("/no/such/page"), &body), 404);
  EXPECT_EQ(Curl(ftd.Url("/api/v2/state"), &body), 404);
  EXPECT_EQ(Curl("-X DELETE " + ftd.Url("/api/v1/state"), &body, &headers), 405);
  EXPECT_NE(headers.find("Allow: GET"), std::string::npos) << headers;
  EXPECT_EQ(Curl(ftd.Url("/api/v1/command"), &body, &headers), 405);  // GET on a POST path
  EXPECT_NE(headers.find("Allow: POST"), std::string::npos) << headers;
  EXPECT_EQ(Curl("-X POST -d '{\"command\":' " + ftd.Url("/api/v1/command"), &body), 400);
  EXPECT_EQ(Curl("-X POST -d '{\"command\":\"explode\"}' " + ftd.Url("/api/v1/command"), &body),
            400);
  EXPECT_NE(body.find("unknown command"), std::string::npos) << body;
  EXPECT_EQ(Curl("-X POST -d '{\"filter_length\":0}' " + ftd.Url("/api/v1/settings"), &body), 422);
  EXPECT_EQ(Curl("'" + ftd.Url("/api/v1/stream?rate_hz=1000") + "'", &body), 400);
  // 64 kB body: refused by size before it is parsed.
  std::string out;
  test::RunShell(
      "head -c 65536 /dev/zero | tr '\\0' x | curl -s -m 10 -o /dev/null -w "
      "'%{http_code}' -X POST --data-binary @- " +
          ftd.Url("/api/v1/command"),
      &out);
  EXPECT_EQ(out, "413");
  // Requests that are not HTTP: refused with 400, or the connection closed without a reply (the
  // library does either, depending on when it sees the client's half-close); never served.
  const std::string sock = " | timeout 5 socat -t 2 - TCP:127.0.0.1:" + std::to_string(ftd.http);
  for (const char* req : {"GARBAGE / HTTP/1.1\\r\\nHost: x\\r\\n\\r\\n", "GARBAGE\\r\\n\\r\\n",
                          "GET /api/v1/state HTTP/9.9\\r\\n\\r\\n"}) {
    test::RunShell(std::string("printf '") + req + "'" + sock, &out);
    EXPECT_TRUE(out.empty() || out.rfind("HTTP/1.1 400", 0) == 0) << req << ": " << out;
  }
  // Sampling went on, not stale, and the page still answers.
  EXPECT_EQ(Curl(ftd.Url("/api/v1/wrench"), &body), 200);
  std::array<std::uint16_t, 2> status{};
  ASSERT_TRUE(mb.ReadInput(fw::kInStatus, 1, status.data()));
  EXPECT_EQ(status[0] & 0x0100, 0) << "stale";
  EXPECT_TRUE(ftd.proc.alive());
}

TEST(FtdHttp, WrongCredentialsGet401RightOnesGetThrough) {
  test::TempDir dir;
  const std::string cred = (dir.path() / "web.cred").string();
  std::ofstream(cred) << "operator\ns3cret:pw\n";
  chmod(cred.c_str(), 0600);
  Ftd ftd({"--http-credentials", cred});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  std::string body, headers;
  EXPECT_EQ(Curl(ftd.Url("/api/v1/state"), &body, &headers), 401);
  EXPECT_NE(headers.find("WWW-Authenticate: Basic"), std::string::npos) << headers;
  EXPECT_EQ(Curl("-u operator:wrong " + ftd.Url("/api/v1/state"), &body), 401);
  EXPECT_EQ(Curl("-u operator:s3cret " + ftd.Url("/api/v1/state"), &body), 401);
  EXPECT_EQ(Curl("-u other:s3cret:pw " + ftd.Url("/"), &body), 401);
  EXPECT_EQ(
      Curl("-X POST -d '{\"command\":\"tare\"}' -u operator:wrong " + ftd.Url("/api/v1/command"),
           &body),
      401);
  EXPECT_EQ(Curl("-u operator:s3cret:pw " + ftd.Url("/api/v1/state"), &body), 200);
  EXPECT_EQ(Curl("-u operator:s3cret:pw " + ftd.Url("/"), &body), 200);
  EXPECT_NE(body.find("<title>"), std::string::npos);
}

TEST(FtdHttp, WriteProtectedSensorRefusesTareAndSaysSo) {
  Ftd ftd({"--http-write-protect"});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  Modbus mb(ftd.proc.port());
  ASSERT_TRUE(mb.ok());
  std::string body;
  EXPECT_EQ(Curl("-X POST -d '{\"command\":\"tare\"}' " + ftd.Url("/api/v1/command"), &body), 403);
  EXPECT_NE(body.find("write-protected"), std::string::npos) << body;
  EXPECT_EQ(Curl("-X POST -d '{\"filter_length\":8}' " + ftd.Url("/api/v1/settings"), &body), 403);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::array<std::uint16_t, 1> tares{};
  ASSERT_TRUE(mb.ReadInput(fw::kInTareCount, 1, tares.data()));
  EXPECT_EQ(tares[0], 0);
  std::array<std::uint16_t, 2> status{};
  ASSERT_TRUE(mb.ReadInput(fw::kInStatus, 1, status.data()));
  EXPECT_EQ(status[0] & 0x0020, 0) << "tare active";
  EXPECT_EQ(Curl(ftd.Url("/api/v1/state"), &body), 200);  // reading still works
}

TEST(FtdHttp, TareOverTheApiZeroesAndIsRecordedWithSourceWeb) {
  Ftd ftd({});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  Modbus mb(ftd.proc.port());
  ASSERT_TRUE(mb.ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::string body;
  ASSERT_EQ(Curl("-X POST -H 'Content-Type: application/json' -d '{\"command\":\"tare\"}' " +
                     ftd.Url("/api/v1/command"),
                 &body),
            200)
      << body;
  std::array<std::uint16_t, fw::kTareRecordRegisters> rec{};
  for (int i = 0; i < 100 && fw::UnpackU32(rec.data()) == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_TRUE(mb.ReadInput(fw::kInTareHistory, fw::kTareRecordRegisters, rec.data()));
  }
  EXPECT_EQ(fw::UnpackU32(rec.data()), 1u);
  EXPECT_EQ(rec[2], 4) << "tare source (4 = web)";
  EXPECT_NEAR(fw::UnpackFloat32(&rec[8 + 2 * 2]), -50.0, 1.0) << "Fz the tare removed";
  std::array<std::uint16_t, 12> w{};
  ASSERT_TRUE(mb.ReadInput(fw::kInWrenchFloat, 12, w.data()));
  EXPECT_NEAR(fw::UnpackFloat32(&w[4]), 0.0, 0.5) << "Fz after the tare";
  // The API's history says the same in words.
  ASSERT_EQ(Curl(ftd.Url("/api/v1/state"), &body), 200);
  const nlohmann::json j = nlohmann::json::parse(body);
  ASSERT_EQ(j["tare_history"].size(), 1u);
  EXPECT_EQ(j["tare_history"][0]["source"], "web");
  EXPECT_EQ(j["runtime"]["http"]["writes"], 1);
}

TEST(FtdHttp, HttpsWithACertificateAndKey) {
  test::TempDir dir;
  const std::string cert = (dir.path() / "cert.pem").string();
  const std::string key = (dir.path() / "key.pem").string();
  std::string out;
  ASSERT_EQ(test::RunShell("openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=127.0.0.1 "
                           "-keyout " +
                               key + " -out " + cert,
                           &out),
            0)
      << out;
  Ftd ftd({"--http-cert", cert, "--http-key", key});
  ASSERT_GT(ftd.http, 0) << ftd.proc.Stderr();
  EXPECT_NE(ftd.proc.Stderr().find("open https://"), std::string::npos) << ftd.proc.Stderr();
  const std::string url = "https://127.0.0.1:" + std::to_string(ftd.http) + "/api/v1/info";
  std::string body;
  EXPECT_EQ(Curl("--cacert " + cert + " " + url, &body), 200) << body;
  EXPECT_NE(body.find("\"api_version\":1"), std::string::npos) << body;
  EXPECT_NE(Curl(ftd.Url("/api/v1/info"), &body), 200);  // plain HTTP is not served
}

}  // namespace
}  // namespace ftstack
