// Development probe: prints the diagnosis of each closed-form fixture (not a test).
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/report/json_report.hpp"
#include "tests/diagnosis/diag_fixture.hpp"

int main(int argc, char** argv) {
  using namespace ftstack::diag;
  const double size = argc > 2 ? std::atof(argv[2]) : 5.0;
  const unsigned seed = argc > 3 ? static_cast<unsigned>(std::atoi(argv[3])) : 1u;
  std::vector<testing::FixtureEffect> fe;
  if (std::string(argv[1]) != "none") fe.push_back({argv[1], size});
  if (argc > 4) fe.push_back({argv[4], size});
  const char* hold = std::getenv("PROBE_HOLD_S");
  auto fx = testing::MakeFixture(fe, seed, 200.0, 1e-4, hold ? std::atof(hold) : 6.0);
  const auto t0 = std::chrono::steady_clock::now();
  const Report r = Diagnose(fx.data);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  auto j = ToJson(r);
  std::printf("%s rows=%zu time=%.0f ms truth=%g\n", argv[1], fx.data.rows(), ms, fx.truth);
  std::printf("verdict %s  hold %.3g -> %.3g\n", r.verdict.c_str(), r.hold_rms_before,
              r.hold_rms_after);
  for (const auto& e : j["effects"])
    std::printf("  %s %s\n   %s\n", e["name"].get<std::string>().c_str(),
                e["params"].dump().c_str(), e["evidence"].get<std::string>().c_str());
  for (std::size_t i = 0; i < std::min<std::size_t>(6, r.candidates.size()); ++i) {
    const auto& c = r.candidates[i];
    std::printf("   cand %-24s p=%3d z=%8.1f score=%10.1f hold=%.3g %s\n", c.name.c_str(),
                c.n_params, c.z, c.score, c.hold_rms_after, c.eligible ? "*" : "");
  }
  std::printf("  not_claimed %s\n  findings %s\n",
              j.value("not_claimed", nlohmann::json()).dump().c_str(),
              j.value("findings", nlohmann::json()).dump().substr(0, 600).c_str());
  std::printf("  mismatch %s\n", j["mismatch"].dump().substr(0, 300).c_str());
  return 0;
}
