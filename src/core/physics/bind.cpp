// Python bindings of the physics: the right-hand side and the outputs, for the model's
// assembly (equilibrium, stiffness), the analyses and the tests (physics/dynamics.py
// re-exports them with their Python signatures).
#include "../bind.hpp"
#include "../convert.hpp"
#include "dynamics.hpp"

namespace mt {

namespace py = pybind11;
using convert::check_state;

namespace {

/// The model, the scratch and the state of a call, converted and checked against each other.
struct Call {
  Model m;
  Scratch s;
  Vec y;
};

Call call(py::handle m_, py::handle s_, py::handle y_, const char* what = "y") {
  Call c{convert::model(m_), convert::scratch(s_), convert::vec(y_, what)};
  check_state(c.m, c.y, what);
  convert::check_scratch(c.s, c.y.n, "s");
  return c;
}

/// The wrenches array of a model: one (6,) row per mount.
M6 wrench_rows(const Model& m, py::handle w) {
  const idx rows = m.lin_point.rows + (m.has_nl ? m.nl.k : 0);
  return convert::matc<6>(w, "wrenches", rows);
}

}  // namespace

void bind_physics(py::module_& mod) {
  mod.attr("COS_TILT_MIN") = physics::COS_TILT_MIN;
  mod.attr("CENTRAL_STEP") = physics::CENTRAL_STEP;
  mod.def(
      "rhs",
      [](double t, py::handle y_, py::handle m_, py::handle s_, py::handle u_,
         py::handle dydt_) {
        auto [m, s, y] = call(m_, s_, y_);
        return physics::rhs(t, y, m, s, convert::vec(u_, "u", INPUT_SIZE),
                            convert::vec(dydt_, "dydt", y.n));
      },
      "dy/dt at time t (s) under the input u into dydt; returns OK (0) or OFF_CHART (1).",
      py::arg("t"), py::arg("y"), py::arg("m"), py::arg("s"), py::arg("u"), py::arg("dydt"));
  mod.def(
      "body_motion",
      [](py::handle y_, py::handle m_, py::handle s_) {
        auto [m, s, y] = call(m_, s_, y_);
        return physics::body_motion(y, m, s);
      },
      "Fill the scratch's body motion from y; returns cos θ (NaN off the chart).",
      py::arg("y"), py::arg("m"), py::arg("s"));
  mod.def(
      "evaluate",
      [](py::handle y_, py::handle m_, py::handle s_, py::handle pose_,
                    py::handle w_) {
        auto [m, s, y] = call(m_, s_, y_);
        return physics::evaluate(y, m, s, convert::vec(pose_, "pose", pose_row::WIDTH),
                                 wrench_rows(m, w_));
      },
      "Outputs at y: a pose row and each mount's wrench (N, N·m, its axes); returns cos θ.",
      py::arg("y"), py::arg("m"), py::arg("s"), py::arg("pose"), py::arg("wrenches"));
  mod.def(
      "outputs",
      [](py::handle y_, py::handle m_, py::handle s_, py::handle pose_,
                    py::handle w_) {
        auto [m, s, y] = call(m_, s_, y_);
        physics::outputs(y, m, s, convert::vec(pose_, "pose", pose_row::WIDTH),
                         wrench_rows(m, w_));
      },
      "`evaluate` when the scratch already holds the body motion at y.", py::arg("y"),
      py::arg("m"), py::arg("s"), py::arg("pose"), py::arg("wrenches"));
  mod.def(
      "mount_wrenches",
      [](py::handle y_, py::handle m_, py::handle s_, py::handle w_) {
        auto [m, s, y] = call(m_, s_, y_);
        physics::mount_wrenches(y, m, s, wrench_rows(m, w_));
      },
      "Each mount's force (N) and couple (N·m) on the body, in its axes.", py::arg("y"),
      py::arg("m"), py::arg("s"), py::arg("wrenches"));
  mod.def(
      "linear_utilisation",
      [](py::handle y_, py::handle m_, py::handle s_, py::handle w_, py::handle peak_) {
        auto [m, s, y] = call(m_, s_, y_);
        physics::linear_utilisation(m, s, wrench_rows(m, w_),
                                    convert::vec(peak_, "peak", m.lin_point.rows));
      },
      "Fold each linear mount's utilisation at the body motion of y (the scratch holds it; "
      "its wrenches in their axes) into peak, its running maxima.",
      py::arg("y"), py::arg("m"), py::arg("s"), py::arg("wrenches"), py::arg("peak"));
  mod.def(
      "mount_deflections",
      [](py::handle y_, py::handle m_, py::handle s_, py::handle d_) {
        auto [m, s, y] = call(m_, s_, y_);
        if (!m.has_nl) throw py::value_error("mount_deflections: the model has no non-linear mounts");
        return physics::mount_deflections(y, m, s, convert::matc<3>(d_, "d", m.nl.k));
      },
      "Each non-linear mount's deflection (m, its axes) at y into d (k, 3); returns cos θ "
      "(NaN off the chart, d not written).",
      py::arg("y"), py::arg("m"), py::arg("s"), py::arg("d"));
  mod.def(
      "mount_monitors",
      [](py::handle y_, py::handle y0_, py::handle nl_, py::handle s_, py::handle g_,
         py::handle util_) {
        const NonLinear nl = convert::nonlinear(nl_);
        Scratch s = convert::scratch(s_);
        const Vec y = convert::vec(y_, "y");
        for (idx i = 0; i < nl.k; ++i) {
          if (nl.state[i] >= y.n) throw py::value_error("y: shorter than the mounts' states");
        }
        return physics::mount_monitors(y, convert::vec(y0_, "y0", y.n), nl, s,
                                       convert::mat(g_, "g", nl.k), convert::vec(util_, "util", nl.k));
      },
      "Event functions g and utilisation util of the non-linear mounts at y, then their "
      "discrete switches; returns whether one switched.",
      py::arg("y"), py::arg("y0"), py::arg("nl"), py::arg("s"), py::arg("g"), py::arg("util"));
  mod.def(
      "rhs_after_rate_step",
      [](py::handle m_, py::handle s_, py::handle dw_, py::handle dydt_) {
        auto [m, s, dydt] = call(m_, s_, dydt_, "dydt");
        physics::rhs_after_rate_step(m, s, convert::vec(dw_, "d_wdot", 3), dydt);
      },
      "Move the last rhs result dydt to an input whose Ω' changed by d_wdot (rad/s², F).",
      py::arg("m"), py::arg("s"), py::arg("d_wdot"), py::arg("dydt"));
  mod.def(
      "central_columns",
      [](py::handle y_, double t, py::handle m_, py::handle s_, py::handle u_, py::handle p_,
         py::handle n_, py::handle jac_) {
        auto [m, s, y] = call(m_, s_, y_);
        const Mat jac = convert::mat(jac_, "jac", y.n);
        if (jac.cols > y.n) throw py::value_error("jac: more columns than states");
        return physics::central_columns(y, t, m, s, convert::vec(u_, "u", INPUT_SIZE),
                                        convert::vec(p_, "plus", y.n),
                                        convert::vec(n_, "minus", y.n), jac);
      },
      "jac[:, c] = ∂(dy/dt)/∂y_c by central differences for its first columns; False if an "
      "evaluation left the chart.",
      py::arg("y"), py::arg("t"), py::arg("m"), py::arg("s"), py::arg("u"), py::arg("plus"),
      py::arg("minus"), py::arg("jac"));
}

}  // namespace mt
