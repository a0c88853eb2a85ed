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
#include <cstddef>

#include "../model.hpp"
#include "../numeric.hpp"

namespace mt::physics {

/// The body motion at y that the mount laws read, copied out of the scratch once per call
/// (`Motion::of`): plain local values the compiler keeps in registers, where the scratch's
/// views, which may alias one another, make it reload every operand after every store.
struct Motion {
  double rot[3][3];   // R, B → F
  double q[3];        // m, the CG's displacement from its reference, F
  double qd[3];       // m/s, its rate
  double w[3];        // rad/s, the body's angular velocity R·ω, F
  double phi[3];      // rad, the rotation vector of R (NaN unless a mount reads it)
  double rate[3];     // rad/s, its rate
  double cmap[3][3];  // J(φ)⁻ᵀ

  /// The motion body_motion left in s.
  static Motion of(const Scratch& s) {
    Motion mo;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        mo.rot[i][j] = s.rot(i, j);
        mo.cmap[i][j] = s.couple_map(i, j);
      }
      mo.q[i] = s.q[i];
      mo.qd[i] = s.qd[i];
      mo.w[i] = s.omega_f[i];
      mo.phi[i] = s.phi[i];
      mo.rate[i] = s.phi_rate[i];
    }
    return mo;
  }
};

/// Displacement d (m) and velocity ḋ (m/s) in F of body point `point` from its reference
/// position into de[0..2], de[3..5]; the lever arm R·p (m, F) into `arm`.
inline void point_motion(const double* point, const Motion& mo, double* arm, double* de) {
  const double p[3] = {point[0], point[1], point[2]};  // locals: arm may alias point
  double a[3];
  for (int j = 0; j < 3; ++j) a[j] = mo.rot[j][0] * p[0] + mo.rot[j][1] * p[1] + mo.rot[j][2] * p[2];
  de[0] = mo.q[0] + a[0] - p[0];
  de[1] = mo.q[1] + a[1] - p[1];
  de[2] = mo.q[2] + a[2] - p[2];
  de[3] = mo.qd[0] + mo.w[1] * a[2] - mo.w[2] * a[1];
  de[4] = mo.qd[1] + mo.w[2] * a[0] - mo.w[0] * a[2];
  de[5] = mo.qd[2] + mo.w[0] * a[1] - mo.w[1] * a[0];
  for (int j = 0; j < 3; ++j) arm[j] = a[j];
}

/// Kelvin–Voigt force (N, F) −(K·d + C·ḋ) of a mount of stiffness k (N/m) and damping c
/// (N·s/m), 3×3 row-major in F, at displacement and velocity de = (d, ḋ) (m, m/s, F).
inline void kelvin_voigt(const double* k, const double* c, const double* de, double* force) {
  for (int j = 0; j < 3; ++j) {
    const double* kj = k + 3 * j;
    const double* cj = c + 3 * j;
    force[j] = -(kj[0] * de[0] + kj[1] * de[1] + kj[2] * de[2] + cj[0] * de[3] +
                 cj[1] * de[4] + cj[2] * de[5]);
  }
}

/// The couple (N·m, F) of rotational springs k_r and dampers c_r (3×3, row-major, F) through
/// the couple map of their generalized force K_r·φ + C_r·φ′. The law is linear in K_r and
/// C_r, so the summed matrices give the linear mounts' total couple in one call.
inline void linear_couple(const double* k_r, const double* c_r, const Motion& mo,
                          double* couple) {
  double g[3];
  for (int j = 0; j < 3; ++j) {
    const double* k = k_r + 3 * j;
    const double* c = c_r + 3 * j;
    g[j] = k[0] * mo.phi[0] + k[1] * mo.phi[1] + k[2] * mo.phi[2] + c[0] * mo.rate[0] +
           c[1] * mo.rate[1] + c[2] * mo.rate[2];
  }
  for (int j = 0; j < 3; ++j) {
    couple[j] = -(mo.cmap[j][0] * g[0] + mo.cmap[j][1] * g[1] + mo.cmap[j][2] * g[2]);
  }
}

/// Model.lin_lanes holds blocks of LANES linear mounts (the last one padded with zeros), each
/// LANE_ROWS rows of LANES: the points (m, B), K_t, C_t, K_r, C_r (F, row-major) and the
/// axes Q (F, row-major), component by component, so that the loops over a block's mounts
/// read each at a fixed offset from the block and the compiler computes two mounts per
/// instruction.
constexpr idx LANES = 8;
constexpr idx LANE_POINT = 0, LANE_K = 3, LANE_C = 12, LANE_K_R = 21, LANE_C_R = 30,
              LANE_AXES = 39, LANE_ROWS = 48;
using Block = const double (*)[LANES];

/// Fill m.lin_lanes from m.lin_point, lin_k_t, lin_c_t, lin_k_r, lin_c_r and lin_axes.
inline void lay_out_lanes(Model& m) {
  const idx n = m.lin_point.rows, blocks = (n + LANES - 1) / LANES;
  m.lin_lanes.assign(static_cast<std::size_t>(blocks * LANE_ROWS * LANES), 0.0);
  double* lanes = m.lin_lanes.data();
  for (idx i = 0; i < n; ++i) {
    double* lane = lanes + (i / LANES) * LANE_ROWS * LANES + i % LANES;
    for (idx c = 0; c < 3; ++c) lane[(LANE_POINT + c) * LANES] = m.lin_point(i, c);
    for (idx k = 0; k < 9; ++k) {
      lane[(LANE_K + k) * LANES] = m.lin_k_t.d[9 * i + k];
      lane[(LANE_C + k) * LANES] = m.lin_c_t.d[9 * i + k];
      lane[(LANE_K_R + k) * LANES] = m.lin_k_r.d[9 * i + k];
      lane[(LANE_C_R + k) * LANES] = m.lin_c_r.d[9 * i + k];
      lane[(LANE_AXES + k) * LANES] = m.lin_axes.d[9 * i + k];
    }
  }
}

/// The block of linear mounts from mount `first` (a multiple of LANES).
inline Block block_of(const Model& m, idx first) {
  return reinterpret_cast<Block>(m.lin_lanes.data() + first * LANE_ROWS);
}

/// row[0..count) of the block from lane row `row` (count ≤ 9) of lane l into out.
inline void lane_rows(Block block, idx row, idx count, idx l, double* out) {
  for (idx j = 0; j < count; ++j) out[j] = block[row + j][l];
}

/// Lane l of a block: the mount's lever arm R·p (m) and Kelvin–Voigt force (N) on the body, F.
inline void lane_force(Block block, idx l, const Motion& mo, double* arm, double* force) {
  double point[3], k[9], c[9], de[6];
  lane_rows(block, LANE_POINT, 3, l, point);
  lane_rows(block, LANE_K, 9, l, k);
  lane_rows(block, LANE_C, 9, l, c);
  point_motion(point, mo, arm, de);
  kelvin_voigt(k, c, de, force);
}

/// Add the linear mounts' forces (N) and their moments about the CG (N·m), F, to total_f and
/// total_m, mount by mount in scene order (`lane_force`, then dynamics.hpp add_load's sums), a
/// block of LANES mounts at a time.
inline void linear_loads(const Model& m, const Motion& mo, double* total_f, double* total_m) {
  const idx n = m.lin_point.rows;
  for (idx first = 0; first < n; first += LANES) {
    const Block block = block_of(m, first);
    double load[6][LANES];
    for (idx l = 0; l < LANES; ++l) {  // the padding's lanes too: a fixed count, zero loads
      double arm[3], f[3];
      lane_force(block, l, mo, arm, f);
      for (idx j = 0; j < 3; ++j) load[j][l] = f[j];
      load[3][l] = arm[1] * f[2] - arm[2] * f[1] + 0.0;  // + 0.0: add_load's no own couple
      load[4][l] = arm[2] * f[0] - arm[0] * f[2] + 0.0;
      load[5][l] = arm[0] * f[1] - arm[1] * f[0] + 0.0;
    }
    const idx count = n - first < LANES ? n - first : LANES;
    for (idx l = 0; l < count; ++l) {
      for (idx j = 0; j < 3; ++j) {
        total_f[j] += load[j][l];
        total_m[j] += load[3 + j][l];
      }
    }
  }
}

/// Each linear mount's force (N) and own couple (N·m) on the body, in its axes, into its
/// wrenches row (m.lin_slot), a block of LANES mounts at a time.
inline void linear_wrenches(const Model& m, const Motion& mo, M6 wrenches) {
  const idx n = m.lin_point.rows;
  for (idx first = 0; first < n; first += LANES) {
    const Block block = block_of(m, first);
    double out[6][LANES];
    for (idx l = 0; l < LANES; ++l) {
      double arm[3], f[3], k_r[9], c_r[9], c[3], q[9];
      lane_force(block, l, mo, arm, f);
      lane_rows(block, LANE_K_R, 9, l, k_r);
      lane_rows(block, LANE_C_R, 9, l, c_r);
      lane_rows(block, LANE_AXES, 9, l, q);
      linear_couple(k_r, c_r, mo, c);
      for (idx j = 0; j < 3; ++j) {  // Qᵀ·f, Qᵀ·c
        out[j][l] = q[j] * f[0] + q[3 + j] * f[1] + q[6 + j] * f[2];
        out[3 + j][l] = q[j] * c[0] + q[3 + j] * c[1] + q[6 + j] * c[2];
      }
    }
    const idx count = n - first < LANES ? n - first : LANES;
    for (idx l = 0; l < count; ++l) {
      const idx row = m.lin_slot[first + l];
      for (idx j = 0; j < 6; ++j) wrenches(row, j) = out[j][l];
    }
  }
}

/// Fold each linear mount's utilisation at the body motion in s into peak (running maxima):
/// the largest over its axes of |travel| / rated travel and |force| / rated load (the travel
/// Qᵀ·d from the reference pose, the force from its wrench row in its axes; m.lin_per_rating
/// holds the inverse ratings, 0 where unrated).
inline void linear_utilisation(const Model& m, const Scratch& s, M6 wrenches, Vec peak) {
  double arm[3], de[6];
  const M33s& axes = m.lin_axes;
  const Motion mo = Motion::of(s);
  for (idx i = 0; i < m.lin_point.rows; ++i) {
    point_motion(&m.lin_point(i, 0), mo, arm, de);
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
