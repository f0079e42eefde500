// The engine's walk over the training rows: the rows a fit sums over, so that an effect never
// reads the hold-out mask itself.
#pragma once

#include <cstddef>

#include "diagnosis/engine/context.hpp"

namespace ftstack::diag {

/// Visits the training rows i of [a, b), every `step`-th row from a, in increasing order.
template <class F>
void ForTrainingRows(const Context& cx, int a, int b, F visit, int step = 1) {
  for (int i = a; i < b; i += step) {
    if (cx.train[static_cast<std::size_t>(i)]) visit(i);
  }
}

}  // namespace ftstack::diag
