// Step-size control shared by the embedded methods (integrate/control.py: the classic
// controller of Hairer, Nørsett & Wanner I, §II.4, the give-up rules and `forget`). The same
// operations in the same order as the Python reference; max/min with Python's NaN semantics.
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"

namespace mt::integrate {

constexpr double SAFETY = 0.9, MIN_FACTOR = 0.2;
/// A step whose right-hand side failed (off the chart, NaN) is retried this much shorter.
constexpr double OFF_CHART_SHRINK = 0.25;
/// A step shorter than this fraction of the interval is a failure.
constexpr double MIN_STEP_FRACTION = 1e-12;

/// The next step over this one after an error norm err of an order-`order` estimate.
inline double step_factor(double err, bool not_finite, int order, double max_factor) {
  if (not_finite) return MIN_FACTOR;
  if (err == 0.0) return max_factor;
  const double expo = -1.0 / static_cast<double>(order + 1);
  return py_min(max_factor, py_max(MIN_FACTOR, SAFETY * std::pow(err, expo)));
}

/// The largest factor the step may grow by at the step to conclude: max_factor, or 1 where that
/// step came right after a rejection and settings[HOLD_AFTER_REJECT] is set (Hairer, Nørsett &
/// Wanner I, §II.4: facmax = 1 right after a rejection, as their DOPRI5 code does). Where the
/// error does not shrink as the step's order says (a right-hand side that bends inside the
/// step: a joint face between sticking and sliding), a step grown at once from one accepted
/// with a tiny error is rejected again, and again (the bolted genset's companion under its
/// shock: 155 of its 436 rejections, docs/benchmarks.md).
inline double growth_limit(Vec settings, bool after_rejection, double max_factor) {
  return after_rejection && settings[HOLD_AFTER_REJECT] != 0.0 ? 1.0 : max_factor;
}

/// SUCCESS to go on, else the status to stop with: too many steps, or a step too small to go
/// on with (NaN or inf, the chart's edge, or plain underflow, as the last rejection says).
inline int give_up(idx steps, double max_steps, bool too_small, bool not_finite,
                   bool off_chart) {
  if (static_cast<double>(steps) >= max_steps) return not_finite ? NOT_FINITE : TOO_MANY_STEPS;
  if (too_small) {
    if (not_finite) return NOT_FINITE;
    return off_chart ? LEFT_CHART : STEP_TOO_SMALL;
  }
  return SUCCESS;
}

/// The step h from t as the time grid holds it, (t + h) − t (exact): the state then advances
/// by the span the time does, and an interval's steps add up to it to the bit. Taken as h, a
/// step whose end t + h rounds (by up to half an ulp of t: 1.1e-16 s at 1 s of the engine's
/// time) moves the state a little more or less than the time; the estimator's checks, two or
/// more such steps against the twin's one, measured that rounding times the state's rate as
/// local error (the pump at 10 kHz under a half-sine shock: 34× its true error of 1e-13,
/// checked at every interval; more with more check steps).
inline double on_grid(double t, double h) { return (t + h) - t; }

/// The step (s) to try from t toward the interval's end t1 (the proposal h, at most h_max),
/// and whether it is the interval's last (then it ends exactly at t1).
struct Trial {
  double step;
  bool last;
};
inline Trial trial_step(double t, double t1, double h, double h_max, double span) {
  const double step = py_min(h, h_max);
  const bool last = t + step >= t1 - 1e-12 * span;
  return {last ? t1 - t : on_grid(t, step), last};
}

/// The proposal after an accepted step: from a full step, not from a last step clipped to the
/// interval (that one keeps the proposal it had).
inline double next_proposal(double step, double h, double factor, bool last) {
  return (!last || step >= h) ? step * factor : h;
}

/// Forget a stepper's history (after its state jumped: a start, a restart, a resync): the step
/// proposal, the chained last stage, the Jacobian held and its matrix functions.
inline void forget(Vec settings) {
  settings[STEP] = 0.0;
  settings[CHAINED] = 0.0;
  settings[JACOBIAN_AGE] = 0.0;
  settings[PHI_STEP] = 0.0;
}

/// What `conclude` decided: the time reached (s), the next step to try (s), whether accepted.
struct Concluded {
  double t;
  double h;
  bool accepted;
};

/// End a step of a method that restarts from f(t, y) (no FSAL: the linearising ones): accept
/// it if err ≤ 1 and the right-hand side at (t + step, y_new) is defined (y ← y_new, and
/// k[row0] ← f there, for the next step and for the outputs; k[row1] is scratch), else reject.
inline Concluded conclude(Vec y, Vec y_new, double t, double t1, double step, double h,
                          bool last, double err, bool not_finite, int order, double max_factor,
                          const Model& m, Scratch& s, Vec u, Mat k, idx row0, idx row1) {
  const double factor = step_factor(err, not_finite, order, max_factor);
  const double t_new = last ? t1 : t + step;
  if (err <= 1.0 && physics::rhs(t_new, y_new, m, s, u, k.row(row1)) == 0) {
    for (idx r = 0; r < y.n; ++r) {
      y[r] = y_new[r];
      k(row0, r) = k(row1, r);
    }
    return {t_new, next_proposal(step, h, factor, last), true};
  }
  return {t, step * py_min(1.0, factor), false};
}

/// Store the run's figures: settings[STEP] ← h, result ← [largest accepted error norm,
/// accepted steps, rejected steps].
/// What every method reads of its settings for one input interval [t0, t1] (s).
struct Interval {
  double rtol, atol, max_steps;
  double span;   // t1 − t0, s
  double h_max;  // the longest step taken (span / MIN_STEPS); caps steps, not the proposal
  double h;      // the first step to try: the proposal held, else the whole interval
};
inline Interval interval(Vec settings, double t0, double t1) {
  const double span = t1 - t0;
  const double h = settings[STEP];
  return {settings[RTOL], settings[ATOL],     settings[MAX_SUBSTEPS],
          span,           span / settings[MIN_STEPS], h <= 0.0 ? span : h};
}

/// Take `conclude`'s outcome: its time and next proposal, the step counted (an accepted
/// one's error norm into the largest).
inline void take(const Concluded& done, double err, double& t, double& h, double& err_max,
                 idx& n_acc, idx& n_rej) {
  t = done.t;
  h = done.h;
  if (done.accepted) {
    err_max = py_max(err_max, err);
    n_acc += 1;
  } else {
    n_rej += 1;
  }
}

inline void record(Vec settings, Vec result, double h, double err_max, idx n_acc, idx n_rej) {
  settings[STEP] = h;
  result[0] = err_max;
  result[1] = static_cast<double>(n_acc);
  result[2] = static_cast<double>(n_rej);
}

}  // namespace mt::integrate
