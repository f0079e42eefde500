#include "calibration/fit/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

namespace ftstack::cal {

// The rig data a fit works on: block detection, reading a recording, and the condition numbers
// of a load set and a Gram matrix.

double GramCondition(const Eigen::MatrixXd& gram) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(gram);
  const double lo = es.eigenvalues().minCoeff();
  const double hi = es.eigenvalues().maxCoeff();
  if (!(lo > 0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(hi / lo);
}

std::vector<int> DetectBlocks(const Eigen::MatrixXd& wrench, const BlockOptions& options,
                              int* block_count, std::string* method) {
  const auto rows = static_cast<std::size_t>(wrench.rows());
  std::array<double, 6> scale = options.scale;
  for (int a = 0; a < 6; ++a) {
    if (!(scale[static_cast<std::size_t>(a)] > 0)) {
      scale[static_cast<std::size_t>(a)] = rows > 0 ? wrench.col(a).cwiseAbs().maxCoeff() : 0.0;
    }
  }
  // The largest axis scale stands in for axes that never move (avoids dividing by zero).
  const double big = *std::max_element(scale.begin(), scale.end());
  for (double& s : scale) {
    if (!(s > 1e-9 * big) || !(s > 0)) s = big > 0 ? big : 1.0;
  }
  // Runs within tolerance of their first row.
  struct Run {
    std::size_t begin, end;
  };
  std::vector<Run> runs;
  std::size_t start = 0;
  for (std::size_t i = 1; i <= rows; ++i) {
    bool split = i == rows;
    if (!split) {
      for (int a = 0; a < 6 && !split; ++a) {
        const auto ii = static_cast<Eigen::Index>(i);
        const auto ss = static_cast<Eigen::Index>(start);
        split = std::fabs(wrench(ii, a) - wrench(ss, a)) >
                options.hold_tolerance * scale[static_cast<std::size_t>(a)];
      }
    }
    if (split) {
      runs.push_back({start, i});
      start = i;
    }
  }
  // A slow ramp also breaks into runs within tolerance; holds are the long runs: at least a
  // fifth of the "N50" length (runs at least that long cover half of the rows).
  std::vector<std::size_t> lengths;
  for (const Run& r : runs) lengths.push_back(r.end - r.begin);
  std::sort(lengths.rbegin(), lengths.rend());
  std::size_t n50 = 0;
  std::size_t acc = 0;
  for (std::size_t len : lengths) {
    acc += len;
    n50 = len;
    if (2 * acc >= rows) break;
  }
  const std::size_t min_hold = std::max(options.min_hold_rows, n50 / 5);
  std::vector<Run> holds;
  std::size_t covered = 0;
  for (const Run& r : runs) {
    if (r.end - r.begin >= min_hold) {
      holds.push_back(r);
      covered += r.end - r.begin;
    }
  }
  std::vector<int> block(rows, 0);
  if (holds.size() >= 2 && static_cast<double>(covered) >= 0.3 * static_cast<double>(rows)) {
    // Transition rows join the nearest hold (split at the midpoint between holds).
    for (std::size_t h = 0; h < holds.size(); ++h) {
      const std::size_t lo = h == 0 ? 0 : (holds[h - 1].end + holds[h].begin) / 2;
      const std::size_t hi = h + 1 == holds.size() ? rows : (holds[h].end + holds[h + 1].begin) / 2;
      for (std::size_t i = lo; i < hi; ++i) block[i] = static_cast<int>(h);
    }
    *block_count = static_cast<int>(holds.size());
    *method = "holds";
  } else {
    const std::size_t k = std::max<std::size_t>(2, std::min(options.continuous_blocks, rows));
    for (std::size_t i = 0; i < rows; ++i) block[i] = static_cast<int>(i * k / rows);
    *block_count = static_cast<int>(k);
    *method = "chunks";
  }
  return block;
}

std::vector<int> GroupBlocksByLoadDirection(const Eigen::MatrixXd& wrench,
                                            const std::vector<int>& block, int block_count,
                                            const std::array<double, 6>& scale,
                                            double tolerance_deg, int* group_count) {
  const auto nb = static_cast<Eigen::Index>(block_count);
  Eigen::MatrixXd mean = Eigen::MatrixXd::Zero(nb, 6);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(nb);
  for (std::size_t i = 0; i < block.size(); ++i) {
    mean.row(block[i]) += wrench.row(static_cast<Eigen::Index>(i));
    count(block[i]) += 1.0;
  }
  for (Eigen::Index b = 0; b < nb; ++b) mean.row(b) /= std::max(1.0, count(b));
  double max_force = 0.0;
  for (Eigen::Index b = 0; b < nb; ++b)
    max_force = std::max(max_force, mean.row(b).head<3>().norm());
  const double cos_tol = std::cos(tolerance_deg * 3.14159265358979323846 / 180.0);
  std::vector<Eigen::Matrix<double, 6, 1>> firsts;  // unit direction of each group's first block
  std::vector<int> group(static_cast<std::size_t>(block_count), -1);
  int unloaded = -1;
  for (Eigen::Index b = 0; b < nb; ++b) {
    Eigen::Matrix<double, 6, 1> u = Eigen::Matrix<double, 6, 1>::Zero();
    bool loaded = false;
    for (int a = 0; a < 6; ++a) {
      const double s =
          scale[static_cast<std::size_t>(a)] > 0 ? scale[static_cast<std::size_t>(a)] : 1.0;
      loaded = loaded || std::fabs(mean(b, a)) > 0.02 * s;
      if (a >= 3) u(a) = mean(b, a) / s;
    }
    if (!loaded) {
      if (unloaded < 0) {
        unloaded = static_cast<int>(firsts.size());
        firsts.emplace_back(u);
      }
      group[static_cast<std::size_t>(b)] = unloaded;
      continue;
    }
    const double force = mean.row(b).head<3>().norm();
    if (force >= 0.1 * max_force && force > 0) {  // the force's direction alone
      u.setZero();
      u.head<3>() = mean.row(b).head<3>().transpose();
    }
    u.normalize();
    int g = -1;
    for (std::size_t k = 0; k < firsts.size() && g < 0; ++k) {
      if (static_cast<int>(k) != unloaded && firsts[k].dot(u) >= cos_tol) g = static_cast<int>(k);
    }
    if (g < 0) {
      g = static_cast<int>(firsts.size());
      firsts.push_back(u);
    }
    group[static_cast<std::size_t>(b)] = g;
  }
  *group_count = static_cast<int>(firsts.size());
  return group;
}

namespace {

/// Numbers the distinct values of a column in order of first row.
std::vector<int> NumberValues(const std::vector<double>& col, int* count) {
  std::map<double, int> ids;
  std::vector<int> out(col.size());
  for (std::size_t i = 0; i < col.size(); ++i) {
    auto it = ids.find(col[i]);
    if (it == ids.end()) it = ids.emplace(col[i], static_cast<int>(ids.size())).first;
    out[i] = it->second;
  }
  *count = static_cast<int>(ids.size());
  return out;
}

/// Validation groups: a `group` column, else the load direction of each block.
void FindGroups(const Recording& rec, const BlockOptions& options, RigData* d) {
  if (rec.Has("group")) {
    d->group = NumberValues(rec.Column("group"), &d->group_count);
    d->group_method = "column group";
    std::vector<int> of_block(static_cast<std::size_t>(d->block_count), -1);
    for (std::size_t i = 0; i < d->group.size(); ++i) {
      int& g = of_block[static_cast<std::size_t>(d->block[i])];
      if (g >= 0 && g != d->group[i]) {
        throw RecordingError(rec.path + ":" +
                             std::to_string(i < rec.data_lines.size() ? rec.data_lines[i] : i + 1) +
                             ": column group changes inside a load block; a block (pose or hold) "
                             "must lie in one group");
      }
      g = d->group[i];
    }
    return;
  }
  std::array<double, 6> scale = options.scale;
  for (int a = 0; a < 6; ++a) {
    auto& s = scale[static_cast<std::size_t>(a)];
    if (!(s > 0)) s = d->wrench.col(a).cwiseAbs().maxCoeff();
  }
  const std::vector<int> of_block =
      GroupBlocksByLoadDirection(d->wrench, d->block, d->block_count, scale, 5.0, &d->group_count);
  d->group.resize(d->block.size());
  for (std::size_t i = 0; i < d->block.size(); ++i)
    d->group[i] = of_block[static_cast<std::size_t>(d->block[i])];
  d->group_method = "load direction within 5°";
}

}  // namespace

RigData RigDataFromRecording(const Recording& rec, const BlockOptions& options) {
  RigData d;
  d.path = rec.path;
  const std::size_t n = rec.BridgeCount();
  if (n < 1 || n > fw::kMaxChannels) {
    throw RecordingError(rec.path + ": needs bridge columns b0 … b{N-1} with 1 <= N <= 8, has " +
                         std::to_string(n));
  }
  const std::size_t rows = rec.rows();
  d.bridges.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(n));
  d.wrench.resize(static_cast<Eigen::Index>(rows), 6);
  for (std::size_t c = 0; c < n; ++c) {
    const auto& col = rec.Column("b" + std::to_string(c));
    for (std::size_t i = 0; i < rows; ++i) {
      d.bridges(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = col[i];
    }
  }
  for (std::size_t a = 0; a < 6; ++a) {
    const auto& col = rec.Column(WrenchColumns()[a]);
    for (std::size_t i = 0; i < rows; ++i) {
      d.wrench(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(a)) = col[i];
    }
  }
  if (rec.Has("temp_C")) {
    const auto& col = rec.Column("temp_C");
    d.temp_c = Eigen::Map<const Eigen::VectorXd>(col.data(), static_cast<Eigen::Index>(rows));
  }
  if (rec.Has("t")) {
    d.t_s = rec.Column("t");
  } else {
    d.t_s.resize(rows);
    std::iota(d.t_s.begin(), d.t_s.end(), 0.0);
  }
  const char* label = rec.Has("block") ? "block" : rec.Has("pose") ? "pose" : nullptr;
  if (label != nullptr) {
    d.block = NumberValues(rec.Column(label), &d.block_count);
    d.block_method = std::string("column ") + label;
  } else {
    d.block = DetectBlocks(d.wrench, options, &d.block_count, &d.block_method);
  }
  FindGroups(rec, options, &d);
  return d;
}

double LoadSetCondition(const Eigen::MatrixXd& wrench, const std::array<double, 6>& rated) {
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(7, 7);
  Eigen::Matrix<double, 7, 1> u;
  for (Eigen::Index i = 0; i < wrench.rows(); ++i) {
    u(0) = 1.0;
    for (int a = 0; a < 6; ++a) {
      const double r = rated[static_cast<std::size_t>(a)];
      u(1 + a) = wrench(i, a) / (r > 0 ? r : 1.0);
    }
    g.selfadjointView<Eigen::Lower>().rankUpdate(u);
  }
  g = g.selfadjointView<Eigen::Lower>();
  return GramCondition(g);
}

double LoadSetCondition(const std::vector<Wrench>& loads, const Wrench& rated) {
  Eigen::MatrixXd w(static_cast<Eigen::Index>(loads.size()), 6);
  for (std::size_t i = 0; i < loads.size(); ++i)
    w.row(static_cast<Eigen::Index>(i)) = loads[i].transpose();
  std::array<double, 6> r{};
  for (int a = 0; a < 6; ++a) r[static_cast<std::size_t>(a)] = rated(a);
  return LoadSetCondition(w, r);
}

std::vector<int> TemperatureLevels(const Eigen::VectorXd& temp_c, double gap_c, int* count) {
  const auto rows = static_cast<std::size_t>(temp_c.size());
  std::vector<std::size_t> order(rows);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return temp_c(static_cast<Eigen::Index>(a)) < temp_c(static_cast<Eigen::Index>(b));
  });
  std::vector<int> level(rows, 0);
  int current = 0;
  for (std::size_t k = 0; k < rows; ++k) {
    if (k > 0 && temp_c(static_cast<Eigen::Index>(order[k])) -
                         temp_c(static_cast<Eigen::Index>(order[k - 1])) >
                     gap_c)
      ++current;
    level[order[k]] = current;
  }
  *count = rows == 0 ? 0 : current + 1;
  return level;
}

}  // namespace ftstack::cal
