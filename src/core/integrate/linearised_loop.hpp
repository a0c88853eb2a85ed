// The step loop the linearising methods share (exprb32, ros34pw2): the linearisation at the
// interval's start, the give-up rules, a held Jacobian renewed after a rejection, a step
// retried shorter where one of its stages failed, and `conclude`. A method gives only its step:
// how long, its stages, its error norm.
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../views.hpp"
#include "control.hpp"
#include "fd_jacobian.hpp"

namespace mt::integrate {

/// How a linearising method's try at one step went: TRIED (its error norm computed, y_new
/// filled), or a stage failed before that, its matrix functions not finite or a right-hand
/// side off the chart (the give-up rules tell the two apart, `give_up`).
enum class Tried : int { TRIED, NOT_FINITE, OFF_CHART };

/// One try at a step: its length (s), whether it ends the interval, how it went, and its error
/// norm (inf where a stage failed; inf or NaN read as not finite).
struct StepTry {
  double step;
  bool last;
  Tried tried;
  double err;
};

/// What a linearising method is to the loop: its work rows (`JacRows`; `conclude` takes f and
/// its scratch), the magnitude its Jacobian's columns are differenced over at least, how many
/// intervals a Jacobian serves, and its controller's order and largest growth.
struct Linearising {
  JacRows rows;
  double typical;
  double max_age;
  int order;
  double max_factor;
};

/// Advance y (in place) over the interval iv of [t0, t1] s with input u held over it: the
/// signature and statuses of explicit_rk::advance (settings[CHAINED] is left at 0; k[rows.f]
/// holds f at the step's start for try_step). try_step(t, h) tries a step from (t, y) with the
/// proposal h (s) and returns a StepTry, its end state in y_new.
template <class TryStep>
inline int advance_linearised(const Interval& iv, const Linearising& method, Vec y, double t0,
                              double t1, Vec settings, const Model& m, Scratch& s, Vec u, Mat k,
                              Vec y_new, Vec result, TryStep&& try_step) {
  const JacRows rows = method.rows;
  settings[CHAINED] = 0.0;
  double t = t0, h = iv.h, err_max = 0.0;
  idx n_acc = 0, n_rej = 0;
  // W-method: a Jacobian serves up to method.max_age intervals, and is taken afresh at the
  // first rejected step of an interval it did not start
  if (!linearise(y, t, m, s, u, k, method.typical, rows, settings, method.max_age)) {
    record(settings, result, h, err_max, n_acc, n_rej);
    return LEFT_CHART;
  }
  bool not_finite = false, off_chart = false;  // what the last rejection was for
  bool retried = false;                         // the last step tried was rejected
  while (t < t1) {
    const bool too_small = h < MIN_STEP_FRACTION * iv.span;
    const int status = give_up(n_acc + n_rej, iv.max_steps, too_small, not_finite, off_chart);
    if (status != SUCCESS) {
      record(settings, result, h, err_max, n_acc, n_rej);
      return status;
    }
    const StepTry got = try_step(t, h);
    const bool ok = got.tried == Tried::TRIED;
    not_finite = got.tried == Tried::NOT_FINITE || (ok && !std::isfinite(got.err));
    off_chart = got.tried == Tried::OFF_CHART;
    if (!(got.err <= 1.0)) renew_if_stale(y, t, m, s, u, k, method.typical, rows, settings);
    if (!ok) {
      h = got.step * OFF_CHART_SHRINK;
      n_rej += 1;
      retried = true;
      continue;
    }
    const Concluded done =
        conclude(y, y_new, t, t1, got.step, h, got.last, got.err, not_finite, method.order,
                 growth_limit(settings, retried, method.max_factor), m, s, u, k, rows.f,
                 rows.tmp);
    take(done, got.err, t, h, err_max, n_acc, n_rej);
    retried = !done.accepted;
  }
  record(settings, result, h, err_max, n_acc, n_rej);
  return SUCCESS;
}

}  // namespace mt::integrate
