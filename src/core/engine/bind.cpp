// Python bindings of the per-sample loop and the gyro filter (engine/kernel.py,
// engine/gyro_filter.py re-export them). Every tuple the engine passes is converted field by
// field with its shape checked against the model, so a wrong array raises naming the field.
#include <cmath>
#include <string>

#include "../bind.hpp"
#include "../convert.hpp"
#include "kernel.hpp"

namespace mt {

namespace py = pybind11;
using convert::field;

namespace {

/// A (1,) int64 array as a pointer to its one counter.
idx* counter(py::handle obj, const char* what) {
  auto a = convert::checked(obj, what, 'i', 8, 1);
  if (a.shape(0) < 1) throw py::value_error(std::string(what) + ": empty");
  return static_cast<idx*>(a.mutable_data());
}

/// A (1,) float64 array as a pointer to its one value.
double* scalar(py::handle obj, const char* what) { return convert::vec(obj, what, 1).d; }

engine::Integrator integrator(py::handle obj, const char* what, idx n_state) {
  engine::Integrator integ;
  integ.method = field(obj, "method").cast<int>();
  const std::string w(what);
  integ.settings = convert::vec(field(obj, "settings"), (w + ".settings").c_str(), N_SETTINGS);
  integ.work2d = convert::mat(field(obj, "work2d"), (w + ".work2d").c_str(), -1, n_state);
  integ.work1d = convert::vec(field(obj, "work1d"), (w + ".work1d").c_str(), n_state);
  integ.result = convert::vec(field(obj, "result"), (w + ".result").c_str(), 3);
  const idx need = integrate::work_rows(integ.method, n_state);  // −1: unknown, advance says so
  if (integ.work2d.rows < need) {
    throw py::value_error(w + ".work2d: " + std::to_string(integ.work2d.rows) + " rows where "
                          "method " + std::to_string(integ.method) + " needs " +
                          std::to_string(need) + " for " + std::to_string(n_state) +
                          " states (Method.work_rows)");
  }
  return integ;
}

engine::Watch watch(py::handle obj, idx k, idx n_state) {
  engine::Watch w;
  w.g = convert::mat(field(obj, "g"), "Watch.g", k);
  w.g_prev = convert::mat(field(obj, "g_prev"), "Watch.g_prev", k, w.g.cols);
  w.util = convert::vec(field(obj, "util"), "Watch.util", k);
  w.util_peak = convert::vec(field(obj, "util_peak"), "Watch.util_peak", k);
  w.events = convert::mat(field(obj, "events"), "Watch.events", -1, 4);
  w.n_events = counter(field(obj, "n_events"), "Watch.n_events");
  w.y_prev = convert::vec(field(obj, "y_prev"), "Watch.y_prev", n_state);
  w.stop_after = scalar(field(obj, "stop_after"), "Watch.stop_after");
  w.stiffens = convert::mat(field(obj, "stiffens"), "Watch.stiffens", k, w.g.cols);
  w.n_stiffening = counter(field(obj, "n_stiffening"), "Watch.n_stiffening");
  return w;
}

/// The estimator's state slots the loop indexes by: ValueError unless valid.
void check_estimator_state(const engine::Estimator& c) {
  const double nc = c.state[engine::N_CARRIED];
  if (!(c.state[engine::CHECK_EVERY] >= 1.0) || !(c.state[engine::LINEARISE_EVERY] >= 1.0) ||
      !(c.state[engine::LINEARISE_MAX] >= c.state[engine::LINEARISE_EVERY]) ||
      !(c.state[engine::OUTPUT_TURN] >= 0.0) ||
      !(nc >= 0.0 && nc <= static_cast<double>(c.carried.n))) {
    throw py::value_error("Estimator.state: CHECK_EVERY and LINEARISE_EVERY must be >= 1, "
                          "LINEARISE_MAX >= LINEARISE_EVERY, OUTPUT_TURN >= 0, N_CARRIED "
                          "within the slots");
  }
}

engine::Estimator estimator(py::handle obj, idx n_state, idx n_mounts) {
  engine::Estimator c;
  c.integ = integrator(obj, "Estimator", n_state);
  c.y = convert::vec(field(obj, "y"), "Estimator.y", n_state);
  c.s = convert::scratch(field(obj, "s"));
  convert::check_scratch(c.s, n_state, "Estimator.s");
  c.y_start = convert::vec(field(obj, "y_start"), "Estimator.y_start", n_state);
  c.y_end = convert::vec(field(obj, "y_end"), "Estimator.y_end", n_state);
  c.e = convert::vec(field(obj, "e"), "Estimator.e", n_state);
  c.carried = convert::vec(field(obj, "carried"), "Estimator.carried");
  c.n_body = field(obj, "n_body").cast<idx>();
  const idx np = c.carried.n, n_out = 3 * n_mounts + 3;
  if (np < 1 || np > n_state || c.n_body < 0 || c.n_body > np) {
    throw py::value_error("Estimator.carried: " + std::to_string(np) + " slots for " +
                          std::to_string(n_state) + " states and n_body " +
                          std::to_string(c.n_body) + " (need n_body <= slots <= states)");
  }
  c.jac = convert::vec(field(obj, "jac"), "Estimator.jac", np * np);
  c.prop = convert::vec(field(obj, "prop"), "Estimator.prop", np * np);
  if (c.n_body % 2 != 0 || c.n_body > 2 * engine::MAX_FREE) {
    throw py::value_error("Estimator.n_body: " + std::to_string(c.n_body) +
                          " (twice the free coordinates, at most 6)");
  }
  const idx nf = c.n_body / 2;
  c.decay = convert::vec(field(obj, "decay"), "Estimator.decay", nf * nf);
  c.work = convert::vec(field(obj, "work"), "Estimator.work", 2 * np * np);
  c.sens = convert::vec(field(obj, "sens"), "Estimator.sens", n_out * np);
  c.f0 = convert::vec(field(obj, "f0"), "Estimator.f0", n_state);
  c.f1 = convert::vec(field(obj, "f1"), "Estimator.f1", n_state);
  c.out0 = convert::vec(field(obj, "out0"), "Estimator.out0", n_out);
  c.out1 = convert::vec(field(obj, "out1"), "Estimator.out1", n_out);
  c.ec = convert::vec(field(obj, "ec"), "Estimator.ec", np);
  c.pc = convert::vec(field(obj, "pc"), "Estimator.pc", np);
  c.wrenches = convert::matc<6>(field(obj, "wrenches"), "Estimator.wrenches", n_mounts);
  c.state = convert::vec(field(obj, "state"), "Estimator.state", engine::N_ESTIMATOR_SLOTS);
  c.figures = convert::vec(field(obj, "figures"), "Estimator.figures", N_FIGURES);
  check_estimator_state(c);
  return c;
}

engine::Companion companion(py::handle obj, idx n_state, idx n_mounts,
                            idx k, idx n_events) {
  engine::Companion c;
  c.integ = integrator(obj, "Companion", n_state);
  c.switching_method = field(obj, "switching_method").cast<int>();
  c.switching_min_steps = field(obj, "switching_min_steps").cast<double>();
  // its own arrays hold it, and the chained first stage means the same to both (kernel.hpp
  // companion_advance: the explicit first-same-as-last pairs), or it is its own method
  const auto fsal = [](int method) { return method == DOPRI54 || method == VERNER65; };
  const int own = c.integ.method, other = c.switching_method;
  const idx need = integrate::work_rows(other, n_state);
  if (need < 0 || c.integ.work2d.rows < need || !(c.switching_min_steps >= 1.0) ||
      !(other == own || (fsal(own) && fsal(other)))) {
    throw py::value_error("Companion.switching_method " + std::to_string(other) + " at " +
                          std::to_string(c.switching_min_steps) + " steps beside method " +
                          std::to_string(own) + " in " + std::to_string(c.integ.work2d.rows) +
                          " work rows: not an explicit pair both hold, nor its own method, "
                          "or under 1 step");
  }
  c.exact_method = field(obj, "exact_method").cast<int>();  // -1: none
  c.check_method = field(obj, "check_method").cast<int>();
  c.check_steps = field(obj, "check_steps").cast<double>();
  const idx check_rows = integrate::work_rows(c.check_method, n_state);
  if (!fsal(c.check_method) || c.integ.work2d.rows < check_rows || !(c.check_steps >= 1.0) ||
      c.check_steps != std::floor(c.check_steps)) {
    throw py::value_error("Companion.check_method " + std::to_string(c.check_method) + " at " +
                          std::to_string(c.check_steps) + " steps in " +
                          std::to_string(c.integ.work2d.rows) +
                          " work rows: not an explicit first-same-as-last method they hold, or "
                          "not a whole number of steps, at least 1");
  }
  const idx exact_rows = c.exact_method < 0 ? 0 : integrate::work_rows(c.exact_method, n_state);
  if (exact_rows < 0 || c.integ.work2d.rows < exact_rows) {
    throw py::value_error("Companion.exact_method " + std::to_string(c.exact_method) + " in " +
                          std::to_string(c.integ.work2d.rows) + " work rows: not one they hold");
  }
  c.y = convert::vec(field(obj, "y"), "Companion.y", n_state);
  c.s = convert::scratch(field(obj, "s"));
  c.y_prev = convert::vec(field(obj, "y_prev"), "Companion.y_prev", n_state);
  c.g = convert::mat(field(obj, "g"), "Companion.g", k, n_events);
  c.g_prev = convert::mat(field(obj, "g_prev"), "Companion.g_prev", k, n_events);
  c.util = convert::vec(field(obj, "util"), "Companion.util", k);
  c.wrenches = convert::matc<6>(field(obj, "wrenches"), "Companion.wrenches", n_mounts);
  c.figures = convert::vec(field(obj, "figures"), "Companion.figures", N_FIGURES);
  c.error_rows = convert::mat(field(obj, "error_rows"), "Companion.error_rows",
                              engine::N_ERROR_ROWS, n_state);
  c.carry = convert::vec(field(obj, "carry"), "Companion.carry", engine::N_CARRY_SLOTS);
  c.treatments = convert::mat(field(obj, "treatments"), "Companion.treatments", k, n_events);
  c.twin_d = convert::mat(field(obj, "twin_d"), "Companion.twin_d", k, 3);
  convert::check_scratch(c.s, n_state, "Companion.s");
  return c;
}

/// run_samples' arrays, converted and checked once: converting its hundred-odd fields at
/// every call took 36–42 µs with nothing to advance, where one sample's work is a few µs. The
/// Loop holds the Python objects, so the views stay valid: NamedTuples and arrays, whose
/// fields cannot be rebound (the driver binds anew when it replaces one: a start's y, a
/// method switch).
/// The estimator's state slots, which Python may change between calls, are checked again at
/// each (`refresh`).
struct Loop {
  py::object refs[8];
  Model m;
  Scratch s;
  Vec u, y;
  engine::Integrator integ;
  engine::RunOptions opts;
  engine::Watch w;
  engine::Estimator est;
  engine::Companion comp;
  engine::Estimator* ep = nullptr;
  engine::Companion* cp = nullptr;

  Loop(py::handle integ_, py::handle m_, py::handle s_, py::handle u_, py::handle y_,
       py::handle opts_, py::handle watch_, py::handle estimate_)
      : refs{py::reinterpret_borrow<py::object>(integ_), py::reinterpret_borrow<py::object>(m_),
             py::reinterpret_borrow<py::object>(s_), py::reinterpret_borrow<py::object>(u_),
             py::reinterpret_borrow<py::object>(y_), py::reinterpret_borrow<py::object>(opts_),
             py::reinterpret_borrow<py::object>(watch_),
             py::reinterpret_borrow<py::object>(estimate_)} {
    m = convert::model(m_);
    s = convert::scratch(s_);
    y = convert::vec(y_, "y");
    convert::check_state(m, y);
    convert::check_scratch(s, y.n, "s");
    const idx n_state = y.n;
    const idx k = m.has_nl ? m.nl.k : 0;
    const idx n_mounts = m.lin_point.rows + k;
    integ = integrator(integ_, "Integrator", n_state);
    opts.zero_order = field(opts_, "zero_order").cast<bool>();
    opts.decimation = field(opts_, "decimation").cast<idx>();
    opts.chain = field(opts_, "chain").cast<bool>();
    if (opts.decimation < 1) throw py::value_error("RunOptions.decimation: below 1");
    w = watch(watch_, k, n_state);
    if (py::hasattr(estimate_, "carried")) {
      est = estimator(estimate_, n_state, n_mounts);
      ep = &est;
    } else if (!estimate_.is_none()) {
      comp = companion(estimate_, n_state, n_mounts, k, w.g.cols);
      cp = &comp;
    }
    u = convert::vec(u_, "u", INPUT_SIZE);
  }
  // ep and cp point into this object: built in place (py::init), never copied or moved.
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  /// Check again what Python may have changed since the binding.
  void refresh() const {
    if (ep != nullptr) check_estimator_state(est);
  }
};

}  // namespace

void bind_engine(py::module_& mod) {
  mod.attr("ESTIMATOR_SLOTS") = py::make_tuple(
      int(engine::CHECK_EVERY), int(engine::LINEARISE_EVERY), int(engine::LINEARISE_MAX),
      int(engine::JACOBIAN_KEEP), int(engine::OUTPUT_TURN), int(engine::LINEARISE_SPAN),
      int(engine::OUTPUT_PENDING), int(engine::PENDING), int(engine::PENDING_NORM),
      int(engine::PROPAGATOR_STEP), int(engine::FASTEST_RATE), int(engine::ERROR_NORM_MEAN),
      int(engine::SINCE_LINEARISED),
      int(engine::N_CARRIED), int(engine::CHECKS), int(engine::LINEARISATIONS),
      int(engine::EXPONENTIALS), int(engine::BORROWED), int(engine::N_ESTIMATOR_SLOTS));
  mod.attr("ERROR_ROWS") = py::make_tuple(
      int(engine::Y_START), int(engine::ERROR), int(engine::TRIAL), int(engine::RATE),
      int(engine::TWIN_RATE), int(engine::CHECK), int(engine::LOCAL),
      int(engine::N_ERROR_ROWS));
  mod.attr("CARRY_SLOTS") = py::make_tuple(
      int(engine::CARRYING), int(engine::SINCE_CHECK), int(engine::CHECK_NORM),
      int(engine::NORM_MEAN), int(engine::INTERVALS), int(engine::KICK_RATE), int(engine::RATED),
      int(engine::TWIN_RATED), int(engine::EXACT_HELD),
      int(engine::N_CARRY_SLOTS));
  py::dict treatments;
  treatments["carried"] = int(engine::CARRIED_THROUGH);
  treatments["integrated"] = int(engine::INTEGRATED);
  treatments["switching"] = int(engine::SWITCHING);
  mod.attr("TREATMENTS") = treatments;
  mod.attr("KICK_LIMIT") = engine::KICK_LIMIT;
  mod.attr("ENGAGED_CHECK_EVERY") = engine::ENGAGED_CHECK_EVERY;
  mod.attr("PERIOD_SHARE") = engine::PERIOD_SHARE;
  mod.attr("BOUND_PERIOD_SHARE") = engine::BOUND_PERIOD_SHARE;
  mod.attr("SPIKE_RATIO") = engine::SPIKE_RATIO;
  mod.attr("OUTPUT_STRIDE_MAX") = engine::OUTPUT_STRIDE_MAX;
  py::class_<Loop>(mod, "Loop",
                   "The per-sample loop's arrays (`run_samples`): each is converted and "
                   "checked (dtype, shape against the model) here, once; the Loop holds them, "
                   "and sees their contents as they change.")
      .def(py::init<py::handle, py::handle, py::handle, py::handle, py::handle, py::handle,
                    py::handle, py::handle>(),
           py::arg("integ"), py::arg("m"), py::arg("s"), py::arg("u"), py::arg("y"),
           py::arg("opts"), py::arg("watch"), py::arg("estimate"))
      .def("__repr__", [](const Loop& loop) {
        return "<Loop of " + std::to_string(loop.y.n) + " states>";
      });
  mod.def(
      "run_samples",
      [](Loop& loop, py::handle samples_, py::handle out_) {
        const Model& m = loop.m;
        const idx n_mounts = m.lin_point.rows + (m.has_nl ? m.nl.k : 0);
        engine::Samples smp;
        smp.t = convert::vec(field(samples_, "t"), "Samples.t");
        const idx n = smp.t.n;
        smp.f = convert::matc<3>(field(samples_, "f"), "Samples.f", n);
        smp.w = convert::matc<3>(field(samples_, "w"), "Samples.w", n);
        engine::Published out;
        out.counter = counter(field(out_, "counter"), "Published.counter");
        out.peak = convert::matc<6>(field(out_, "peak"), "Published.peak", n_mounts);
        out.pose = convert::matc<pose_row::WIDTH>(field(out_, "pose"), "Published.pose");
        out.wrenches = convert::stackc<6>(field(out_, "wrenches"), "Published.wrenches", -1, n_mounts);
        auto publish = convert::checked(field(out_, "publish"), "Published.publish", 'b', 1, 1);
        out.publish = static_cast<bool*>(publish.mutable_data());
        out.step_log = convert::mat(field(out_, "step_log"), "Published.step_log", -1, 3);
        out.wrench_abs_max =
            convert::matc<6>(field(out_, "wrench_abs_max"), "Published.wrench_abs_max", n_mounts);
        out.cos_tilt_min = scalar(field(out_, "cos_tilt_min"), "Published.cos_tilt_min");
        out.lin_util =
            convert::vec(field(out_, "lin_util"), "Published.lin_util", m.lin_point.rows);
        if (out.pose.rows < n || out.wrenches.n < n || publish.shape(0) < n ||
            out.step_log.rows < n) {
          throw py::value_error("Published: buffers shorter than the samples");
        }
        loop.refresh();
        engine::RunResult r;
        {
          py::gil_scoped_release release;  // the loop touches no Python object
          r = engine::run_samples(loop.integ, m, loop.s, loop.u, loop.y, smp, loop.opts, out,
                                  loop.w, loop.ep, loop.cp);
        }
        return py::make_tuple(r.done, r.status);
      },
      "Advance the bound y through samples 1..n−1 of `samples` (row 0: the last one done); "
      "returns (index of the last sample done, status: 0 all done, AT_EVENT, or the stepper's "
      "failure).",
      py::arg("loop"), py::arg("samples"), py::arg("out"));
  mod.def(
      "close_estimate",
      [](Loop& loop) {
        if (loop.ep == nullptr) return;
        loop.refresh();
        engine::close_run(*loop.ep);
      },
      "A run ends (a restart follows, or the stream ends): the sampled estimate (engine."
      "estimator) folds the outputs' errors of the intervals since it last did into its "
      "figures; nothing for the companion (it folds at every interval) or without an estimate.",
      py::arg("loop"));
  mod.def(
      "expm",
      [](py::handle a_, double scale) {
        const Mat a = convert::mat(a_, "a");
        if (a.rows != a.cols) throw py::value_error("a: not square");
        py::array_t<double> out({a.rows, a.rows}), w({2 * a.rows, a.rows});
        const Mat o{out.mutable_data(), a.rows, a.rows};
        const Mat w0{w.mutable_data(), a.rows, a.rows};
        const Mat w1{w.mutable_data() + a.rows * a.rows, a.rows, a.rows};
        if (!linalg::expm(a, scale, o, w0, w1)) throw py::value_error("a: not finite");
        return out;
      },
      "exp(scale·a) of a square float64 array (the error estimate's propagator: scaling and "
      "squaring of a Taylor polynomial, to about 1e-8 relative).",
      py::arg("a"), py::arg("scale"));
  mod.def(
      "fir_rows",
      [](py::handle raw_, py::handle half_, py::handle out_) {
        const Mat raw = convert::mat(raw_, "raw", 3);
        const Vec half = convert::vec(half_, "half");
        const Mat out = convert::mat(out_, "out", 3);
        if (half.n < 1) throw py::value_error("half: no taps");
        if (raw.cols < out.cols + 2 * (half.n - 1)) {
          throw py::value_error("raw: fewer columns than out needs (out + 2N)");
        }
        engine::fir_rows(raw, half, out);
      },
      "out[i, k]: the filtered rate (rad/s) of the sample at raw[:, k + N] (N = len(half) − 1).",
      py::arg("raw"), py::arg("half"), py::arg("out"));
}

}  // namespace mt
