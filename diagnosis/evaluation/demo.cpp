#include "diagnosis/evaluation/demo.hpp"

#include <filesystem>

#include "measurement/recording.hpp"
#include "sim/record.hpp"

namespace ftstack::diag {

DemoFiles MakeDemo(const DemoRequest& request) {
  DemoFiles f;
  f.name = request.effect.substr(0, request.effect.find(':'));
  sim::RecordRequest req;
  req.seed = request.seed;
  req.duration_s = request.duration_s;
  req.profile = f.name.rfind("thermal", 0) == 0 ? "thermal" : "rig";
  if (f.name != "none") req.effects = sim::ParseEffects({request.effect});
  f.profile = req.profile;
  f.dir = request.out_dir.empty() ? "ftdiag-demo-" + f.name : request.out_dir;
  std::filesystem::create_directories(f.dir);
  const sim::RecordResult rec = sim::MakeRecording(req);
  f.real_csv = f.dir + "/real.csv";
  f.sim_csv = f.dir + "/sim.csv";
  f.truth_json = f.dir + "/truth.json";
  WriteRecording(f.real_csv, rec.real);
  WriteRecording(f.sim_csv, rec.sim);
  sim::WriteTruth(f.truth_json, rec.truth);
  f.rows = rec.real.rows();
  f.truth_strongest = rec.truth.value("strongest", "none");
  return f;
}

}  // namespace ftstack::diag
