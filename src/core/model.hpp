// The assembled model and the scratch, as views of the Python side's arrays
// (physics/dynamics.py ModelArrays, NonLinearMounts and Scratch: same fields, same meaning,
// SI units, frames as named there).
#pragma once

#include <vector>

#include "views.hpp"

namespace mt {

/// Mounts of the kinds in mount_twin.kinds (k of them).
struct NonLinear {
  idx k = 0;
  IVec kind;        // (k,) kind code
  M3 point;         // (k, 3) m, attachment point from the CG, in B
  M33s axes;        // (k, 3, 3) mount axes Q (columns) in F
  IVec slot;        // (k,) index in the scene
  IVec state;       // (k,) offset of the mount's internal states in y (−1: none)
  Mat par;          // (k, N_PAR) parameter rows
  BVec rotational;  // (k,) the kind has a rotational law
  BVec aligned;     // (k,) the mount's axes are F's
};

struct Model {
  double mass = 0.0;     // kg
  M3 inertia;            // (3, 3) kg·m², about the CG, in B
  double inertia_inv[3][3] = {};  // its inverse, 1/(kg·m²) (convert fills it)
  Vec cg_ref;            // (3,) m, in F
  Vec sensor_position;   // (3,) m, in F
  IVec free_trans;       // (nt,) free indices among X, Y, Z
  IVec free_rot;         // (nr,) free indices among α, γ, δ
  Vec q_fixed;           // (6,)
  M3 lin_point;          // (n, 3) m, in B
  M33s lin_axes;         // (n, 3, 3)
  M33s lin_k_t, lin_c_t, lin_k_r, lin_c_r;  // (n, 3, 3) in F
  double lin_k_r_sum[9] = {}, lin_c_r_sum[9] = {};  // Σ lin_k_r, Σ lin_c_r (row-major)
  std::vector<double> lin_lanes;  // the linear mounts' points and laws in blocks of LANES
                                  // mounts side by side (physics/linear_mount.hpp)
  IVec lin_slot;         // (n,)
  M6 lin_per_rating;     // (n, 6) 1/m (travel x, y, z), then 1/N (load); 0: unrated
  bool has_nl = false;   // NonLinearMounts present (None on the Python side: false)
  NonLinear nl;
  bool rotation_read = false;
};

/// Work arrays (physics/dynamics.py Scratch says who fills what and who may read it).
struct Scratch {
  Vec q, trig, qd;
  M3 rot, kin, kin_rate;
  Vec omega, omega_f, phi, phi_rate;
  M3 couple_map;
  Vec quat, total_force, total_moment, f_s, big_w, big_w_dot, rel, w_x_rel,
      moment_b, w_b, w_dot_b, acc, w_abs, h, i_w;
  M3 mass_rot;
  Vec rhs_rot, rate_step;
  Vec sink;  // (n_state,)
};

}  // namespace mt
