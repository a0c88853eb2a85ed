// What the integrators need of the physics: the right-hand side.
#pragma once

#include "../model.hpp"

namespace mt::physics {

/// dy/dt at time t (s) into dydt under the input u (13 floats, dynamics.py's module
/// docstring); returns OK or OFF_CHART.
inline int rhs(double t, Vec y, const Model& m, Scratch& s, Vec u, Vec dydt);

}  // namespace mt::physics
