// Equations of motion on the free generalized coordinates, in the moving foundation frame F
// (physics/dynamics.py holds the derivation, the state layout and which call fills which
// scratch field; this is the compiled implementation). The hot loops read the body motion from
// a `Motion` of locals and solve the 3×3 system at a fixed size: the scratch's views may alias,
// and through them the compiler reloads every operand after every store.
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../kinds/dispatch.hpp"
#include "../model.hpp"
#include "chart.hpp"
#include "dynamics_api.hpp"
#include "linear_mount.hpp"
#include "rotations.hpp"
#include "small_angles.hpp"

namespace mt::physics {

/// cos θ below which the state counts as off the chart (dynamics.py COS_TILT_MIN).
constexpr double COS_TILT_MIN = 1.0e-6;

/// The body motion at y into mo, and into s.q, s.qd, s.trig, s.rot, s.kin, s.omega, s.omega_f
/// (and s.phi, s.quat, s.phi_rate, s.couple_map where m.rotation_read, else NaN); returns
/// cos θ (NaN off the chart: mo is then incomplete). Computed in locals, the scratch written
/// once: read back through its views, which may alias, values just stored one by one stalled
/// on store forwarding (the pump's rhs).
inline double body_motion(Vec y, const Model& m, Scratch& s, Motion& mo) {
  const idx nt = m.free_trans.n, nr = m.free_rot.n, nf = nt + nr;
  double q[6], qd[6], trig[6];
  for (int i = 0; i < 6; ++i) {
    q[i] = m.q_fixed[i];
    qd[i] = 0.0;
  }
  for (idx k = 0; k < nt; ++k) {
    q[m.free_trans[k]] = y[k];
    qd[m.free_trans[k]] = y[nf + k];
  }
  for (idx k = 0; k < nr; ++k) {
    q[3 + m.free_rot[k]] = y[nt + k];
    qd[3 + m.free_rot[k]] = y[nf + nt + k];
  }
  for (int i = 0; i < 3; ++i) {
    sin_cos(q[3 + i], trig[i], trig[3 + i]);
  }
  for (int i = 0; i < 6; ++i) {
    s.q[i] = q[i];
    s.qd[i] = qd[i];
    s.trig[i] = trig[i];
  }
  const double sa = trig[0], sg = trig[1], sd = trig[2], ca = trig[3], cg = trig[4],
               cd = trig[5];
  const M3 rot{&mo.rot[0][0], 3};
  const double ct = rotation_from_chart(sa, sg, cg, sd, cd, rot);
  if (std::isnan(ct)) return NAN;  // rot not written
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) s.rot(i, j) = mo.rot[i][j];
  }
  if (!(ct > COS_TILT_MIN)) return NAN;
  double kin[3][3], omega[3];
  kinematic_matrix(sa, ca, sg, cg, ct, M3{&kin[0][0], 3});
  for (int i = 0; i < 3; ++i) omega[i] = kin[i][0] * qd[3] + kin[i][1] * qd[4] + kin[i][2] * qd[5];
  for (int i = 0; i < 3; ++i) {
    mo.w[i] = rot(i, 0) * omega[0] + rot(i, 1) * omega[1] + rot(i, 2) * omega[2];
    mo.q[i] = q[i];
    mo.qd[i] = qd[i];
  }
  if (m.rotation_read) {
    double quat[4];
    const Vec phi{mo.phi, 3};
    rotation_vector(rot, Vec{quat, 4}, phi);
    couple_map(phi, Vec{quat, 4}, M3{&mo.cmap[0][0], 3});
    for (int i = 0; i < 3; ++i) {
      mo.rate[i] = mo.cmap[0][i] * mo.w[0] + mo.cmap[1][i] * mo.w[1] + mo.cmap[2][i] * mo.w[2];
    }
    for (int i = 0; i < 4; ++i) s.quat[i] = quat[i];
  } else {
    for (int i = 0; i < 3; ++i) {
      mo.phi[i] = NAN;
      mo.rate[i] = NAN;
      for (int j = 0; j < 3; ++j) mo.cmap[i][j] = NAN;
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      s.kin(i, j) = kin[i][j];
      s.couple_map(i, j) = mo.cmap[i][j];
    }
    s.omega[i] = omega[i];
    s.omega_f[i] = mo.w[i];
    s.phi[i] = mo.phi[i];
    s.phi_rate[i] = mo.rate[i];
  }
  return ct;
}

/// `body_motion` into the scratch alone.
inline double body_motion(Vec y, const Model& m, Scratch& s) {
  Motion mo;
  return body_motion(y, m, s, mo);
}

/// out = Qᵢᵀ·x: a vector of F in non-linear mount i's axes (copied where they are F's).
inline void into_axes(const NonLinear& nl, idx i, double x0, double x1, double x2, double* out) {
  if (nl.aligned[i]) {
    out[0] = x0;
    out[1] = x1;
    out[2] = x2;
    return;
  }
  for (int j = 0; j < 3; ++j) {
    out[j] = nl.axes(i, 0, j) * x0 + nl.axes(i, 1, j) * x1 + nl.axes(i, 2, j) * x2;
  }
}

/// out = Qᵢ·local: a vector of mount i's axes in F (copied where they are F's).
inline void out_of_axes(const NonLinear& nl, idx i, const double* local, double* out) {
  if (nl.aligned[i]) {
    out[0] = local[0];
    out[1] = local[1];
    out[2] = local[2];
    return;
  }
  for (int j = 0; j < 3; ++j) {
    out[j] = nl.axes(i, j, 0) * local[0] + nl.axes(i, j, 1) * local[1] +
             nl.axes(i, j, 2) * local[2];
  }
}

/// A non-linear mount's motion and load in its own axes, held in locals: through the scratch's
/// views, which may alias, values stored one by one and read back as a pair stalled on store
/// forwarding (43 % of `local_motion`'s time on the bundled genset).
struct MountLocal {
  double arm[3];  // m, F: the lever arm R·p
  double d[3];    // m: deflection
  double v[3];    // m/s: its rate
  double phi[3];  // rad: rotation vector (NaN for a kind without a rotational law)
  double w[3];    // rad/s: its rate (NaN likewise)
  double f[3];    // N: force on the body
  double c[3];    // N·m: generalized couple, conjugate to phi
};

/// Deflection, rate, rotation vector and its rate of non-linear mount i in its axes, and its
/// arm, into ml.
inline void local_motion(idx i, const NonLinear& nl, const Motion& mo, MountLocal& ml) {
  double de[6];
  point_motion(&nl.point(i, 0), mo, ml.arm, de);
  into_axes(nl, i, de[0], de[1], de[2], ml.d);
  into_axes(nl, i, de[3], de[4], de[5], ml.v);
  if (nl.rotational[i]) {
    into_axes(nl, i, mo.phi[0], mo.phi[1], mo.phi[2], ml.phi);
    into_axes(nl, i, mo.rate[0], mo.rate[1], mo.rate[2], ml.w);
  } else {
    for (int j = 0; j < 3; ++j) {
      ml.phi[j] = NAN;
      ml.w[j] = NAN;
    }
  }
}

/// The kinds' carry of the error estimate's companion where a pass over the mounts for its
/// wrenches takes it too (`rhs_with_wrenches`; kernel.hpp `carry_interval` says what each
/// holds): each mount's rate-independent states returned by its kind's carry before its load,
/// from its deflection in the pass and the twin's, twin_d (k, 3), as the twin's pass took them.
/// A carry moves its own mount's states alone, so every load is the one after a carry of all.
struct KindCarry {
  Vec trial;   // the companion's state before the kick
  Vec twin;    // the twin's state
  Mat twin_d;  // (k, 3) m: the twin's mount deflections, in their axes
};

/// Non-linear mount i's rate-independent states in y returned by its kind's carry (a kind
/// that returns nothing skipped, `kind_carries`), at its deflection ml.d and the twin's.
inline void carry_kind(idx i, const NonLinear& nl, Vec y, const MountLocal& ml,
                       const KindCarry& carry) {
  if (!kinds::kind_carries(nl.kind[i])) return;
  kinds::kind_carry(nl.kind[i], &nl.par(i, 0), y, carry.trial, carry.twin, nl.state[i], ml.d,
                    &carry.twin_d(i, 0));
}

/// Load of non-linear mount i in its axes into ml.f, ml.c (its motion first, then, where carry
/// is given, its kind's carry: `carry_kind`); its state rates into dydt.
inline void nl_load(idx i, Vec y, const NonLinear& nl, const Motion& mo, MountLocal& ml,
                    Vec dydt, const KindCarry* carry = nullptr) {
  local_motion(i, nl, mo, ml);
  if (carry != nullptr) carry_kind(i, nl, y, ml, *carry);
  kinds::kind_load(nl.kind[i], &nl.par(i, 0), y, nl.state[i], ml.d, ml.v, ml.phi, ml.w, dydt,
                   ml.f, ml.c);
}

/// c = J(φ)⁻ᵀ·Qᵢ·ml.c: the couple on the body (F) of mount i's generalized force.
inline void nl_couple(idx i, const NonLinear& nl, const Motion& mo, const MountLocal& ml,
                      double* c) {
  out_of_axes(nl, i, ml.c, c);
  const double c0 = c[0], c1 = c[1], c2 = c[2];
  for (int j = 0; j < 3; ++j) c[j] = mo.cmap[j][0] * c0 + mo.cmap[j][1] * c1 + mo.cmap[j][2] * c2;
}

inline void add_load(const double* arm, const double* f, const double* c, double* total_f,
                     double* total_m) {
  total_f[0] += f[0];
  total_f[1] += f[1];
  total_f[2] += f[2];
  total_m[0] += arm[1] * f[2] - arm[2] * f[1] + c[0];
  total_m[1] += arm[2] * f[0] - arm[0] * f[2] + c[1];
  total_m[2] += arm[0] * f[1] - arm[1] * f[0] + c[2];
}

/// Non-linear mount i's wrench row (slot) in its axes: its force ml.f and, where it is
/// rotational, its couple c on the body (F) taken into its axes (ml.c otherwise, its law's).
inline void put_wrench(const NonLinear& nl, idx i, const double* c, MountLocal& ml, M6 wrenches) {
  if (nl.rotational[i]) into_axes(nl, i, c[0], c[1], c[2], ml.c);
  const idx row = nl.slot[i];
  for (int j = 0; j < 3; ++j) {
    wrenches(row, j) = ml.f[j];
    wrenches(row, 3 + j) = ml.c[j];
  }
}

/// The mounts' monitors where a pass over them for their wrenches takes them too, each mount's
/// event functions and discrete switch from the local motion its load was taken at (one local
/// motion a mount where a pass for the wrenches and one for the monitors took two, at every
/// sample of the twin and every interval of the companion): y0 the state at the previous
/// sample, g (k, NE) and util (k) written as `mount_monitors` writes them, `switched` whether
/// a switch moved y.
struct MonitorRows {
  Vec y0;
  Mat g;
  Vec util;
  bool switched = false;
  Mat d{};  // where given (k, 3): each mount's deflection (m, its axes) the pass took
};

/// Non-linear mount i's event functions and utilisation at its motion ml into mon (and its
/// deflection where mon.d is given), then its discrete switch (y's states may jump):
/// `mount_monitors`' work on one mount.
inline void monitor_mount(idx i, Vec y, const NonLinear& nl, const MountLocal& ml,
                          MonitorRows& mon) {
  const idx code = nl.kind[i], o = nl.state[i];
  const double* p = &nl.par(i, 0);
  if (mon.d.rows > 0) {
    for (int j = 0; j < 3; ++j) mon.d(i, j) = ml.d[j];
  }
  mon.util[i] = kinds::kind_monitor(code, p, y, mon.y0, o, ml.d, ml.v, mon.g.row(i));
  if (kinds::kind_update(code, p, y, o, ml.d)) mon.switched = true;
}

/// Sum the mount loads on the body at the motion mo into s.total_force, s.total_moment (F,
/// about the CG); the internal-state rates of the mounts that have them into dydt. With
/// kWrenches, each non-linear mount's force and own couple in its axes into its row of
/// *wrenches as well (`mount_wrenches`' rows, from the same loads), and where mon is given its
/// monitors after its load (`monitor_mount`: a mount's switch moves its own states alone, after
/// its load, so every load is the one a pass without the monitors takes), and where carry is
/// given its kind's carry before its load (`carry_kind`).
template <bool kWrenches>
inline void mount_loads_into(Vec y, const Model& m, const Motion& mo, Scratch& s, Vec dydt,
                             M6* wrenches, MonitorRows* mon, const KindCarry* carry) {
  double total_f[3] = {0.0, 0.0, 0.0}, total_m[3] = {0.0, 0.0, 0.0};
  linear_loads(m, mo, total_f, total_m);
  if (m.lin_point.rows > 0) {  // their own couples, through their summed K_r, C_r
    double c[3];
    linear_couple(m.lin_k_r_sum, m.lin_c_r_sum, mo, c);
    for (int j = 0; j < 3; ++j) total_m[j] += c[j];
  }
  if (m.has_nl) {
    const NonLinear& nl = m.nl;
    MountLocal ml;
    for (idx i = 0; i < nl.k; ++i) {
      double f[3], c[3] = {0.0, 0.0, 0.0};
      nl_load(i, y, nl, mo, ml, dydt, carry);
      out_of_axes(nl, i, ml.f, f);
      if (nl.rotational[i]) nl_couple(i, nl, mo, ml, c);
      add_load(ml.arm, f, c, total_f, total_m);
      if constexpr (kWrenches) {
        put_wrench(nl, i, c, ml, *wrenches);
        if (mon != nullptr) monitor_mount(i, y, nl, ml, *mon);
      }
    }
  }
  for (int j = 0; j < 3; ++j) {
    s.total_force[j] = total_f[j];
    s.total_moment[j] = total_m[j];
  }
}

/// `mount_loads_into` without the wrenches: the right-hand side's.
inline void mount_loads(Vec y, const Model& m, const Motion& mo, Scratch& s, Vec dydt) {
  mount_loads_into<false>(y, m, mo, s, dydt, nullptr, nullptr, nullptr);
}

/// Each mount's force (N) and own couple (N·m) on the body, in its axes: wrenches row slot;
/// where mon is given, each non-linear mount's monitors after its wrench (`monitor_mount`).
inline void mount_wrenches(Vec y, const Model& m, Scratch& s, M6 wrenches,
                           MonitorRows* mon = nullptr) {
  const Motion mo = Motion::of(s);
  linear_wrenches(m, mo, wrenches);
  if (!m.has_nl) return;
  const NonLinear& nl = m.nl;
  MountLocal ml;
  for (idx i = 0; i < nl.k; ++i) {
    nl_load(i, y, nl, mo, ml, s.sink);
    double c[3] = {0.0, 0.0, 0.0};
    if (nl.rotational[i]) nl_couple(i, nl, mo, ml, c);
    put_wrench(nl, i, c, ml, wrenches);
    if (mon != nullptr) monitor_mount(i, y, nl, ml, *mon);
  }
}

/// Each non-linear mount's deflection in its own axes (m) at y into d (k, 3) (the start of
/// hysteretic mounts on their loading curve reads it: model/loading.py). Returns cos θ (NaN
/// off the chart: d is then not written).
inline double mount_deflections(Vec y, const Model& m, Scratch& s, M3 d) {
  Motion mo;
  const double ct = body_motion(y, m, s, mo);
  if (!(ct > 0.0)) return NAN;
  MountLocal ml;
  for (idx i = 0; i < m.nl.k; ++i) {
    local_motion(i, m.nl, mo, ml);
    for (int j = 0; j < 3; ++j) d(i, j) = ml.d[j];
  }
  return ct;
}

/// Event functions g (k, NE) and utilisation util (k) of each non-linear mount at y (its body
/// motion computed); then their discrete switches. Returns whether one switched (y jumped).
inline bool mount_monitors(Vec y, Vec y0, const NonLinear& nl, Scratch& s, Mat g, Vec util) {
  const Motion mo = Motion::of(s);
  MountLocal ml;
  MonitorRows mon{y0, g, util};
  for (idx i = 0; i < nl.k; ++i) {
    local_motion(i, nl, mo, ml);
    monitor_mount(i, y, nl, ml, mon);
  }
  return mon.switched;
}

inline double cross(const Vec a, const Vec b, idx i) {
  if (i == 0) return a[1] * b[2] - a[2] * b[1];
  if (i == 1) return a[2] * b[0] - a[0] * b[2];
  return a[0] * b[1] - a[1] * b[0];
}

/// Free translational accelerations into dydt[nf:nf + nt].
inline void translational(const Model& m, Scratch& s, Vec dydt, idx nf) {
  const Vec q = s.q, qd = s.qd, f_s = s.f_s, w = s.big_w, w_dot = s.big_w_dot, rel = s.rel,
            wxr = s.w_x_rel, total_f = s.total_force;
  for (int i = 0; i < 3; ++i) rel[i] = m.cg_ref[i] + q[i] - m.sensor_position[i];
  for (int i = 0; i < 3; ++i) wxr[i] = cross(w, rel, i);
  const double inv_mass = 1.0 / m.mass;
  for (idx k = 0; k < m.free_trans.n; ++k) {
    const idx i = m.free_trans[k];
    const double frame = 2.0 * cross(w, qd, i) + cross(w_dot, rel, i) + cross(w, wxr, i);
    dydt[nf + k] = total_f[i] * inv_mass - f_s[i] - frame;
  }
}

/// Solve L Lᵀ x = b in place, L (N×N, lower) in l: forward, then back substitution.
template <idx N>
inline void substitute(const double (&l)[3][3], double (&b)[3]) {
  for (idx i = 0; i < N; ++i) {
    double e = b[i];
    for (idx k = 0; k < i; ++k) e -= l[i][k] * b[k];
    b[i] = e / l[i][i];
  }
  for (idx i = N - 1; i >= 0; --i) {
    double e = b[i];
    for (idx k = i + 1; k < N; ++k) e -= l[k][i] * b[k];
    b[i] = e / l[i][i];
  }
}

/// The lower triangle of a and b[:N] into locals (the views may alias: in locals the compiler
/// keeps them in registers; N fixed: the loops unroll).
template <idx N>
inline void load_lower(M3 a, Vec b, double (&l)[3][3], double (&x)[3]) {
  for (idx i = 0; i < N; ++i) {
    x[i] = b[i];
    for (idx k = 0; k <= i; ++k) l[i][k] = a(i, k);
  }
}

/// `substitute` on views (`load_lower` first).
template <idx N>
inline void cholesky_solve_n(M3 low, Vec b) {
  double l[3][3], x[3];
  load_lower<N>(low, b, l, x);
  substitute<N>(l, x);
  for (idx i = 0; i < N; ++i) b[i] = x[i];
}

/// Solve L Lᵀ x = b[:n] in place, L the lower triangle of low (n ≤ 2: three free rotations
/// take `chart_accelerations`).
inline void cholesky_solve(M3 low, Vec b, idx n) {
  if (n == 2) {
    cholesky_solve_n<2>(low, b);
  } else if (n == 1) {
    cholesky_solve_n<1>(low, b);
  }
}

/// `solve_spd` for a fixed N.
template <idx N>
inline bool solve_spd_n(M3 a, Vec b) {
  double l[3][3], x[3];
  load_lower<N>(a, b, l, x);
  for (idx j = 0; j < N; ++j) {
    double d = l[j][j];
    for (idx k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    l[j][j] = d;
    for (idx i = j + 1; i < N; ++i) {
      double e = l[i][j];
      for (idx k = 0; k < j; ++k) e -= l[i][k] * l[j][k];
      l[i][j] = e / d;
    }
  }
  substitute<N>(l, x);
  for (idx i = 0; i < N; ++i) {
    b[i] = x[i];
    for (idx k = 0; k <= i; ++k) a(i, k) = l[i][k];
  }
  return true;
}

/// Solve a[:n, :n] x = b[:n] in place by Cholesky (n of 1 or 2, as `cholesky_solve`; the lower
/// triangle of a keeps its factor); false if a is not positive definite, or for any other n
/// (three free rotations take `chart_accelerations`: a call with 3 is a mistake, and fails).
inline bool solve_spd(M3 a, Vec b, idx n) {
  if (n == 2) return solve_spd_n<2>(a, b);
  if (n == 1) return solve_spd_n<1>(a, b);
  return false;
}

/// With all three rotations free, the projected Euler equations Bᵀ·(I·(B·x + a) − m) = 0
/// are I·(B·x + a) = m: the chart accelerations x = B⁻¹·I⁻¹·h for h (N·m, body axes, the
/// moments less the known accelerations' share), into dydt[first:first + 3], directly (the
/// reduced mass matrix BᵀIB squares B's condition and takes a factorisation).
inline void chart_accelerations(const Model& m, const Scratch& s, double ct, const Vec h,
                                Vec dydt, idx first) {
  const double(&inv)[3][3] = m.inertia_inv;
  double v[3], x[3];
  for (int i = 0; i < 3; ++i) v[i] = inv[i][0] * h[0] + inv[i][1] * h[1] + inv[i][2] * h[2];
  inverse_kinematic(s.trig[0], s.trig[3], s.trig[1], s.trig[4], ct, v, x);
  for (idx a = 0; a < 3; ++a) dydt[first + a] = x[m.free_rot[a]];
}

/// Free rotational accelerations (projected Euler equations) into dydt[first:first + nr];
/// false if the reduced mass matrix (fewer than three free rotations) is numerically
/// singular.
inline bool rotational(const Model& m, Scratch& s, double ct, Vec dydt, idx first) {
  const M3 rot = s.rot, kin = s.kin, kin_rate = s.kin_rate, inertia = m.inertia,
            mass_rot = s.mass_rot;
  const Vec qd = s.qd, omega = s.omega, trig = s.trig, w = s.big_w, w_dot = s.big_w_dot,
            total_m = s.total_moment, moment_b = s.moment_b, w_b = s.w_b,
            w_dot_b = s.w_dot_b, acc = s.acc, w_abs = s.w_abs, h = s.h, i_w = s.i_w,
            rhs_rot = s.rhs_rot;
  kinematic_matrix_rate(trig[0], trig[3], trig[1], trig[4], ct, qd[3], qd[4], kin_rate);
  for (int i = 0; i < 3; ++i) {
    moment_b[i] = rot(0, i) * total_m[0] + rot(1, i) * total_m[1] + rot(2, i) * total_m[2];
    w_b[i] = rot(0, i) * w[0] + rot(1, i) * w[1] + rot(2, i) * w[2];
    w_dot_b[i] = rot(0, i) * w_dot[0] + rot(1, i) * w_dot[1] + rot(2, i) * w_dot[2];
  }
  for (int i = 0; i < 3; ++i) {
    const double bdq = kin_rate(i, 0) * qd[3] + kin_rate(i, 1) * qd[4] + kin_rate(i, 2) * qd[5];
    acc[i] = bdq - cross(omega, w_b, i) + w_dot_b[i];
    w_abs[i] = omega[i] + w_b[i];
  }
  for (int i = 0; i < 3; ++i) {
    i_w[i] = inertia(i, 0) * w_abs[0] + inertia(i, 1) * w_abs[1] + inertia(i, 2) * w_abs[2];
  }
  for (int i = 0; i < 3; ++i) {
    const double i_acc = inertia(i, 0) * acc[0] + inertia(i, 1) * acc[1] + inertia(i, 2) * acc[2];
    h[i] = moment_b[i] - cross(w_abs, i_w, i) - i_acc;
  }
  const idx nr = m.free_rot.n;
  if (nr == 3) {
    chart_accelerations(m, s, ct, h, dydt, first);
    return true;
  }
  for (idx a = 0; a < nr; ++a) {
    const idx ca = m.free_rot[a];
    const double k0 = kin(0, ca), k1 = kin(1, ca), k2 = kin(2, ca);
    rhs_rot[a] = k0 * h[0] + k1 * h[1] + k2 * h[2];
    const double i0 = inertia(0, 0) * k0 + inertia(0, 1) * k1 + inertia(0, 2) * k2;
    const double i1 = inertia(1, 0) * k0 + inertia(1, 1) * k1 + inertia(1, 2) * k2;
    const double i2 = inertia(2, 0) * k0 + inertia(2, 1) * k1 + inertia(2, 2) * k2;
    for (idx b = 0; b <= a; ++b) {
      const idx cb = m.free_rot[b];
      mass_rot(a, b) = i0 * kin(0, cb) + i1 * kin(1, cb) + i2 * kin(2, cb);
    }
  }
  if (!solve_spd(mass_rot, rhs_rot, nr)) return false;
  for (idx a = 0; a < nr; ++a) dydt[first + a] = rhs_rot[a];
  return true;
}

/// The right-hand side (`rhs`); with kWrenches, every mount's wrench into *wrenches as well,
/// from the same loads (`mount_wrenches`' rows: the error estimate's carried companion takes
/// its rate and its outputs in one pass).
template <bool kWrenches>
inline int rhs_into(double t, Vec y, const Model& m, Scratch& s, Vec u, Vec dydt,
                    M6* wrenches, MonitorRows* mon, const KindCarry* carry) {
  Motion mo;
  const double ct = body_motion(y, m, s, mo);
  if (!(ct > 0.0)) return OFF_CHART;
  mount_loads_into<kWrenches>(y, m, mo, s, dydt, wrenches, mon, carry);
  if constexpr (kWrenches) linear_wrenches(m, mo, *wrenches);
  const idx nt = m.free_trans.n, nr = m.free_rot.n, nf = nt + nr;
  for (idx k = 0; k < nf; ++k) dydt[k] = y[nf + k];
  const double tau = t - u[0];
  for (int i = 0; i < 3; ++i) {
    s.f_s[i] = u[1 + i] + u[4 + i] * tau;
    s.big_w[i] = u[7 + i] + u[10 + i] * tau;
    s.big_w_dot[i] = u[10 + i];
  }
  if (nt > 0) translational(m, s, dydt, nf);
  if (nr > 0 && !rotational(m, s, ct, dydt, nf + nt)) return OFF_CHART;
  return OK;
}

inline int rhs(double t, Vec y, const Model& m, Scratch& s, Vec u, Vec dydt) {
  return rhs_into<false>(t, y, m, s, u, dydt, nullptr, nullptr, nullptr);
}

/// `rhs`, and each mount's force (N) and own couple (N·m) on the body in its axes into its
/// wrenches row, as `mount_wrenches` gives them, in one pass over the mounts; where mon is
/// given, their monitors in that pass too (taken where the body's motion is on the chart,
/// even if the rotational rows then fail); where carry is given, each kind's carry before its
/// mount's load (`KindCarry`: the error estimate's carried companion).
inline int rhs_with_wrenches(double t, Vec y, const Model& m, Scratch& s, Vec u, Vec dydt,
                             M6 wrenches, MonitorRows* mon = nullptr,
                             const KindCarry* carry = nullptr) {
  return rhs_into<true>(t, y, m, s, u, dydt, &wrenches, mon, carry);
}

/// Outputs when s already holds the body motion at y (the last rhs was at y): the pose row
/// (physics/pose_row.py) and each mount's wrench in its axes; where mon is given, the
/// non-linear mounts' monitors in the same pass (`mount_wrenches`).
inline void outputs(Vec y, const Model& m, Scratch& s, Vec pose, M6 wrenches,
                    MonitorRows* mon = nullptr) {
  mount_wrenches(y, m, s, wrenches, mon);
  if (!m.rotation_read) quaternion_from_matrix(s.rot, s.quat);
  for (int i = 0; i < 3; ++i) {
    pose[pose_row::POSITION + i] = m.cg_ref[i] + s.q[i];
    pose[pose_row::ANGLES + i] = s.q[3 + i];
  }
  for (int i = 0; i < 4; ++i) pose[pose_row::QUATERNION + i] = s.quat[i];
}

/// Outputs at state y; returns cos θ (NaN off the chart, outputs then untouched).
inline double evaluate(Vec y, const Model& m, Scratch& s, Vec pose, M6 wrenches) {
  const double ct = body_motion(y, m, s);
  if (!(ct > 0.0)) return NAN;
  outputs(y, m, s, pose, wrenches);
  return ct;
}

/// Move dydt, the last rhs's result (whose kinematics, and with fewer than three free rotations
/// factored reduced mass matrix, s holds), to an input whose Ω' changed by d_wdot (rad/s², F).
inline void rhs_after_rate_step(const Model& m, Scratch& s, Vec d_wdot, Vec dydt) {
  const idx nt = m.free_trans.n, nr = m.free_rot.n, nf = nt + nr;
  for (idx k = 0; k < nt; ++k) dydt[nf + k] -= cross(d_wdot, s.rel, m.free_trans[k]);
  if (nr == 0) return;
  const M3 rot = s.rot, kin = s.kin, inertia = m.inertia;
  const Vec b = s.rhs_rot, dw_b = s.w_dot_b, h = s.h;
  for (int i = 0; i < 3; ++i) {
    dw_b[i] = rot(0, i) * d_wdot[0] + rot(1, i) * d_wdot[1] + rot(2, i) * d_wdot[2];
  }
  for (int i = 0; i < 3; ++i) {
    h[i] = -(inertia(i, 0) * dw_b[0] + inertia(i, 1) * dw_b[1] + inertia(i, 2) * dw_b[2]);
  }
  if (nr == 3) {  // as `rotational` solves it: the change of x = B⁻¹·I⁻¹·h
    double x[3];
    chart_accelerations(m, s, s.rot(2, 2), h, Vec{x, 3}, 0);
    for (idx a = 0; a < 3; ++a) dydt[nf + nt + a] += x[a];
    return;
  }
  for (idx a = 0; a < nr; ++a) {
    const idx ca = m.free_rot[a];
    b[a] = kin(0, ca) * h[0] + kin(1, ca) * h[1] + kin(2, ca) * h[2];
  }
  cholesky_solve(s.mass_rot, b, nr);
  for (idx a = 0; a < nr; ++a) dydt[nf + nt + a] += b[a];
}

/// Central-difference step of central_columns, relative to max(1, |y_c|).
constexpr double CENTRAL_STEP = 1.0e-7;

/// jac[:, c] = ∂(dy/dt)/∂y_c at (t, y) under u for the first jac.cols columns; plus, minus:
/// (n,) work; y restored. False if an evaluation failed (jac then incomplete).
inline bool central_columns(Vec y, double t, const Model& m, Scratch& s, Vec u, Vec plus,
                            Vec minus, Mat jac) {
  for (idx c = 0; c < jac.cols; ++c) {
    const double keep = y[c];
    const double h = CENTRAL_STEP * py_max(1.0, std::fabs(keep));
    y[c] = keep + h;
    const double up = y[c];
    bool ok = rhs(t, y, m, s, u, plus) == OK;
    y[c] = keep - h;
    const double down = y[c];
    ok = ok && rhs(t, y, m, s, u, minus) == OK;
    y[c] = keep;
    if (!ok) return false;
    for (idx r = 0; r < y.n; ++r) jac(r, c) = (plus[r] - minus[r]) / (up - down);
  }
  return true;
}

}  // namespace mt::physics
