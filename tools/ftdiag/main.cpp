// ftdiag — sim-vs-real diagnosis (docs/spec/diagnosis.md): argument parsing and the exit codes; the
// work is done by the diagnosis libraries (diagnosis/, diagnosis/report/, diagnosis/evaluation/).
#include <malloc.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/evaluation/demo.hpp"
#include "diagnosis/evaluation/model_prediction.hpp"
#include "diagnosis/evaluation/scorecard.hpp"
#include "diagnosis/report/html_report.hpp"
#include "diagnosis/report/json_report.hpp"
#include "tools/unit_options.hpp"

namespace {

using namespace ftstack::diag;  // NOLINT(google-build-using-namespace): one program, one library

/// ftdiag's exit codes.
enum ExitCode : int {
  kExitOk = 0,              ///< diagnosis (or scorecard, demo) completed
  kExitBadInput = 2,        ///< bad options or files: one line on stderr names them
  kExitBelowThreshold = 3,  ///< scorecard: fewer cases passed than --min-pass asks
};

struct DiagnoseArgs {
  std::string sim, model, real, json, html;
  RealUnitSources units;  ///< --cal and the unit options: how the real file's bridges are read
  bool no_pairs = false;
  double block_s = 0.5;
  int threads = 0;
};
struct ScorecardArgs {
  int seeds = 3;
  double duration_s = 120.0;
  std::string out;
  double min_pass = 0.0;  ///< fraction of cases that must meet every criterion
};

/// A progress bar on stderr when it is a terminal.
struct Bar {
  bool tty = isatty(STDERR_FILENO) != 0;
  int last = -1;
};
void DrawBar(double fraction, const char* stage, void* user) {
  auto* bar = static_cast<Bar*>(user);
  if (!bar->tty) return;
  const int pct = static_cast<int>(fraction * 100.0);
  if (pct == bar->last) return;
  bar->last = pct;
  constexpr int kWidth = 30;
  const int fill = pct * kWidth / 100;
  char line[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) line[i] = i < fill ? '#' : '.';
  line[kWidth] = 0;
  std::fprintf(stderr, "\r[%s] %3d%% %-28s", line, pct, stage);
  std::fflush(stderr);
}

/// The diagnosis allocates and frees n × N buffers (predictions, features, targets) for every
/// candidate fit. Mapped one by one, each would be faulted in and zeroed by the kernel again. They
/// are kept in one heap instead: no mapping, one arena for every thread (a buffer freed by one
/// thread serves the next fit on any), and up to 256 MiB of free space kept rather than returned
/// (time and peak memory: docs/diagnosis.md, "Buffers kept for the next fit").
void KeepBuffersForTheNextFit() {
#ifdef __GLIBC__
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

int RunDiagnose(const DiagnoseArgs& args) {
  KeepBuffersForTheNextFit();
  Bar bar;
  try {
    if (args.sim.empty() == args.model.empty()) {
      throw DiagInputError(
          "ftdiag diagnose: give exactly one of --sim SIM.csv or --model SENSOR.json");
    }
    if (!(args.block_s > 0)) throw DiagInputError("ftdiag diagnose: --block-s must be positive");
    DiagData data =
        args.sim.empty()
            ? LoadModelReal(args.model, args.real, &DrawBar, &bar, args.units)
            : LoadSimReal(args.sim, args.real, &DrawBar, &bar, MakeRealUnits(args.units));
    DiagnoseOptions opt;
    opt.pairs = !args.no_pairs;
    opt.block_s = args.block_s;
    opt.threads = args.threads;
    opt.progress = &DrawBar;
    opt.progress_user = &bar;
    bar.last = -1;
    const Report report = Diagnose(&data, opt);  // its bridges become the context's (memory)
    if (bar.tty) std::fprintf(stderr, "\n");
    auto json = ToJson(report);
    json["real_bridge_unit"] = data.real_unit;
    WriteJson(args.json, json);
    if (!args.html.empty()) WriteHtml(args.html, data, report);
    std::printf("real recording: %s (diagnosed in mV/V)\n", data.real_unit.c_str());
    std::fputs(SummaryText(report).c_str(), stdout);
    return kExitOk;
  } catch (const std::exception& e) {
    if (bar.tty) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "ftdiag: %s\n", e.what());
    return kExitBadInput;
  }
}

int RunDemo(const DemoRequest& request) {
  try {
    const DemoFiles f = MakeDemo(request);
    std::printf(
        "recorded %s (%s profile, %zu rows, seed %llu): effect hidden in real.csv, truth in "
        "truth.json\n",
        f.name.c_str(), f.profile.c_str(), f.rows, static_cast<unsigned long long>(request.seed));
    DiagnoseArgs args;
    args.sim = f.sim_csv;
    args.real = f.real_csv;
    args.json = f.dir + "/report.json";
    args.html = f.dir + "/report.html";
    const int code = RunDiagnose(args);
    if (code == kExitOk) {
      std::printf("truth: %s  ->  report: %s\n", f.truth_strongest.c_str(), args.html.c_str());
    }
    return code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftdiag demo: %s\n", e.what());
    return kExitBadInput;
  }
}

int RunScorecard(const ScorecardArgs& args) {
  try {
    std::vector<ScoreResult> results;
    int passed = 0;
    for (const auto& c : StandardCases(args.seeds, args.duration_s)) {
      results.push_back(RunCase(c));
      const auto& r = results.back();
      passed += r.passed();
      std::fprintf(stderr, "%-40s seed %llu: %-28s %s\n", c.effect.c_str(),
                   static_cast<unsigned long long>(c.seed), r.verdict.c_str(),
                   r.passed() ? "ok" : "MISSED");
    }
    const std::string cmd = "ftdiag scorecard --seeds " + std::to_string(args.seeds) +
                            " --duration-s " + std::to_string(static_cast<int>(args.duration_s));
    const std::string md = ScorecardMarkdown(results, cmd);
    if (args.out.empty()) {
      std::fputs(md.c_str(), stdout);
    } else {
      std::ofstream f(args.out);
      f << md;
      if (!f) throw std::runtime_error(args.out + ": cannot write");
    }
    std::printf("scorecard: %d/%zu cases meet every criterion\n", passed, results.size());
    const double fraction = results.empty() ? 0.0 : passed / static_cast<double>(results.size());
    if (fraction < args.min_pass) {
      std::fprintf(stderr, "ftdiag scorecard: %d/%zu = %.3f is below --min-pass %.3f\n", passed,
                   results.size(), fraction, args.min_pass);
      return kExitBelowThreshold;
    }
    return kExitOk;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftdiag scorecard: %s\n", e.what());
    return kExitBadInput;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ftdiag: locate and explain the mismatch between a simulation and a real recording"};
  app.require_subcommand(1);
  int exit_code = kExitOk;

  DiagnoseArgs diagnose;
  auto* d = app.add_subcommand(
      "diagnose", "compare a simulation with a real recording and explain the difference");
  d->add_option("--sim", diagnose.sim, "simulation recording (same t and wrench as --real)");
  d->add_option("--model", diagnose.model,
                "sensor description (JSON, or 'builtin'): predict the real file's bridges");
  d->add_option("--real", diagnose.real, "real recording")->required();
  d->add_option("--cal", diagnose.units.cal_path,
                "the real sensor's calibration: the real file's bridges are read in the unit and "
                "converter it was fitted from unless the file or an option declares one");
  ftstack::tools::AddUnitOptions(d, &diagnose.units.cli);
  d->add_option("--json", diagnose.json, "JSON report (schema ftdiag-report/1)")->required();
  d->add_option("--html", diagnose.html, "self-contained HTML report with plots");
  d->add_flag("--no-pairs", diagnose.no_pairs, "consider single effects only");
  d->add_option("--threads", diagnose.threads,
                "threads for independent fits (default 0: the machine's, at most 4); the report "
                "does not depend on it")
      ->check(CLI::Range(0, 64));
  d->add_option("--block-s", diagnose.block_s,
                "length of the interleaved hold-out blocks, s (default 0.5)");
  d->callback([&] { exit_code = RunDiagnose(diagnose); });

  DemoRequest demo;
  auto* m = app.add_subcommand(
      "demo",
      "make a concealed-effect recording with the simulator, diagnose it, write the HTML report");
  m->add_option("EFFECT", demo.effect,
                "effect name from the vocabulary (docs/effects.md), NAME[:k=v,...]")
      ->required();
  m->add_option("--out-dir", demo.out_dir,
                "where to write real.csv, sim.csv, truth.json, report.json/html");
  m->add_option("--seed", demo.seed, "simulator seed (default 1)");
  m->add_option("--duration-s", demo.duration_s, "recording length, s (default 150)");
  m->callback([&] { exit_code = RunDemo(demo); });

  ScorecardArgs scorecard;
  auto* sc = app.add_subcommand(
      "scorecard", "diagnose simulator recordings of every effect and write the docs table");
  sc->add_option("--seeds", scorecard.seeds,
                 "seeds (and sizes ×1, ×0.5, ×2 cycling) per effect (default 3)");
  sc->add_option("--duration-s", scorecard.duration_s, "recording length, s (default 120)");
  sc->add_option("--out", scorecard.out, "Markdown file to write (default: print)");
  sc->add_option("--min-pass", scorecard.min_pass,
                 "exit 3 when fewer than this fraction of cases meet every criterion")
      ->check(CLI::Range(0.0, 1.0));
  sc->callback([&] { exit_code = RunScorecard(scorecard); });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return exit_code;
}
