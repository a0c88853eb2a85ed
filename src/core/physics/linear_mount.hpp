// Six-component linear Kelvin–Voigt mount (physics notes §7).
//
// Parameters, per mount i, are pre-rotated at scene load into F: K_t = Q·diag(kx, ky, kz)·Qᵀ,
// C_t, K_r, C_r likewise, with Q the mount axes in F. Deformation is measured from the reference
// pose, where the mount is unstressed.
//
// The rotational spring and damper act on the rotation vector φ of the body's attitude: they give
// a generalized force g = K_r·φ + C_r·φ′ conjugate to φ, and its couple on the body is −J(φ)⁻ᵀ·g
// (`rotations.couple_map`). The spring is then the gradient of ½ φᵀK_rφ, conservative at any
// rotation, anisotropic or not; the couple −K_r·φ, its small-rotation limit, is not (an
// undamped body on anisotropic rotational springs turned 0.4 rad drifted by 9 % of its energy).
#pragma once

#include <cmath>

#include "../model.hpp"
#include "../numeric.hpp"

namespace mt::physics {

/// Displacement d (m) and velocity ḋ (m/s) in F of body point `point` from its reference
/// position into de[0..2], de[3..5]; the lever arm R·p (m, F) into `arm`.
inline void point_motion(const double* point, M3 rot, Vec q, Vec qd, Vec omega_f, Vec arm,
                         double* de) {
  for (int j = 0; j < 3; ++j) {
    arm[j] = rot(j, 0) * point[0] + rot(j, 1) * point[1] + rot(j, 2) * point[2];
  }
  de[0] = q[0] + arm[0] - point[0];
  de[1] = q[1] + arm[1] - point[1];
  de[2] = q[2] + arm[2] - point[2];
  de[3] = qd[0] + omega_f[1] * arm[2] - omega_f[2] * arm[1];
  de[4] = qd[1] + omega_f[2] * arm[0] - omega_f[0] * arm[2];
  de[5] = qd[2] + omega_f[0] * arm[1] - omega_f[1] * arm[0];
}

/// Load of linear mount i on the body, in F: force (N) at its point, lever arm `arm` (m),
/// its own couple (N·m) through the couple map of the generalized force K_r·φ + C_r·φ′.
inline void linear_mount_load(idx i, const Model& m, const Scratch& s, Vec arm, Vec force,
                              Vec couple) {
  double de[6];
  point_motion(&m.lin_point(i, 0), s.rot, s.q, s.qd, s.omega_f, arm, de);
  const M33s &k_t = m.lin_k_t, &c_t = m.lin_c_t, &k_r = m.lin_k_r, &c_r = m.lin_c_r;
  for (int j = 0; j < 3; ++j) {
    force[j] = -(k_t(i, j, 0) * de[0] + k_t(i, j, 1) * de[1] + k_t(i, j, 2) * de[2] +
                 c_t(i, j, 0) * de[3] + c_t(i, j, 1) * de[4] + c_t(i, j, 2) * de[5]);
  }
  double g[3];
  const Vec phi = s.phi, rate = s.phi_rate;
  for (int j = 0; j < 3; ++j) {
    g[j] = k_r(i, j, 0) * phi[0] + k_r(i, j, 1) * phi[1] + k_r(i, j, 2) * phi[2] +
           c_r(i, j, 0) * rate[0] + c_r(i, j, 1) * rate[1] + c_r(i, j, 2) * rate[2];
  }
  const M3 cmap = s.couple_map;
  for (int j = 0; j < 3; ++j) {
    couple[j] = -(cmap(j, 0) * g[0] + cmap(j, 1) * g[1] + cmap(j, 2) * g[2]);
  }
}

/// Fold each linear mount's utilisation at the body motion in s into peak (running maxima):
/// the largest over its axes of |travel| / rated travel and |force| / rated load (the travel
/// Qᵀ·d from the reference pose, the force from its wrench row in its axes; m.lin_per_rating
/// holds the inverse ratings, 0 where unrated).
inline void linear_utilisation(const Model& m, const Scratch& s, M6 wrenches, Vec peak) {
  double arm_d[3], de[6];
  const Vec arm{arm_d, 3};
  const M33s& axes = m.lin_axes;
  for (idx i = 0; i < m.lin_point.rows; ++i) {
    point_motion(&m.lin_point(i, 0), s.rot, s.q, s.qd, s.omega_f, arm, de);
    const idx row = m.lin_slot[i];
    double u = peak[i];
    for (int j = 0; j < 3; ++j) {
      const double travel = axes(i, 0, j) * de[0] + axes(i, 1, j) * de[1] + axes(i, 2, j) * de[2];
      u = py_max(u, std::fabs(travel) * m.lin_per_rating(i, j));
      u = py_max(u, std::fabs(wrenches(row, j)) * m.lin_per_rating(i, 3 + j));
    }
    peak[i] = u;
  }
}

}  // namespace mt::physics
