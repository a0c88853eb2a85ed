// Shear key: stiff along its shear axes, free along the others, with an optional clearance and
// engagement height: the port of mount_twin/kinds/shear_key.py's `load`, `monitor` and
// `update`, held to it by mount_twin.kinds.check_dispatch. Same operations in the same order
// as the Python reference. No internal states, no couple.
#pragma once

#include <cmath>

#include "../numeric.hpp"
#include "../views.hpp"

namespace mt::kinds::shear_key {

inline constexpr const char* KIND = "shear_key";
inline constexpr int N_EVENTS = 2;  // key_contact, key_overload

// parameter columns: stiffness (3), damping (3), clearance, allowable force, engagement height
inline constexpr idx K0 = 0, C0 = 3, CLEAR = 6, FALLOW = 7, HEIGHT = 8;
inline constexpr idx N_PAR = 9;

/// Whether the foot is still low enough for the key to hold it.
inline bool engaged(const double* p, const double* d) {
  return p[HEIGHT] <= 0.0 || d[2] <= p[HEIGHT];
}

/// Force f (N) on the body in local axes; a key has no couple (c = 0) and no states.
inline void load(const double* p, Vec /*y*/, idx /*o*/, const double* d, const double* v,
                 const double* /*phi*/, const double* /*w*/, Vec /*dydt*/, double* f,
                 double* c) {
  const bool on = engaged(p, d);
  for (idx j = 0; j < 3; ++j) {
    f[j] = 0.0;
    c[j] = 0.0;
    const double k = p[K0 + j];
    if (k > 0.0 && on) {
      const double pen = std::fabs(d[j]) - p[CLEAR];
      if (pen > 0.0) {
        const double side = d[j] > 0.0 ? 1.0 : -1.0;
        // contact pushes, never pulls: damping cannot hold a key face that separates
        f[j] = -side * py_max(k * pen + p[C0 + j] * side * v[j], 0.0);
      }
    }
  }
}

/// Contact (penetration past the clearance, m) and overload into g; returns the largest
/// per-axis spring force over the allowable force (0 if not monitored).
inline double monitor(const double* p, Vec /*y*/, Vec /*y0*/, idx /*o*/, const double* d,
                      const double* /*v*/, Vec g) {
  double pen = -1.0;
  double force = 0.0;
  const bool on = engaged(p, d);
  for (idx j = 0; j < 3; ++j) {
    if (p[K0 + j] > 0.0 && on) {
      const double pj = std::fabs(d[j]) - p[CLEAR];
      pen = py_max(pen, pj);
      force = py_max(force, p[K0 + j] * py_max(pj, 0.0));
    }
  }
  g[0] = p[CLEAR] > 0.0 ? pen : -1.0;
  if (p[FALLOW] > 0.0) {
    g[1] = force / p[FALLOW] - 1.0;
    return force / p[FALLOW];
  }
  g[1] = -1.0;
  return 0.0;
}

/// The companion after its carried error's kick (bolted_joint.hpp carry): A key has no internal state.
/// CARRIES false: the companion does not call it (test_core_contract holds that it writes
/// nothing).
constexpr bool CARRIES = false;
inline void carry(const double* /*p*/, Vec /*y*/, Vec /*y0*/, Vec /*yt*/, idx /*o*/,
                  const double* /*d*/, const double* /*dt*/) {}

/// No discrete state: never switches.
inline bool update(const double* /*p*/, Vec /*y*/, idx /*o*/, const double* /*d*/) {
  return false;
}

/// A key has no internal state. For the bindings' checks.
inline idx states(const double* /*p*/) { return 0; }

/// A key's row cannot make the law index outside it. For the bindings' checks.
inline const char* invalid(const double* /*p*/) { return nullptr; }

}  // namespace mt::kinds::shear_key
