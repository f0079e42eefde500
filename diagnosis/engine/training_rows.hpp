// The engine's walk over the training rows: the rows a fit sums over, so that an effect never
// reads the hold-out mask itself.
#pragma once

#include <cstddef>
#include <vector>

#include "diagnosis/engine/context.hpp"

namespace ftstack::diag {

/// Visits the training rows i of [a, b), every `step`-th row from a, in increasing order.
template <class F>
void ForTrainingRows(const Context& cx, int a, int b, F visit, int step = 1) {
  for (int i = a; i < b; i += step) {
    if (cx.train[static_cast<std::size_t>(i)]) visit(i);
  }
}

/// The training rows of every `step`-th row from 0, in increasing order: the rows a search
/// evaluates its grid on, as a list.
[[nodiscard]] inline std::vector<int> TrainingRowList(const Context& cx, int step = 1) {
  std::vector<int> rows;
  ForTrainingRows(
      cx, 0, cx.n, [&](int i) { rows.push_back(i); }, step);
  return rows;
}

/// Visits every `step`-th row i of [a, b) in increasing order, with whether it is a training row:
/// for a model that carries a state through every row (a filter, a relay, a prediction written
/// for all rows) and sums its fit over the training rows only.
template <class F>
void ForRowsWithTraining(const Context& cx, int a, int b, F visit, int step = 1) {
  for (int i = a; i < b; i += step) visit(i, cx.train[static_cast<std::size_t>(i)] != 0);
}

/// A visit of streamed features (ForLaggedLoad, ForRinging: `visit(i, c, features)` on every row,
/// their filters stepping through all of them) passed on for the training rows only.
template <class F>
[[nodiscard]] auto OnTrainingRows(const Context& cx, F visit) {
  return [&cx, visit](int i, int c, const double* features) mutable {
    if (cx.train[static_cast<std::size_t>(i)]) visit(i, c, features);
  };
}

}  // namespace ftstack::diag
