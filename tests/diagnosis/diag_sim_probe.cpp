// Development probe: `diag_sim_probe PROFILE SEED DURATION EFFECT[:k=v] ...` diagnoses a simulator
// recording and prints the verdict next to the truth (not a test).
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/report/json_report.hpp"
#include "sim/record.hpp"

int main(int argc, char** argv) {
  using namespace ftstack;
  sim::RecordRequest req;
  req.profile = argv[1];
  req.seed = static_cast<std::uint64_t>(std::atoi(argv[2]));
  req.duration_s = std::atof(argv[3]);
  std::vector<std::string> eff;
  for (int i = 4; i < argc; ++i) eff.push_back(argv[i]);
  req.effects = sim::ParseEffects(eff);
  const auto rec = sim::MakeRecording(req);
  const auto data = diag::FromRecordings(rec.sim, rec.real);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = diag::Diagnose(data);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  auto j = diag::ToJson(r);
  std::printf("rows=%zu time=%.0f ms\nTRUTH %s\n", data.rows(), ms,
              rec.truth["effects"].dump().substr(0, 600).c_str());
  std::printf("verdict %s  hold %.3g -> %.3g  noise %.3g\n", r.verdict.c_str(), r.hold_rms_before,
              r.hold_rms_after, r.noise_rms(0));
  for (const auto& e : j["effects"])
    std::printf("  %s %s\n   %s\n", e["name"].get<std::string>().c_str(),
                e["params"].dump().substr(0, 300).c_str(),
                e["evidence"].get<std::string>().c_str());
  for (std::size_t i = 0; i < std::min<std::size_t>(5, r.candidates.size()); ++i) {
    const auto& c = r.candidates[i];
    std::printf("   cand %-24s p=%3d z=%8.1f score=%10.1f hold=%.3g %s\n", c.name.c_str(),
                c.n_params, c.z, c.score, c.hold_rms_after, c.eligible ? "*" : "");
  }
  std::printf("  mismatch %s\n", j["mismatch"].dump().substr(0, 250).c_str());
  return 0;
}
