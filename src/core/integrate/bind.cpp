// Python bindings of the core's integrate: the steppers' `advance` (the switch on the method
// id, and each method's own), `forget` and the φ functions (integrate/stepper.py, control.py,
// phi.py and each method's module re-export them with their Python signatures). Every array is
// checked here (dtype, contiguity, length, the work array's rows for the method), so the
// header-only steppers never see a short array.
#include <cstddef>
#include <string>

#include "../bind.hpp"
#include "../convert.hpp"
#include "../physics/dynamics.hpp"  // the right-hand side's definition (declared in dynamics_api)
#include "stepper.hpp"

namespace mt {

namespace py = pybind11;

namespace integrate_binding {

/// A method's scene name (methods.py METHODS), "" for an unknown id.
inline const char* method_name(int method) {
  switch (method) {
    case DOPRI54: return "dopri54";
    case ROS34PW2: return "ros34pw2";
    case EXPRB32: return "exprb32";
    case VERNER65: return "verner65";
    default: return "";
  }
}

/// The converted arguments of a stepper's advance.
struct Args {
  Model m;
  Scratch s;
  Vec y, settings, u, work1d, result;
  Mat work2d;
};

/// Convert and check an advance's arguments; `method` < 0 or unknown: no row count is required
/// of work2d (the switch returns UNKNOWN_METHOD without touching it).
inline Args args(int method, py::handle y_, py::handle settings_, py::handle m_,
                 py::handle s_, py::handle u_, py::handle work2d_, py::handle work1d_,
                 py::handle result_) {
  Args a;
  a.m = convert::model(m_);
  a.s = convert::scratch(s_);
  a.y = convert::vec(y_, "y");
  convert::check_state(a.m, a.y, "y");
  convert::check_scratch(a.s, a.y.n, "s");
  if (a.y.n <= 0) throw py::value_error("y: empty state");
  a.settings = convert::vec(settings_, "settings", N_SETTINGS);
  a.u = convert::vec(u_, "u", INPUT_SIZE);
  a.work2d = convert::mat(work2d_, "work2d", -1, a.y.n);
  a.work1d = convert::vec(work1d_, "work1d", a.y.n);
  a.result = convert::vec(result_, "result", 3);
  const idx need = integrate::work_rows(method, a.y.n);
  if (need >= 0 && a.work2d.rows < need) {
    throw py::value_error("work2d: " + std::to_string(a.work2d.rows) + " rows where " +
                          method_name(method) + " needs " + std::to_string(need) +
                          " for " + std::to_string(a.y.n) + " states (Method.work_rows)");
  }
  return a;
}

/// phi.Blocks (a NamedTuple, or any object with j, p1, z, scale, or a 4-sequence) → Blocks.
inline integrate::phi::Blocks blocks(py::handle b) {
  if (py::hasattr(b, "p1")) {
    return {b.attr("j").cast<idx>(), b.attr("p1").cast<idx>(), b.attr("z").cast<idx>(),
            b.attr("scale").cast<idx>()};
  }
  if (!py::isinstance<py::sequence>(b) || py::len(b) != 4) {
    throw py::type_error("b: expected phi.Blocks (j, p1, z, scale)");
  }
  auto seq = py::reinterpret_borrow<py::sequence>(b);
  return {seq[0].cast<idx>(), seq[1].cast<idx>(), seq[2].cast<idx>(), seq[3].cast<idx>()};
}

/// Raise ValueError unless rows [first, first + count) lie in k.
inline void check_rows(const Mat& k, idx first, idx count, const char* what) {
  if (first < 0 || first + count > k.rows) {
    throw py::value_error(std::string("k: the block ") + what + " (rows " +
                          std::to_string(first) + " to " + std::to_string(first + count) +
                          ") does not lie in its " + std::to_string(k.rows) + " rows");
  }
}

/// Bind Fn, a switch on the method id with `integrate::advance`'s signature, as `name`.
template <auto Fn>
void def_switch(py::module_& mod, const char* name, const char* doc) {
  mod.def(
      name,
      [](int method, py::handle y_, double t0, double t1, py::handle settings_, py::handle m_,
         py::handle s_, py::handle u_, py::handle work2d_, py::handle work1d_,
         py::handle result_) {
        Args a = args(method, y_, settings_, m_, s_, u_, work2d_, work1d_, result_);
        return Fn(method, a.y, t0, t1, a.settings, a.m, a.s, a.u, a.work2d, a.work1d, a.result);
      },
      doc, py::arg("method"), py::arg("y"), py::arg("t0"), py::arg("t1"), py::arg("settings"),
      py::arg("m"), py::arg("s"), py::arg("u"), py::arg("work2d"), py::arg("work1d"),
      py::arg("result"));
}

template <int Method>
void def_method_advance(py::module_& mod, const char* name, const char* doc) {
  mod.def(
      name,
      [](py::handle y_, double t0, double t1, py::handle settings_, py::handle m_,
         py::handle s_, py::handle u_, py::handle k_, py::handle y_new_, py::handle result_) {
        Args a = args(Method, y_, settings_, m_, s_, u_, k_, y_new_, result_);
        return integrate::advance(Method, a.y, t0, t1, a.settings, a.m, a.s, a.u, a.work2d,
                                  a.work1d, a.result);
      },
      doc, py::arg("y"), py::arg("t0"), py::arg("t1"), py::arg("settings"), py::arg("m"),
      py::arg("s"), py::arg("u"), py::arg("k"), py::arg("y_new"), py::arg("result"));
}

template <std::size_t N>
py::tuple row(const double (&v)[N]) {
  py::tuple t(N);
  for (std::size_t i = 0; i < N; ++i) t[i] = v[i];
  return t;
}

template <std::size_t R, std::size_t C>
py::tuple rows(const double (&v)[R][C]) {
  py::tuple t(R);
  for (std::size_t i = 0; i < R; ++i) t[i] = row(v[i]);
  return t;
}

/// An explicit method's table T by the names of its Python module.
template <class T>
py::dict explicit_table() {
  constexpr std::size_t R = T::STAGES;
  py::dict d;
  py::tuple c(R), e(R);
  for (std::size_t i = 0; i < R; ++i) {
    c[i] = T::C[i];
    e[i] = T::E[i];
  }
  d["C"] = c;
  d["A"] = rows(T::A);
  d["E"] = e;
  d["FSAL"] = T::FSAL;
  d["ORDER"] = T::ORDER;
  d["MAX_FACTOR"] = T::MAX_FACTOR;
  return d;
}

/// Each method's tables and constants as the core has them, by the names its Python module
/// uses (test/test_core_contract.py holds them equal to the module's).
py::dict method_tables() {
  py::dict ros, exp;
  ros["GAMMA"] = integrate::ros34pw2::GAMMA;
  ros["ALPHA"] = rows(integrate::ros34pw2::ALPHA);
  ros["GAMMAS"] = rows(integrate::ros34pw2::GAMMAS);
  ros["B"] = row(integrate::ros34pw2::B);
  ros["B_HAT"] = row(integrate::ros34pw2::B_HAT);
  ros["C"] = row(integrate::ros34pw2::C);
  ros["D"] = row(integrate::ros34pw2::D);
  ros["ORDER"] = integrate::ros34pw2::ORDER;
  ros["STAGES"] = integrate::ros34pw2::STAGES;
  ros["MAX_FACTOR"] = integrate::ros34pw2::MAX_FACTOR;
  ros["JACOBIAN_MAX_AGE"] = integrate::ros34pw2::JACOBIAN_MAX_AGE;
  ros["J0"] = integrate::ros34pw2::J0;
  exp["ORDER"] = integrate::exprb32::ORDER;
  exp["MAX_FACTOR"] = integrate::exprb32::MAX_FACTOR;
  exp["JACOBIAN_MAX_AGE"] = integrate::exprb32::JACOBIAN_MAX_AGE;
  exp["PHI_REUSE"] = integrate::exprb32::PHI_REUSE;
  exp["TYPICAL"] = integrate::exprb32::TYPICAL;
  exp["J0"] = integrate::exprb32::J0;
  exp["BLOCKS"] = integrate::exprb32::BLOCKS;
  py::dict out;
  out["dopri54"] = explicit_table<integrate::dopri54::Table>();
  out["verner65"] = explicit_table<integrate::verner65::Table>();
  out["ros34pw2"] = ros;
  out["exprb32"] = exp;
  return out;
}

}  // namespace integrate_binding

void bind_integrate(py::module_& mod) {
  using namespace integrate_binding;
  def_switch<integrate::advance>(
      mod, "advance",
      "Advance the state y (in place; m, rad, m/s, rad/s and the mounts' internal states) from "
      "t0 to t1 (s) with the stepper `method` (a methods.METHODS id) under the input u held "
      "over the interval. settings: the slots of integrate.settings (STEP s, RTOL, ATOL in the "
      "state's units, MAX_SUBSTEPS, CHAINED, MIN_STEPS, JACOBIAN_AGE, PHI_STEP s), updated; "
      "work2d: (Method.work_rows(n), n), work1d: (n,) work arrays; result: out [largest "
      "accepted error norm, accepted, rejected substeps]. Returns a status of "
      "integrate.methods (0 = SUCCESS; UNKNOWN_METHOD for an id no method has, nothing "
      "touched).");
  def_switch<integrate::advance_fixed>(
      mod, "advance_fixed",
      "`advance` by settings[MIN_STEPS] equal steps of an explicit method (dopri54, verner65), "
      "every one taken: no error control; settings[STEP] untouched. result: [largest error "
      "norm of the steps at the settings' tolerances, steps taken, 0]. Returns a status "
      "(UNKNOWN_METHOD for a method that is not explicit, nothing touched).");
  def_method_advance<DOPRI54>(
      mod, "dopri54_advance",
      "Dormand–Prince 5(4) across one input interval: `advance` without the method id (k: "
      "(7, n) stages; y_new: (n,); t0, t1 in s). On success k[0] holds dy/dt at (t1, y) and "
      "settings[CHAINED] is 1.");
  def_method_advance<ROS34PW2>(
      mod, "ros34pw2_advance",
      "Rosenbrock-W ROS34PW2 across one input interval: `advance` without the method id (k: "
      "(10 + 2n, n): stages, f, stage state, Σγk, ∂f/∂t, pivots, scratch, J, LU; t0, t1 in s).");
  def_method_advance<EXPRB32>(
      mod, "exprb32_advance",
      "Exponential Rosenbrock EXPRB32 across one input interval: `advance` without the method "
      "id (k: (6 + 8n, n): f0, ∂f/∂t, scratch, U, D, balancing, then J, φ1..φ3 and four work "
      "blocks; t0, t1 in s).");
  def_method_advance<VERNER65>(
      mod, "verner65_advance",
      "Verner's 6(5) pair across one input interval: `advance` without the method id (k: "
      "(9, n) stages; y_new: (n,); t0, t1 in s). On success k[0] holds dy/dt at (t1, y) and "
      "settings[CHAINED] is 1.");
  mod.def("method_tables", &method_tables,
          "Each method's tables and constants as the core has them: {method: {name: value}}, "
          "by the names of its Python module.");
  mod.def(
      "work_rows",
      [](int method, idx n) { return integrate::work_rows(method, n); },
      "Rows of a method's work array for n states (−1 for an unknown id).", py::arg("method"),
      py::arg("n"));
  mod.def(
      "forget",
      [](py::handle settings_) {
        integrate::forget(convert::vec(settings_, "settings", N_SETTINGS));
      },
      "Forget a stepper's history (after its state jumped): zero settings' STEP (s), CHAINED, "
      "JACOBIAN_AGE and PHI_STEP (s).",
      py::arg("settings"));
  mod.def(
      "phi_functions",
      [](py::handle k_, idx n, double h, py::handle b_) {
        const integrate::phi::Blocks b = blocks(b_);
        if (n < 0) throw py::value_error("n: " + std::to_string(n) + " where ≥ 0 is needed");
        const Mat k = convert::mat(k_, "k", -1, n);
        check_rows(k, b.j, n, "j");
        check_rows(k, b.p1, 3 * n, "p1");
        check_rows(k, b.z, 4 * n, "z");
        check_rows(k, b.scale, 1, "scale");
        return integrate::phi::phi_functions(k, n, h, b);
      },
      "φ_1, φ_2, φ_3 of h·J (h in s, J = k[b.j : b.j + n] in 1/s) into k[b.p1 : b.p1 + 3n], "
      "using k[b.z : b.z + 4n] and the row k[b.scale] as work (b: phi.Blocks); False if they "
      "are not finite (J with NaN or inf).",
      py::arg("k"), py::arg("n"), py::arg("h"), py::arg("b"));
}

}  // namespace mt
