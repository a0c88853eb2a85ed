// Dormand–Prince 5(4) with error control, advancing across one input-sample interval
// (integrate/dopri54.py: the table, the work layout and the step logic, the same operations in
// the same order). The state advances with the 5th-order solution; the embedded 4th-order one
// estimates the local error. Error norm: RMS of err / (atol + rtol·|y|).
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"
#include "control.hpp"

namespace mt::integrate::dopri54 {

// The table, as dopri54.py writes it (Python's int/int true division is the correctly rounded
// quotient, as these double divisions of exactly representable integers are).
constexpr double C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
constexpr double A[7][6] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {1.0 / 5, 0.0, 0.0, 0.0, 0.0, 0.0},
    {3.0 / 40, 9.0 / 40, 0.0, 0.0, 0.0, 0.0},
    {44.0 / 45, -56.0 / 15, 32.0 / 9, 0.0, 0.0, 0.0},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0.0, 0.0},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0.0},
    {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84},
};
/// 5th-order weights (the last row of A: the last stage is first-same-as-last).
inline constexpr const double (&B)[6] = A[6];
/// 5th-order weights minus the embedded 4th-order weights.
constexpr double E[7] = {71.0 / 57600,      0.0,          -71.0 / 16695, 71.0 / 1920,
                         -17253.0 / 339200, 22.0 / 525, -1.0 / 40};
constexpr bool FSAL = true;
/// Order of the error estimate (the controller's exponent is −1/(ORDER + 1)).
constexpr int ORDER = 4;
constexpr double MAX_FACTOR = 10.0;
/// Rows of the 2-D work array (the stages, the FSAL one included).
constexpr idx STAGES = 7;

inline idx work_rows(idx /*n*/) { return STAGES; }

/// Advance y (in place) from t0 to t1 s with input u held over the interval.
///
/// settings: the slots of constants.hpp Setting (STEP: first trial step s, 0 for the whole
/// interval, updated to the next proposal; CHAINED: on entry 1 if k[0] holds dy/dt at (t0, y)
/// for this input, left at 1 on success with k[0] = dy/dt at (t1, y)). k: (7, n) stages;
/// y_new: (n,); result: [largest accepted error norm, accepted, rejected steps].
/// Returns a Status; y is left at the last accepted time on failure.
inline int advance(Vec y, double t0, double t1, Vec settings, const Model& m, Scratch& s, Vec u,
                   Mat k, Vec y_new, Vec result) {
  const Interval iv = interval(settings, t0, t1);
  const double rtol = iv.rtol, atol = iv.atol, max_steps = iv.max_steps, span = iv.span;
  const double h_max = iv.h_max;
  double h = iv.h;
  const idx n = y.n;
  double t = t0;
  double err_max = 0.0;
  idx n_acc = 0, n_rej = 0;
  bool rhs_failed = false;
  bool not_finite = false;  // the last rejection was for NaN or inf (stage state or error norm)
  if (settings[CHAINED] == 0.0) {  // else the caller put dy/dt at (t0, y) for this input in k[0]
    rhs_failed = physics::rhs(t, y, m, s, u, k.row(0)) != 0;
  }
  settings[CHAINED] = 0.0;  // set again below on success: k[0] is then dy/dt at (t1, y)
  while (t < t1) {
    // a step too small, or the start state itself off the chart (no step can help)
    const bool too_small = h < MIN_STEP_FRACTION * span || (rhs_failed && n_acc == 0 && t == t0);
    const int status = give_up(n_acc + n_rej, max_steps, too_small, not_finite, rhs_failed);
    if (status != SUCCESS) {
      record(settings, result, h, err_max, n_acc, n_rej);
      return status;
    }
    const Trial trial = trial_step(t, t1, h, h_max, span);
    const double step = trial.step;
    const bool last = trial.last;
    bool ok = true;
    for (int stage = 1; stage < 7; ++stage) {
      for (idx i = 0; i < n; ++i) y_new[i] = y[i];
      for (int j = 0; j < stage; ++j) {  // row by row: the inner loop runs along k[j]
        const double a = step * A[stage][j];
        if (a != 0.0) {
          const Vec kj = k.row(j);
          for (idx i = 0; i < n; ++i) y_new[i] += a * kj[i];
        }
      }
      if (physics::rhs(t + C[stage] * step, y_new, m, s, u, k.row(stage)) != 0) {
        ok = false;
        break;
      }
    }
    rhs_failed = !ok;
    if (rhs_failed) {
      // a NaN stage state also reads as off the chart: tell them apart (only on failure)
      not_finite = false;
      for (idx i = 0; i < n; ++i) {
        if (!std::isfinite(y_new[i])) not_finite = true;
      }
      h = step * OFF_CHART_SHRINK;
      n_rej += 1;
      continue;
    }
    // y_new holds the 5th-order solution (the last stage row equals B).
    double err = 0.0;
    for (idx i = 0; i < n; ++i) {
      double e = 0.0;
      for (int j = 0; j < 7; ++j) e += E[j] * k(j, i);
      const double scale = atol + rtol * py_max(std::fabs(y[i]), std::fabs(y_new[i]));
      const double x = step * e / scale;
      err += x * x;  // numba's x ** 2 (a literal integer exponent): x·x
    }
    err = std::sqrt(err / static_cast<double>(n));
    // NaN or inf: rejected below and shrunk by the most; if it persists, NOT_FINITE
    not_finite = !std::isfinite(err);
    const double factor = step_factor(err, not_finite, ORDER, MAX_FACTOR);
    if (err <= 1.0) {
      t = last ? t1 : t + step;
      for (idx i = 0; i < n; ++i) {
        y[i] = y_new[i];
        k(0, i) = k(6, i);
      }
      err_max = py_max(err_max, err);
      n_acc += 1;
      h = next_proposal(step, h, factor, last);
    } else {
      h = step * py_min(1.0, factor);
      n_rej += 1;
    }
  }
  record(settings, result, h, err_max, n_acc, n_rej);
  settings[CHAINED] = 1.0;
  return SUCCESS;
}

}  // namespace mt::integrate::dopri54
