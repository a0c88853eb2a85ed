// Rubber-metal (elastomeric) mount: the port of mount_twin/kinds/elastomer.py's force law
// (`load`), event functions (`monitor`) and switches (`update`), held to it by
// mount_twin.kinds.check_dispatch. Same operations in the same order as the Python reference
// (results bitwise equal to it where the platform's libm agrees).
//
// Along each local axis (deflection x, m; rate ẋ, m/s):
//     F = a·F_el(x) + (1 − a)·k₀·z + c·ẋ + F_snub      (a = 1 without hysteresis)
// F_el: PCHIP table (extended linearly) or k₁·x + k₃·x³; z: Bouc–Wen, internal state;
// F_snub: k_s·⟨|x| − g⟩ᵖ·(1 + h·δ̇) in compression only. Rotations: linear springs and dampers.
#pragma once

#include <cmath>

#include "../numeric.hpp"
#include "../views.hpp"

namespace mt::kinds::elastomer {

inline constexpr const char* KIND = "elastomer";
inline constexpr int N_EVENTS = 2;  // snubber_contact, over_travel
inline constexpr idx TABLE_MAX = 16;  // most points in a force–deflection table

// parameter columns, per axis block of N_AXIS starting at j·N_AXIS (elastomer.py)
inline constexpr idx K1 = 0, K3 = 1, C = 2, RATIO = 3, BW_A = 4, BETA = 5, GAMMA = 6, N_EXP = 7,
                     K0 = 8, ZSLOT = 9, GAP = 10, KS = 11, PEXP = 12, HC = 13, RATED = 14,
                     NTAB = 15;
inline constexpr idx TAB_X = 16;
inline constexpr idx TAB_C = TAB_X + TABLE_MAX;
inline constexpr idx N_AXIS = TAB_C + 4 * (TABLE_MAX - 1);
inline constexpr idx ROT = 3 * N_AXIS;
inline constexpr idx N_PAR = ROT + 6;
static_assert(N_PAR == 282, "elastomer.py: N_PAR = 3·(16 + 16 + 4·15) + 6");

/// PCHIP segment k of the axis block at b at dx from its left knot, N.
inline double segment(const double* p, idx b, idx k, double dx) {
  const idx c = b + TAB_C + 4 * k;
  return ((p[c] * dx + p[c + 1]) * dx + p[c + 2]) * dx + p[c + 3];
}

/// F_el(x) of the axis block at b, N: PCHIP table (linear beyond it) or k₁x + k₃x³.
inline double elastic_force(const double* p, idx b, double x) {
  const idx n = static_cast<idx>(p[b + NTAB]);  // int(): truncation
  if (n == 0) return p[b + K1] * x + p[b + K3] * x * x * x;
  const double x0 = p[b + TAB_X], xn = p[b + TAB_X + n - 1];
  if (x <= x0) return segment(p, b, 0, 0.0) + p[b + TAB_C + 2] * (x - x0);
  if (x >= xn) {
    const idx k = n - 2;
    const double h = xn - p[b + TAB_X + k];
    const idx c = b + TAB_C + 4 * k;
    const double slope = 3.0 * p[c] * h * h + 2.0 * p[c + 1] * h + p[c + 2];
    return segment(p, b, k, h) + slope * (x - xn);
  }
  idx k = 0;
  while (x > p[b + TAB_X + k + 1]) ++k;
  return segment(p, b, k, x - p[b + TAB_X + k]);
}

/// ż of the axis block at b, m/s (Bouc–Wen).
inline double bouc_wen_rate(const double* p, idx b, double z, double xd) {
  const double az = std::fabs(z);
  // |z|¹ without the call: pow(x, 1) is x exactly, and the default n = 1 spent a third of the
  // time of 256 hysteretic mounts in pow
  const double zn = p[b + N_EXP] == 1.0 ? az : std::pow(az, p[b + N_EXP]);
  const double zn1 = az > 0.0 ? zn / az : (p[b + N_EXP] == 1.0 ? 1.0 : 0.0);
  return p[b + BW_A] * xd - p[b + BETA] * std::fabs(xd) * zn1 * z - p[b + GAMMA] * xd * zn;
}

/// Contact force magnitude of the axis block's snubber, N (≥ 0; 0 without contact).
inline double snubber_force(const double* p, idx b, double x, double xd) {
  const double gap = p[b + GAP];
  if (gap < 0.0) return 0.0;
  const double pen = std::fabs(x) - gap;
  if (pen <= 0.0) return 0.0;
  const double pen_rate = x > 0.0 ? xd : -xd;
  return py_max(p[b + KS] * std::pow(pen, p[b + PEXP]) * (1.0 + p[b + HC] * pen_rate), 0.0);
}

/// Force f and couple c on the body in local axes (N, N·m); ż into dydt from o.
inline void load(const double* p, Vec y, idx o, const double* d, const double* v,
                 const double* phi, const double* w, Vec dydt, double* f, double* c) {
  for (idx j = 0; j < 3; ++j) {
    const idx b = j * N_AXIS;
    const double x = d[j], xd = v[j];
    const double a = p[b + RATIO];
    double force = a * elastic_force(p, b, x) + p[b + C] * xd;
    const idx slot = static_cast<idx>(p[b + ZSLOT]);
    if (slot >= 0) {
      const double z = y[o + slot];
      force += (1.0 - a) * p[b + K0] * z;
      dydt[o + slot] = bouc_wen_rate(p, b, z, xd);
    }
    const double snub = snubber_force(p, b, x, xd);
    force += x > 0.0 ? snub : -snub;
    f[j] = -force;
    c[j] = -(p[ROT + j] * phi[j] + p[ROT + 3 + j] * w[j]);
  }
}

/// Snubber contact (|x| − gap, m) and over-travel (|x|/rated − 1) into g; returns the largest
/// |x|/rated (0 if no axis is rated).
inline double monitor(const double* p, Vec /*y*/, Vec /*y0*/, idx /*o*/, const double* d,
                      const double* /*v*/, Vec g) {
  g[0] = -1.0;
  g[1] = -1.0;
  double util = 0.0;
  for (idx j = 0; j < 3; ++j) {
    const idx b = j * N_AXIS;
    if (p[b + GAP] >= 0.0) g[0] = py_max(g[0], std::fabs(d[j]) - p[b + GAP]);
    if (p[b + RATED] > 0.0) {
      const double u = std::fabs(d[j]) / p[b + RATED];
      util = py_max(util, u);
      g[1] = py_max(g[1], u - 1.0);
    }
  }
  return util;
}

/// The companion after its carried error's kick (bolted_joint.hpp carry): A Bouc–Wen z has a rate: its kick carries it. Nothing to return.
/// CARRIES false: the companion does not call it (test_core_contract holds that it writes
/// nothing).
constexpr bool CARRIES = false;
inline void carry(const double* /*p*/, Vec /*y*/, Vec /*y0*/, Vec /*yt*/, idx /*o*/,
                  const double* /*d*/, const double* /*dt*/) {}

/// No discrete state: never switches.
inline bool update(const double* /*p*/, Vec /*y*/, idx /*o*/, const double* /*d*/) {
  return false;
}

/// Internal states the row p asks for (one Bouc–Wen z per hysteretic axis, at o + slot):
/// 1 + the largest slot, 0 without hysteresis. For the bindings' checks.
inline idx states(const double* p) {
  idx n = 0;
  for (idx j = 0; j < 3; ++j) {
    const idx slot = static_cast<idx>(p[j * N_AXIS + ZSLOT]);
    if (slot + 1 > n) n = slot + 1;
  }
  return n;
}

/// Why the row p would make the law index outside it (nullptr: it cannot): a table length or
/// a state slot that is not a small finite number. For the bindings' checks.
inline const char* invalid(const double* p) {
  for (idx j = 0; j < 3; ++j) {
    const double n = p[j * N_AXIS + NTAB], slot = p[j * N_AXIS + ZSLOT];
    if (!(n > -1.0 && n < static_cast<double>(TABLE_MAX + 1))) {
      return "elastomer: a force-table length (column NTAB of an axis block) outside 0..16";
    }
    if (!(slot > -1.0e9 && slot < 1.0e9)) {
      return "elastomer: a Bouc-Wen state slot (column ZSLOT of an axis block) is not finite";
    }
  }
  return nullptr;
}

}  // namespace mt::kinds::elastomer
