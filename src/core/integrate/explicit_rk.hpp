// The explicit Runge–Kutta step with error control, advancing across one input-sample
// interval, for any embedded pair given as its table (dopri54.hpp's `Table` is Dormand–Prince
// 5(4)'s): a new explicit method is its table and a branch in stepper.hpp, not another copy of
// this loop.
//
// A table T has STAGES, C[STAGES], A[STAGES][STAGES − 1] (row i: the weights of stage i), E[STAGES]
// (the propagated weights minus the embedded ones), ORDER (of the error estimate), MAX_FACTOR and
// FSAL. Only first-same-as-last tables are taken (the last row of A is the propagated weights and
// its stage is dy/dt at the new point, the next step's first): the static_assert says so, where a
// table without it would need the weighted update this loop leaves out.
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"
#include "control.hpp"

namespace mt::integrate::explicit_rk {

/// The stage state y_new = y + Σⱼ (step·A[S][j])·k[j] over j < S in order, a state at a time
/// (its sum in a register, the table's zeros skipped at compile time: the operations on each
/// state are those of adding the rows one after another, so the same bits, without storing
/// and reloading y_new once per row). A nonzero weight times a step never rounds to zero
/// (steps are at least MIN_STEP_FRACTION of an interval).
template <class T, int S>
inline void stage_state(Vec y, double step, Mat k, Vec y_new) {
  double a[S];
  const double* rows[S];
  for (int j = 0; j < S; ++j) {
    a[j] = step * T::A[S][j];
    rows[j] = k.row(j).d;
  }
  const double* __restrict from = y.d;
  double* __restrict to = y_new.d;
  for (idx i = 0; i < y.n; ++i) {
    double sum = from[i];
    for (int j = 0; j < S; ++j) {
      if (T::A[S][j] != 0.0) sum += a[j] * rows[j][i];
    }
    to[i] = sum;
  }
}

/// Stages S.. of a step of `step` s from (t, y): each stage state into y_new and its rate into
/// k[S]; false as soon as a right-hand side fails (y_new then holds that stage's state).
template <class T, int S>
inline bool stages(Vec y, double t, double step, const Model& m, Scratch& s, Vec u, Mat k,
                   Vec y_new) {
  stage_state<T, S>(y, step, k, y_new);
  if (physics::rhs(t + T::C[S] * step, y_new, m, s, u, k.row(S)) != 0) return false;
  if constexpr (S + 1 < T::STAGES) {
    return stages<T, S + 1>(y, t, step, m, s, u, k, y_new);
  } else {
    return true;
  }
}

/// The error norm of the step of `step` s just taken from y (stages in k, its propagated
/// solution in y_new): the root mean square over the states of step·Σⱼ E[j]·k[j] over
/// atol + rtol·max(|y|, |y_new|).
template <class T>
inline double error_norm(Vec y, Vec y_new, Mat k, double step, double rtol, double atol) {
  double err = 0.0;
  for (idx i = 0; i < y.n; ++i) {
    double e = 0.0;
    for (int j = 0; j < T::STAGES; ++j) e += T::E[j] * k(j, i);
    const double scale = atol + rtol * py_max(std::fabs(y[i]), std::fabs(y_new[i]));
    const double x = step * e / scale;
    err += x * x;  // numba's x ** 2 (a literal integer exponent): x·x
  }
  return std::sqrt(err / static_cast<double>(y.n));
}

/// Advance y (in place) from t0 to t1 s by settings[MIN_STEPS] equal steps, every one taken: no
/// error control (a step of a length known to serve: the carried error's check where the twin
/// took one step, engine/kernel.hpp `add_local_error`). settings[CHAINED] is read and left as
/// `advance` reads and leaves it; settings[STEP], the controller's proposal, is untouched.
/// result: [largest error norm of the steps at settings' tolerances, steps, 0]. Returns
/// SUCCESS, else LEFT_CHART (a right-hand side failed) or NOT_FINITE (a stage state was not
/// finite), y then at the failed step's start.
template <class T>
inline int advance_fixed(Vec y, double t0, double t1, Vec settings, const Model& m, Scratch& s,
                         Vec u, Mat k, Vec y_new, Vec result) {
  static_assert(T::FSAL, "explicit_rk::advance_fixed takes first-same-as-last tables only");
  const idx steps = settings[MIN_STEPS] > 1.0 ? static_cast<idx>(settings[MIN_STEPS]) : 1, n = y.n;
  const double span = t1 - t0;
  const bool chained = settings[CHAINED] != 0.0;
  settings[CHAINED] = 0.0;  // set again below on success: k[0] is then dy/dt at (t1, y)
  if (!chained && physics::rhs(t0, y, m, s, u, k.row(0)) != 0) return LEFT_CHART;
  double err_max = 0.0, t = t0;
  idx taken = 0;
  int status = SUCCESS;
  for (; taken < steps; ++taken) {
    const double t_next = taken + 1 == steps ? t1 : t0 + span * (taken + 1.0) / steps;
    const double step = t_next - t;
    if (!stages<T, 1>(y, t, step, m, s, u, k, y_new)) {
      status = LEFT_CHART;
      for (idx i = 0; i < n; ++i) {
        if (!std::isfinite(y_new[i])) status = NOT_FINITE;
      }
      break;
    }
    err_max = py_max(err_max, error_norm<T>(y, y_new, k, step, settings[RTOL], settings[ATOL]));
    for (idx i = 0; i < n; ++i) {
      y[i] = y_new[i];
      k(0, i) = k(T::STAGES - 1, i);
    }
    t = t_next;
  }
  result[0] = err_max;
  result[1] = static_cast<double>(taken);
  result[2] = 0.0;
  if (status == SUCCESS) settings[CHAINED] = 1.0;
  return status;
}

/// Advance y (in place) from t0 to t1 s with input u held over the interval.
///
/// settings: the slots of constants.hpp Setting (STEP: first trial step s, 0 for the whole
/// interval, updated to the next proposal; CHAINED: on entry 1 if k[0] holds dy/dt at (t0, y)
/// for this input, left at 1 on success with k[0] = dy/dt at (t1, y)). k: (T::STAGES, n) stages;
/// y_new: (n,); result: [largest accepted error norm, accepted, rejected steps].
/// Returns a Status; y is left at the last accepted time on failure.
template <class T>
inline int advance(Vec y, double t0, double t1, Vec settings, const Model& m, Scratch& s, Vec u,
                   Mat k, Vec y_new, Vec result) {
  static_assert(T::FSAL, "explicit_rk::advance takes first-same-as-last tables only");
  const Interval iv = interval(settings, t0, t1);
  const double rtol = iv.rtol, atol = iv.atol, max_steps = iv.max_steps, span = iv.span;
  const double h_max = iv.h_max;
  double h = iv.h;
  const idx n = y.n;
  double t = t0;
  double err_max = 0.0;
  idx n_acc = 0, n_rej = 0;
  bool rhs_failed = false;  // the start state's right-hand side, then the last step's stages
  bool not_finite = false;  // the last rejection was for NaN or inf (stage state or error norm)
  bool retried = false;     // the last step tried was rejected
  if (settings[CHAINED] == 0.0) {  // else the caller put dy/dt at (t0, y) for this input in k[0]
    rhs_failed = physics::rhs(t, y, m, s, u, k.row(0)) != 0;
  }
  const bool start_failed = rhs_failed;  // off the chart at t0 itself: no step can help
  settings[CHAINED] = 0.0;  // set again below on success: k[0] is then dy/dt at (t1, y)
  while (t < t1) {
    // a step too small, or the start state itself off the chart (a stage of the first step off
    // it is retried shorter, as any step's: the motion itself may stay on it)
    const bool too_small = h < MIN_STEP_FRACTION * span || start_failed;
    const int status = give_up(n_acc + n_rej, max_steps, too_small, not_finite, rhs_failed);
    if (status != SUCCESS) {
      record(settings, result, h, err_max, n_acc, n_rej);
      return status;
    }
    const Trial trial = trial_step(t, t1, h, h_max, span);
    const double step = trial.step;
    const bool last = trial.last;
    const bool ok = stages<T, 1>(y, t, step, m, s, u, k, y_new);
    rhs_failed = !ok;
    if (rhs_failed) {
      // a NaN stage state also reads as off the chart: tell them apart (only on failure)
      not_finite = false;
      for (idx i = 0; i < n; ++i) {
        if (!std::isfinite(y_new[i])) not_finite = true;
      }
      h = step * OFF_CHART_SHRINK;
      n_rej += 1;
      retried = true;
      continue;
    }
    // y_new holds the propagated solution (FSAL: the last stage row of A is the weights B).
    double err = error_norm<T>(y, y_new, k, step, rtol, atol);
    // NaN or inf: rejected below and shrunk by the most; if it persists, NOT_FINITE
    not_finite = !std::isfinite(err);
    const double factor =
        step_factor(err, not_finite, T::ORDER, growth_limit(settings, retried, T::MAX_FACTOR));
    if (err <= 1.0) {
      t = last ? t1 : t + step;
      for (idx i = 0; i < n; ++i) {
        y[i] = y_new[i];
        k(0, i) = k(T::STAGES - 1, i);
      }
      err_max = py_max(err_max, err);
      n_acc += 1;
      h = next_proposal(step, h, factor, last);
      retried = false;
    } else {
      h = step * py_min(1.0, factor);
      n_rej += 1;
      retried = true;
    }
  }
  record(settings, result, h, err_max, n_acc, n_rej);
  settings[CHAINED] = 1.0;
  return SUCCESS;
}

}  // namespace mt::integrate::explicit_rk
