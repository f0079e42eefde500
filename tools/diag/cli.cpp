#include "tools/diag/cli.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "tools/diag/html_report.hpp"
#include "tools/diag/scorecard.hpp"

namespace ftstack::diag {
namespace {

int g_exit = 0;

struct Bar {
  bool tty = false;
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

}  // namespace

void WriteJson(const std::string& path, const nlohmann::json& j) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

int RunDiagnose(const DiagnoseArgs& args) {
  Bar bar;
  bar.tty = isatty(STDERR_FILENO) != 0;
  try {
    if (args.sim.empty() == args.model.empty()) {
      throw DiagInputError(
          "ftdiag diagnose: give exactly one of --sim SIM.csv or --model SENSOR.json");
    }
    if (!(args.block_s > 0)) throw DiagInputError("ftdiag diagnose: --block-s must be positive");
    const DiagData data = args.sim.empty() ? LoadModelReal(args.model, args.real, &DrawBar, &bar)
                                           : LoadSimReal(args.sim, args.real, &DrawBar, &bar);
    DiagnoseOptions opt;
    opt.pairs = !args.no_pairs;
    opt.block_s = args.block_s;
    opt.progress = &DrawBar;
    opt.progress_user = &bar;
    bar.last = -1;
    const Report report = Diagnose(data, opt);
    if (bar.tty) std::fprintf(stderr, "\n");
    WriteJson(args.json, ToJson(report));
    if (!args.html.empty()) WriteHtml(args.html, data, report);
    std::printf("verdict: %s", report.verdict.c_str());
    for (std::size_t i = 1; i < report.effects.size(); ++i)
      std::printf(" + %s", report.effects[i].fit.name.c_str());
    std::printf("  (held-out RMS %.4g -> %.4g mV/V)\n", report.hold_rms_before,
                report.hold_rms_after);
    for (const auto& e : report.effects)
      std::printf("  %s: %s\n", e.fit.name.c_str(), e.fit.evidence.c_str());
    return 0;
  } catch (const std::exception& e) {
    if (bar.tty) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "ftdiag: %s\n", e.what());
    return 2;
  }
}

void AddCommands(CLI::App& app) {
  static DiagnoseArgs args;
  auto* d = app.add_subcommand(
      "diagnose", "compare a simulation with a real recording and explain the difference");
  d->add_option("--sim", args.sim, "simulation recording (same t and wrench as --real)");
  d->add_option("--model", args.model,
                "sensor description (JSON, or 'builtin'): predict the real file's bridges");
  d->add_option("--real", args.real, "real recording")->required();
  d->add_option("--json", args.json, "JSON report (schema ftdiag-report/1)")->required();
  d->add_option("--html", args.html, "self-contained HTML report with plots");
  d->add_flag("--no-pairs", args.no_pairs, "consider single effects only");
  d->add_option("--block-s", args.block_s,
                "length of the interleaved hold-out blocks, s (default 0.5)");
  d->callback([] { g_exit = RunDiagnose(args); });
  AddDemoCommand(app, &g_exit);

  static int seeds = 3;
  static double duration_s = 120.0;
  static std::string out;
  auto* sc = app.add_subcommand(
      "scorecard", "diagnose simulator recordings of every effect and write the docs table");
  sc->add_option("--seeds", seeds, "seeds (and sizes ×1, ×0.5, ×2 cycling) per effect (default 3)");
  sc->add_option("--duration-s", duration_s, "recording length, s (default 120)");
  sc->add_option("--out", out, "Markdown file to write (default: print)");
  sc->callback([] {
    try {
      std::vector<ScoreResult> results;
      int passed = 0;
      for (const auto& c : StandardCases(seeds, duration_s)) {
        results.push_back(RunCase(c));
        const auto& r = results.back();
        passed += r.passed();
        std::fprintf(stderr, "%-40s seed %llu: %-28s %s\n", c.effect.c_str(),
                     static_cast<unsigned long long>(c.seed), r.verdict.c_str(),
                     r.passed() ? "ok" : "MISSED");
      }
      const std::string cmd = "ftdiag scorecard --seeds " + std::to_string(seeds) +
                              " --duration-s " + std::to_string(static_cast<int>(duration_s));
      const std::string md = ScorecardMarkdown(results, cmd);
      if (out.empty()) {
        std::fputs(md.c_str(), stdout);
      } else {
        std::ofstream f(out);
        f << md;
        if (!f) throw std::runtime_error(out + ": cannot write");
      }
      std::printf("scorecard: %d/%zu cases meet every criterion\n", passed, results.size());
      g_exit = 0;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ftdiag scorecard: %s\n", e.what());
      g_exit = 2;
    }
  });
}

int LastExitCode() { return g_exit; }

}  // namespace ftstack::diag
