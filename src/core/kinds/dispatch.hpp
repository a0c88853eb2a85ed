// The kinds' dispatchers: select a kind's law by its code (its index in mount_twin.kinds.KINDS)
// as mount_twin/kinds/__init__.py describes. Adding a kind: its header here, a line in
// KIND_NAMES and a branch in each dispatcher (and in kind_states, kind_events, kind_invalid).
// A code without a branch writes NaN (force and couple; event functions and utilisation; the
// state), so the stepper fails with NOT_FINITE instead of running another kind's law.
#pragma once

#include <limits>

#include "../views.hpp"
#include "bolted_joint.hpp"
#include "elastomer.hpp"
#include "shear_key.hpp"

namespace mt::kinds {

inline constexpr double NOT_A_NUMBER = std::numeric_limits<double>::quiet_NaN();  // math.nan

inline constexpr int N_KINDS = 3;
inline constexpr const char* KIND_NAMES[N_KINDS] = {elastomer::KIND, bolted_joint::KIND,
                                                    shear_key::KIND};
inline constexpr idx ELASTOMER = 0, BOLTED_JOINT = 1, SHEAR_KEY = 2;

constexpr int max3(idx a, idx b, idx c) {
  return static_cast<int>(a > b ? (a > c ? a : c) : (b > c ? b : c));
}
/// Length of a parameter row: the longest kind's.
inline constexpr int N_PAR = max3(elastomer::N_PAR, bolted_joint::N_PAR, shear_key::N_PAR);
/// Event functions per mount: the most of any kind.
inline constexpr int N_EVENTS =
    max3(elastomer::N_EVENTS, bolted_joint::N_EVENTS, shear_key::N_EVENTS);
static_assert(N_PAR == 282 && N_EVENTS == 4, "mount_twin.kinds: N_PAR 282, N_EVENTS 4");

/// The kind's load: local force f (N) and generalized couple c (N·m, conjugate to phi) on the
/// body; internal state rates into dydt from o. An unknown code writes NaN into f and c.
inline void kind_load(idx code, const double* p, Vec y, idx o, const double* d, const double* v,
                      const double* phi, const double* w, Vec dydt, double* f, double* c) {
  if (code == ELASTOMER) {
    elastomer::load(p, y, o, d, v, phi, w, dydt, f, c);
  } else if (code == BOLTED_JOINT) {
    bolted_joint::load(p, y, o, d, v, phi, w, dydt, f, c);
  } else if (code == SHEAR_KEY) {
    shear_key::load(p, y, o, d, v, phi, w, dydt, f, c);
  } else {
    for (int j = 0; j < 3; ++j) {
      f[j] = NOT_A_NUMBER;
      c[j] = NOT_A_NUMBER;
    }
  }
}

/// The kind's monitor: event functions into g (y0: state at the previous sample); returns the
/// utilisation. An unknown code writes NaN into all of g and returns NaN.
inline double kind_monitor(idx code, const double* p, Vec y, Vec y0, idx o, const double* d,
                           const double* v, Vec g) {
  if (code == ELASTOMER) return elastomer::monitor(p, y, y0, o, d, v, g);
  if (code == BOLTED_JOINT) return bolted_joint::monitor(p, y, y0, o, d, v, g);
  if (code == SHEAR_KEY) return shear_key::monitor(p, y, y0, o, d, v, g);
  for (idx e = 0; e < g.n; ++e) g[e] = NOT_A_NUMBER;
  return NOT_A_NUMBER;
}

/// The kind's update: discrete switches between samples; returns whether one changed the
/// state. An unknown code writes NaN into y[max(o, 0)] and returns true.
inline bool kind_update(idx code, const double* p, Vec y, idx o, const double* d) {
  if (code == ELASTOMER) return elastomer::update(p, y, o, d);
  if (code == BOLTED_JOINT) return bolted_joint::update(p, y, o, d);
  if (code == SHEAR_KEY) return shear_key::update(p, y, o, d);
  y[o > 0 ? o : 0] = NOT_A_NUMBER;
  return true;
}

/// The kind's carry: the companion's rate-independent states after its carried error's kick
/// (y after the kick, y0 before it, yt the twin's; d, dt their deflections). An unknown code
/// writes NaN into y[max(o, 0)].
inline void kind_carry(idx code, const double* p, Vec y, Vec y0, Vec yt, idx o, const double* d,
                       const double* dt) {
  if (code == ELASTOMER) return elastomer::carry(p, y, y0, yt, o, d, dt);
  if (code == BOLTED_JOINT) return bolted_joint::carry(p, y, y0, yt, o, d, dt);
  if (code == SHEAR_KEY) return shear_key::carry(p, y, y0, yt, o, d, dt);
  y[o > 0 ? o : 0] = NOT_A_NUMBER;
}

/// Whether the kind's carry returns anything (its CARRIES; an unknown code: true, so that
/// kind_carry marks it): the companion skips the carry, and the mount's motion it needs, of
/// a kind that returns nothing.
inline bool kind_carries(idx code) {
  if (code == ELASTOMER) return elastomer::CARRIES;
  if (code == BOLTED_JOINT) return bolted_joint::CARRIES;
  if (code == SHEAR_KEY) return shear_key::CARRIES;
  return true;
}

/// Internal states the kind reads and writes from o for the row p (-1: unknown code). For the
/// bindings' checks.
inline idx kind_states(idx code, const double* p) {
  if (code == ELASTOMER) return elastomer::states(p);
  if (code == BOLTED_JOINT) return bolted_joint::states(p);
  if (code == SHEAR_KEY) return shear_key::states(p);
  return -1;
}

/// Event functions the kind writes into g (-1: unknown code, which writes all of g).
inline int kind_events(idx code) {
  if (code == ELASTOMER) return elastomer::N_EVENTS;
  if (code == BOLTED_JOINT) return bolted_joint::N_EVENTS;
  if (code == SHEAR_KEY) return shear_key::N_EVENTS;
  return -1;
}

/// Why the row p would make the kind's law index outside it (nullptr: it cannot, or unknown
/// code). For the bindings' checks.
inline const char* kind_invalid(idx code, const double* p) {
  if (code == ELASTOMER) return elastomer::invalid(p);
  if (code == BOLTED_JOINT) return bolted_joint::invalid(p);
  if (code == SHEAR_KEY) return shear_key::invalid(p);
  return nullptr;
}

}  // namespace mt::kinds
