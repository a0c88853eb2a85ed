// Bolted joint (VDI 2230 joint diagram) with bolt plasticity, fracture, friction and bearing:
// the port of mount_twin/kinds/bolted_joint.py's `load`, `monitor` and `update`, held to it by
// mount_twin.kinds.check_dispatch. Same operations in the same order as the Python reference.
//
// Local z along the bolt (positive: the joint opens); x, y span the joint face. States from o:
// plastic elongation e_p (m), slip s_x, s_y (m), fractured (0/1).
#pragma once

#include <cmath>

#include "../numeric.hpp"
#include "../views.hpp"

namespace mt::kinds::bolted_joint {

inline constexpr const char* KIND = "bolted_joint";
inline constexpr int N_EVENTS = 4;  // bolt_yielded, joint_opened, joint_slipped, bolt_fractured
inline constexpr idx N_STATES = 4;  // plastic_elongation, slip_x, slip_y, fractured

// parameter columns (bolted_joint.py)
inline constexpr idx KS = 0, KP = 1, FV = 2, FY = 3, ALPHA = 4, FU = 5, EPU = 6, MU = 7, KT = 8,
                     CLEAR = 9, KB = 10, CAX = 11, CSH = 12;
inline constexpr idx N_PAR = 13;

/// Bolt tension F_S, N (0 once broken or slack).
inline double bolt_force(const double* p, double u, double e_p, double broken) {
  if (broken > 0.5) return 0.0;
  return py_max(p[FV] + p[KS] * (u - e_p), 0.0);
}

/// Clamp force F_K = max(F_V − k_P·u, 0), N, at the axial deflection u (m): 0 once open.
inline double clamp_force(const double* p, double u) { return py_max(p[FV] - p[KP] * u, 0.0); }

/// The yield force's rise per metre of plastic elongation, N/m: α·k_S/(1 − α), so that the bolt
/// flows along the post-yield tangent α·k_S.
inline double hardening(const double* p) { return p[ALPHA] * p[KS] / (1.0 - p[ALPHA]); }

/// Current yield force, N: linear hardening with the post-yield tangent α·k_S.
inline double yield_limit(const double* p, double e_p) { return p[FY] + hardening(p) * e_p; }

/// The plastic elongation (m) that puts the bolt on its yield line at the axial deflection u:
/// F_V + k_S·(u − e_p) = F_y + hardening·e_p.
inline double yield_elongation(const double* p, double u) {
  return (p[FV] + p[KS] * u - p[FY]) / (p[KS] + hardening(p));
}

/// A face's friction bound μ·F_K (N), its stick spring's stretch e = d − s_p (m, local x and y)
/// and the spring's force k_τ·|e| (N), at the deflection d with the stick point in y from o.
struct Face {
  double limit, ex, ey, tau;
};

inline Face face(const double* p, Vec y, idx o, const double* d) {
  const double ex = d[0] - y[o + 1], ey = d[1] - y[o + 2];
  return {p[MU] * clamp_force(p, d[2]), ex, ey, p[KT] * std::sqrt(ex * ex + ey * ey)};
}

/// Force f and couple c (N, N·m) on the body in local axes; state rates into dydt from o.
/// phi and w are unused (a single bolt carries no moment): c is zero.
inline void load(const double* p, Vec y, idx o, const double* d, const double* v,
                 const double* /*phi*/, const double* /*w*/, Vec dydt, double* f, double* c) {
  const double e_p = y[o], sx = y[o + 1], sy = y[o + 2], broken = y[o + 3];
  const double u = d[2], ud = v[2];
  const double f_s = bolt_force(p, u, e_p, broken);
  const double f_k = clamp_force(p, u);
  const bool flow = broken < 0.5 && f_s >= yield_limit(p, e_p) && ud > 0.0;
  dydt[o] = flow ? (1.0 - p[ALPHA]) * ud : 0.0;
  dydt[o + 3] = 0.0;
  // the dashpots act through the joint: not on a foot whose bolt broke and that left the deck
  const double joined = (broken < 0.5 || f_k > 0.0) ? 1.0 : 0.0;
  f[2] = f_k - f_s - joined * p[CAX] * ud;
  // shear: stick spring in series with slip, bounded by μ·F_K
  const double ex = d[0] - sx, ey = d[1] - sy;
  const double tx = p[KT] * ex, ty = p[KT] * ey;
  const double tau = std::sqrt(tx * tx + ty * ty);
  const double limit = p[MU] * f_k;
  dydt[o + 1] = 0.0;
  dydt[o + 2] = 0.0;
  double scale = 1.0;
  if (limit <= 0.0) {
    // nothing holds the face: the stick point moves with the foot
    scale = 0.0;
    dydt[o + 1] = v[0];
    dydt[o + 2] = v[1];
  } else if (tau >= limit) {
    scale = limit / tau;
    // consistency: sliding keeps k_τ·|e| on the bound μ·F_K as the clamp force moves
    const double norm = tau / p[KT];
    const double rate = (ex * v[0] + ey * v[1]) / norm + p[MU] * p[KP] * ud / p[KT];
    if (rate > 0.0) {
      dydt[o + 1] = rate * ex / norm;
      dydt[o + 2] = rate * ey / norm;
    }
  }
  f[0] = -scale * tx - joined * p[CSH] * v[0];
  f[1] = -scale * ty - joined * p[CSH] * v[1];
  if (broken < 0.5) {
    const double s = std::sqrt(d[0] * d[0] + d[1] * d[1]);
    const double bear = s - p[CLEAR];
    if (bear > 0.0) {
      f[0] -= p[KB] * bear * d[0] / s;
      f[1] -= p[KB] * bear * d[1] / s;
    }
  }
  c[0] = 0.0;
  c[1] = 0.0;
  c[2] = 0.0;
}

/// m: the trial slip past the friction bound in one sample below which `monitor` sees no slip
/// (bolted_joint.py SLIP_FLOOR).
inline constexpr double SLIP_FLOOR = 1e-12;

/// Event functions into g (order of EVENTS; ≥ 0: happening); returns the utilisation F_S/F_y.
/// Yield and slip are judged on the trial state (e_p and slip frozen at y0, the previous
/// sample's state).
inline double monitor(const double* p, Vec y, Vec y0, idx o, const double* d,
                      const double* /*v*/, Vec g) {
  const double e_p = y[o], broken = y[o + 3];
  const double e_t = y0[o], sx = y0[o + 1], sy = y0[o + 2];
  const double u = d[2];
  g[0] = broken < 0.5 ? bolt_force(p, u, e_t, broken) - yield_limit(p, e_t) : -1.0;
  g[1] = p[KP] * u - p[FV];
  const double tx = p[KT] * (d[0] - sx), ty = p[KT] * (d[1] - sy);
  const double shear = std::sqrt(tx * tx + ty * ty), bound = p[MU] * clamp_force(p, u);
  g[2] = p[MU] > 0.0 ? shear - bound - p[KT] * SLIP_FLOOR : -1.0;  // frictionless: no grip
  const double f_s = bolt_force(p, u, e_p, broken);
  g[3] = broken > 0.5 ? 1.0 : py_max(f_s / p[FU] - 1.0, e_p / p[EPU] - 1.0);
  return f_s / p[FY];
}

/// Between samples: a bolt at its ultimate load or elongation breaks, irreversibly. Returns
/// whether it broke now.
inline bool update(const double* p, Vec y, idx o, const double* d) {
  if (y[o + 3] < 0.5) {
    const double f_s = bolt_force(p, d[2], y[o], 0.0);
    if (f_s >= p[FU] || y[o] >= p[EPU]) {
      y[o + 3] = 1.0;
      return true;
    }
  }
  return false;
}

/// The companion's bolt and face after its carried error's kick (engine/kernel.hpp
/// carry_interval; bolted_joint.py carry says why): y the companion's state after the kick, y0
/// the state the kick started from, yt the twin's; d, dt the companion's and the twin's
/// deflections (m, local axes). Where the twin's bolt flows or the companion's passes its yield
/// force, the companion's e_p on its hardening line at its u. While μ·F_K > 0 the stick point's
/// error is carried, not kicked (s ← y0's), then, where the twin's face is on its bound or the
/// companion's passes its own, put on the bound along e (radial return). An open face keeps
/// its kick (ṡ = v there).
constexpr bool CARRIES = true;
inline void carry(const double* p, Vec y, Vec y0, Vec yt, idx o, const double* d,
                  const double* dt) {
  if (y[o + 3] < 0.5 && yt[o + 3] < 0.5) {
    const bool flows = bolt_force(p, dt[2], yt[o], 0.0) >= yield_limit(p, yt[o]);
    if (flows || bolt_force(p, d[2], y[o], 0.0) > yield_limit(p, y[o])) {
      y[o] = py_max(yield_elongation(p, d[2]), 0.0);
    }
  }
  if (!(p[MU] * clamp_force(p, d[2]) > 0.0)) return;
  y[o + 1] = y0[o + 1];
  y[o + 2] = y0[o + 2];
  const Face own = face(p, y, o, d), twin = face(p, yt, o, dt);
  if (own.tau > 0.0 && ((twin.limit > 0.0 && twin.tau >= twin.limit) || own.tau > own.limit)) {
    const double scale = own.limit / own.tau;
    y[o + 1] = d[0] - scale * own.ex;
    y[o + 2] = d[1] - scale * own.ey;
  }
}

/// Internal states of a joint (all joints have them). For the bindings' checks.
inline idx states(const double* /*p*/) { return N_STATES; }

/// A joint's row cannot make the law index outside it. For the bindings' checks.
inline const char* invalid(const double* /*p*/) { return nullptr; }

}  // namespace mt::kinds::bolted_joint
