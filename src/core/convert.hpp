// Python → core views: every array is checked (dtype, C-contiguity, shape where it is fixed)
// and a mismatch raises TypeError/ValueError naming the field, so a wrong array can never
// reach the physics as a wrong pointer.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "linalg.hpp"
#include "model.hpp"
#include "physics/linear_mount.hpp"

namespace mt::convert {

namespace py = pybind11;

inline py::array checked(py::handle obj, const char* what, char kind, int itemsize, int ndim) {
  if (!py::isinstance<py::array>(obj)) {
    throw py::type_error(std::string(what) + ": expected a numpy array, got " +
                         std::string(py::str(py::type::of(obj))));
  }
  auto a = py::reinterpret_borrow<py::array>(obj);
  const auto dt = a.dtype();
  if (dt.kind() != kind || dt.itemsize() != itemsize) {
    throw py::type_error(std::string(what) + ": dtype " + std::string(py::str(dt)) +
                         " where " + (kind == 'f' ? "float64" : kind == 'i' ? "int64" : "bool") +
                         " is needed");
  }
  if (a.ndim() != ndim) {
    throw py::value_error(std::string(what) + ": " + std::to_string(a.ndim()) +
                          "-D array where " + std::to_string(ndim) + "-D is needed");
  }
  if (!(a.flags() & py::array::c_style)) {
    throw py::value_error(std::string(what) + ": array is not C-contiguous");
  }
  if (kind != 'b' && !a.writeable()) {
    throw py::value_error(std::string(what) + ": array is read-only");
  }
  return a;
}

/// A 1-D array of the dtype (kind, itemsize); `n` ≥ 0 requires that length.
inline py::array vector1d(py::handle obj, const char* what, char kind, int itemsize, idx n) {
  auto a = checked(obj, what, kind, itemsize, 1);
  if (n >= 0 && a.shape(0) != n) {
    throw py::value_error(std::string(what) + ": length " + std::to_string(a.shape(0)) +
                          " where " + std::to_string(n) + " is needed");
  }
  return a;
}

/// A float64 1-D array; `n` ≥ 0 requires that length.
inline Vec vec(py::handle obj, const char* what, idx n = -1) {
  auto a = vector1d(obj, what, 'f', 8, n);
  return Vec{static_cast<double*>(a.mutable_data()), a.shape(0)};
}

/// A float64 2-D array; rows/cols ≥ 0 require those.
inline Mat mat(py::handle obj, const char* what, idx rows = -1, idx cols = -1) {
  auto a = checked(obj, what, 'f', 8, 2);
  if ((rows >= 0 && a.shape(0) != rows) || (cols >= 0 && a.shape(1) != cols)) {
    throw py::value_error(std::string(what) + ": shape (" + std::to_string(a.shape(0)) + ", " +
                          std::to_string(a.shape(1)) + ") where (" + std::to_string(rows) +
                          ", " + std::to_string(cols) + ") is needed (-1: any)");
  }
  return Mat{static_cast<double*>(a.mutable_data()), a.shape(0), a.shape(1)};
}

/// A float64 3-D array; n/rows/cols ≥ 0 require those.
inline Mats mats(py::handle obj, const char* what, idx n = -1, idx rows = -1, idx cols = -1) {
  auto a = checked(obj, what, 'f', 8, 3);
  if ((n >= 0 && a.shape(0) != n) || (rows >= 0 && a.shape(1) != rows) ||
      (cols >= 0 && a.shape(2) != cols)) {
    throw py::value_error(std::string(what) + ": shape (" + std::to_string(a.shape(0)) + ", " +
                          std::to_string(a.shape(1)) + ", " + std::to_string(a.shape(2)) +
                          ") does not fit");
  }
  return Mats{static_cast<double*>(a.mutable_data()), a.shape(0), a.shape(1), a.shape(2)};
}

/// A float64 (rows, C) array; rows ≥ 0 requires that many.
template <idx C>
inline MatC<C> matc(py::handle obj, const char* what, idx rows = -1) {
  const Mat a = mat(obj, what, rows, C);
  return MatC<C>{a.d, a.rows};
}

/// A float64 (n, R, C) array; n ≥ 0 requires that many.
template <idx R, idx C>
inline MatsRC<R, C> matsrc(py::handle obj, const char* what, idx n = -1) {
  const Mats a = mats(obj, what, n, R, C);
  return MatsRC<R, C>{a.d, a.n};
}

/// A float64 (n, rows, C) array; n, rows ≥ 0 require those.
template <idx C>
inline StackC<C> stackc(py::handle obj, const char* what, idx n = -1, idx rows = -1) {
  const Mats a = mats(obj, what, n, rows, C);
  return StackC<C>{a.d, a.n, a.rows};
}

/// An int64 1-D array; `n` ≥ 0 requires that length.
inline IVec ivec(py::handle obj, const char* what, idx n = -1) {
  auto a = vector1d(obj, what, 'i', 8, n);
  return IVec{static_cast<const idx*>(a.data()), a.shape(0)};
}

/// A bool 1-D array; `n` ≥ 0 requires that length.
inline BVec bvec(py::handle obj, const char* what, idx n = -1) {
  auto a = vector1d(obj, what, 'b', 1, n);
  return BVec{static_cast<const bool*>(a.data()), a.shape(0)};
}

inline py::object field(py::handle obj, const char* name) { return obj.attr(name); }

/// physics.dynamics.NonLinearMounts → NonLinear.
inline NonLinear nonlinear(py::handle nl) {
  NonLinear v;
  v.kind = ivec(field(nl, "kind"), "NonLinearMounts.kind");
  v.k = v.kind.n;
  v.point = matc<3>(field(nl, "point"), "NonLinearMounts.point", v.k);
  v.axes = matsrc<3, 3>(field(nl, "axes"), "NonLinearMounts.axes", v.k);
  v.slot = ivec(field(nl, "slot"), "NonLinearMounts.slot", v.k);
  v.state = ivec(field(nl, "state"), "NonLinearMounts.state", v.k);
  v.par = mat(field(nl, "par"), "NonLinearMounts.par", v.k);
  v.rotational = bvec(field(nl, "rotational"), "NonLinearMounts.rotational", v.k);
  v.aligned = bvec(field(nl, "aligned"), "NonLinearMounts.aligned", v.k);
  return v;
}

/// physics.dynamics.ModelArrays → Model.
inline Model model(py::handle m) {
  Model out;
  out.mass = field(m, "mass").cast<double>();
  out.inertia = matc<3>(field(m, "inertia"), "ModelArrays.inertia", 3);
  linalg::invert_3x3(out.inertia, out.inertia_inv);
  out.cg_ref = vec(field(m, "cg_ref"), "ModelArrays.cg_ref", 3);
  out.sensor_position = vec(field(m, "sensor_position"), "ModelArrays.sensor_position", 3);
  out.free_trans = ivec(field(m, "free_trans"), "ModelArrays.free_trans");
  out.free_rot = ivec(field(m, "free_rot"), "ModelArrays.free_rot");
  out.q_fixed = vec(field(m, "q_fixed"), "ModelArrays.q_fixed", 6);
  out.lin_point = matc<3>(field(m, "lin_point"), "ModelArrays.lin_point");
  const idx n = out.lin_point.rows;
  out.lin_axes = matsrc<3, 3>(field(m, "lin_axes"), "ModelArrays.lin_axes", n);
  out.lin_k_t = matsrc<3, 3>(field(m, "lin_k_t"), "ModelArrays.lin_k_t", n);
  out.lin_c_t = matsrc<3, 3>(field(m, "lin_c_t"), "ModelArrays.lin_c_t", n);
  out.lin_k_r = matsrc<3, 3>(field(m, "lin_k_r"), "ModelArrays.lin_k_r", n);
  out.lin_c_r = matsrc<3, 3>(field(m, "lin_c_r"), "ModelArrays.lin_c_r", n);
  for (idx i = 0; i < n; ++i) {  // the linear mounts' couples sum through one law
    for (int k = 0; k < 9; ++k) {
      out.lin_k_r_sum[k] += out.lin_k_r.d[9 * i + k];
      out.lin_c_r_sum[k] += out.lin_c_r.d[9 * i + k];
    }
  }
  physics::lay_out_lanes(out);
  out.lin_slot = ivec(field(m, "lin_slot"), "ModelArrays.lin_slot", n);
  out.lin_per_rating = matc<6>(field(m, "lin_per_rating"), "ModelArrays.lin_per_rating", n);
  auto nl = field(m, "nl");
  out.has_nl = !nl.is_none();
  if (out.has_nl) out.nl = nonlinear(nl);
  out.rotation_read = field(m, "rotation_read").cast<bool>();
  for (const IVec* free : {&out.free_trans, &out.free_rot}) {
    if (free->n > 3) {
      throw py::value_error("ModelArrays: more than three free translations or rotations");
    }
    for (idx k = 0; k < free->n; ++k) {
      if ((*free)[k] < 0 || (*free)[k] > 2) {
        throw py::value_error("ModelArrays.free_trans/free_rot: an index outside 0..2");
      }
    }
  }
  return out;
}

/// Raise ValueError unless the state y (and the scratch's sink) fit the model: 2·(free
/// coordinates) entries at least, every mount's internal-state offset inside y.
inline void check_state(const Model& m, Vec y, const char* what = "y") {
  const idx nf = m.free_trans.n + m.free_rot.n;
  if (y.n < 2 * nf) {
    throw py::value_error(std::string(what) + ": length " + std::to_string(y.n) +
                          " is shorter than the model's 2 × " + std::to_string(nf) +
                          " free coordinates and rates");
  }
  if (m.has_nl) {
    for (idx i = 0; i < m.nl.k; ++i) {
      if (m.nl.state[i] >= y.n) {
        throw py::value_error(std::string(what) + ": mount " + std::to_string(i) +
                              "'s internal states lie beyond its length");
      }
    }
  }
}

/// Raise ValueError unless the scratch's state-sized sink holds n_state entries.
inline void check_scratch(const Scratch& s, idx n_state, const char* what) {
  if (s.sink.n < n_state) {
    throw py::value_error(std::string(what) + ".sink: length " + std::to_string(s.sink.n) +
                          " where the state has " + std::to_string(n_state));
  }
}

/// physics.dynamics.Scratch → Scratch.
inline Scratch scratch(py::handle s) {
  Scratch o;
  auto v3 = [&](const char* name) { return vec(field(s, name), name, 3); };
  auto m33 = [&](const char* name) { return matc<3>(field(s, name), name, 3); };
  o.q = vec(field(s, "q"), "Scratch.q", 6);
  o.trig = vec(field(s, "trig"), "Scratch.trig", 6);
  o.qd = vec(field(s, "qd"), "Scratch.qd", 6);
  o.rot = m33("rot");
  o.kin = m33("kin");
  o.kin_rate = m33("kin_rate");
  o.omega = v3("omega");
  o.omega_f = v3("omega_f");
  o.phi = v3("phi");
  o.phi_rate = v3("phi_rate");
  o.couple_map = m33("couple_map");
  o.quat = vec(field(s, "quat"), "Scratch.quat", 4);
  o.total_force = v3("total_force");
  o.total_moment = v3("total_moment");
  o.f_s = v3("f_s");
  o.big_w = v3("big_w");
  o.big_w_dot = v3("big_w_dot");
  o.rel = v3("rel");
  o.w_x_rel = v3("w_x_rel");
  o.moment_b = v3("moment_b");
  o.w_b = v3("w_b");
  o.w_dot_b = v3("w_dot_b");
  o.acc = v3("acc");
  o.w_abs = v3("w_abs");
  o.h = v3("h");
  o.i_w = v3("i_w");
  o.mass_rot = m33("mass_rot");
  o.rhs_rot = v3("rhs_rot");
  o.rate_step = v3("rate_step");
  o.sink = vec(field(s, "sink"), "Scratch.sink");
  return o;
}

}  // namespace mt::convert
