// A stepper with its own arrays, as the loop and the error estimate hold one
// (engine/kernel.py Integrator).
#pragma once

#include "../views.hpp"

namespace mt::engine {

/// A stepper's id, settings and work arrays.
struct Integrator {
  int method = 0;
  Vec settings;
  Mat work2d;
  Vec work1d;
  Vec result;
};

}  // namespace mt::engine
