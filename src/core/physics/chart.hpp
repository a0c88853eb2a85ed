// The paper's attitude chart (α, γ, δ) with its corrected kinematics (physics/chart.py holds
// the reference and the derivation; physics notes §2–§4). Angles rad, rates rad/s.
#pragma once

#include <cmath>

#include "../views.hpp"

namespace mt::physics {

/// Write R into `out` (3×3) from sin α, sin γ, cos γ, sin δ, cos δ; return cos θ (NaN off the
/// chart, `out` untouched).
inline double rotation_from_chart(double sa, double sg, double cg, double sd, double cd,
                                  M3 out) {
  const double c2 = cg * cg - sa * sa;
  if (!(c2 > 0.0 && cg > 0.0)) return NAN;
  const double ct = std::sqrt(c2);
  const double sb = sa / cg, cb = ct / cg;
  const double r1[3] = {cg, -sg * sb, -sg * cb};
  const double r2[3] = {0.0, cb, -sb};
  for (int j = 0; j < 3; ++j) {
    out(0, j) = cd * r1[j] - sd * r2[j];
    out(1, j) = sd * r1[j] + cd * r2[j];
  }
  out(2, 0) = sg;
  out(2, 1) = sa;
  out(2, 2) = ct;
  return ct;
}

/// B with ω = B·[α', γ', δ'].
inline void kinematic_matrix(double sa, double ca, double sg, double cg, double ct, M3 out) {
  out(0, 0) = ca / ct;
  out(0, 1) = sa * sg / (cg * ct);
  out(0, 2) = sg;
  out(1, 0) = 0.0;
  out(1, 1) = -ct / cg;
  out(1, 2) = sa;
  out(2, 0) = 0.0;
  out(2, 1) = sa / cg;
  out(2, 2) = ct;
}

/// x = B⁻¹·v (B of `kinematic_matrix`): the chart rates (α', γ', δ') of the angular velocity
/// v (rad/s, body axes), or their accelerations of an angular acceleration. B's lower 2×2
/// block has determinant −cos γ (cos²θ + sin²α = cos²γ), and its first column is (cos α /
/// cos θ, 0, 0): both invertible on the chart (cos θ > 0 needs |sin α| < cos γ).
inline void inverse_kinematic(double sa, double ca, double sg, double cg, double ct,
                              const double* v, double* x) {
  x[1] = -(ct * v[1] - sa * v[2]) / cg;
  x[2] = (sa * v[1] + ct * v[2]) / (cg * cg);
  x[0] = (v[0] - sa * sg / (cg * ct) * x[1] - sg * x[2]) * ct / ca;
}

/// dB/dt along the motion, 1/s.
inline void kinematic_matrix_rate(double sa, double ca, double sg, double cg, double ct,
                                  double alpha_dot, double gamma_dot, M3 out) {
  const double ct_dot = -(alpha_dot * sa * ca + gamma_dot * sg * cg) / ct;
  const double sa_dot = ca * alpha_dot, sg_dot = cg * gamma_dot;
  const double ca_dot = -sa * alpha_dot, cg_dot = -sg * gamma_dot;
  out(0, 0) = (ca_dot * ct - ca * ct_dot) / (ct * ct);
  const double num = sa * sg, den = cg * ct;
  out(0, 1) = ((sa_dot * sg + sa * sg_dot) * den - num * (cg_dot * ct + cg * ct_dot)) / (den * den);
  out(0, 2) = sg_dot;
  out(1, 0) = 0.0;
  out(1, 1) = -(ct_dot * cg - ct * cg_dot) / (cg * cg);
  out(1, 2) = sa_dot;
  out(2, 0) = 0.0;
  out(2, 1) = (sa_dot * cg - sa * cg_dot) / (cg * cg);
  out(2, 2) = ct_dot;
}

}  // namespace mt::physics
