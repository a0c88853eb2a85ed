// Rotation helpers: quaternion (x, y, z, w), rotation vector, the couple map J(φ)⁻ᵀ
// (physics/rotations.py holds the quaternion's Python twin, which the io layer uses).
#pragma once

#include <cmath>

#include "../numeric.hpp"
#include "../views.hpp"

namespace mt::physics {

/// Unit quaternion (x, y, z, w), w ≥ 0, of a rotation matrix (Shepperd's method).
inline void quaternion_from_matrix(M3 rot, Vec out) {
  const double tr = rot(0, 0) + rot(1, 1) + rot(2, 2);
  if (tr > py_max(py_max(rot(0, 0), rot(1, 1)), rot(2, 2))) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    out[3] = 0.25 * s;
    out[0] = (rot(2, 1) - rot(1, 2)) / s;
    out[1] = (rot(0, 2) - rot(2, 0)) / s;
    out[2] = (rot(1, 0) - rot(0, 1)) / s;
  } else if (rot(0, 0) >= rot(1, 1) && rot(0, 0) >= rot(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + rot(0, 0) - rot(1, 1) - rot(2, 2));
    out[3] = (rot(2, 1) - rot(1, 2)) / s;
    out[0] = 0.25 * s;
    out[1] = (rot(0, 1) + rot(1, 0)) / s;
    out[2] = (rot(0, 2) + rot(2, 0)) / s;
  } else if (rot(1, 1) >= rot(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + rot(1, 1) - rot(0, 0) - rot(2, 2));
    out[3] = (rot(0, 2) - rot(2, 0)) / s;
    out[0] = (rot(0, 1) + rot(1, 0)) / s;
    out[1] = 0.25 * s;
    out[2] = (rot(1, 2) + rot(2, 1)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + rot(2, 2) - rot(0, 0) - rot(1, 1));
    out[3] = (rot(1, 0) - rot(0, 1)) / s;
    out[0] = (rot(0, 2) + rot(2, 0)) / s;
    out[1] = (rot(1, 2) + rot(2, 1)) / s;
    out[2] = 0.25 * s;
  }
  if (out[3] < 0.0) {
    for (int i = 0; i < 4; ++i) out[i] = -out[i];
  }
}

/// Rotation vector (axis × angle, rad) of `rot`; `quat` (4) receives its quaternion.
inline void rotation_vector(M3 rot, Vec quat, Vec out) {
  quaternion_from_matrix(rot, quat);
  const double sin_half = std::sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2]);
  const double scale = sin_half > 1e-12 ? 2.0 * std::atan2(sin_half, quat[3]) / sin_half : 2.0;
  for (int i = 0; i < 3; ++i) out[i] = scale * quat[i];
}

/// J(φ)⁻ᵀ = 1 + ½[φ]× + c·[φ]×², c = 1/θ² − cot(θ/2)/(2θ), θ = |φ| (rad): the inverse
/// transpose of the left Jacobian of SO(3) at the rotation vector φ of a rotation whose
/// quaternion (x, y, z, w), w ≥ 0, is `quat` (as `rotation_vector` left it).
///
/// A body turned by δθ (in F, small) changes φ by J(φ)⁻¹·δθ, and φ changes at J(φ)⁻¹·ω for
/// an angular velocity ω in F. So a mount law giving a generalized force g conjugate to φ (a
/// spring −K·φ: the gradient of ½ φᵀKφ) exerts the couple J(φ)⁻ᵀ·g on the body, and it
/// conserves energy at any rotation; at small φ the map is 1 + O(φ).
inline void couple_map(Vec phi, Vec quat, M3 out) {
  const double angle_sq = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2];
  double c;
  if (angle_sq < 1e-4) {
    c = 1.0 / 12.0 + angle_sq / 720.0 + angle_sq * angle_sq / 30240.0;
  } else {
    const double angle = std::sqrt(angle_sq);
    const double sin_half = std::sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2]);
    c = 1.0 / angle_sq - quat[3] / (2.0 * angle * sin_half);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out(i, j) = c * phi[i] * phi[j];
    out(i, i) += 1.0 - c * angle_sq;
  }
  out(0, 1) -= 0.5 * phi[2];
  out(1, 0) += 0.5 * phi[2];
  out(0, 2) += 0.5 * phi[1];
  out(2, 0) -= 0.5 * phi[1];
  out(1, 2) -= 0.5 * phi[0];
  out(2, 1) += 0.5 * phi[0];
}

}  // namespace mt::physics
