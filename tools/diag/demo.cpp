// `ftdiag demo EFFECT`: a concealed-effect recording from the simulator, diagnosed, with its HTML
// report.
#include <cstdio>
#include <filesystem>

#include "sim/record.hpp"
#include "tools/diag/cli.hpp"

namespace ftstack::diag {

void AddDemoCommand(CLI::App& app, int* exit_code) {
  static std::string effect;
  static std::string out_dir;
  static std::uint64_t seed = 1;
  static double duration_s = 150.0;
  auto* d = app.add_subcommand(
      "demo",
      "make a concealed-effect recording with the simulator, diagnose it, write the HTML report");
  d->add_option("EFFECT", effect,
                "effect name from the vocabulary (docs/effects.md), NAME[:k=v,...]")
      ->required();
  d->add_option("--out-dir", out_dir,
                "where to write real.csv, sim.csv, truth.json, report.json/html");
  d->add_option("--seed", seed, "simulator seed (default 1)");
  d->add_option("--duration-s", duration_s, "recording length, s (default 150)");
  d->callback([exit_code] {
    try {
      sim::RecordRequest req;
      req.seed = seed;
      req.duration_s = duration_s;
      const std::string name = effect.substr(0, effect.find(':'));
      req.profile = name.rfind("thermal", 0) == 0 ? "thermal" : "rig";
      if (name != "none") req.effects = sim::ParseEffects({effect});
      const std::string dir = out_dir.empty() ? "ftdiag-demo-" + name : out_dir;
      std::filesystem::create_directories(dir);
      const sim::RecordResult rec = sim::MakeRecording(req);
      WriteRecording(dir + "/real.csv", rec.real);
      WriteRecording(dir + "/sim.csv", rec.sim);
      sim::WriteTruth(dir + "/truth.json", rec.truth);
      std::printf(
          "recorded %s (%s profile, %zu rows, seed %llu): effect hidden in real.csv, truth in "
          "truth.json\n",
          name.c_str(), req.profile.c_str(), rec.real.rows(),
          static_cast<unsigned long long>(seed));
      DiagnoseArgs args;
      args.sim = dir + "/sim.csv";
      args.real = dir + "/real.csv";
      args.json = dir + "/report.json";
      args.html = dir + "/report.html";
      *exit_code = RunDiagnose(args);
      if (*exit_code == 0) {
        std::printf("truth: %s  ->  report: %s\n", rec.truth.value("strongest", "none").c_str(),
                    args.html.c_str());
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ftdiag demo: %s\n", e.what());
      *exit_code = 2;
    }
  });
}

}  // namespace ftstack::diag
